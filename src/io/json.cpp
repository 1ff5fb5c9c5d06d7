#include "ctid/io/json.hpp"

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <set>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "ctid/core/check.hpp"
#include "ctid/core/names.hpp"
#include "ctid/io/file.hpp"

namespace ctid {

// Ordered: object members keep the file's order (a grey-box model's outputs and parameters are declared in order).
using json = nlohmann::ordered_json;

const char* version() { return CTID_VERSION_STRING; }

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
double to_num(const json& j) { return j.is_null() ? kNaN : j.get<double>(); }

json vec(const Eigen::VectorXd& v) {
  json a = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(num(v(i)));
  return a;
}
json mat(const Eigen::MatrixXd& m) {
  json a = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) a.push_back(vec(m.row(r).transpose()));
  return a;
}

struct Reader {
  std::string source;
  [[noreturn]] void fail(const std::string& what) const { throw FileError(source + ": " + what); }
  const json& member(const json& j, const char* key, const char* where) const {
    if (!j.is_object() || !j.contains(key)) fail(detail::format("{} has no member \"{}\"", where, key));
    return j.at(key);
  }
  Eigen::VectorXd vector(const json& j, const char* what) const {
    if (!j.is_array()) fail(detail::format("\"{}\" must be an array of numbers", what));
    Eigen::VectorXd v(static_cast<Eigen::Index>(j.size()));
    for (std::size_t i = 0; i < j.size(); ++i) {
      if (!j[i].is_number() && !j[i].is_null()) fail(detail::format("\"{}\"[{}] is not a number", what, i));
      v(static_cast<Eigen::Index>(i)) = to_num(j[i]);
    }
    return v;
  }
  // A count (samples, parameters, iterations): a whole number in [0, INT_MAX].
  int count(const json& j, const char* what) const {
    const double v = j.is_number() ? j.get<double>() : kNaN;
    if (!(v >= 0 && v <= std::numeric_limits<int>::max()) || v != std::floor(v))
      fail(detail::format("\"{}\" must be a whole number in [0, {}], got {}", what, std::numeric_limits<int>::max(),
                          j.dump()));
    return static_cast<int>(v);
  }
  Eigen::MatrixXd matrix(const json& j, const char* what) const {
    if (!j.is_array()) fail(detail::format("\"{}\" must be an array of rows", what));
    if (j.empty()) return Eigen::MatrixXd(0, 0);
    Eigen::MatrixXd m;
    for (std::size_t r = 0; r < j.size(); ++r) {
      const Eigen::VectorXd row = vector(j[r], what);
      if (r == 0) m.resize(static_cast<Eigen::Index>(j.size()), row.size());
      if (row.size() != m.cols()) fail(detail::format("\"{}\" rows have different lengths", what));
      m.row(static_cast<Eigen::Index>(r)) = row.transpose();
    }
    return m;
  }
};

json tf_json(const TransferFunction& tf) {
  return {{"type", "transfer_function"}, {"num", vec(tf.num().coefficients())}, {"den", vec(tf.den().coefficients())},
          {"io_delay", tf.io_delay()}};
}

json model_json(const LinearModel& m) {
  if (const auto* tf = std::get_if<TransferFunction>(&m)) return tf_json(*tf);
  if (const auto* mi = std::get_if<MisoModel>(&m)) {
    json ch = json::array();
    for (const auto& c : mi->channels) ch.push_back(tf_json(c));
    return {{"type", "miso"}, {"channels", ch}};
  }
  const auto& ss = std::get<StateSpace>(m);
  json j = {{"type", "state_space"}, {"A", mat(ss.A())}, {"B", mat(ss.B())}, {"C", mat(ss.C())}, {"D", mat(ss.D())}};
  if (ss.has_innovation_gain()) j["K"] = mat(ss.K());
  return j;
}

LinearModel model_from(const json& root, const Reader& rd) {
  const json& m = root.is_object() && root.contains("model") ? root.at("model") : root;
  const json& type = rd.member(m, "type", "the model");
  if (!type.is_string()) rd.fail("model \"type\" must be a string");
  const std::string t = type.get<std::string>();
  try {
    if (t == "transfer_function") {
      if (m.contains("io_delay") && !m.at("io_delay").is_number())
        rd.fail("\"io_delay\" must be a number (seconds)");
      const double delay = m.contains("io_delay") ? m.at("io_delay").get<double>() : 0.0;
      TransferFunction g(rd.vector(rd.member(m, "num", "the model"), "num"), rd.vector(rd.member(m, "den", "the model"), "den"),
                         delay);
      if (const std::string why = parasitic_pole_problem(g); !why.empty()) rd.fail(why);
      return g;
    }
    if (t == "miso") {
      const json& ch = rd.member(m, "channels", "the model");
      if (!ch.is_array() || ch.empty()) rd.fail("\"channels\" must be a non-empty array of transfer functions");
      MisoModel mm;
      for (const auto& c : ch) {
        const LinearModel one = model_from(c, rd);
        if (!std::holds_alternative<TransferFunction>(one)) rd.fail("every MISO channel must be a transfer_function");
        mm.channels.push_back(std::get<TransferFunction>(one));
      }
      return mm;
    }
    if (t == "state_space")
      return StateSpace(rd.matrix(rd.member(m, "A", "the model"), "A"), rd.matrix(rd.member(m, "B", "the model"), "B"),
                        rd.matrix(rd.member(m, "C", "the model"), "C"), rd.matrix(rd.member(m, "D", "the model"), "D"),
                        m.contains("K") ? rd.matrix(m.at("K"), "K") : Eigen::MatrixXd());
  } catch (const InvalidArgument& e) {
    rd.fail(std::string("invalid model: ") + e.what());
  }
  rd.fail(detail::format("model type \"{}\" is not a linear model this command can use (transfer_function, state_space)", t));
}

json parse_text(const std::string& text, const Reader& rd) {
  // A key twice in one object: JSON parsers keep one of the values (nlohmann the last) without a word; refused.
  std::vector<std::set<std::string>> open;  // the keys of each object being read
  std::string repeated;
  const json::parser_callback_t keys = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) open.emplace_back();
    else if (event == json::parse_event_t::object_end && !open.empty()) open.pop_back();
    else if (event == json::parse_event_t::key && !open.empty() && !open.back().insert(parsed.get<std::string>()).second &&
             repeated.empty())
      repeated = parsed.get<std::string>();
    return true;
  };
  json j;
  try {
    j = json::parse(text, keys);
  } catch (const json::exception& e) {  // parse_error, or out_of_range for a number like 1e99999
    rd.fail(std::string("not valid JSON: ") + e.what());
  }
  if (!repeated.empty())
    rd.fail(detail::format("the key \"{}\" appears twice in one object; a JSON reader would silently keep one of the "
                           "values: keep the one you mean", repeated));
  return j;
}

}  // namespace

std::string model_to_json(const LinearModel& m, int indent) { return model_json(m).dump(indent); }

LinearModel parse_model_json(const std::string& text, const std::string& source) {
  const Reader rd{source};
  return model_from(parse_text(text, rd), rd);
}

LinearModel read_model_json(const std::string& path) { return parse_model_json(read_text_file(path), path); }

void write_model_json(const std::string& path, const LinearModel& m) {
  write_text_file(path, model_to_json(m) + "\n");
}

namespace {
json fsf_json(const FsfModel& f) {
  json j = {{"type", "fsf"}, {"delta", f.delta()}, {"N", f.N()}, {"n", f.n()}, {"shift", f.shift()}, {"theta", vec(f.theta())}};
  if (f.covariance().size() > 0) j["covariance"] = mat(f.covariance());
  return j;
}

template <class Terms>
json terms_json(const Terms& terms, const Eigen::VectorXd& c) {
  json t = json::array();
  for (size_t i = 0; i < terms.size(); ++i) t.push_back({{"name", terms[i].name()}, {"value", num(c(static_cast<Eigen::Index>(i)))}});
  return t;
}
json narx_json(const NarxModel& m) { return {{"type", "narx"}, {"ts", m.ts()}, {"terms", terms_json(m.terms(), m.coefficients())}}; }
json nde_json(const NdeModel& m0, bool exact) {
  const NdeModel m = !exact && m0.coefficient("y") != 0.0 ? m0.normalized() : m0;
  return {{"type", "nde"}, {"terms", terms_json(m.terms(), m.coefficients())}};
}

json greybox_json(const GreyboxModel& g) {
  const GreyboxSpec& s = g.spec();
  json outputs = json::object(), params = json::object(), eqs = json::object(), init = json::object();
  for (const auto& [name, e] : s.outputs) outputs[name] = e;
  for (const auto& p : s.parameters) {
    json q = {{"value", p.value}};
    if (p.lower > -INFINITY) q["lower"] = p.lower;
    if (p.upper < INFINITY) q["upper"] = p.upper;
    if (p.fixed) q["fixed"] = true;
    params[p.name] = q;
  }
  for (size_t i = 0; i < s.states.size(); ++i) {
    eqs[s.states[i]] = s.equations[i];
    const GreyboxInitial& in = s.initial[i];
    // A number is written as a number; an estimated state with its start (or estimate) as {"estimate": true, "value"}.
    char* end = nullptr;
    const double v = std::strtod(in.expression.c_str(), &end);
    const json value = !in.expression.empty() && end && *end == '\0' ? json(v) : json(in.expression);
    if (!in.estimate) init[s.states[i]] = value;
    else if (in.expression.empty()) init[s.states[i]] = "estimate";
    else init[s.states[i]] = {{"estimate", true}, {"value", value}};
  }
  return {{"type", "greybox"}, {"inputs", s.inputs}, {"states", s.states},   {"outputs", outputs},
          {"parameters", params},  {"equations", eqs},   {"initial", init}};
}

// The model object of a bare model or an envelope, of the given type.
const json& typed_model(const json& j, const char* type, const Reader& rd) {
  const json& m = j.contains("model") ? j.at("model") : j;
  const json& t = rd.member(m, "type", "the model");
  if (!t.is_string() || t.get<std::string>() != type)
    rd.fail(detail::format("the model type is {}, expected \"{}\"", t.dump(), type));
  return m;
}

template <class Term>
std::pair<std::vector<Term>, Eigen::VectorXd> read_terms(const json& m, const Reader& rd) {
  const json& ts = rd.member(m, "terms", "the model");
  if (!ts.is_array()) rd.fail("\"terms\" must be an array of {name, value}");
  std::vector<Term> terms;
  Eigen::VectorXd c(static_cast<Eigen::Index>(ts.size()));
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const json& t = ts[i];
    if (!t.is_object() || !t.contains("name") || !t.contains("value") || !t.at("name").is_string() ||
        !t.at("value").is_number())
      rd.fail(detail::format("terms[{}] must be {{\"name\": string, \"value\": number}}", i));
    try {
      terms.push_back(Term::parse(t.at("name").get<std::string>()));
    } catch (const InvalidArgument& e) {
      rd.fail(detail::format("terms[{}]: {}", i, e.what()));
    }
    c(static_cast<Eigen::Index>(i)) = t.at("value").get<double>();
  }
  return {terms, c};
}

// A NARX / NDE model object (already of its type).
NarxModel narx_from(const json& m, const Reader& rd) {
  auto [terms, c] = read_terms<NarxTerm>(m, rd);
  const json& ts = rd.member(m, "ts", "the model");
  if (!ts.is_number()) rd.fail("\"ts\" must be a number (seconds)");
  try {
    return NarxModel(terms, c, ts.get<double>());
  } catch (const InvalidArgument& e) {
    rd.fail(std::string("invalid NARX model: ") + e.what());
  }
}

GreyboxModel greybox_from(const json& m, const Reader& rd) {
  GreyboxSpec s;
  auto names = [&](const char* key, bool required) {
    std::vector<std::string> v;
    if (!m.contains(key)) {
      if (required) rd.fail(detail::format("the grey-box model has no member \"{}\" (an array of names)", key));
      return v;
    }
    const json& a = m.at(key);
    if (!a.is_array()) rd.fail(detail::format("\"{}\" must be an array of names", key));
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (!a[i].is_string()) rd.fail(detail::format("\"{}\"[{}] must be a name (a string)", key, i));
      v.push_back(a[i].get<std::string>());
    }
    return v;
  };
  auto text = [&](const json& j, const std::string& where) {
    if (j.is_string()) return j.get<std::string>();
    if (j.is_number()) return detail::round_trip(j.get<double>());
    rd.fail(where + " must be an expression (a string) or a number");
  };
  auto object = [&](const char* key) -> const json& {
    const json& o = rd.member(m, key, "the grey-box model");
    if (!o.is_object()) rd.fail(detail::format("\"{}\" must be an object", key));
    return o;
  };
  s.inputs = names("inputs", false);
  s.states = names("states", true);
  for (const auto& [name, e] : object("outputs").items()) s.outputs.emplace_back(name, text(e, "outputs." + name));
  if (m.contains("parameters"))
    for (const auto& [name, q] : object("parameters").items()) {
      GreyboxParameter p;
      p.name = name;
      if (q.is_number()) p.value = q.get<double>();
      else if (q.is_object()) {
        for (const auto& [k, v] : q.items()) {
          if (k == "fixed") {
            if (!v.is_boolean()) rd.fail("parameters." + name + ".fixed must be true or false");
            p.fixed = v.get<bool>();
            continue;
          }
          if (k != "value" && k != "lower" && k != "upper")
            rd.fail(detail::format("parameters.{}: unknown member \"{}\" (value, lower, upper, fixed)", name, k));
          if (!v.is_number() && !v.is_null()) rd.fail(detail::format("parameters.{}.{} must be a number", name, k));
          const double x = v.is_null() ? (k == "lower" ? -INFINITY : k == "upper" ? INFINITY : kNaN) : v.get<double>();
          (k == "value" ? p.value : k == "lower" ? p.lower : p.upper) = x;
        }
        if (!q.contains("value")) rd.fail("parameters." + name + " has no \"value\"");
      } else {
        rd.fail("parameters." + name + " must be a number or {\"value\", \"lower\", \"upper\", \"fixed\"}");
      }
      s.parameters.push_back(p);
    }
  const json& eqs = object("equations");
  const json init = m.contains("initial") ? m.at("initial") : json::object();
  if (!init.is_object()) rd.fail("\"initial\" must be an object: state -> number, expression or \"estimate\"");
  for (const auto& [name, e] : eqs.items())
    if (std::find(s.states.begin(), s.states.end(), name) == s.states.end())
      rd.fail(detail::format("equations.{}: '{}' is not a state{}", name, name,
                             closest_name(name, s.states).empty() ? "" : "; did you mean '" + closest_name(name, s.states) + "'?"));
  for (const auto& [name, e] : init.items())
    if (std::find(s.states.begin(), s.states.end(), name) == s.states.end())
      rd.fail(detail::format("initial.{}: '{}' is not a state", name, name));
  for (const auto& x : s.states) {
    if (!eqs.contains(x)) rd.fail(detail::format("\"equations\" has no equation for the state {} (dx/dt)", x));
    s.equations.push_back(text(eqs.at(x), "equations." + x));
    GreyboxInitial in;
    if (init.contains(x)) {
      const json& v = init.at(x);
      if (v.is_string() && v.get<std::string>() == "estimate") {
        in.estimate = true;
        in.expression.clear();
      } else if (v.is_object()) {
        if (!v.contains("estimate") || !v.at("estimate").is_boolean())
          rd.fail("initial." + x + " must be a number, an expression, \"estimate\" or {\"estimate\": true, \"value\": start}");
        in.estimate = v.at("estimate").get<bool>();
        in.expression = v.contains("value") ? text(v.at("value"), "initial." + x + ".value") : std::string(in.estimate ? "" : "0");
      } else {
        in.expression = text(v, "initial." + x);
      }
    }
    s.initial.push_back(in);
  }
  for (const auto& [k, v] : m.items())
    if (k != "type" && k != "inputs" && k != "states" && k != "outputs" && k != "parameters" && k != "equations" &&
        k != "initial")
      rd.fail(detail::format("the grey-box model has an unknown member \"{}\" (type, inputs, states, outputs, parameters, "
                             "equations, initial)", k));
  try {
    return GreyboxModel(std::move(s));
  } catch (const InvalidArgument& e) {
    rd.fail(e.what());
  }
}

NdeModel nde_from(const json& m, const Reader& rd) {
  auto [terms, c] = read_terms<NdeTerm>(m, rd);
  try {
    return NdeModel(terms, c);
  } catch (const InvalidArgument& e) {
    rd.fail(std::string("invalid NDE model: ") + e.what());
  }
}
}  // namespace

NarxModel parse_narx_json(const std::string& text, const std::string& source) {
  const Reader rd{source};
  return narx_from(typed_model(parse_text(text, rd), "narx", rd), rd);
}

NdeModel parse_nde_json(const std::string& text, const std::string& source) {
  const Reader rd{source};
  return nde_from(typed_model(parse_text(text, rd), "nde", rd), rd);
}

NarxModel read_narx_json(const std::string& path) { return parse_narx_json(read_text_file(path), path); }

GreyboxModel parse_greybox_json(const std::string& text, const std::string& source) {
  const Reader rd{source};
  return greybox_from(typed_model(parse_text(text, rd), "greybox", rd), rd);
}
GreyboxModel read_greybox_json(const std::string& path) { return parse_greybox_json(read_text_file(path), path); }
std::string greybox_to_json(const GreyboxModel& model, int indent) { return greybox_json(model).dump(indent); }

namespace {
json any_model_json(const AnyModel& m, bool exact = false) {
  if (const auto* f = std::get_if<FsfModel>(&m)) return fsf_json(*f);
  if (const auto* n = std::get_if<NarxModel>(&m)) return narx_json(*n);
  if (const auto* e = std::get_if<NdeModel>(&m)) return nde_json(*e, exact);
  if (const auto* g = std::get_if<GreyboxModel>(&m)) return greybox_json(*g);
  if (const auto* t = std::get_if<TransferFunction>(&m)) return model_json(*t);
  if (const auto* i = std::get_if<MisoModel>(&m)) return model_json(*i);
  return model_json(std::get<StateSpace>(m));
}

FsfModel fsf_from(const json& m, const Reader& rd) {
  const json& delta = rd.member(m, "delta", "the model");
  if (!delta.is_number()) rd.fail("\"delta\" must be a number (seconds)");
  const json& shift = m.contains("shift") ? m.at("shift") : json(0.0);
  if (!shift.is_number()) rd.fail("\"shift\" must be a number (1/s)");
  try {
    return FsfModel(delta.get<double>(), rd.count(rd.member(m, "N", "the model"), "N"),
                    rd.count(rd.member(m, "n", "the model"), "n"), rd.vector(rd.member(m, "theta", "the model"), "theta"),
                    m.contains("covariance") ? rd.matrix(m.at("covariance"), "covariance") : Eigen::MatrixXd(),
                    shift.get<double>());
  } catch (const InvalidArgument& e) {
    rd.fail(std::string("invalid FSF model: ") + e.what());
  }
}

// The model of a bare model object or of a result envelope, whatever its type.
AnyModel any_model_from(const json& root, const Reader& rd) {
  const json& m = root.is_object() && root.contains("model") ? root.at("model") : root;
  const json& type = rd.member(m, "type", "the model");
  if (!type.is_string()) rd.fail("model \"type\" must be a string");
  const std::string t = type.get<std::string>();
  if (t == "fsf") return fsf_from(m, rd);
  if (t == "narx") return narx_from(m, rd);
  if (t == "nde") return nde_from(m, rd);
  if (t == "greybox") return greybox_from(m, rd);
  if (t == "transfer_function" || t == "miso" || t == "state_space")
    return std::visit([](const auto& x) { return AnyModel(x); }, model_from(m, rd));
  rd.fail(detail::format("model type \"{}\" is not one ctid knows (transfer_function, miso, state_space, fsf, narx, nde, greybox)",
                         t));
}
}  // namespace
NdeModel read_nde_json(const std::string& path) { return parse_nde_json(read_text_file(path), path); }

std::string any_model_to_json(const AnyModel& model, bool exact, int indent) {
  return any_model_json(model, exact).dump(indent);
}

namespace {
std::string result_json(const Result<AnyModel>& r, const std::string& method, int indent, const Provenance* prov) {
  json j;
  j["ctid_version"] = version();
  j["method"] = method;
  if (prov) {
    json files = json::array();
    for (const auto& f : prov->data) files.push_back({{"path", f.path}, {"content_hash", f.content_hash}, {"rows", f.rows}});
    j["provenance"] = {{"command_line", prov->command_line}, {"version", prov->version}, {"commit", prov->commit},
                       {"data", files}, {"preprocessing", prov->preprocessing}};
  }
  j["model"] = any_model_json(r.model);
  json params = json::array();
  for (int i = 0; i < r.parameters.size(); ++i)
    params.push_back({{"name", r.parameters.names[i]},
                      {"value", num(r.parameters.values(i))},
                      {"std", num(i < r.parameters.std.size() ? r.parameters.std(i) : kNaN)},
                      {"fixed", i < static_cast<int>(r.parameters.fixed.size()) && r.parameters.fixed[i]}});
  j["parameters"] = params;
  j["covariance"] = mat(r.parameters.covariance);
  const FitReport& f = r.fit;
  j["fit"] = {{"fit_percent", num(f.fit_percent)}, {"nrmse", num(f.nrmse)}, {"mse", num(f.mse)},   {"fpe", num(f.fpe)},
              {"aic", num(f.aic)},                 {"aicc", num(f.aicc)},   {"bic", num(f.bic)},   {"n_samples", f.n_samples},
              {"n_parameters", f.n_parameters}};
  j["summary"] = {{"termination", to_string(r.summary.termination)},
                  {"iterations", r.summary.iterations},
                  {"seconds", r.summary.seconds},
                  {"message", r.summary.message},
                  {"usable", r.usable()},
                  {"not_usable_because", r.why_not_usable()}};
  json d;
  d["condition_number"] = num(r.diagnostics.condition_number);
  d["warnings"] = r.diagnostics.warnings;
  d["choices"] = r.diagnostics.choices;
  d["scalars"] = json::object();
  for (const auto& [k, v] : r.diagnostics.scalars()) d["scalars"][k] = num(v);
  d["vectors"] = json::object();
  for (const auto& [k, v] : r.diagnostics.vectors()) d["vectors"][k] = vec(v);
  j["diagnostics"] = d;
  return j.dump(indent);
}
}  // namespace

namespace {
// Parameters, fit, summary and diagnostics of a result file (the envelope around its model).
template <class M>
void read_envelope(const json& j, const Reader& rd, Result<M>& r) {
  try {
    const json& ps = rd.member(j, "parameters", "the result");
    const int np = static_cast<int>(ps.size());
    r.parameters.values.resize(np);
    r.parameters.std.resize(np);
    for (int i = 0; i < np; ++i) {
      r.parameters.names.push_back(ps[i].at("name").get<std::string>());
      r.parameters.values(i) = to_num(ps[i].at("value"));
      r.parameters.std(i) = to_num(ps[i].at("std"));
      r.parameters.fixed.push_back(ps[i].value("fixed", false));
    }
    r.parameters.covariance = j.contains("covariance") ? rd.matrix(j.at("covariance"), "covariance") : Eigen::MatrixXd();
    const json& f = rd.member(j, "fit", "the result");
    r.fit.fit_percent = to_num(f.at("fit_percent"));
    r.fit.nrmse = to_num(f.at("nrmse"));
    r.fit.mse = to_num(f.at("mse"));
    r.fit.fpe = to_num(f.at("fpe"));
    r.fit.aic = to_num(f.at("aic"));
    r.fit.aicc = to_num(f.at("aicc"));
    r.fit.bic = to_num(f.at("bic"));
    r.fit.n_samples = rd.count(f.at("n_samples"), "fit.n_samples");
    r.fit.n_parameters = rd.count(f.at("n_parameters"), "fit.n_parameters");
    const json& s = rd.member(j, "summary", "the result");
    r.summary.termination = termination_from_string(s.at("termination").get<std::string>());
    r.summary.iterations = rd.count(s.at("iterations"), "summary.iterations");
    r.summary.seconds = s.at("seconds").get<double>();
    r.summary.message = s.at("message").get<std::string>();
    if (j.contains("diagnostics")) {
      const json& d = j.at("diagnostics");
      r.diagnostics.condition_number = to_num(d.at("condition_number"));
      r.diagnostics.warnings = d.at("warnings").get<std::vector<std::string>>();
      if (d.contains("choices")) r.diagnostics.choices = d.at("choices").get<std::vector<std::string>>();
      for (const auto& [k, v] : d.at("scalars").items()) r.diagnostics.set_stored(k, to_num(v));
      for (const auto& [k, v] : d.at("vectors").items()) r.diagnostics.set_stored(k, rd.vector(v, "diagnostics.vectors"));
    }
  } catch (const json::exception& e) {
    rd.fail(std::string("malformed result: ") + e.what());
  } catch (const InvalidArgument& e) {
    rd.fail(std::string("malformed result: ") + e.what());
  }
}
}  // namespace

std::string result_to_json(const Result<AnyModel>& r, const std::string& method, int indent, const Provenance* provenance) {
  return result_json(r, method, indent, provenance);
}
void write_result_json(const std::string& path, const Result<AnyModel>& r, const std::string& method,
                       const Provenance* provenance) {
  write_text_file(path, result_to_json(r, method, 2, provenance) + "\n");
}

ResultFile parse_result_file(const std::string& text, const std::string& source) {
  const Reader rd{source};
  const json j = parse_text(text, rd);
  ResultFile f;
  f.result.model = any_model_from(j, rd);
  f.bare = !(j.is_object() && j.contains("model") && j.contains("parameters"));
  if (!f.bare) {
    read_envelope(j, rd, f.result);
    if (j.contains("method") && j.at("method").is_string()) f.method = j.at("method").get<std::string>();
  } else {
    // A bare model (or a file with the model but no parameter table, e.g. ctid validate --json): the
    // coefficients of term models are their parameters, without uncertainty.
    ParameterSet& p = f.result.parameters;
    std::visit(
        [&p](const auto& m) {
          using M = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<M, NarxModel> || std::is_same_v<M, NdeModel>) {
            p.values = m.coefficients();
            for (const auto& t : m.terms()) p.names.push_back(t.name());
            p.std = Eigen::VectorXd::Constant(p.values.size(), kNaN);
            p.fixed.assign(m.terms().size(), false);
          }
        },
        f.result.model);
  }
  if (auto* fsf = std::get_if<FsfModel>(&f.result.model); fsf && f.result.parameters.covariance.rows() == fsf->n())
    *fsf = FsfModel(fsf->delta(), fsf->N(), fsf->n(), fsf->theta(), f.result.parameters.covariance, fsf->shift());
  return f;
}

ResultFile read_result_file(const std::string& path) { return parse_result_file(read_text_file(path), path); }

namespace {
template <class M>
Result<M> parse_linear_result(const std::string& text, const std::string& source, const char* what) {
  ResultFile f = parse_result_file(text, source);
  if (!std::holds_alternative<M>(f.result.model))
    throw FileError(source + ": the result's model is " + model_type_name(f.result.model) + ", not " + what);
  if (f.bare) throw FileError(source + ": a bare model, not a result (it has no \"parameters\")");
  Result<M> r;
  r.model = std::get<M>(f.result.model);
  r.parameters = f.result.parameters;
  r.fit = f.result.fit;
  r.summary = f.result.summary;
  r.diagnostics = f.result.diagnostics;
  return r;
}
}  // namespace

Result<TransferFunction> parse_result_json(const std::string& text, const std::string& source) {
  return parse_linear_result<TransferFunction>(text, source, "a transfer function");
}

Result<MisoModel> parse_miso_result_json(const std::string& text, const std::string& source) {
  return parse_linear_result<MisoModel>(text, source, "a multi-input (miso) model");
}


std::string order_selection_to_json(const std::vector<OrderCandidate>& candidates, OrderCriterion rank_by,
                                    bool interrupted, int indent) {
  json list = json::array();
  for (const OrderCandidate& c : candidates)
    list.push_back({{"nb", c.orders.nb},      {"nf", c.orders.nf},   {"nk", c.orders.nk},
                    {"yic", num(c.yic)},      {"rt2", num(c.rt2)},   {"aic", num(c.aic)},
                    {"bic", num(c.bic)},      {"fit_percent", num(c.fit_percent)},
                    {"usable", c.usable},     {"termination", c.termination}});
  const json j = {{"type", "order_selection"}, {"rank_by", to_string(rank_by)}, {"interrupted", interrupted},
                  {"candidates", list}};
  return j.dump(indent) + "\n";
}

std::string table_to_json(const std::string& type, const std::vector<std::pair<std::string, std::string>>& fields,
                          const std::vector<std::string>& names, const Eigen::MatrixXd& values, int indent) {
  CTID_REQUIRE(static_cast<Eigen::Index>(names.size()) == values.cols(), "table_to_json: {} names for {} columns",
               names.size(), values.cols());
  json j = {{"type", type}};
  for (const auto& [k, v] : fields) {
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    j[k] = !v.empty() && end == v.c_str() + v.size() ? num(x) : json(v);
  }
  json cols = json::object();
  for (std::size_t c = 0; c < names.size(); ++c) cols[names[c]] = vec(values.col(static_cast<Eigen::Index>(c)));
  j["columns"] = cols;
  return j.dump(indent) + "\n";
}

std::string poles_to_json(const PolesComparison& c, int order, double ts, int indent) {
  auto estimate = [](const PoleEstimate& p) {
    json poles = json::array();
    for (const auto& z : p.poles) poles.push_back({{"re", num(z.real())}, {"im", num(z.imag())}});
    return json{{"poles", poles},
                {"characteristic", vec(p.characteristic.coefficients())},
                {"augmented", vec(p.augmented.coefficients())},
                {"condition", num(p.condition)},
                {"warnings", p.warnings}};
  };
  const json j = {{"type", "poles"},
                  {"order", order},
                  {"ts", ts},
                  {"data_matrix", estimate(c.data_matrix)},
                  {"prony", c.prony ? estimate(*c.prony) : json(nullptr)},
                  {"prony_error", c.prony_problem},
                  {"shifts", vec(c.free_response.shifts)},
                  {"choices", c.choices}};
  return j.dump(indent) + "\n";
}

}  // namespace ctid
