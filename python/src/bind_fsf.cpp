// ctid Python module — Gawthrop & Wang (2005) frequency-sampling filters: the compressed model and its
// step, impulse and frequency responses with standard deviations.
#include "common.hpp"

namespace ctid::python {

void bind_fsf(py::module_& m) {
  bind_options<FsfOptions>(m, "FsfOptions");
  py::class_<FsfModel>(m, "FsfModel", "Frequency-sampling-filter model (GW 2005): N samples per window, n filters.")
      .def("__repr__", [](const FsfModel& f) { return describe(AnyModel(f)); })
      .def_property_readonly("delta", &FsfModel::delta)
      .def_property_readonly("N", &FsfModel::N)
      .def_property_readonly("n", &FsfModel::n)
      .def_property_readonly("T", &FsfModel::T)
      .def_property_readonly("theta", &FsfModel::theta)
      .def_property_readonly("covariance", &FsfModel::covariance)
      .def("freqresp", &FsfModel::frequency_response, py::arg("w"))
      .def("freqresp_std", &FsfModel::frequency_response_std, py::arg("w"), "std of the real and imaginary parts (re + j im).")
      .def("step", &FsfModel::step_response, py::arg("t"))
      .def("step_std", &FsfModel::step_response_std, py::arg("t"))
      .def("impulse", &FsfModel::impulse_response, py::arg("t"))
      .def("impulse_std", &FsfModel::impulse_response_std, py::arg("t"))
      .def("simulate", &FsfModel::simulate, py::arg("u"), "Discrete FSF model output for u (from rest).");
  bind_result<FsfModel>(m, "FsfResult");
  def_report<FsfModel>(m);
  m.def(
      "fsf",
      [](const IdData& d, const FsfOptions& o) { return interruptible([&] { return fsf(d, o); }); },
      py::arg("data"), py::arg("options"), "Stage 1 of Gawthrop & Wang: the FSF model by least squares.");
  m.def(
      "fsf_from_spectra",
      [](const Eigen::VectorXcd& U, const Eigen::VectorXcd& Y, int L, double ts, const FsfOptions& o) {
        return interruptible([&] { return fsf_from_spectra(U, Y, L, ts, o); });
      },
      py::arg("U"), py::arg("Y"), py::arg("L"), py::arg("ts"), py::arg("options"),
      "Stage 1 from one-sided DFTs (bins 0..L/2) of records zero-padded to L >= M + N (GW 24-29).");
  m.def("one_sided_dft", &one_sided_dft, py::arg("x"), py::arg("L"), "Bins 0..L/2 of x zero-padded to length L (even).");
}

}  // namespace ctid::python
