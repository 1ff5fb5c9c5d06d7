// ctid Python module — settings from Python values (one conversion per option kind) and the method registry:
// ctid.methods() and ctid.settings(name) read estimate/methods.hpp, the list the CLI's help reads.
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

void bind_registry(py::module_& m) {
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
