// ctid — El-Shafey's modal-function tools: shared --set parsing, `ctid poles` (free-response data
// matrix, Theorem 4.3, against Prony) and `ctid response --method modal` (step, impulse, frequency).
#include <cmath>
#include <cstdio>
#include <functional>

#include "common.hpp"

namespace ctid::cli {

namespace {
// A comma-separated list, parsed by the library's option parser.
std::vector<double> to_list(const std::string& key, const std::string& value) {
  std::vector<double> out;
  try {
    out = options_detail::parse_reals("--set", key, value);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  if (out.empty()) throw UsageError("--set " + key + ": give a comma-separated list (got '" + value + "')");
  return out;
}

int whole_samples(const std::string& key, double v) {
  if (!(std::abs(v - std::round(v)) <= 1e-9) || v < 0 || v > 1e9)
    throw UsageError(detail::format("--set {}: {} is not a whole number of samples", key, v));
  return static_cast<int>(std::lround(v));
}
}  // namespace

namespace {
// The CLI's shift_samples (whole samples) taken out of `sets` as seconds; the other settings are returned.
std::vector<std::string> take_shift_samples(const std::vector<std::string>& sets, double Ts, Eigen::VectorXd& shifts) {
  std::vector<std::string> rest;
  std::vector<double> samples;
  for (const auto& [k, v] : parse_sets(sets)) {
    if (k == "shift_samples") samples = to_list(k, v);
    else rest.push_back(k + "=" + v);
  }
  shifts.resize(static_cast<Eigen::Index>(samples.size()));
  for (std::size_t i = 0; i < samples.size(); ++i)
    shifts(static_cast<Eigen::Index>(i)) = whole_samples("shift_samples", samples[i]) * Ts;
  return rest;
}

void set_shifts(Eigen::VectorXd& shifts, const Eigen::VectorXd& from_samples) {
  if (from_samples.size() == 0) return;
  if (shifts.size() > 0) throw UsageError("give either shifts (seconds) or shift_samples (samples), not both");
  shifts = from_samples;
}
}  // namespace

ModalOptions modal_options(const std::string& method, const std::vector<std::string>& sets, double Ts,
                           const std::vector<std::string>& own, std::map<std::string, std::string>& own_values) {
  ModalOptions o;
  Eigen::VectorXd from_samples;
  std::vector<std::string> rest;
  for (const auto& kv : take_shift_samples(sets, Ts, from_samples)) {
    const std::string k = kv.substr(0, kv.find('='));
    if (std::find(own.begin(), own.end(), k) != own.end()) own_values[k] = kv.substr(kv.find('=') + 1);
    else rest.push_back(kv);
  }
  apply_sets(method, rest, o);
  set_shifts(o.shifts, from_samples);
  return o;
}

namespace {

struct PolesArgs {
  DataArgs data;
  int order = 0;
  std::vector<double> generator;
  std::vector<std::string> sets;
  std::string json;
  bool force = false;
};

int run_poles(PolesArgs a) {
  check_outputs({a.json}, {a.data.path}, a.force);
  if (a.order < 1) throw UsageError("--order must be >= 1");
  if (a.data.outputs.empty()) {
    try {
      const CsvTable tab = read_csv(a.data.path);
      std::vector<std::string> rest;
      for (const auto& n : tab.names)
        if (n != a.data.time) rest.push_back(n);
      if (rest.size() != 1) throw UsageError(a.data.path + ": choose the free-response column with --output");
      a.data.outputs = rest;
    } catch (const FileError& e) {
      throw InputError(e.what());
    }
  }
  a.data.inputs = a.data.outputs;  // the response only, loaded as the one column; no input is used
  const IdData d = a.data.load(false);
  const double Ts = d.ts();
  const Eigen::VectorXd y = d.u().col(0);
  PolesOptions o;
  Eigen::VectorXd from_samples;
  apply_sets("poles", take_shift_samples(a.sets, Ts, from_samples), o);
  set_shifts(o.shifts, from_samples);
  if (!a.generator.empty()) {
    if (o.generator.size() > 0) throw UsageError("give either --generator or --set generator, not both");
    o.generator = Eigen::Map<const Eigen::VectorXd>(a.generator.data(), static_cast<Eigen::Index>(a.generator.size()));
  }
  PolesComparison c;
  try {
    c = compare_poles(y, Ts, a.order, o);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  auto print = [](const char* title, const PoleEstimate& p) {
    std::printf("%s\n  characteristic polynomial: %s\n  poles:", title, p.characteristic.to_string("s", 6).c_str());
    for (auto z : p.poles) std::printf("  %.6g%+.6gj", z.real(), z.imag());
    std::printf("\n  condition number: %.4g\n", p.condition);
    for (const auto& w : p.warnings) std::printf("  warning: %s\n", w.c_str());
  };
  std::printf("free response: %d samples, Ts = %.6g s, order %d\n", d.size(), Ts, a.order);
  for (const auto& choice : c.choices) std::printf("chosen: %s\n", choice.c_str());
  print("data-matrix method (Theorem 4.3, El-Shafey 1987):", c.data_matrix);
  if (o.generator.size() > 0) std::printf("  before deflation by the generator: %s\n", c.data_matrix.augmented.to_string("s", 6).c_str());
  const PronyOptions& po = c.prony_options;
  if (c.prony)
    print(detail::format("Prony (order {}, T = {} samples, {} equations):", po.order, po.spacing, po.equations).c_str(), *c.prony);
  else
    std::printf("Prony: not computed (%s)\n", c.prony_problem.c_str());
  if (!a.json.empty()) {
    write_text_file(a.json, poles_to_json(c, a.order, Ts));
    std::printf("wrote %s\n", a.json.c_str());
  }
  return kOk;
}

struct ResponseArgs {
  DataArgs data;
  std::string method = "modal", kind = "step", out, json;
  int order = 0;
  std::vector<std::string> sets;
  bool force = false;
};

int run_response(const ResponseArgs& a) {
  check_outputs({a.out, a.json}, {a.data.path}, a.force);
  if (a.order < 1) throw UsageError("--order must be >= 1");
  const IdData d = a.data.load(true);
  // The response as named columns: to --out (CSV) and --json.
  auto write = [&](const std::vector<std::string>& names, const Eigen::MatrixXd& tab) {
    if (!a.out.empty()) write_csv(a.out, names, tab);
    if (!a.json.empty())
      write_text_file(a.json, table_to_json("response", {{"method", a.method}, {"kind", a.kind},
                                                         {"order", std::to_string(a.order)}},
                                            names, tab));
  };
  if (d.nu() != 1 || d.ny() != 1) throw UsageError("response needs one --input and one --output");
  ModalResponseOptions ro;
  ModalOptions mo;
  Eigen::VectorXd from_samples;
  apply_sets("modal_response", take_shift_samples(a.sets, d.ts(), from_samples), ro, mo);
  set_shifts(mo.shifts, from_samples);
  const ResponseKind kind = a.kind == "frequency" ? ResponseKind::Frequency
                            : a.kind == "impulse" ? ResponseKind::Impulse
                                                  : ResponseKind::Step;
  ModalResponse m;
  try {
    m = modal_response(d, a.order, kind, ro, mo);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  std::printf("modal parameters p_0:");
  for (int i = 0; i < a.order; ++i) std::printf(" %.6g", m.p0.model.P()(0, i));
  std::printf("   (shifts");
  for (int i = 0; i < a.order; ++i) std::printf(" %.6g", m.modal.shifts(i));
  std::printf(" s)");
  std::printf("   (%zu windows, condition %.3g)\n", m.modal.windows.size(), m.p0.diagnostics.condition_number);
  if (kind == ResponseKind::Frequency) {
    const FrequencyData& f = m.frequency.response;
    Eigen::MatrixXd tab(f.size(), 5);
    for (int i = 0; i < f.size(); ++i) {
      const auto G = f.response()(i);
      tab.row(i) << f.w()(i), G.real(), G.imag(), std::abs(G), std::arg(G) * 180 / 3.14159265358979;
      std::printf("  w = %-10.5g  H = %.6g %+.6gj   |H| = %.6g  phase = %.4g deg\n", f.w()(i), G.real(), G.imag(),
                  std::abs(G), tab(i, 4));
    }
    write({"w", "re", "im", "mag", "phase_deg"}, tab);
  } else {
    const TimeResponse& g = m.time;
    const char* name = kind == ResponseKind::Impulse ? "impulse" : "step";
    const int K = static_cast<int>(g.t.size());
    for (int i = 0; i < K; i += std::max(1, K / 20)) std::printf("  t = %-10.5g  %s = %.6g\n", g.t(i), name, g.value(i));
    Eigen::MatrixXd tab(K, 2);
    tab << g.t, g.value;
    write({"t", name}, tab);
  }
  for (const std::string* f : {&a.out, &a.json})
    if (!f->empty()) std::printf("wrote %s\n", f->c_str());
  return kOk;
}

}  // namespace

void setup_poles(CLI::App& app, Command& command) {
  auto a = std::make_shared<PolesArgs>();
  app.add_option("DATA", a->data.path, "CSV/.dat table or .mat file holding a free (or generated-input) response")
      ->required();
  a->data.add_to(app, true);
  app.add_option("--order", a->order, "Number of system poles n")->required();
  app.add_option("--generator", a->generator,
                 "A response forced by a known generated input: its frequencies w1,.. (rad/s; 0 = constant); the "
                 "augmented estimate is deflated by them")
      ->delimiter(',');
  app.add_option("--set", a->sets,
                 "KEY=VALUE; " + settings_help(method_info("poles")) +
                     "  shift_samples  the shifts counted in samples (instead of shifts)");
  app.add_option("--json", a->json, "Write both estimates (poles, characteristic polynomials, conditions) to this JSON file");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &command] {
    command = [a](Provenance& prov) {
      a->data.provenance = &prov;
      return run_poles(*a);
    };
  });
}

void setup_response(CLI::App& app, Command& command) {
  auto a = std::make_shared<ResponseArgs>();
  app.add_option("DATA", a->data.path, "CSV/.dat table or .mat file")->required();
  app.add_option("--method", a->method, "Estimator of the response: modal (El-Shafey)")
      ->check(CLI::IsMember({"modal"}))
      ->capture_default_str();
  app.add_option("--kind", a->kind, "step, impulse or frequency")
      ->check(CLI::IsMember({"step", "impulse", "frequency"}))
      ->capture_default_str();
  a->data.add_to(app, true);
  app.add_option("--order", a->order, "System order n")->required();
  app.add_option("--set", a->sets,
                 "KEY=VALUE; " + settings_help(method_info("modal_response")) +
                     "  shift_samples  the shifts counted in samples (instead of shifts)");
  app.add_option("--out", a->out, "Write the response to this CSV file");
  app.add_option("--json", a->json, "Write the response to this JSON file (the --out columns, with kind and order)");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &command] {
    command = [a](Provenance& prov) {
      a->data.provenance = &prov;
      return run_response(*a);
    };
  });
}

}  // namespace ctid::cli
