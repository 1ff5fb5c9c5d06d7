// ctid Python module — shared helpers of the binding files (one file per area: adding a method's binding is
// a change to one bind_*.cpp file plus its keyword wrapper in ctid/__init__.py).
#pragma once

#include <pybind11/complex.h>
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "ctid/ctid.hpp"

namespace py = pybind11;

namespace ctid::python {

/// What Ctrl-C does to a call: a single estimation returns its best iterate as Termination::Interrupted
/// (the result says what happened); a routine that runs several estimations (select_order) raises
/// KeyboardInterrupt once it has stopped.
enum class OnInterrupt { ReturnResult, Raise };

/// Runs f() with the GIL released. Ctrl-C is noticed at the estimator's next progress report (every
/// iteration and every grid point: the callback takes the GIL and checks for signals); the library's stop
/// request is sticky within the call, so every later fit of a multi-fit routine stops at once.
template <class F>
auto interruptible(F&& f, OnInterrupt on = OnInterrupt::ReturnResult) {
  bool stop = false;
  ProgressScope scope([&stop](const ProgressEvent&) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
      PyErr_Clear();
      stop = true;
    }
    return !stop;
  });
  auto result = [&] {
    py::gil_scoped_release release;
    return f();
  }();
  if (stop && on == OnInterrupt::Raise) {
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
  return result;
}

/// The typed Python result (TransferFunctionResult, MisoResult, ...) of a Result<AnyModel>.
py::object typed(const Result<AnyModel>& r);
/// Physical parameters from {"name": initial} or {"name": {"initial": .., "lower": .., "upper": .., "fixed": ..}}.
std::vector<PhysicalParameter> parameters_of(const py::dict& spec);
/// Binds Result<Model> as a Python class `name` (model, parameters, fit, summary, diagnostics, usable()).
template <class Model>
void bind_result(py::module_& m, const char* name) {
  using R = Result<Model>;
  py::class_<R>(m, name)
      .def_readonly("model", &R::model)
      .def_readonly("parameters", &R::parameters)
      .def_readonly("fit", &R::fit)
      .def_readonly("summary", &R::summary)
      .def_readonly("diagnostics", &R::diagnostics)
      .def(
          "__repr__",
          [](const R& r) {
            // The model as the library describes it (a model outside AnyModel, e.g. ModalModel: its Python repr).
            const py::object m = py::cast(r.model);
            std::string text;
            if constexpr (std::is_constructible_v<AnyModel, Model>) text = describe(AnyModel(r.model));
            else text = std::string(py::repr(m));
            return brief_text(r, std::string(py::str(m.get_type().attr("__name__"))) + ": " + text);
          })
      .def("report", [](const R& r) { return std::string(py::repr(py::cast(r))); },
           "A brief text report: the model, termination, parameters, fit and warnings (the library's brief_text).")
      .def("_repr_html_",
           [](const R& r) {
             std::string text = std::string(py::repr(py::cast(r))), html = "<pre>";
             for (char c : text) html += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
             return html + "</pre>";
           })
      .def("usable", &R::usable, "Whether the estimate can be trusted (the rules of why_not_usable).")
      .def("why_not_usable", &R::why_not_usable,
           "Why the estimate cannot be trusted ('' when it can): the estimator failed, a parameter is not finite, "
           "the fit is not better than the output's mean, a standard deviation is zero or not finite, the covariance "
           "is not positive semi-definite, or no parameter differs significantly from zero.");
}

/// ctid.html_report(data, result, path, method="", title="", settings={}) for Result<Model>: writes the
/// self-contained HTML report (io/report.hpp).
template <class Model>
void def_report(py::module_& m) {
  m.def(
      "html_report",
      [](const IdData& d, const Result<Model>& r, const std::string& path, const std::string& method,
         const std::string& title, const std::map<std::string, std::string>& settings, const std::string& initial,
         const std::vector<std::pair<std::string, IdData>>& more_records) {
        ReportOptions o;
        o.more_records = more_records;
        o.method = method;
        o.title = title;
        o.settings.assign(settings.begin(), settings.end());
        if (!initial.empty()) o.initial = initial_condition_from_string(initial);
        write_text_file(path, html_report(d, r, o));
      },
      py::arg("data"), py::arg("result"), py::arg("path"), py::arg("method") = "", py::arg("title") = "",
      py::arg("settings") = std::map<std::string, std::string>{}, py::arg("initial") = "",
      py::arg("more_records") = std::vector<std::pair<std::string, IdData>>{},
      "Write the self-contained HTML report of a result on a record (plots, residual tests, parameters); initial: "
      "'rest', 'measured' or 'estimated', or '' for the one the result's fit used; more_records: [(name, IdData), ..] "
      "further records of the system, a section each.");
}

/// A setting's value from Python, converted by the setting's kind (estimate/options.hpp): numbers, 0/1 or
/// bool, a choice by name (or an enumeration member), a sequence of numbers, a dict of numbers, a dict of
/// (lower, upper) pairs, a TransferFunction or None.
OptionValue option_value_from_python(py::handle v, const OptionInfo& info, const std::string& method);

/// Binds options struct O as Python class `name` from its table: one property per setting (same name, typed
/// get/set, the table's doc with unit and range), `_names` (the setting names, in table order) and a repr
/// listing every setting.
template <class O>
py::class_<O> bind_options(py::module_& m, const char* name) {
  const OptionTable<O>& t = option_table<O>();
  static const std::string doc = [&] {
    std::string s = "Settings of " + t.method() + " (the same names, units and defaults as the C++ struct and the CLI's --set):";
    for (const auto& i : t.info())
      s += "\n  " + i.name + (i.unit.empty() ? "" : " (" + i.unit + ")") + ": " + i.doc + "; default " +
           (i.default_value.empty() ? "none" : i.default_value) + (i.range.empty() ? "" : "; " + i.range);
    return s;
  }();
  py::class_<O> c(m, name, doc.c_str());
  c.def(py::init<>());
  py::list names;
  for (const auto& f : t.fields()) {
    const std::string n = f.info.name;
    names.append(n);
    c.def_property(
        f.info.name.c_str(), py::cpp_function([n](const O& o) { return option_table<O>().field(n).get(o); }),
        py::cpp_function(
            [n](O& o, py::handle v) {
              const OptionTable<O>& tt = option_table<O>();
              tt.set_value(o, n, option_value_from_python(v, tt.field(n).info, tt.method()));
            },
            py::is_method(c)),
        f.info.doc.c_str());
  }
  c.attr("_names") = names;
  c.def("__repr__", [name = std::string(name)](const O& o) {
    std::string s = name + "(";
    bool first = true;
    for (const auto& [k, v] : option_table<O>().settings(o)) {
      s += (first ? "" : ", ") + k + "=" + v;
      first = false;
    }
    return s + ")";
  });
  return c;
}

void bind_core(py::module_& m);
void bind_registry(py::module_& m);
void bind_linear(py::module_& m);
void bind_fsf(py::module_& m);
void bind_nonlinear(py::module_& m);
void bind_modal(py::module_& m);
void bind_physical(py::module_& m);
void bind_models(py::module_& m);
void bind_pickle(py::module_& m);

}  // namespace ctid::python
