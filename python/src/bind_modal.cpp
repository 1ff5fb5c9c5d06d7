// ctid Python module — El-Shafey (1987): modal functions and parameters (modal_estimate), parametric
// identification (modal_fit), poles from a free-response data matrix (Theorem 4.3) against Prony, the
// nonparametric frequency, step and impulse responses (ch. 5) and the minimum-time observer (ch. 6).
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
  bind_options<ModalOptions>(m, "ModalOptions");
  py::class_<InputGenerator>(m, "InputGenerator", "Known input generator u = c^T x_c, x_c' = A x_c (ES ch. 4).")
      .def(py::init<Eigen::MatrixXd, Eigen::VectorXd, Eigen::VectorXd>(), py::arg("A"), py::arg("c"), py::arg("x0"))
      .def_static("constant", &InputGenerator::constant, py::arg("level") = 1.0)
      .def_static("exponential", &InputGenerator::exponential, py::arg("sigma"), py::arg("amplitude") = 1.0)
      .def_static("sinusoid", &InputGenerator::sinusoid, py::arg("w"), py::arg("a_sin"), py::arg("a_cos") = 0.0,
                  py::arg("sigma") = 0.0)
      .def("__add__", &InputGenerator::operator+)
      .def("modes", &InputGenerator::modes)
      .def("__call__", [](const InputGenerator& g, const Eigen::VectorXd& t) { return g(t); }, py::arg("t"));
  m.def("generator_fitted_to_input", &generator_fitted_to_input, py::arg("frequencies"), py::arg("data"),
        "The generator of the frequencies (rad/s; 0 = constant) with its coefficients fitted to the record's input.");
  m.def("modal_fit", [](const IdData& d, int nb, const ModalOptions& o, const InputGenerator* input) {
          return interruptible([&] { return modal_fit(d, nb, o, input); });
        }, py::arg("data"), py::arg("nb"), py::arg("options"), py::arg("input") = nullptr,
        "Transfer function by modal functions (El-Shafey): generated input (Theorems 4.1-4.2) or piecewise-constant input.");
  m.def("modal_fit", [](const std::vector<IdData>& d, int nb, const ModalOptions& o, const InputGenerator* input) {
          return interruptible([&] { return modal_fit(d, nb, o, input); });
        }, py::arg("data"), py::arg("nb"), py::arg("options"), py::arg("input") = nullptr,
        "Several records (experiments of one system) with piecewise-constant inputs, fitted jointly.");

  py::class_<ModalParameters>(m, "ModalParameters", "Modal parameters of a known model (ES-C1).")
      .def_readonly("P", &ModalParameters::P, "(max_order + 1) x n; row j is p_j")
      .def_readonly("psi", &ModalParameters::psi, "n x n; row i is c^T e^{-A T_i}")
      .def_readonly("condition", &ModalParameters::condition, "2-norm condition number of psi");
  m.def("modal_parameters",
        py::overload_cast<const TransferFunction&, const Eigen::VectorXd&, int>(&modal_parameters), py::arg("model"),
        py::arg("shifts"), py::arg("max_order"),
        "Modal parameters p_0 .. p_max_order of a known transfer function for n distinct shifts (s; n = its order).");
  py::class_<ModalModel>(m, "ModalModel", "Modal parameters p_j (rows of P) and modal-function coefficients q_j (rows of Q).")
      .def(py::init<Eigen::VectorXd, Eigen::MatrixXd, Eigen::MatrixXd>(), py::arg("shifts"), py::arg("P"), py::arg("Q"))
      .def_property_readonly("shifts", &ModalModel::shifts)
      .def_property_readonly("P", &ModalModel::P)
      .def_property_readonly("Q", &ModalModel::Q)
      .def_property_readonly("order", &ModalModel::order)
      .def_property_readonly("max_order", &ModalModel::max_order)
      .def("characteristic_polynomial", [](const ModalModel& mm) { return mm.characteristic_polynomial().coefficients(); },
           "Theorem 4.1: the monic denominator, descending powers (needs max_order >= order).")
      .def("transfer_function", &ModalModel::transfer_function, py::arg("input"),
           "Theorems 4.1 and 4.2 with the generator of the input the Q refer to.")
      .def("__repr__", [](const ModalModel& mm) {
        return detail::format("ModalModel(order {}, derivatives 0..{})", mm.order(), mm.max_order());
      });
  bind_result<ModalModel>(m, "ModalResult");
  m.def("piecewise_constant_windows", &piecewise_constant_windows, py::arg("data"), py::arg("settle"),
        py::arg("min_length") = 0.0, "Windows of constant input from `settle` s after each level switch.");
  m.def("modal_estimate", [](const IdData& d, const InputGenerator& g, const ModalOptions& o) {
          return interruptible([&] { return modal_estimate(d, g, o); });
        }, py::arg("data"), py::arg("input"), py::arg("options"), "p_j and q_j with a known input generator.");
  m.def("modal_estimate", [](const IdData& d, const Eigen::MatrixXd& basis, const ModalOptions& o) {
          return interruptible([&] { return modal_estimate(d, basis, o); });
        }, py::arg("data"), py::arg("input"), py::arg("options"),
        "p_j and q_j with the input basis sampled (N x n_c; u itself for a piecewise-constant input).");

  py::class_<TimeResponse>(m, "TimeResponse")
      .def_readonly("t", &TimeResponse::t)
      .def_readonly("value", &TimeResponse::value);
  py::class_<HarmonicResponse>(m, "HarmonicResponse")
      .def_readonly("response", &HarmonicResponse::response)
      .def_readonly("nu", &HarmonicResponse::nu)
      .def_readonly("q", &HarmonicResponse::q);
  py::class_<ImpulseFromStep>(m, "ImpulseFromStep")
      .def_readonly("impulse", &ImpulseFromStep::impulse)
      .def_readonly("p1", &ImpulseFromStep::p1)
      .def_readonly("q10", &ImpulseFromStep::q10)
      .def_readonly("g_To", &ImpulseFromStep::g_To);
  m.def("modal_frequency_response", &modal_frequency_response, py::arg("data"), py::arg("model"), py::arg("period"),
        py::arg("harmonics"), py::arg("window_start"), py::arg("rule") = Quadrature::Simpson,
        "ES 5.1-5.14: H(j k w_o) at harmonics k of a periodic input, transients annihilated by p_0.");
  m.def("modal_step_response", &modal_step_response, py::arg("data"), py::arg("model"), py::arg("level_period"),
        py::arg("horizon"), "ES 5.15-5.37: step response from a piecewise-constant input (levels change at i T).");
  m.def("modal_impulse_from_step", &modal_impulse_from_step, py::arg("step"), py::arg("negative_shifts"), py::arg("To"),
        py::arg("functions") = 6, py::arg("rule") = Quadrature::Simpson,
        "ES 5.38-5.42: impulse response from a step response with negative shifts.");

  py::class_<DeadbeatObserver>(m, "DeadbeatObserver", "El-Shafey's minimum-time (dead-beat) state observer (ch. 6).")
      .def_static("from_model", &DeadbeatObserver::from_model, py::arg("model"), py::arg("T"), py::arg("ts"))
      .def_static("from_step_response", &DeadbeatObserver::from_step_response, py::arg("model"), py::arg("step"),
                  py::arg("T"))
      .def_property_readonly("order", &DeadbeatObserver::order)
      .def_property_readonly("period", &DeadbeatObserver::period)
      .def_property_readonly("offsets", &DeadbeatObserver::offsets)
      .def_property_readonly("P", &DeadbeatObserver::P)
      .def("Qbar", &DeadbeatObserver::Qbar, py::arg("offset"))
      .def("r", &DeadbeatObserver::r, py::arg("offset"))
      .def_property_readonly("q_tilde0", &DeadbeatObserver::q_tilde0)
      .def("Q_discrete", &DeadbeatObserver::Q_discrete)
      .def("reconstruct", &DeadbeatObserver::reconstruct, py::arg("data"),
           "Phase-variable state at every sample (NaN for the first n level periods).")
      .def("markov_parameters", &DeadbeatObserver::markov_parameters, py::arg("p_n"),
           "ES-C14: the Markov parameters b~_1 .. b~_n from p_n (stable or unstable; refused for a pole at s = 0).");

  py::class_<PronyOptions>(m, "PronyOptions")
      .def(py::init<>())
      .def_readwrite("order", &PronyOptions::order)
      .def_readwrite("spacing", &PronyOptions::spacing)
      .def_readwrite("equations", &PronyOptions::equations)
      .def_readwrite("start", &PronyOptions::start);

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
  m.def("prony", &prony, py::arg("y"), py::arg("ts"), py::arg("options"), "Prony's method (poles modulo 2 pi / T).");
  bind_options<ModalResponseOptions>(m, "ModalResponseOptions");
  py::enum_<ResponseKind>(m, "ResponseKind")
      .value("step", ResponseKind::Step)
      .value("impulse", ResponseKind::Impulse)
      .value("frequency", ResponseKind::Frequency);
  py::class_<ModalResponse>(m, "ModalResponse")
      .def_readonly("kind", &ModalResponse::kind)
      .def_readonly("time", &ModalResponse::time)
      .def_readonly("frequency", &ModalResponse::frequency)
      .def_readonly("p0", &ModalResponse::p0)
      .def_readonly("modal", &ModalResponse::modal)
      .def("__repr__", &modal_response_text);
  m.def(
      "modal_response",
      [](const IdData& d, int order, ResponseKind kind, const ModalResponseOptions& o, const ModalOptions& mo) {
        return modal_response(d, order, kind, o, mo);
      },
      py::arg("data"), py::arg("order"), py::arg("kind"), py::arg("options"), py::arg("modal"),
      "El-Shafey ch. 5 step, impulse or frequency response (ctid response --method modal).");
  bind_options<PolesOptions>(m, "PolesOptions");
  py::class_<PolesComparison>(m, "PolesComparison")
      .def_readonly("data_matrix", &PolesComparison::data_matrix)
      .def_readonly("prony", &PolesComparison::prony)
      .def_readonly("prony_problem", &PolesComparison::prony_problem)
      .def_readonly("free_response", &PolesComparison::free_response)
      .def_readonly("prony_options", &PolesComparison::prony_options)
      .def_readonly("choices", &PolesComparison::choices)
      .def("__repr__", &poles_text);
  m.def("compare_poles", &compare_poles, py::arg("y"), py::arg("ts"), py::arg("order"), py::arg("options"),
        "El-Shafey's data-matrix poles beside Prony's, instants chosen from the record unless given (ctid poles).");
}

}  // namespace ctid::python
