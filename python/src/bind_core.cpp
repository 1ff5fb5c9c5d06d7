// ctid Python module — data, results, linear models, simulation and validation.
#include "common.hpp"
#include "ctid/core/check.hpp"
#include "ctid/simulate/closed_loop.hpp"
#include "ctid/simulate/example_data.hpp"

namespace ctid::python {

namespace {
// TransferFunction.simulate: u and t read in place (float64 arrays are not copied), the output written into a new
// numpy array or into `out` (a float64 array of len(u), reused by the caller), with the GIL released.
py::array_t<double> lsim_tf(const TransferFunction& g, const Eigen::Ref<const Eigen::VectorXd>& u, const py::object& t,
                            const std::string& intersample, const py::object& out) {
  using Out = py::array_t<double, py::array::c_style>;
  const Intersample is = intersample_from_string(intersample);
  const auto refuse = [&](const std::string& got) {
    throw InvalidArgument(detail::format("simulate: out must be a writable, contiguous 1-D float64 numpy array of {} "
                                         "entries (got {})", u.size(), got));
  };
  if (!out.is_none() && !py::isinstance<Out>(out)) refuse(py::str(py::type::of(out)).cast<std::string>() +
                                                          (py::isinstance<py::array>(out) ? " of dtype " +
                                                           py::str(out.attr("dtype")).cast<std::string>() : ""));
  Out y = out.is_none() ? Out(u.size()) : py::reinterpret_borrow<Out>(out);
  if (y.ndim() != 1 || y.shape(0) != u.size() || !y.writeable())
    refuse(detail::format("{} entries in {} dimension(s){}", y.size(), y.ndim(), y.writeable() ? "" : ", read-only"));
  Eigen::Map<Eigen::VectorXd> ym(y.mutable_data(), u.size());
  // t: the sample times, or a number: the sampling period of samples from t = 0 (no times to read or check).
  if (py::isinstance<py::float_>(t) || py::isinstance<py::int_>(t) ||
      (py::isinstance<py::array>(t) && py::reinterpret_borrow<py::array>(t).ndim() == 0)) {
    const double ts = t.cast<double>();
    py::gil_scoped_release release;
    lsim_into(g, u, ts, is, ym);
  } else {
    // The caster keeps a converted copy (a list, an integer array) alive while the times are read.
    py::detail::make_caster<Eigen::Ref<const Eigen::VectorXd>> times;
    if (!times.load(t, true))
      throw py::type_error("simulate: t must be a 1-D array of sample times or a sampling period (got " +
                           py::str(py::type::of(t)).cast<std::string>() + ")");
    const Eigen::Ref<const Eigen::VectorXd>& tv = times;
    py::gil_scoped_release release;
    lsim_into(g, u, tv, is, ym);
  }
  return y;
}
}  // namespace

void bind_core(py::module_& m) {
  py::class_<ParameterSet>(m, "ParameterSet", "Estimated parameters: names, values, std, covariance, fixed.")
      .def_readonly("names", &ParameterSet::names)
      .def_readonly("values", &ParameterSet::values)
      .def_readonly("std", &ParameterSet::std)
      .def_readonly("covariance", &ParameterSet::covariance)
      .def_readonly("fixed", &ParameterSet::fixed)
      .def("__len__", &ParameterSet::size)
      .def("__getitem__", &ParameterSet::value, py::arg("name"), "Value of a parameter by name.")
      .def("__repr__", &parameters_text);

  py::class_<FitReport>(m, "FitReport", "Quality of fit of the simulated output (see validate/metrics.hpp).")
      .def_readonly("fit_percent", &FitReport::fit_percent)
      .def_readonly("nrmse", &FitReport::nrmse)
      .def_readonly("mse", &FitReport::mse)
      .def_readonly("fpe", &FitReport::fpe)
      .def_readonly("aic", &FitReport::aic)
      .def_readonly("aicc", &FitReport::aicc)
      .def_readonly("bic", &FitReport::bic)
      .def_readonly("n_samples", &FitReport::n_samples)
      .def_readonly("n_parameters", &FitReport::n_parameters)
      .def("__repr__", &fit_report_text);

  py::class_<Summary>(m, "Summary", "How the run ended.")
      .def_property_readonly("termination", [](const Summary& s) { return std::string(to_string(s.termination)); })
      .def_readonly("message", &Summary::message)
      .def_readonly("iterations", &Summary::iterations)
      .def_readonly("seconds", &Summary::seconds)
      .def("succeeded", &Summary::succeeded)
      .def("__repr__", &summary_text);

  py::class_<Diagnostics>(m, "Diagnostics", "Numerical diagnostics: condition number, warnings, method-specific numbers.")
      .def_readonly("condition_number", &Diagnostics::condition_number)
      .def_readonly("warnings", &Diagnostics::warnings)
      .def_readonly("choices", &Diagnostics::choices,
                    "settings the estimator chose itself (left automatic), one line each: 'NAME = VALUE: why'")
      .def_property_readonly("scalars", &Diagnostics::scalars, "method-specific numbers by name (ctid.diagnostics())")
      .def_property_readonly("vectors", &Diagnostics::vectors, "method-specific vectors by name (ctid.diagnostics())")
      .def("__repr__", &diagnostics_text);

  py::class_<TrendInfo>(m, "TrendInfo", "What IdData.detrend_with_trend removed, per channel: offset + slope * (t - t_ref).")
      .def_readonly("u_offset", &TrendInfo::u_offset)
      .def_readonly("u_slope", &TrendInfo::u_slope)
      .def_readonly("y_offset", &TrendInfo::y_offset)
      .def_readonly("y_slope", &TrendInfo::y_slope)
      .def_readonly("t_ref", &TrendInfo::t_ref)
      .def("__repr__", [](const TrendInfo& t) {
        return detail::format("TrendInfo(u_offset={}, u_slope={}, y_offset={}, y_slope={}, t_ref={})",
                              Eigen::RowVectorXd(t.u_offset), Eigen::RowVectorXd(t.u_slope), Eigen::RowVectorXd(t.y_offset),
                              Eigen::RowVectorXd(t.y_slope), t.t_ref);
      });

  py::class_<IdData>(m, "IdData", "Sampled input/output record (columns = channels).")
      .def(py::init<Eigen::MatrixXd, Eigen::MatrixXd, double, double>(), py::arg("u"), py::arg("y"), py::arg("ts"),
           py::arg("t0") = 0.0)
      .def(py::init<Eigen::MatrixXd, Eigen::MatrixXd, Eigen::VectorXd>(), py::arg("u"), py::arg("y"), py::arg("t"))
      .def_static("from_times", &IdData::from_times, py::arg("u"), py::arg("y"), py::arg("t"),
                  "Samples at times t; uniform when every time is within kUniformTimeTolerance (1e-3) sampling "
                  "periods of a uniform grid (uniform_time_deviation() says how far).")
      .def(
          "detrend",
          [](const IdData& d, const std::string& kind) {
            CTID_REQUIRE(kind == "mean" || kind == "linear", "IdData.detrend: kind must be 'mean' or 'linear' (got '{}')",
                         kind);
            return d.detrend(kind == "mean" ? Detrend::Mean : Detrend::Linear);
          },
          py::arg("kind") = "mean",
          "A copy with each channel's mean (kind='mean') or least-squares line in time (kind='linear') removed.")
      .def(
          "detrend_with_trend",
          [](const IdData& d, const std::string& kind) {
            CTID_REQUIRE(kind == "mean" || kind == "linear",
                         "IdData.detrend_with_trend: kind must be 'mean' or 'linear' (got '{}')", kind);
            TrendInfo t;
            IdData out = d.detrend(kind == "mean" ? Detrend::Mean : Detrend::Linear, &t);
            return py::make_tuple(out, t);
          },
          py::arg("kind") = "mean", "detrend, and the TrendInfo it removed: (data, trend).")
      .def("remove_trend", &IdData::remove_trend, py::arg("trend"),
           "A copy with another record's trend (detrend_with_trend) removed at this record's times: a held-out "
           "validation record treated with the estimation record's means, so that none of its statistics enters the "
           "model.")
      .def_property_readonly("u", &IdData::u)
      .def_property_readonly("y", &IdData::y)
      .def_property_readonly("ts", &IdData::ts)
      .def_property_readonly("t0", &IdData::t0)
      .def_property_readonly("times", &IdData::times)
      .def_property_readonly("is_uniform", &IdData::is_uniform)
      .def_property_readonly("uniform_time_deviation", &IdData::uniform_time_deviation,
                             "largest distance (in Ts) of a given time from the uniform grid the data were read as")
      .def_property_readonly("nu", &IdData::nu)
      .def_property_readonly("ny", &IdData::ny)
      .def("__len__", &IdData::size)
      .def_property("input_names", &IdData::input_names, &IdData::set_input_names)
      .def_property("output_names", &IdData::output_names, &IdData::set_output_names)
      .def_property(
          "intersample",
          [](const IdData& d) {
            std::vector<std::string> v;
            for (int i = 0; i < d.nu(); ++i) v.emplace_back(to_string(d.intersample(i)));
            return v;
          },
          [](IdData& d, const std::string& s) { d.set_intersample(intersample_from_string(s)); },
          "Per input: 'zoh', 'foh' or 'bandlimited' (set: one value for all inputs).")
      .def("slice", &IdData::slice, py::arg("begin"), py::arg("end"), "Samples [begin, end).")
      .def("split", py::overload_cast<double>(&IdData::split, py::const_), py::arg("fraction"),
           "(estimation, validation) at a fraction of the samples.");

  m.def(
      "load",
      [](const std::string& path, std::vector<std::string> inputs, std::vector<std::string> outputs,
         const std::string& time, double ts, const std::string& intersample, const std::string& detrend,
         const std::string& rows) {
        RecordChoice c;
        c.inputs = std::move(inputs);
        c.outputs = std::move(outputs);
        c.time = time;
        c.ts = ts;
        c.intersample = intersample_from_string(intersample);
        if (detrend == "mean") c.detrend = Detrend::Mean;
        else if (detrend == "linear") c.detrend = Detrend::Linear;
        else if (detrend != "none") throw InvalidOptions("load: detrend must be 'none', 'mean' or 'linear' (got '" + detrend + "')");
        c.rows = rows;
        return choose_record(path, c).data;
      },
      py::arg("path"), py::arg("inputs") = std::vector<std::string>{}, py::arg("outputs") = std::vector<std::string>{},
      py::arg("time") = "", py::arg("ts") = 0.0, py::arg("intersample") = "zoh", py::arg("detrend") = "none",
      py::arg("rows") = "",
      "Load a CSV/.dat or .mat record by column / variable names or 1-based positions, with ctid fit's defaults: "
      "without time and ts the column named t or time is the time axis; without inputs and outputs a file of two other "
      "columns gives the input and the output (more: name them); with the outputs named, every other column is an "
      "input. rows='A:B' takes rows A..B (1-based, inclusive); detrend='mean' or 'linear' removes the trend after "
      "that.");

  py::class_<TransferFunction>(m, "TransferFunction", "G(s) = e^{-s delay} B(s)/A(s), descending powers of s.")
      .def(py::init([](const Eigen::VectorXd& num, const Eigen::VectorXd& den, double delay) {
             TransferFunction g(num, den, delay);
             if (const std::string why = parasitic_pole_problem(g); !why.empty()) throw InvalidArgument("TransferFunction: " + why);
             return g;
           }),
           py::arg("num"), py::arg("den"), py::arg("delay") = 0.0)
      .def_property_readonly("num", [](const TransferFunction& g) { return g.num().coefficients(); })
      .def_property_readonly("den", [](const TransferFunction& g) { return g.den().coefficients(); })
      .def_property_readonly("delay", &TransferFunction::io_delay)
      .def_property_readonly("order", &TransferFunction::order)
      .def("poles", &TransferFunction::poles)
      .def("zeros", &TransferFunction::zeros)
      .def("dc_gain", &TransferFunction::dc_gain)
      .def("is_stable", &TransferFunction::is_stable)
      .def("freqresp", &TransferFunction::frequency_response, py::arg("w"), "G(jw) at the angular frequencies w (rad/s).")
      .def("step", [](const TransferFunction& g, const Eigen::VectorXd& t) { return step_response(g, t); }, py::arg("t"))
      .def("impulse", [](const TransferFunction& g, const Eigen::VectorXd& t) { return impulse_response(g, t); },
           py::arg("t"))
      .def("simulate", &lsim_tf, py::arg("u"), py::arg("t"), py::arg("intersample") = "zoh",
           py::arg("out") = py::none(),
           "Exact simulation from rest of the input u at the times t (float64 arrays are read in place), or, t a "
           "number, at the uniform times 0, t, 2t, ... (seconds; the same as time_grid(t, len(u))); out: a "
           "float64 array of len(u) to write the output into (returned), e.g. reused over many simulations.")
      .def("__call__", &TransferFunction::operator(), py::arg("s"))
      .def("__repr__", [](const TransferFunction& g) { return g.to_string(6); });
  bind_result<TransferFunction>(m, "TransferFunctionResult");
  def_report<TransferFunction>(m);

  m.def("time_grid", &time_grid, py::arg("ts"), py::arg("n"));
  py::class_<RstController>(m, "RstController",
                            "Digital controller P(q^-1) v_k = T(q^-1) r_k - S(q^-1) y_k, u_k = clip(v_k, u_min, u_max).")
      .def(py::init<>())
      .def_readwrite("P", &RstController::P)
      .def_readwrite("S", &RstController::S)
      .def_readwrite("T", &RstController::T)
      .def_readwrite("u_min", &RstController::u_min)
      .def_readwrite("u_max", &RstController::u_max)
      .def_static("gains", &RstController::gains, py::arg("r_gain"), py::arg("y_gain"), "u = r_gain r - y_gain y.")
      .def_static("pid", &RstController::pid, py::arg("kp"), py::arg("ki"), py::arg("kd"), py::arg("tf"), py::arg("ts"),
                  "Digital PID: e = r - y, I += Ts e, D = (tf D + kd (y - y_prev)) / (tf + Ts), u = kp e + ki I - D.");
  m.def("simulate_closed_loop", &simulate_closed_loop, py::arg("plant"), py::arg("controller"), py::arg("reference"),
        py::arg("ts"), py::arg("noise") = Eigen::VectorXd(),
        "A continuous plant under a digital RST controller, sampled every ts with the input held: IdData (u, y).");
  py::class_<ExampleData>(m, "ExampleData", "A simulated example record (ctid example-data): its table and what it is.")
      .def_readonly("name", &ExampleData::name)
      .def_readonly("description", &ExampleData::description)
      .def_readonly("columns", &ExampleData::columns)
      .def_readonly("values", &ExampleData::values)
      .def("__repr__", [](const ExampleData& e) {
        return "ExampleData('" + e.name + "', " + std::to_string(e.values.rows()) + " rows: " + e.description + ")";
      });
  m.def("example_data", &example_data, py::arg("name"),
        "The simulated example record `name` the README and docs use (as `ctid example-data NAME OUT.csv`).");
  m.def("example_data_names", &example_data_names, "The names example_data knows.");
  m.def("prbs", [](int n, int register_length, int clock_period, std::uint32_t initial_state) {
          return prbs(n, {.register_length = register_length, .clock_period = clock_period, .initial_state = initial_state});
        }, py::arg("n"), py::arg("register_length") = 10, py::arg("clock_period") = 1, py::arg("initial_state") = 1,
        "PRBS of +-1 (initial_state: the non-zero register seed).");
  m.def("random_binary", &random_binary, py::arg("n"), py::arg("seed"), py::arg("clock_period") = 1,
        py::arg("amplitude") = 1.0,
        "Random binary signal: independent +-amplitude values (equal probability), each held clock_period samples.");
  m.def("multisine", &multisine, py::arg("t"), py::arg("frequencies"), py::arg("amplitudes"),
        py::arg("phases") = std::vector<double>{},
        "Sum of sinusoids at the times t: sum a_i sin(w_i t + phi_i), frequencies in rad/s; phases empty: Schroeder "
        "phases (low crest factor).");
  m.def("steps", &steps, py::arg("t"), py::arg("step_times"), py::arg("levels"),
        "Piecewise-constant signal at the times t: levels[i] from step_times[i] on (0 before the first).");
  m.def("white_noise", &white_noise, py::arg("n"), py::arg("stddev"), py::arg("seed"), "White Gaussian noise.");
  m.def("add_noise_snr", &add_noise_snr, py::arg("x"), py::arg("snr_db"), py::arg("seed"),
        "x plus white Gaussian noise at the given signal-to-noise ratio (dB, power of x - mean).");
  m.def("fit_percent", &fit_percent, py::arg("y"), py::arg("yhat"), "100 (1 - ||y - yhat|| / ||y - mean(y)||).");
  m.def("fit_percent_text", &fit_percent_text, py::arg("fit_percent"),
        "A fit in percent as text: two decimals, three significant digits from a magnitude of 10 000 (a diverging "
        "simulation), 'nan'/'inf'.");

  py::class_<CorrelationTest>(m, "CorrelationTest")
      .def_readonly("lags", &CorrelationTest::lags)
      .def_readonly("values", &CorrelationTest::values)
      .def_readonly("bound", &CorrelationTest::bound)
      .def_readonly("n_outside", &CorrelationTest::n_outside)
      .def("passed", &CorrelationTest::passed);
  m.def("residual_autocorrelation", &residual_autocorrelation, py::arg("e"), py::arg("max_lag") = 25);
  m.def("input_residual_crosscorrelation", &input_residual_crosscorrelation, py::arg("u"), py::arg("e"),
        py::arg("max_lag") = 25);
  py::class_<NonlinearCorrelationTests>(m, "NonlinearCorrelationTests")
      .def_readonly("ee", &NonlinearCorrelationTests::ee)
      .def_readonly("ue", &NonlinearCorrelationTests::ue)
      .def_readonly("e_eu", &NonlinearCorrelationTests::e_eu)
      .def_readonly("u2_e", &NonlinearCorrelationTests::u2_e)
      .def_readonly("u2_e2", &NonlinearCorrelationTests::u2_e2)
      .def("passed", &NonlinearCorrelationTests::passed);
  m.def("nonlinear_correlation_tests", &nonlinear_correlation_tests, py::arg("u"), py::arg("e"), py::arg("max_lag") = 20);

  // Response views shared with the HTML report (validate/uncertainty.hpp).
  m.def("frequency_grid", &frequency_grid, py::arg("poles"), py::arg("w_max") = 0.0, py::arg("n") = 300,
        "n log-spaced rad/s from two decades below the slowest to two above the fastest pole magnitude (<= w_max).");
  m.def("response_horizon", &response_horizon, py::arg("models"), py::arg("fallback"),
        "8 slowest stable time constants plus the largest delay of the transfer functions (s); fallback otherwise.");
  m.def(
      "magnitude_band",
      [](const Result<TransferFunction>& r, const Eigen::VectorXd& w, double level, int draws, unsigned seed) {
        const MagnitudeBand b = magnitude_band(r, w, level, draws, seed);
        return b.empty() ? py::object(py::none()) : py::object(py::make_tuple(b.lower, b.upper));
      },
      py::arg("result"), py::arg("w"), py::arg("level") = 0.95, py::arg("draws") = 200, py::arg("seed") = 1,
      "(lower, upper) of |G(jw)| over draws from the parameter covariance, or None when the result has none.");
  m.def(
      "response_band",
      [](const Result<TransferFunction>& r, const std::function<Eigen::VectorXd(const TransferFunction&)>& response,
         double level, int draws, unsigned seed) {
        const MagnitudeBand b = response_band(r, response, level, draws, seed);
        return b.empty() ? py::object(py::none()) : py::object(py::make_tuple(b.lower, b.upper));
      },
      py::arg("result"), py::arg("response"), py::arg("level") = 0.95, py::arg("draws") = 200, py::arg("seed") = 1,
      "(lower, upper): the pointwise central band of response(g) (a real array, one value per point) over the "
      "transfer functions drawn from the parameter covariance (drawn_models), or None when the result has none.");
  m.def("drawn_models", &drawn_models, py::arg("result"), py::arg("draws") = 200, py::arg("seed") = 1,
        "Transfer functions whose coefficients are drawn from N(values, covariance) of a result (seeded; empty "
        "without a usable covariance): the models behind the report's bands and pole-zero cloud.");
}

}  // namespace ctid::python
