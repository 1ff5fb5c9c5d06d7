// ctid Python module — settings from Python values (one conversion per option kind) and the method registry:
// ctid.methods(), ctid.settings(name), ctid.method_capabilities(name) read estimate/methods.hpp, the list the CLI's
// help reads; _ctid.fit runs a registered method through the library's fit() (estimate/fit.hpp).
#include <optional>
#include <algorithm>
#include <cctype>

#include "common.hpp"

namespace ctid::python {

OptionValue option_value_from_python(py::handle v, const OptionInfo& info, const std::string& method) {
  auto bad = [&](const std::string& what) -> OptionValue {
    throw InvalidOptions(method + ": " + info.name + " takes " + what + " (got " + std::string(py::str(py::repr(v))) + ")");
  };
  try {
    switch (info.kind) {
      case OptionKind::Real:
        if (py::isinstance<py::str>(v) || v.is_none()) return bad("a number");
        return py::cast<double>(v);
      case OptionKind::Integer: {
        if (py::isinstance<py::bool_>(v)) return bad("a whole number");
        if (py::isinstance<py::float_>(v)) {
          const double x = py::cast<double>(v);
          if (x != static_cast<double>(static_cast<long long>(x))) return bad("a whole number");
        }
        return static_cast<int>(py::cast<long long>(py::int_(py::reinterpret_borrow<py::object>(v))));
      }
      case OptionKind::Flag:
        if (py::isinstance<py::str>(v) || v.is_none()) return bad("True or False");
        return py::cast<bool>(py::bool_(py::reinterpret_borrow<py::object>(v)));
      case OptionKind::Choice: {
        std::string s = py::hasattr(v, "name") && !py::isinstance<py::str>(v) ? py::cast<std::string>(v.attr("name"))
                                                                              : py::cast<std::string>(v);
        std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
        return s;
      }
      case OptionKind::Reals:
        if (py::isinstance<py::str>(v)) return bad("a sequence of numbers");
        if (v.is_none()) return std::vector<double>{};
        return py::cast<std::vector<double>>(v);
      case OptionKind::NamedReals: return py::cast<std::map<std::string, double>>(v);
      case OptionKind::NamedBounds: return py::cast<std::map<std::string, std::pair<double, double>>>(v);
      case OptionKind::Names: {
        if (py::isinstance<py::str>(v)) return bad("a list of names");
        std::vector<std::string> out;
        for (py::handle x : py::reinterpret_borrow<py::iterable>(v))
          out.push_back(py::isinstance<py::str>(x) ? py::cast<std::string>(x) : py::cast<std::string>(x.attr("name")));
        return out;
      }
      case OptionKind::Model:
        if (v.is_none()) return std::optional<TransferFunction>{};
        return std::optional<TransferFunction>(py::cast<TransferFunction>(v));
    }
  } catch (const py::cast_error&) {
    return bad(std::string("a ") + to_string(info.kind));
  }
  return bad("?");
}

namespace {
// The settings of a Python fit, typed by the setting's kind where a method's table declares the name (the method's
// own table first); a name no table declares is passed on as it is (text, a number or a list of numbers: the
// method's own settings such as modal's shift_samples), and the library refuses it if the method has no such one.
SettingList settings_from_python(const std::string& method, const py::dict& settings) {
  const MethodInfo& own = method_info(method);
  auto declared = [&](const std::string& name) -> const OptionInfo* {
    for (const auto& s : own.settings)
      if (s.name == name) return &s;
    for (const auto& m : methods())
      for (const auto& s : m.settings)
        if (s.name == name) return &s;
    return nullptr;
  };
  SettingList out;
  for (const auto& [k, v] : settings) {
    const std::string name = py::cast<std::string>(k);
    if (const OptionInfo* info = declared(name)) out.emplace_back(name, option_value_from_python(v, *info, own.name));
    else if (py::isinstance<py::str>(v)) out.emplace_back(name, py::cast<std::string>(v));
    else if (py::isinstance<py::bool_>(v)) out.emplace_back(name, OptionValue(py::cast<bool>(v)));
    else if (py::isinstance<py::int_>(v) || py::isinstance<py::float_>(v)) out.emplace_back(name, OptionValue(py::cast<double>(v)));
    else out.emplace_back(name, OptionValue(py::cast<std::vector<double>>(v)));
  }
  return out;
}

py::dict capabilities_dict(const MethodInfo& m) {
  const MethodCapabilities& c = m.capabilities;
  py::dict d;
  d["records"] = c.records;
  d["several_records"] = c.several_records;
  d["frequency_data"] = c.frequency_data;
  d["several_inputs"] = c.several_inputs;
  d["several_outputs"] = c.several_outputs;
  d["orders"] = c.orders;
  d["needs_orders"] = c.needs_orders;
  d["nx"] = c.nx;
  d["initial_model"] = c.initial_model;
  d["greybox_model"] = c.greybox_model;
  d["physical_model"] = c.physical_model;
  d["references"] = c.references;
  d["narx_model"] = c.narx_model;
  d["model_types"] = c.model_types;
  d["default_detrend"] = c.default_detrend;
  d["aliases"] = m.aliases;
  d["reached_by"] = m.reached_by;
  return d;
}
}  // namespace

void bind_registry(py::module_& m) {
  m.def("fit_methods", &fit_method_names,
        "Names of the registered methods that fit records (ctid.fit's and ctid fit's --method choices).");
  m.def(
      "method_capabilities", [](const std::string& name) { return capabilities_dict(method_info(name)); },
      py::arg("method"),
      "What a method takes: a dict of flags (records, several_records, frequency_data, several_inputs, "
      "several_outputs, orders, needs_orders, nx, initial_model, greybox_model, physical_model, references, "
      "narx_model), its result model types, its aliases and, for an entry that does not run alone, how it is reached.");
  m.def(
      "default_method",
      [](bool orders, bool frequency_data) {
        FitStructure s;
        if (orders) s.orders.push_back({});
        return default_method(s, frequency_data);
      },
      py::arg("orders"), py::arg("frequency_data") = false,
      "The method ctid.fit runs when none is named: tfest on frequency data, else srivc with orders, srivc_auto "
      "without.");
  m.def(
      "fit",
      [](const std::string& method, py::object data, const std::vector<std::tuple<int, int, int>>& orders,
         const py::dict& settings, std::optional<StateSpace> initial, std::optional<GreyboxModel> greybox,
         std::optional<std::string> expression, const py::dict& parameters, const std::string& route,
         const std::vector<Eigen::VectorXd>& references, std::optional<NarxModel> narx) {
        FitRequest r;
        if (py::isinstance<FrequencyData>(data)) r.frequency = py::cast<FrequencyData>(data);
        else if (py::isinstance<IdData>(data)) r.records.push_back(py::cast<IdData>(data));
        else r.records = py::cast<std::vector<IdData>>(data);
        for (const auto& [nb, nf, nk] : orders) r.structure.orders.push_back({nb, nf, nk});
        r.structure.initial = std::move(initial);
        r.structure.greybox = std::move(greybox);
        if (expression) r.structure.physical = PhysicalStructure{*expression, parameters_of(parameters), route};
        r.structure.references = references;
        r.structure.narx = std::move(narx);
        r.settings = settings_from_python(method, settings);
        FitOutcome out = interruptible([&] { return fit(method, r); });
        py::list s;
        for (const auto& [k, v] : out.settings) s.append(py::make_tuple(k, v));
        return py::make_tuple(typed(out.result), out.method, s);
      },
      py::arg("method"), py::arg("data"), py::arg("orders"), py::arg("settings"), py::arg("initial"),
      py::arg("greybox"), py::arg("expression"), py::arg("parameters"), py::arg("route"), py::arg("references"),
      py::arg("narx"),
      "The library's fit(): (typed result, the registry name of the method that ran, its settings as (name, text)). "
      "Python users call ctid.fit.");
  m.def(
      "methods", [] {
        std::vector<std::string> names;
        for (const auto& x : methods()) names.push_back(x.name);
        return names;
      },
      "Names of the registered estimation methods (the keys of ctid.settings).");
  m.def(
      "method_structs", [](const std::string& name) { return method_info(name).options; }, py::arg("method"),
      "The names of the options classes whose settings a method takes (e.g. ['FsfOptions', 'PhysicalFitOptions']).");
  m.def(
      "settings",
      [](const std::string& name) {
        py::list out;
        for (const auto& s : method_info(name).settings) {
          py::dict d;
          d["name"] = s.name;
          d["kind"] = to_string(s.kind);
          d["unit"] = s.unit;
          d["range"] = s.range;
          d["default"] = s.default_value;
          d["doc"] = s.doc;
          out.append(d);
        }
        return out;
      },
      py::arg("method"),
      "The settings of a method: a list of dicts (name, kind, unit, range, default as text, doc) — the keyword "
      "arguments of its function and the CLI's --set names.");
  m.def(
      "diagnostics",
      [](const std::optional<std::string>& method) {
        py::list out;
        auto add = [&](const DiagnosticInfo& d) {
          py::dict x;
          x["name"] = d.name;
          x["kind"] = d.vector ? "vector" : "scalar";
          x["unit"] = d.unit;
          x["doc"] = d.doc;
          x["per_record"] = d.per_record;
          out.append(x);
        };
        if (method)
          for (const auto& name : method_info(*method).diagnostics) add(*find_diagnostic(name));
        else
          for (const auto& d : diagnostic_catalogue()) add(d);
        return out;
      },
      py::arg("method") = py::none(),
      "The declared diagnostics (of one method, or all): a list of dicts (name, kind 'scalar'/'vector', unit, doc, "
      "per_record) — the keys of a result's diagnostics.scalars and diagnostics.vectors.");
}

}  // namespace ctid::python
