// ctid Python module `ctid._ctid`: the C++ library bound with pybind11; the pure-Python
// package `ctid` (python/ctid) adds keyword arguments, reports and plots on top.
#include "common.hpp"

PYBIND11_MODULE(_ctid, m) {
  m.doc() = "ctid: continuous-time system identification (C++ core)";
  // Error tier 1 -> Python exceptions: bad input and bad options are ValueErrors, file problems OSErrors.
  static py::exception<ctid::InvalidArgument> invalid_argument(m, "InvalidArgument", PyExc_ValueError);
  static py::exception<ctid::InvalidOptions> invalid_options(m, "InvalidOptions", invalid_argument.ptr());
  static py::exception<ctid::FileError> file_error(m, "FileError", PyExc_OSError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ctid::UnknownSetting& e) {
      // An unknown keyword is a TypeError in Python, worded as the keyword layer words it.
      const std::string hint = e.closest.empty() ? "" : "; did you mean '" + e.closest + "'?";
      PyErr_SetString(PyExc_TypeError, (e.method + ": unknown option '" + e.key + "'" + hint + " (ctid.settings('" +
                                        e.method + "') lists them)").c_str());
    } catch (const ctid::InvalidOptions& e) {
      PyErr_SetString(invalid_options.ptr(), e.what());
    } catch (const ctid::InvalidArgument& e) {
      PyErr_SetString(invalid_argument.ptr(), e.what());
    } catch (const ctid::FileError& e) {
      PyErr_SetString(file_error.ptr(), e.what());
    }
  });
  m.attr("__version__") = ctid::version();
  ctid::python::bind_core(m);
  ctid::python::bind_registry(m);
  ctid::python::bind_linear(m);
  ctid::python::bind_fsf(m);
  ctid::python::bind_nonlinear(m);
  ctid::python::bind_modal(m);
  ctid::python::bind_physical(m);
  ctid::python::bind_models(m);
  ctid::python::bind_pickle(m);  // last: pickling of the classes above
}
