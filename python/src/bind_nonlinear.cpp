// ctid Python module — Billings & Li (1999): polynomial NARX/NARMAX by FROLS, GFRFs, NDE models, the Kernel
// Invariance Algorithm and the output-error refinement of NDE models. Terms convert from their names
// ("y(k-1)*u(k-2)", "y*Dy").
#include "common.hpp"

namespace ctid::python {

namespace {
// The step response of a nonlinear model at the times t, counted from t[0] (the library's model_step_response):
// one input, so one column, returned as a vector.
template <class M>
Eigen::VectorXd step_from(const M& model, const Eigen::VectorXd& t, double amplitude) {
  const Eigen::VectorXd from = t.array() - (t.size() ? t(0) : 0.0);
  return model_step_response(AnyModel(model), from, amplitude).col(0);
}
}  // namespace

namespace {
template <class Term>
std::vector<std::string> names(const std::vector<Term>& terms) {
  std::vector<std::string> v;
  for (const auto& t : terms) v.push_back(t.name());
  return v;
}
}  // namespace

void bind_nonlinear(py::module_& m) {
  py::class_<NarxTerm>(m, "NarxTerm")
      .def(py::init([](const std::string& s) { return NarxTerm::parse(s); }), py::arg("name"))
      .def_property_readonly("name", &NarxTerm::name)
      .def_property_readonly("degree", &NarxTerm::degree)
      .def("__repr__", &NarxTerm::name);
  py::implicitly_convertible<std::string, NarxTerm>();
  m.def("narx_candidates", [](int degree, int ylag, int ulag, bool constant, int umin) {
          return names(narx_candidates(degree, ylag, ulag, constant, umin));
        }, py::arg("degree"), py::arg("ylag"), py::arg("ulag"), py::arg("constant") = true, py::arg("umin") = 1,
        "Names of every monomial up to `degree` in y(k-1..ylag), u(k-umin..ulag) (and 1).");
  m.def("narx_noise_candidates", [](int elag, int degree, int cross_lag) {
          return names(narx_noise_candidates(elag, degree, cross_lag));
        }, py::arg("elag"), py::arg("degree") = 1, py::arg("cross_lag") = 0);

  py::class_<NarxModel>(m, "NarxModel", "Polynomial NARX(MAX) model y(k) = sum theta_m term_m(k).")
      .def(py::init<std::vector<NarxTerm>, Eigen::VectorXd, double>(), py::arg("terms"), py::arg("coefficients"),
           py::arg("ts"))
      .def_property_readonly("terms", [](const NarxModel& n) { return names(n.terms()); })
      .def_property_readonly("coefficients", &NarxModel::coefficients)
      .def_property_readonly("ts", &NarxModel::ts)
      .def_property_readonly("max_lag", &NarxModel::max_lag)
      .def("process", &NarxModel::process, "The model without its noise terms.")
      .def("simulate", [](const NarxModel& n, const Eigen::VectorXd& u, const Eigen::VectorXd& y0) {
             return n.simulate(u, y0);
           }, py::arg("u"), py::arg("y0") = Eigen::VectorXd(), "Free run (NaN from an escape on).")
      .def("predict", &NarxModel::predict, py::arg("u"), py::arg("y"), py::arg("steps") = 1)
      .def("gfrf", [](const NarxModel& n, const std::vector<std::complex<double>>& s, bool zoh) {
             return narx_gfrf_ct(n.process(), s, zoh);
           }, py::arg("s"), py::arg("zoh") = true,
           "Continuous-time symmetric H_n(s_1..s_n) = H_n^NARX(e^{s_i T}) / prod Z(s_i) (zoh: held input).")
      .def("gfrf_discrete", [](const NarxModel& n, const std::vector<std::complex<double>>& z) {
             return narx_gfrf(n.process(), z);
           }, py::arg("z"))
      .def("freqresp", [](const NarxModel& n, const Eigen::VectorXd& w, bool zoh) {
             Eigen::VectorXcd h(w.size());
             for (Eigen::Index i = 0; i < w.size(); ++i) h(i) = narx_gfrf_ct(n.process(), {{0.0, w(i)}}, zoh);
             return h;
           }, py::arg("w"), py::arg("zoh") = true,
           "The linear part's frequency response H_1(jw) read as continuous-time (zoh: hold factor removed).")
      .def("step", [](const NarxModel& n, const Eigen::VectorXd& t, double amplitude) {
             return step_from(n, t, amplitude);
           }, py::arg("t"), py::arg("amplitude") = 1.0,
           "Free-run response from rest to the step amplitude * 1(t); t on the model's grid k * ts (from t[0]).")
      .def("__repr__", [](const NarxModel& n) { return n.to_string(6); });
  bind_result<NarxModel>(m, "NarxResult");
  def_report<NarxModel>(m);
  m.def("read_narx_json", &read_narx_json, py::arg("path"));

  bind_options<FrolsOptions>(m, "FrolsOptions");
  bind_options<NarmaxOptions>(m, "NarmaxOptions");
  // Each NARX estimator takes one record or a list of records of one system (one regression, no row across records).
  m.def("frols", [](const IdData& d, const std::vector<NarxTerm>& c, const FrolsOptions& o) {
          return interruptible([&] { return frols(d, c, o); });
        }, py::arg("data"), py::arg("candidates"), py::arg("options") = FrolsOptions{});
  m.def("frols", [](const std::vector<IdData>& d, const std::vector<NarxTerm>& c, const FrolsOptions& o) {
          return interruptible([&] { return frols(d, c, o); });
        }, py::arg("data"), py::arg("candidates"), py::arg("options") = FrolsOptions{});
  bind_options<NarxOptions>(m, "NarxOptions");
  m.def("narx", [](const IdData& d, const NarxOptions& o) { return interruptible([&] { return narx(d, o); }); },
        py::arg("data"), py::arg("options") = NarxOptions{},
        "The NARX workflow: candidates from degree and lags, FROLS with a criterion (AIC), NARMAX when noise_terms > 0.");
  m.def("narx", [](const std::vector<IdData>& d, const NarxOptions& o) { return interruptible([&] { return narx(d, o); }); },
        py::arg("data"), py::arg("options") = NarxOptions{});
  m.def("narmax", [](const IdData& d, const std::vector<NarxTerm>& c, const NarmaxOptions& o) {
          return interruptible([&] { return narmax(d, c, o); });
        }, py::arg("data"), py::arg("candidates"), py::arg("options") = NarmaxOptions{});
  m.def("narmax", [](const std::vector<IdData>& d, const std::vector<NarxTerm>& c, const NarmaxOptions& o) {
          return interruptible([&] { return narmax(d, c, o); });
        }, py::arg("data"), py::arg("candidates"), py::arg("options") = NarmaxOptions{});

  py::class_<NdeTerm>(m, "NdeTerm")
      .def(py::init([](const std::string& s) { return NdeTerm::parse(s); }), py::arg("name"))
      .def_property_readonly("name", &NdeTerm::name)
      .def_property_readonly("degree", &NdeTerm::degree)
      .def("__repr__", &NdeTerm::name);
  py::implicitly_convertible<std::string, NdeTerm>();
  py::class_<NdeSimulation>(m, "NdeSimulation")
      .def_readonly("y", &NdeSimulation::y)
      .def_property_readonly("termination", [](const NdeSimulation& s) { return std::string(to_string(s.termination)); })
      .def_readonly("message", &NdeSimulation::message)
      .def("ok", &NdeSimulation::ok);
  py::class_<NdeModel>(m, "NdeModel", "Polynomial nonlinear differential equation sum c_m prod D^l x = 0.")
      .def(py::init<std::vector<NdeTerm>, Eigen::VectorXd>(), py::arg("terms"), py::arg("coefficients"))
      .def_property_readonly("terms", [](const NdeModel& n) { return names(n.terms()); })
      .def_property_readonly("coefficients", &NdeModel::coefficients)
      .def("coefficient", &NdeModel::coefficient, py::arg("name"))
      .def("normalized", &NdeModel::normalized)
      .def("h1", &NdeModel::h1, py::arg("s"))
      .def("freqresp", [](const NdeModel& n, const Eigen::VectorXd& w) {
             Eigen::VectorXcd h(w.size());
             for (Eigen::Index i = 0; i < w.size(); ++i) h(i) = n.h1({0.0, w(i)});
             return h;
           }, py::arg("w"), "The linear part's frequency response H_1(jw) (w in rad/s).")
      .def("step", [](const NdeModel& n, const Eigen::VectorXd& t, double amplitude) {
             return step_from(n, t, amplitude);
           }, py::arg("t"), py::arg("amplitude") = 1.0,
           "Response from rest to the step amplitude * 1(t) at the times t (from t[0]); the amplitude matters: the "
           "model is nonlinear.")
      .def("h2", &NdeModel::h2, py::arg("s1"), py::arg("s2"))
      .def("h3", &NdeModel::h3, py::arg("s1"), py::arg("s2"), py::arg("s3"))
      .def("simulate", [](const NdeModel& n, const Eigen::VectorXd& u, const Eigen::VectorXd& t,
                          const std::string& intersample, const Eigen::VectorXd& x0, double rtol) {
             return n.simulate(u, t, intersample_from_string(intersample), x0, rtol);
           }, py::arg("u"), py::arg("t"), py::arg("intersample") = "zoh", py::arg("x0") = Eigen::VectorXd(),
           py::arg("rtol") = 1e-9)
      .def("__repr__", [](const NdeModel& n) { return n.to_string(6); });
  bind_result<NdeModel>(m, "NdeResult");
  def_report<NdeModel>(m);
  m.def("read_nde_json", &read_nde_json, py::arg("path"));

  bind_options<KiaPointOptions>(m, "KiaPointOptions");
  bind_options<KiaLinearOptions>(m, "KiaLinearOptions");
  bind_options<KiaQuadraticOptions>(m, "KiaQuadraticOptions");
  bind_options<KiaCubicOptions>(m, "KiaCubicOptions");
  m.def("kia_linear", &kia_linear, py::arg("narx"), py::arg("options") = KiaLinearOptions{});
  m.def("kia_quadratic", &kia_quadratic, py::arg("narx"), py::arg("linear"), py::arg("options"));
  m.def("kia_cubic", &kia_cubic, py::arg("narx"), py::arg("model"), py::arg("options"));
  m.def("kia_product_candidates", &kia_product_candidates, py::arg("degree"), py::arg("y_order"), py::arg("u_order"),
        "The default candidates of a KIA stage: every product of `degree` factors of y, Dy .. D^(y_order-1) y and "
        "u .. D^u_order u.");

  bind_options<NdeOeOptions>(m, "NdeOeOptions");
  m.def("nde_oe", [](const IdData& d, const NdeModel& initial, const NdeOeOptions& o) {
          return interruptible([&] { return nde_oe(d, initial, o); });
        }, py::arg("data"), py::arg("initial"), py::arg("options") = NdeOeOptions{});
  m.def("nde_oe", [](const std::vector<IdData>& d, const NdeModel& initial, const NdeOeOptions& o) {
          return interruptible([&] { return nde_oe(d, initial, o); });
        }, py::arg("data"), py::arg("initial"), py::arg("options") = NdeOeOptions{});

  py::class_<GreyboxSimulation>(m, "GreyboxSimulation", "Outputs y (N x ny) and states x (N x nx) of a grey-box simulation.")
      .def_readonly("y", &GreyboxSimulation::y)
      .def_readonly("x", &GreyboxSimulation::x)
      .def_readonly("message", &GreyboxSimulation::message)
      .def_property_readonly("integrator", [](const GreyboxSimulation& s) {
             return s.integrator == GreyboxIntegrator::Bdf ? "bdf" : "explicit";
           }, "the integrator that ran: explicit or bdf")
      .def("ok", &GreyboxSimulation::ok);
  py::class_<GreyboxModel>(m, "GreyboxModel",
                           "Nonlinear continuous-time grey-box model dx/dt = f(x, u, theta, t), y = h(x, u, theta, t) "
                           "(ctid.greybox_model(dict or path) builds one).")
      .def_property_readonly("inputs", [](const GreyboxModel& g) { return g.spec().inputs; })
      .def_property_readonly("states", [](const GreyboxModel& g) { return g.spec().states; })
      .def_property_readonly("outputs", &GreyboxModel::output_names)
      .def_property_readonly("parameter_names", &GreyboxModel::parameter_names)
      .def_property_readonly("parameter_values", &GreyboxModel::parameter_values)
      .def("parameter", [](const GreyboxModel& g, const std::string& name) {
             return g.parameter_values()(g.parameter_index(name));
           }, py::arg("name"))
      .def_property_readonly("initial_state", &GreyboxModel::initial_state,
                             "x0 at the parameters (NaN: an estimated state without a value)")
      .def("with_parameters", &GreyboxModel::with_parameters, py::arg("values"))
      .def("simulate", [](const GreyboxModel& g, const Eigen::MatrixXd& u, const Eigen::VectorXd& t,
                          const std::string& intersample, const Eigen::VectorXd& x0, double rtol,
                          const std::string& integrator) {
             GreyboxOptions o;  // the integrator's names are those of the fit's option
             option_table<GreyboxOptions>().set(o, "integrator", integrator);
             return g.simulate(u, t, intersample_from_string(intersample), x0, rtol, o.integrator);
           }, py::arg("u"), py::arg("t"), py::arg("intersample") = "zoh", py::arg("x0") = Eigen::VectorXd(),
           py::arg("rtol") = 1e-8, py::arg("integrator") = "auto",
           "Simulate from x0 (default: the model's initial state); u is N x nu; integrator auto, explicit or bdf.")
      .def("to_json", [](const GreyboxModel& g) { return greybox_to_json(g); }, "The model file's text.")
      .def("__eq__", [](const GreyboxModel& a, const GreyboxModel& b) { return a == b; })
      .def("__repr__", &GreyboxModel::to_string);
  bind_result<GreyboxModel>(m, "GreyboxResult");
  def_report<GreyboxModel>(m);
  m.def("parse_greybox_json", &parse_greybox_json, py::arg("text"), py::arg("source") = "<json>");
  m.def("read_greybox_json", &read_greybox_json, py::arg("path"));
  m.def("greybox_initial_state", &greybox_initial_state, py::arg("model"), py::arg("data"), py::arg("samples") = 0,
        py::arg("rtol") = 1e-8);
  bind_options<GreyboxOptions>(m, "GreyboxOptions");
  m.def("greybox", [](const IdData& d, const GreyboxModel& g, const GreyboxOptions& o) {
          return interruptible([&] { return greybox(d, g, o); });
        }, py::arg("data"), py::arg("model"), py::arg("options") = GreyboxOptions{});
  m.def("greybox", [](const std::vector<IdData>& d, const GreyboxModel& g, const GreyboxOptions& o) {
          return interruptible([&] { return greybox(d, g, o); });
        }, py::arg("data"), py::arg("model"), py::arg("options") = GreyboxOptions{});

  bind_options<KiaOptions>(m, "KiaOptions");
  py::class_<KiaRun>(m, "KiaRun", "The KIA workflow's stages: reconstructed, narx_fit_percent, refined, result().")
      .def_readonly("reconstructed", &KiaRun::reconstructed)
      .def_readonly("narx_fit_percent", &KiaRun::narx_fit_percent)
      .def_readonly("refined", &KiaRun::refined)
      .def("result", &KiaRun::result, py::return_value_policy::reference_internal,
           "The refinement when it is usable, the reconstructed equation otherwise.");
  m.def("kia", [](const IdData& d, const NarxModel& narx, const KiaOptions& o) {
          return interruptible([&] { return kia(d, narx, o); }, OnInterrupt::Raise);
        }, py::arg("data"), py::arg("narx"), py::arg("options") = KiaOptions{});
  m.def("kia", [](const std::vector<IdData>& d, const NarxModel& narx, const KiaOptions& o) {
          return interruptible([&] { return kia(d, narx, o); }, OnInterrupt::Raise);
        }, py::arg("data"), py::arg("narx"), py::arg("options") = KiaOptions{},
        "Several records (experiments of one system): pooled fits, one refinement with an initial state per record.");
}

}  // namespace ctid::python
