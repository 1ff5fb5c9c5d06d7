// ctid Python module — linear transfer-function estimators: Johansson's LSSVF/IVSVF, SRIVC (SISO, MISO,
// closed loop), output error, tfest, fits to frequency-response data and order selection (options structs
// field for field; ctid/__init__.py turns keyword arguments into them).
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
template <class Options>
using ExperimentsEstimator = Result<TransferFunction> (*)(const std::vector<IdData>&, const TfOrders&, const Options&);

template <class Options>
void def_experiments_estimator(py::module_& m, const char* name, ExperimentsEstimator<Options> f) {
  m.def(
      name,
      [f](const std::vector<IdData>& d, int nb, int nf, int nk, const Options& o) {
        return interruptible([&] { return f(d, TfOrders{nb, nf, nk}, o); });
      },
      py::arg("data"), py::arg("nb"), py::arg("nf"), py::arg("nk") = 0, py::arg("options") = Options{},
      "The same on several experiments (a list of IdData) of one system: one parameter set.");
}
}  // namespace

void bind_linear(py::module_& m) {

  bind_options<LssvfOptions>(m, "LssvfOptions");
  bind_options<SubspaceOptions>(m, "SubspaceOptions");
  m.def("subspace", [](const IdData& d, const SubspaceOptions& o) { return interruptible([&] { return subspace(d, o); }); },
        py::arg("data"), py::arg("options") = SubspaceOptions{},
        "MIMO continuous-time state space by subspace identification.");
  m.def("subspace",
        [](const FrequencyData& d, const SubspaceOptions& o) { return interruptible([&] { return subspace(d, o); }); },
        py::arg("data"), py::arg("options") = SubspaceOptions{},
        "Continuous-time state space from an FRF matrix by frequency-domain subspace identification.");
  bind_options<SsestOptions>(m, "SsestOptions");
  m.def("ssest",
        [](const FrequencyData& d, const std::optional<StateSpace>& initial, const SsestOptions& o) {
          return interruptible([&] { return initial ? ssest(d, *initial, o) : ssest(d, o); });
        },
        py::arg("data"), py::arg("initial") = std::nullopt, py::arg("options") = SsestOptions{},
        "Continuous-time state space from an FRF matrix by weighted least squares from the frequency-domain subspace "
        "start.");
  m.def("ssest",
        [](const std::vector<IdData>& d, const std::optional<StateSpace>& initial, const SsestOptions& o) {
          return interruptible([&] { return initial ? ssest(d, *initial, o) : ssest(d, o); });
        },
        py::arg("data"), py::arg("initial") = std::nullopt, py::arg("options") = SsestOptions{},
        "MIMO continuous-time state space by output error (records: a list of IdData; initial: a starting model).");
  m.def("crlb", &crlb, py::arg("truth"), py::arg("nb"), py::arg("data"), py::arg("noise_variance"),
        py::arg("with_delay") = false,
        "Cramer-Rao bound of a transfer function's [a1..an, b0..b(nb-1)] (and the delay last with with_delay) for "
        "output-error identification with white output noise of this variance, on the record's input and times.");
  m.def("ssest_crlb", &ssest_crlb, py::arg("truth"), py::arg("data"), py::arg("noise_variance"),
        py::arg("options") = SsestOptions{},
        "Cramer-Rao bound of ssest's parameters and modes at a true model (records at rest, white output noise).");
  m.def(
      "mode_uncertainty",
      [](const Result<StateSpace>& r) {
        const std::vector<ModeUncertainty> u = mode_uncertainty(r);
        Eigen::MatrixXd out(static_cast<Eigen::Index>(u.size()), 2);
        for (size_t k = 0; k < u.size(); ++k) out.row(static_cast<Eigen::Index>(k)) << u[k].wn_std, u[k].zeta_std;
        return out;
      },
      py::arg("result"), "Standard deviations [wn (rad/s), zeta] of each mode of a state-space result, one row per mode.");
  m.def(
      "frequency_response_std",
      [](const Result<StateSpace>& r, const Eigen::VectorXd& w, int out, int in) {
        const ResponseStd s = frequency_response_std(r, w, out, in);
        return std::make_pair(s.magnitude, s.phase);
      },
      py::arg("result"), py::arg("w"), py::arg("out") = 0, py::arg("in") = 0,
      "Standard deviations of |G(jw)| and arg G(jw) (rad) from input `in` to output `out` of a state-space result.");
  bind_options<IvsvfOptions>(m, "IvsvfOptions");
  bind_options<SrivcOptions>(m, "SrivcOptions");
  bind_options<OeOptions>(m, "OeOptions");
  bind_options<RlsSvfOptions>(m, "RlsSvfOptions");

  bind_options<SrivcAutoOptions>(m, "SrivcAutoOptions");
  bind_options<SrivcMisoOptions>(m, "SrivcMisoOptions");
  bind_options<ClosedLoopOptions>(m, "ClosedLoopOptions");
  py::class_<FrequencyData>(m, "FrequencyData",
                            "G(jw) at angular frequencies w (rad/s): one channel, or an ny x nu matrix per frequency "
                            "with optional variances E|G_hat - G|^2 of its entries.")
      .def(py::init<Eigen::VectorXd, Eigen::VectorXcd>(), py::arg("w"), py::arg("response"))
      .def(py::init<Eigen::VectorXd, std::vector<Eigen::MatrixXcd>, std::vector<Eigen::MatrixXd>>(), py::arg("w"),
           py::arg("matrices"), py::arg("variance") = std::vector<Eigen::MatrixXd>{})
      .def_property_readonly("matrices", &FrequencyData::matrices)
      .def_property_readonly("variance", &FrequencyData::variance)
      .def_property_readonly("outputs", &FrequencyData::outputs)
      .def_property_readonly("inputs", &FrequencyData::inputs)
      .def("channel", &FrequencyData::channel, py::arg("out"), py::arg("in"), "G_out,in(jw) (0-based indices).")
      .def_readwrite("input_names", &FrequencyData::input_names)
      .def_readwrite("output_names", &FrequencyData::output_names)
      .def_static("from_spectra", &FrequencyData::from_spectra, py::arg("w"), py::arg("U"), py::arg("Y"),
                  "G = Y / U from input and output spectra at w.")
      .def_property_readonly("w", &FrequencyData::w)
      .def_property_readonly("response", &FrequencyData::response)
      .def("__len__", &FrequencyData::size);
  bind_options<FrequencyFitOptions>(m, "FrequencyFitOptions");
  m.def("average_periods", &average_periods, py::arg("data"), py::arg("period"), py::arg("skip") = 1,
        "The mean period of a periodic record (period in samples; the first `skip` periods dropped).");
  m.def("frf_from_periodic", &frf_from_periodic, py::arg("records"), py::arg("period"), py::arg("skip") = 1,
        py::arg("excited") = 0.1,
        "FRF matrix with variances from periodic records (one per input), at the excited DFT bins.");
  py::enum_<OrderCriterion>(m, "OrderCriterion")
      .value("Yic", OrderCriterion::Yic)
      .value("Rt2", OrderCriterion::Rt2)
      .value("Aic", OrderCriterion::Aic)
      .value("Bic", OrderCriterion::Bic);
  py::class_<OrderSelectionOptions>(m, "OrderSelectionOptions")
      .def(py::init<>())
      .def_readwrite("srivc", &OrderSelectionOptions::srivc)
      .def_readwrite("rank_by", &OrderSelectionOptions::rank_by);
  py::class_<OrderCandidate>(m, "OrderCandidate", "One ranked structure of select_order.")
      .def_property_readonly("orders",
                             [](const OrderCandidate& c) { return py::make_tuple(c.orders.nb, c.orders.nf, c.orders.nk); })
      .def_readonly("yic", &OrderCandidate::yic)
      .def_readonly("rt2", &OrderCandidate::rt2)
      .def_readonly("aic", &OrderCandidate::aic)
      .def_readonly("bic", &OrderCandidate::bic)
      .def_readonly("fit_percent", &OrderCandidate::fit_percent)
      .def_readonly("usable", &OrderCandidate::usable)
      .def_readonly("termination", &OrderCandidate::termination)
      .def("__repr__", [](const OrderCandidate& c) {
        char criteria[64];
        std::snprintf(criteria, sizeof criteria, "yic %.4g, rt2 %.4g", c.yic, c.rt2);
        return detail::format("[nb={} nf={} nk={}] {}, fit {} %{}", c.orders.nb, c.orders.nf, c.orders.nk, criteria,
                              fit_percent_text(c.fit_percent),
                              c.usable ? "" : " (not usable: " + c.termination + ")");
      });
  py::class_<MisoModel>(m, "MisoModel", "y = sum_i G_i(s) u_i: one transfer function per input.")
      .def(py::init<>())
      .def_readwrite("channels", &MisoModel::channels)
      .def_property_readonly("nu", &MisoModel::nu)
      .def("is_stable", &MisoModel::is_stable)
      .def("simulate", [](const MisoModel& g, const IdData& d) { return lsim(g, d); }, py::arg("data"),
           "Exact simulation from rest of the inputs of data (their intersample behaviour).")
      .def("freqresp", [](const MisoModel& g, const Eigen::VectorXd& w) { return model_frequency_response(g, w); },
           py::arg("w"), "G_i(jw) at w (rad/s), one column per input channel.")
      .def("step", [](const MisoModel& g, const Eigen::VectorXd& t) { return model_step_response(g, t); }, py::arg("t"),
           "Unit-step response of each channel at the times t (s), one column per input channel.")
      .def("impulse", [](const MisoModel& g, const Eigen::VectorXd& t) { return model_impulse_response(g, t); },
           py::arg("t"), "Impulse response of each channel at the times t (s), one column per input channel.")
      .def("__repr__", [](const MisoModel& g) { return g.to_string(6); });
  bind_result<MisoModel>(m, "MisoResult");
  def_report<MisoModel>(m);

  def_tf_estimator<LssvfOptions>(m, "lssvf", &lssvf, "Johansson (1986) least squares on state-variable-filtered signals.");
  def_tf_estimator<IvsvfOptions>(m, "ivsvf", &ivsvf, "Johansson's regression with instrumental variables.");
  def_tf_estimator<SrivcOptions>(m, "srivc", &srivc, "Simplified refined instrumental variables (SISO).");
  m.def(
      "srivc_auto",
      [](const IdData& d, const SrivcAutoOptions& o) { return interruptible([&] { return srivc_auto(d, o); }); },
      py::arg("data"), py::arg("options") = SrivcAutoOptions{},
      "SRIVC over nf = 1..nf_max, nb = 1..nf, each with and without a delay search; the least BIC.");
  m.def(
      "srivc_auto_miso",
      [](const IdData& d, const SrivcAutoOptions& o) { return interruptible([&] { return srivc_auto_miso(d, o); }); },
      py::arg("data"), py::arg("options") = SrivcAutoOptions{},
      "srivc_auto for several inputs: each channel's structure and delay by srivc_auto, backfitted on the output "
      "less the other channels, the joint srivc_miso fit of least BIC.");
  // Several experiments (a list of IdData) of one system: one parameter set.
  def_experiments_estimator<SrivcOptions>(m, "srivc", &srivc);
  def_experiments_estimator<LssvfOptions>(m, "lssvf", &lssvf);
  def_experiments_estimator<IvsvfOptions>(m, "ivsvf", &ivsvf);
  def_experiments_estimator<OeOptions>(m, "oe", &oe);
  def_experiments_estimator<OeOptions>(m, "tfest", &tfest);
  def_experiments_estimator<RlsSvfOptions>(m, "rls_svf", &rls_svf);
  def_tf_estimator<OeOptions>(m, "oe", &oe, "Continuous-time output error (Levenberg-Marquardt).");
  def_tf_estimator<OeOptions>(m, "tfest", &tfest, "SRIVC start, then output-error refinement.");
  def_tf_estimator<RlsSvfOptions>(m, "rls_svf", &rls_svf,
                                  "Recursive least squares on filtered signals run once over the record (final estimate).");
  m.def(
      "srivc_miso",
      [](const std::vector<IdData>& d, const std::vector<std::tuple<int, int, int>>& orders, const SrivcMisoOptions& o) {
        std::vector<TfOrders> to;
        for (const auto& [nb, nf, nk] : orders) to.push_back({nb, nf, nk});
        return interruptible([&] { return srivc_miso(d, to, o); });
      },
      py::arg("data"), py::arg("orders"), py::arg("options") = SrivcMisoOptions{},
      "SRIVC with several inputs on several experiments (a list of IdData), jointly; orders: one (nb, nf, nk) per input.");
  m.def(
      "srivc_miso",
      [](const IdData& d, const std::vector<std::tuple<int, int, int>>& orders, const SrivcMisoOptions& o) {
        std::vector<TfOrders> to;
        for (const auto& [nb, nf, nk] : orders) to.push_back({nb, nf, nk});
        return interruptible([&] { return srivc_miso(d, to, o); });
      },
      py::arg("data"), py::arg("orders"), py::arg("options") = SrivcMisoOptions{},
      "SRIVC with several inputs; orders: one (nb, nf, nk) per input.");
  m.def(
      "srivc_closed_loop",
      [](const IdData& d, const Eigen::VectorXd& reference, int nb, int nf, int nk, const ClosedLoopOptions& o) {
        return interruptible([&] { return srivc_closed_loop(d, reference, TfOrders{nb, nf, nk}, o); });
      },
      py::arg("data"), py::arg("reference"), py::arg("nb"), py::arg("nf"), py::arg("nk"), py::arg("options"),
      "Closed-loop SRIVC with a known controller (instruments from the reference).");
  m.def(
      "srivc_closed_loop",
      [](const std::vector<IdData>& d, const std::vector<Eigen::VectorXd>& references, int nb, int nf, int nk,
         const ClosedLoopOptions& o) {
        return interruptible([&] { return srivc_closed_loop(d, references, TfOrders{nb, nf, nk}, o); });
      },
      py::arg("data"), py::arg("references"), py::arg("nb"), py::arg("nf"), py::arg("nk"), py::arg("options"),
      "Closed-loop SRIVC on several experiments of one loop (a list of IdData, one reference per record), jointly.");
  m.def(
      "tf_from_frequency",
      [](const FrequencyData& d, int nb, int nf, const FrequencyFitOptions& o) {
        return interruptible([&] { return tf_from_frequency(d, TfOrders{nb, nf, 0}, o); });
      },
      py::arg("data"), py::arg("nb"), py::arg("nf"), py::arg("options") = FrequencyFitOptions{},
      "Sanathanan-Koerner iterations, then output-error refinement on G(jw).");
  m.def(
      "lssvf",
      [](const FrequencyData& d, int nb, int nf, int nk, const LssvfOptions& o) {
        return interruptible([&] { return lssvf(d, TfOrders{nb, nf, nk}, o); });
      },
      py::arg("data"), py::arg("nb"), py::arg("nf"), py::arg("nk") = 0, py::arg("options") = LssvfOptions{},
      "Johansson's least squares in the frequency domain (RJ 45) on frequency-response data.");
  m.def("svf_gamma", &svf_gamma, py::arg("model"), py::arg("tau"), py::arg("w"),
        "Gamma_tau(i w) = [z G0, .., z^n G0, z, .., z^n] (RJ 49-50): the filtered regressor's response to the input.");
  py::class_<SvfInformation>(m, "SvfInformation",
                             "Information matrix of theta_tau per second of data for an input line spectrum (RJ 47-50).")
      .def_readonly("matrix", &SvfInformation::matrix)
      .def_readonly("eigenvalues", &SvfInformation::eigenvalues)
      .def_readonly("directions", &SvfInformation::directions)
      .def_readonly("rank", &SvfInformation::rank)
      .def_readonly("condition", &SvfInformation::condition)
      .def_property_readonly("identifiable", &SvfInformation::identifiable);
  m.def("svf_information", &svf_information, py::arg("model"), py::arg("tau"), py::arg("w"), py::arg("power"),
        "Information matrix of theta_tau for u = sum A_k cos(w_k t + phase_k), power_k = A_k^2 / 2 (RJ 47-50).");
  m.def(
      "select_order",
      [](const IdData& d, std::pair<int, int> nb, std::pair<int, int> nf, std::pair<int, int> nk,
         const OrderSelectionOptions& o) {
        return interruptible(
            [&] { return select_order(d, {nb.first, nb.second}, {nf.first, nf.second}, {nk.first, nk.second}, o); },
            OnInterrupt::Raise);
      },
      py::arg("data"), py::arg("nb"), py::arg("nf"), py::arg("nk"), py::arg("options") = OrderSelectionOptions{},
      "Fit every [nb nf nk] of the (min, max) ranges by SRIVC; ranked, usable first.");
}

}  // namespace ctid::python
