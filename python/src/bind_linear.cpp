// ctid Python module — linear transfer-function estimators: Johansson's LSSVF/IVSVF, SRIVC, output error
// and tfest (options structs field for field; ctid/__init__.py turns keyword arguments into them).
#include "common.hpp"

namespace ctid::python {

namespace {
template <class Options>
using Estimator = Result<TransferFunction> (*)(const IdData&, const TfOrders&, const Options&);

template <class Options>
void def_tf_estimator(py::module_& m, const char* name, Estimator<Options> f, const char* doc) {
  m.def(
      name,
      [f](const IdData& d, int nb, int nf, int nk, const Options& o) {
        return interruptible([&] { return f(d, TfOrders{nb, nf, nk}, o); });
      },
      py::arg("data"), py::arg("nb"), py::arg("nf"), py::arg("nk") = 0, py::arg("options") = Options{}, doc);
}
}  // namespace

void bind_linear(py::module_& m) {
  py::enum_<SvfWeights>(m, "SvfWeights").value("Riemann", SvfWeights::Riemann).value("Trapezoidal", SvfWeights::Trapezoidal);

  py::class_<LssvfOptions>(m, "LssvfOptions")
      .def(py::init<>())
      .def_readwrite("tau", &LssvfOptions::tau)
      .def_readwrite("weights", &LssvfOptions::weights)
      .def_readwrite("alpha", &LssvfOptions::alpha)
      .def_readwrite("transient_time", &LssvfOptions::transient_time)
      .def_readwrite("fixed", &LssvfOptions::fixed)
      .def_readwrite("data_filter", &LssvfOptions::data_filter)
      .def_readwrite("tau_grid_size", &LssvfOptions::tau_grid_size);
  py::class_<IvsvfOptions>(m, "IvsvfOptions")
      .def(py::init<>())
      .def_readwrite("svf", &IvsvfOptions::svf)
      .def_readwrite("max_iterations", &IvsvfOptions::max_iterations)
      .def_readwrite("tolerance", &IvsvfOptions::tolerance);
  py::class_<SrivcOptions>(m, "SrivcOptions")
      .def(py::init<>())
      .def_readwrite("max_iterations", &SrivcOptions::max_iterations)
      .def_readwrite("tolerance", &SrivcOptions::tolerance)
      .def_readwrite("initial", &SrivcOptions::initial)
      .def_readwrite("delay", &SrivcOptions::delay)
      .def_readwrite("estimate_delay", &SrivcOptions::estimate_delay)
      .def_readwrite("delay_min", &SrivcOptions::delay_min)
      .def_readwrite("delay_max", &SrivcOptions::delay_max)
      .def_readwrite("delay_grid", &SrivcOptions::delay_grid);
  py::class_<OeOptions>(m, "OeOptions")
      .def(py::init<>())
      .def_readwrite("max_iterations", &OeOptions::max_iterations)
      .def_readwrite("tolerance", &OeOptions::tolerance)
      .def_readwrite("initial", &OeOptions::initial)
      .def_readwrite("fixed", &OeOptions::fixed)
      .def_readwrite("bounds", &OeOptions::bounds)
      .def_readwrite("estimate_delay", &OeOptions::estimate_delay)
      .def_readwrite("delay", &OeOptions::delay)
      .def_readwrite("srivc", &OeOptions::srivc);

  def_tf_estimator<LssvfOptions>(m, "lssvf", &lssvf, "Johansson (1986) least squares on state-variable-filtered signals.");
  def_tf_estimator<IvsvfOptions>(m, "ivsvf", &ivsvf, "Johansson's regression with instrumental variables.");
  def_tf_estimator<SrivcOptions>(m, "srivc", &srivc, "Simplified refined instrumental variables (SISO).");
  def_tf_estimator<OeOptions>(m, "oe", &oe, "Continuous-time output error (Levenberg-Marquardt).");
  def_tf_estimator<OeOptions>(m, "tfest", &tfest, "SRIVC start, then output-error refinement.");
}

}  // namespace ctid::python
