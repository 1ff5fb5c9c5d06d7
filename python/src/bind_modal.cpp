// ctid Python module — El-Shafey (1987): modal functions, parametric identification by modal_fit, and poles
// from a free-response data matrix (Theorem 4.3).
#include "common.hpp"

namespace ctid::python {

void bind_modal(py::module_& m) {
  py::enum_<ModalBasis>(m, "ModalBasis")
      .value("Discrete", ModalBasis::Discrete)
      .value("Fourier", ModalBasis::Fourier)
      .value("Walsh", ModalBasis::Walsh);
  py::enum_<Quadrature>(m, "Quadrature").value("Simpson", Quadrature::Simpson).value("Trapezoid", Quadrature::Trapezoid);
  py::class_<ModalWindow>(m, "ModalWindow")
      .def(py::init([](double start, double length) { return ModalWindow{start, length}; }), py::arg("start"),
           py::arg("length"))
      .def_readwrite("start", &ModalWindow::start)
      .def_readwrite("length", &ModalWindow::length);
  py::class_<ModalOptions>(m, "ModalOptions")
      .def(py::init<>())
      .def_readwrite("shifts", &ModalOptions::shifts)
      .def_readwrite("basis", &ModalOptions::basis)
      .def_readwrite("max_order", &ModalOptions::max_order)
      .def_readwrite("windows", &ModalOptions::windows)
      .def_readwrite("functions", &ModalOptions::functions)
      .def_readwrite("quadrature", &ModalOptions::quadrature)
      .def_readwrite("stride", &ModalOptions::stride)
      .def_readwrite("iv_shift", &ModalOptions::iv_shift);
  py::class_<InputGenerator>(m, "InputGenerator", "Known input generator u = c^T x_c, x_c' = A x_c (ES ch. 4).")
      .def(py::init<Eigen::MatrixXd, Eigen::VectorXd, Eigen::VectorXd>(), py::arg("A"), py::arg("c"), py::arg("x0"))
      .def_static("constant", &InputGenerator::constant, py::arg("level") = 1.0)
      .def_static("exponential", &InputGenerator::exponential, py::arg("sigma"), py::arg("amplitude") = 1.0)
      .def_static("sinusoid", &InputGenerator::sinusoid, py::arg("w"), py::arg("a_sin"), py::arg("a_cos") = 0.0,
                  py::arg("sigma") = 0.0)
      .def("__add__", &InputGenerator::operator+)
      .def("modes", &InputGenerator::modes)
      .def("__call__", [](const InputGenerator& g, const Eigen::VectorXd& t) { return g(t); }, py::arg("t"));
  m.def("modal_fit", [](const IdData& d, int nb, const ModalOptions& o, const InputGenerator* input) {
          return interruptible([&] { return modal_fit(d, nb, o, input); });
        }, py::arg("data"), py::arg("nb"), py::arg("options"), py::arg("input") = nullptr,
        "Transfer function by modal functions (El-Shafey): generated input (Theorems 4.1-4.2) or piecewise-constant input.");

  py::class_<FreeResponseOptions>(m, "FreeResponseOptions")
      .def(py::init<>())
      .def_readwrite("shifts", &FreeResponseOptions::shifts)
      .def_readwrite("start", &FreeResponseOptions::start)
      .def_readwrite("interval", &FreeResponseOptions::interval)
      .def_readwrite("spacing", &FreeResponseOptions::spacing)
      .def_readwrite("pairs", &FreeResponseOptions::pairs)
      .def_readwrite("quadrature", &FreeResponseOptions::quadrature);
  py::class_<PoleEstimate>(m, "PoleEstimate")
      .def_readonly("poles", &PoleEstimate::poles)
      .def_property_readonly("characteristic", [](const PoleEstimate& p) { return p.characteristic.coefficients(); })
      .def_readonly("condition", &PoleEstimate::condition)
      .def_readonly("warnings", &PoleEstimate::warnings);
  m.def("free_response_poles", &free_response_poles, py::arg("y"), py::arg("ts"), py::arg("options"),
        "Poles from a free-response data matrix (El-Shafey Theorem 4.3).");
}

}  // namespace ctid::python
