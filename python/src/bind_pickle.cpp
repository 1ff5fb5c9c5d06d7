// ctid Python module — pickling, and so copy.copy, copy.deepcopy, multiprocessing and Dask, of records, models and
// results, bit for bit. A model travels as the library's one serialisation, the JSON text of io/json.hpp
// (any_model_to_json with exact = true, read back by parse_result_file; finite doubles round-trip exactly); a record
// and the members of a result travel as their arrays (a record of 10^6 samples as 16 MB of binary, not as text).
// Bound last: it adds __getstate__/__setstate__ to the classes the other files declared.
#include "common.hpp"

namespace ctid::python {

namespace {

template <class T>
py::class_<T> declared(py::module_& m, const char* name) {
  return py::reinterpret_borrow<py::class_<T>>(m.attr(name));
}

// The state tuple of `what`, checked for its length before it is unpacked.
void require_state(const py::tuple& t, size_t n, const char* what) {
  CTID_REQUIRE(t.size() == n, "{}: a pickled state of {} members was expected, got {} (pickled by another ctid version?)",
               what, n, t.size());
}

template <class M>
void pickle_model(py::module_& m, const char* name) {
  declared<M>(m, name).def(py::pickle([](const M& x) { return py::make_tuple(any_model_to_json(AnyModel(x), true, -1)); },
                                      [name](const py::tuple& t) {
                                        require_state(t, 1, name);
                                        ResultFile f = parse_result_file(t[0].cast<std::string>(), "<pickle>");
                                        CTID_REQUIRE(std::holds_alternative<M>(f.result.model),
                                                     "{}: the pickled model is a {}", name,
                                                     model_type_name(f.result.model));
                                        return std::get<M>(std::move(f.result.model));
                                      }));
}

template <class M>
void pickle_result(py::module_& m, const char* name) {
  using R = Result<M>;
  declared<R>(m, name).def(py::pickle(
      [](const R& r) { return py::make_tuple(r.model, r.parameters, r.fit, r.summary, r.diagnostics); },
      [name](const py::tuple& t) {
        require_state(t, 5, name);
        R r;
        r.model = t[0].cast<M>();
        r.parameters = t[1].cast<ParameterSet>();
        r.fit = t[2].cast<FitReport>();
        r.summary = t[3].cast<Summary>();
        r.diagnostics = t[4].cast<Diagnostics>();
        return r;
      }));
}

}  // namespace

void bind_pickle(py::module_& m) {
  declared<ParameterSet>(m, "ParameterSet")
      .def(py::pickle([](const ParameterSet& p) { return py::make_tuple(p.names, p.values, p.covariance, p.std, p.fixed); },
                      [](const py::tuple& t) {
                        require_state(t, 5, "ParameterSet");
                        ParameterSet p;
                        p.names = t[0].cast<std::vector<std::string>>();
                        p.values = t[1].cast<Eigen::VectorXd>();
                        p.covariance = t[2].cast<Eigen::MatrixXd>();
                        p.std = t[3].cast<Eigen::VectorXd>();
                        p.fixed = t[4].cast<std::vector<bool>>();
                        return p;
                      }));
  declared<FitReport>(m, "FitReport")
      .def(py::pickle(
          [](const FitReport& f) {
            return py::make_tuple(f.fit_percent, f.nrmse, f.mse, f.fpe, f.aic, f.aicc, f.bic, f.n_samples, f.n_parameters);
          },
          [](const py::tuple& t) {
            require_state(t, 9, "FitReport");
            return FitReport{t[0].cast<double>(), t[1].cast<double>(), t[2].cast<double>(), t[3].cast<double>(),
                             t[4].cast<double>(), t[5].cast<double>(), t[6].cast<double>(), t[7].cast<int>(),
                             t[8].cast<int>()};
          }));
  declared<Summary>(m, "Summary")
      .def(py::pickle(
          [](const Summary& s) { return py::make_tuple(std::string(to_string(s.termination)), s.message, s.iterations, s.seconds); },
          [](const py::tuple& t) {
            require_state(t, 4, "Summary");
            return Summary{termination_from_string(t[0].cast<std::string>()), t[1].cast<std::string>(), t[2].cast<int>(),
                           t[3].cast<double>()};
          }));
  declared<Diagnostics>(m, "Diagnostics")
      .def(py::pickle(
          [](const Diagnostics& d) {
            return py::make_tuple(d.condition_number, d.warnings, d.choices, d.scalars(), d.vectors());
          },
          [](const py::tuple& t) {
            require_state(t, 5, "Diagnostics");
            Diagnostics d;
            d.condition_number = t[0].cast<double>();
            d.warnings = t[1].cast<std::vector<std::string>>();
            d.choices = t[2].cast<std::vector<std::string>>();
            for (const auto& [k, v] : t[3].cast<std::map<std::string, double>>()) d.set_stored(k, v);
            for (auto& [k, v] : t[4].cast<std::map<std::string, Eigen::VectorXd>>()) d.set_stored(k, std::move(v));
            return d;
          }));
  declared<TrendInfo>(m, "TrendInfo")
      .def(py::pickle([](const TrendInfo& x) { return py::make_tuple(x.u_offset, x.u_slope, x.y_offset, x.y_slope, x.t_ref); },
                      [](const py::tuple& t) {
                        require_state(t, 5, "TrendInfo");
                        return TrendInfo{t[0].cast<Eigen::VectorXd>(), t[1].cast<Eigen::VectorXd>(),
                                         t[2].cast<Eigen::VectorXd>(), t[3].cast<Eigen::VectorXd>(), t[4].cast<double>()};
                      }));
  // A record: uniform as (ts, t0) and the deviation of the times it was read from, irregular as its times.
  declared<IdData>(m, "IdData")
      .def(py::pickle(
          [](const IdData& d) {
            std::vector<std::string> is;
            for (int i = 0; i < d.nu(); ++i) is.emplace_back(to_string(d.intersample(i)));
            const bool uniform = d.is_uniform();
            return py::make_tuple(d.u(), d.y(), uniform ? py::cast(d.ts()) : py::none(),
                                  uniform ? py::cast(d.t0()) : py::cast(d.times()), d.uniform_time_deviation(), is,
                                  py::make_tuple(d.input_names(), d.output_names(),
                                                 d.input_units(), d.output_units()));
          },
          [](const py::tuple& t) {
            require_state(t, 7, "IdData");
            auto u = t[0].cast<Eigen::MatrixXd>();
            auto y = t[1].cast<Eigen::MatrixXd>();
            IdData d = t[2].is_none() ? IdData(std::move(u), std::move(y), t[3].cast<Eigen::VectorXd>())
                                      : IdData(std::move(u), std::move(y), t[2].cast<double>(), t[3].cast<double>());
            if (d.is_uniform()) d.set_uniform_time_deviation(t[4].cast<double>());
            const auto is = t[5].cast<std::vector<std::string>>();
            for (size_t i = 0; i < is.size(); ++i) d.set_intersample(static_cast<int>(i), intersample_from_string(is[i]));
            const auto names = t[6].cast<py::tuple>();
            require_state(names, 4, "IdData names");
            const auto list = [&names](int i) { return names[static_cast<size_t>(i)].cast<std::vector<std::string>>(); };
            if (!list(0).empty()) d.set_input_names(list(0));  // empty: never named
            if (!list(1).empty()) d.set_output_names(list(1));
            if (!list(2).empty()) d.set_input_units(list(2));
            if (!list(3).empty()) d.set_output_units(list(3));
            return d;
          }));
  declared<FrequencyData>(m, "FrequencyData")
      .def(py::pickle(
          [](const FrequencyData& f) {
            return py::make_tuple(f.w(), f.matrices(), f.variance(), f.input_names, f.output_names);
          },
          [](const py::tuple& t) {
            require_state(t, 5, "FrequencyData");
            FrequencyData f(t[0].cast<Eigen::VectorXd>(), t[1].cast<std::vector<Eigen::MatrixXcd>>(),
                            t[2].cast<std::vector<Eigen::MatrixXd>>());
            f.input_names = t[3].cast<std::vector<std::string>>();
            f.output_names = t[4].cast<std::vector<std::string>>();
            return f;
          }));

  // Each model type with its result type.
  pickle_model<TransferFunction>(m, "TransferFunction");
  pickle_result<TransferFunction>(m, "TransferFunctionResult");
  pickle_model<MisoModel>(m, "MisoModel");
  pickle_result<MisoModel>(m, "MisoResult");
  pickle_model<StateSpace>(m, "StateSpace");
  pickle_result<StateSpace>(m, "StateSpaceResult");
  pickle_model<FsfModel>(m, "FsfModel");
  pickle_result<FsfModel>(m, "FsfResult");
  pickle_model<NarxModel>(m, "NarxModel");
  pickle_result<NarxModel>(m, "NarxResult");
  pickle_model<NdeModel>(m, "NdeModel");
  pickle_result<NdeModel>(m, "NdeResult");
  pickle_model<GreyboxModel>(m, "GreyboxModel");
  pickle_result<GreyboxModel>(m, "GreyboxResult");
  declared<ModalModel>(m, "ModalModel")
      .def(py::pickle([](const ModalModel& x) { return py::make_tuple(x.shifts(), x.P(), x.Q()); },
                      [](const py::tuple& t) {
                        require_state(t, 3, "ModalModel");
                        return ModalModel(t[0].cast<Eigen::VectorXd>(), t[1].cast<Eigen::MatrixXd>(),
                                          t[2].cast<Eigen::MatrixXd>());
                      }));
  pickle_result<ModalModel>(m, "ModalResult");
}

}  // namespace ctid::python
