// ctid Python module — any model (model/any_model.hpp): state-space models, simulate() with its initial
// condition, and the one reader/writer of result files (io/json.hpp). Bound after every model type.
#include "common.hpp"

namespace ctid::python {

py::object typed(const Result<AnyModel>& r) {
  return std::visit(
      [&r](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        return py::cast(Result<M>{m, r.parameters, r.fit, r.summary, r.diagnostics});
      },
      r.model);
}

namespace {
template <class M>
void def_write_result(py::module_& m) {
  m.def(
      "write_result",
      [](const std::string& path, const Result<M>& r, const std::string& method) {
        write_result_json(path, to_any(r), method);
      },
      py::arg("path"), py::arg("result"), py::arg("method"),
      "Write a result as JSON (the file ctid fit --json writes; read back by read_result and the CLI).");
}
}  // namespace

namespace {
// A batch row as a dict (column -> str, float, int or bool) and back (None and NaN as NaN).
py::dict row_dict(const BatchRow& row) {
  py::dict d;
  for (const auto& [name, cell] : row) d[py::str(name)] = std::visit([](const auto& v) { return py::cast(v); }, cell);
  return d;
}
BatchRow dict_row(const py::dict& d) {
  BatchRow row;
  for (const auto& [k, v] : d) {
    const std::string name = py::str(k);
    if (py::isinstance<py::bool_>(v)) row.emplace_back(name, v.cast<bool>());
    else if (py::isinstance<py::str>(v)) row.emplace_back(name, v.cast<std::string>());
    else if (py::isinstance<py::int_>(v)) row.emplace_back(name, v.cast<std::int64_t>());
    else if (v.is_none()) row.emplace_back(name, std::numeric_limits<double>::quiet_NaN());
    else row.emplace_back(name, v.cast<double>());  // float, numpy numbers; anything else: TypeError
  }
  return row;
}

// The library's batch rows and their file (io/batch_file.hpp), for ctid.batch.
void bind_batch_rows(py::module_& m) {
  m.attr("BATCH_COLUMNS") = batch_columns();
  std::apply(
      [&](auto... model) {
        (m.def(
             "batch_row",
             [](const std::string& id, const std::string& method, const Result<decltype(model)>& r) {
               const Result<AnyModel> any = to_any(r);
               return row_dict(batch_row(id, method, &any, "", 0.0));
             },
             py::arg("id"), py::arg("method"), py::arg("result"),
             "The batch row of a fitted record (the columns of batch_columns, then NAME and NAME_std per parameter)."),
         ...);
      },
      std::tuple<TransferFunction, MisoModel, StateSpace, FsfModel, NarxModel, NdeModel, GreyboxModel>{});
  m.def(
      "batch_row",
      [](const std::string& id, const std::string& method, py::none, const std::string& error, double seconds) {
        return row_dict(batch_row(id, method, nullptr, error, seconds));
      },
      py::arg("id"), py::arg("method"), py::arg("result"), py::arg("error"), py::arg("seconds"),
      "The batch row of a record that could not be read or fitted: its error and the seconds spent.");
  py::class_<BatchFile>(m, "BatchFile",
                        "A batch's rows file (.csv or .jsonl), written row by row as rows are added; with resume the "
                        "rows of an existing file are read first.")
      .def(py::init<std::string, bool>(), py::arg("path"), py::arg("resume"))
      .def_property_readonly("path", &BatchFile::path)
      .def_property_readonly("rows",
                             [](const BatchFile& f) {
                               py::list out;
                               for (const auto& r : f.rows()) out.append(row_dict(r));
                               return out;
                             })
      .def("__contains__", &BatchFile::contains, py::arg("id"))
      .def("usable", &BatchFile::usable)
      .def("add", [](BatchFile& f, const py::dict& row) { f.add(dict_row(row)); }, py::arg("row"));
}
}  // namespace

void bind_models(py::module_& m) {
  py::class_<StateSpace>(m, "StateSpace",
                         "Continuous-time state-space model x' = A x + B u, y = C x + D u; with an innovation gain K "
                         "(nx x ny) the innovation form x' = A x + B u + K e, y = C x + D u + e.")
      .def(py::init<Eigen::MatrixXd, Eigen::MatrixXd, Eigen::MatrixXd, Eigen::MatrixXd, Eigen::MatrixXd>(),
           py::arg("A"), py::arg("B"), py::arg("C"), py::arg("D"), py::arg("K") = Eigen::MatrixXd())
      .def_property_readonly("A", &StateSpace::A)
      .def_property_readonly("B", &StateSpace::B)
      .def_property_readonly("C", &StateSpace::C)
      .def_property_readonly("D", &StateSpace::D)
      .def_property_readonly("K", [](const StateSpace& ss) -> py::object {
             if (!ss.has_innovation_gain()) return py::none();
             return py::cast(ss.K());
           }, "The innovation gain (nx x ny), None for an output-error model.")
      .def("predict",
           [](const StateSpace& ss, const IdData& d, const Eigen::VectorXd& x0) {
             LsimOptions o;
             o.x0 = x0;
             py::gil_scoped_release release;
             return predict(ss, d, o);
           },
           py::arg("data"), py::arg("x0") = Eigen::VectorXd(),
           "One-step-ahead predictions (N x ny) with the innovation held between samples (exact for held and "
           "first-order-hold inputs, any sample times); without K the simulation.")
      .def_property_readonly("nx", &StateSpace::nx)
      .def_property_readonly("nu", &StateSpace::nu)
      .def_property_readonly("ny", &StateSpace::ny)
      .def("poles", &StateSpace::poles)
      .def("modes", [](const StateSpace& ss) {
             py::list out;
             for (const Mode& m : ss.modes())
               out.append(py::dict(py::arg("pole") = m.pole, py::arg("wn") = m.wn, py::arg("zeta") = m.zeta,
                                   py::arg("shape") = m.shape));
             return out;
           },
           "Modes by increasing natural frequency: dicts with pole, wn (rad/s), zeta and shape (C v, unit norm, its "
           "largest entry real and positive).")
      .def("to_transfer_function", &StateSpace::to_transfer_function, py::arg("out") = 0, py::arg("input") = 0)
      .def("step", [](const StateSpace& ss, const Eigen::VectorXd& t) { return step_response(ss, t); }, py::arg("t"),
           "Step responses: a list over the inputs of (len(t) x ny) arrays (unit step at t = 0, from rest).")
      .def("impulse", [](const StateSpace& ss, const Eigen::VectorXd& t) { return impulse_response(ss, t); },
           py::arg("t"), "Impulse responses C e^{At} B: a list over the inputs of (len(t) x ny) arrays.")
      .def("frequency_response", [](const StateSpace& ss, const Eigen::VectorXd& w) { return frequency_response(ss, w); },
           py::arg("w"), "G(jw) (ny x nu complex) at each w (rad/s), as a list.");
  bind_result<StateSpace>(m, "StateSpaceResult");

  py::class_<Simulation>(m, "Simulation", "A simulation: outputs y (N x ny), the initial state used, and the problem "
                                          "('' when every output is finite).")
      .def_readonly("y", &Simulation::y)
      .def_readonly("x0", &Simulation::x0)
      .def_readonly("problem", &Simulation::problem)
      .def("ok", &Simulation::ok);
  m.def(
      "simulate_model",
      [](const AnyModel& model, const IdData& d, const std::string& initial, const Eigen::VectorXd& x0, int initial_samples) {
        SimulateOptions o;
        o.initial = initial_condition_from_string(initial);
        o.x0 = x0;
        o.initial_samples = initial_samples;
        return simulate(model, d, o);
      },
      py::arg("model"), py::arg("data"), py::arg("initial") = "rest", py::arg("x0") = Eigen::VectorXd(),
      py::arg("initial_samples") = 0,
      "Simulate any model on a record (simulate/simulate.hpp): initial 'rest', 'measured' or 'estimated'.");
  m.def("model_frequency_grid", &model_frequency_grid, py::arg("model"), py::arg("w_max") = 0.0, py::arg("n") = 300,
        "The default frequency grid (rad/s) of a model's frequency response, the report's: frequency_grid of its poles "
        "up to w_max (linear models), an FSF model's own band (log-spaced, 2 pi / (2 T) to 0.95 pi / Delta).");
  // A result simulated for a purpose: the library's one rule for its initial state (simulate_options).
  const auto purpose_of = [](const std::string& p) {
    if (p == "own_fit") return SimulationPurpose::OwnFit;
    if (p == "other_record") return SimulationPurpose::OtherRecord;
    if (p == "validation") return SimulationPurpose::Validation;
    if (p == "free_run") return SimulationPurpose::FreeRun;
    throw InvalidArgument("simulate: purpose must be own_fit, other_record, validation or free_run (got '" + p + "')");
  };
  std::apply(
      [&](auto... model) {
        (m.def(
             "simulate_result",
             [purpose_of](const Result<decltype(model)>& r, const IdData& d, const std::string& purpose,
                          const std::string& initial, int initial_samples) {
               const std::optional<InitialCondition> given =
                   initial.empty() ? std::nullopt : std::optional(initial_condition_from_string(initial));
               return simulate(to_any(r), d, purpose_of(purpose), given, initial_samples);
             },
             py::arg("result"), py::arg("data"), py::arg("purpose") = "free_run", py::arg("initial") = "",
             py::arg("initial_samples") = 0,
             "A result's model simulated on a record for a purpose (own_fit, other_record, validation, free_run): the "
             "library's rule for the initial state; initial '' is the purpose's default."),
         ...);
      },
      std::tuple<TransferFunction, MisoModel, StateSpace, FsfModel, NarxModel, NdeModel, GreyboxModel>{});
  py::class_<ModelComparison>(m, "ModelComparison",
                              "One model scored on a record (compare_models): name, model, initial (the initial "
                              "condition it was simulated from), simulation, fits (a FitReport per output), whiteness "
                              "(a CorrelationTest per output; no lags where the residuals are not finite) and "
                              "independence (per output, one CorrelationTest per input).")
      .def_readonly("name", &ModelComparison::name)
      .def_property_readonly("model", [](const ModelComparison& c) { return c.model; })
      .def_property_readonly("initial", [](const ModelComparison& c) { return std::string(to_string(c.initial)); })
      .def_readonly("simulation", &ModelComparison::simulation)
      .def_readonly("fits", &ModelComparison::fits)
      .def_readonly("whiteness", &ModelComparison::whiteness)
      .def_readonly("independence", &ModelComparison::independence)
      .def("mean_fit", &ModelComparison::mean_fit, "Mean fit (%) over the outputs (-inf where a simulation diverges).")
      .def("mean_nrmse", &ModelComparison::mean_nrmse, "Mean NRMSE over the outputs.")
      .def("total_aic", &ModelComparison::total_aic, "AIC summed over the outputs.")
      .def("__repr__", [](const ModelComparison& c) {
        char fit[32];
        std::snprintf(fit, sizeof fit, "%.2f", c.mean_fit());
        return "<ModelComparison " + c.name + ": " + model_type_name(c.model) + ", fit " + fit + " %, initial " +
               to_string(c.initial) + ">";
      });
  m.def(
      "compare_models",
      [](const IdData& d, const std::vector<std::pair<std::string, AnyModel>>& models, const std::string& initial,
         int max_lag) {
        std::optional<InitialCondition> ic;
        if (!initial.empty()) ic = initial_condition_from_string(initial);
        py::gil_scoped_release release;
        return compare_models(d, models, ic, max_lag);
      },
      py::arg("data"), py::arg("models"), py::arg("initial") = "", py::arg("max_lag") = 25,
      "Score several models [(name, model), ..] on one record (validate/compare.hpp): each simulated from initial "
      "('rest', 'measured', 'estimated'; '' = each model's validation condition), its fit per output and residual "
      "tests. A diverging model is recorded (its simulation.problem), not an error.");
  m.def(
      "html_comparison_report",
      [](const IdData& d, const std::vector<ModelComparison>& cs, const std::string& path, const std::string& title,
         const std::string& data_source) {
        ReportOptions o;
        o.title = title;
        o.data_source = data_source;
        write_text_file(path, html_comparison_report(d, cs, o));
      },
      py::arg("data"), py::arg("comparisons"), py::arg("path"), py::arg("title") = "", py::arg("data_source") = "",
      "Write the side-by-side HTML report (ctid compare --report) of compare_models' result on the same record.");
  m.def("model_type_name", &model_type_name, py::arg("model"), "The model's JSON type name.");
  m.def("model_step_response", &model_step_response, py::arg("model"), py::arg("t"), py::arg("amplitude") = 1.0,
        "Response from rest to the step amplitude * 1(t) at the times t (s) of any model, one column per input.");
  m.def("model_impulse_response", &model_impulse_response, py::arg("model"), py::arg("t"),
        "Impulse response at the times t (s) of a linear model, one column per input.");
  m.def("model_frequency_response", &model_frequency_response, py::arg("model"), py::arg("w"),
        "G(jw) at the angular frequencies w (rad/s) of a linear model, one column per input.");

  py::class_<ResultFile>(m, "ResultFile", "A result file read back: result (typed by its model), method, bare.")
      .def_property_readonly("result", [](const ResultFile& f) { return typed(f.result); })
      .def_readonly("method", &ResultFile::method)
      .def_readonly("bare", &ResultFile::bare);
  m.def("read_result", &read_result_file, py::arg("path"),
        "Read any result or model file ctid writes; the model type is recognised from the file.");
  def_write_result<TransferFunction>(m);
  def_write_result<MisoModel>(m);
  def_write_result<StateSpace>(m);
  def_write_result<FsfModel>(m);
  def_write_result<NarxModel>(m);
  def_write_result<NdeModel>(m);
  def_write_result<GreyboxModel>(m);
  bind_batch_rows(m);
}

}  // namespace ctid::python
