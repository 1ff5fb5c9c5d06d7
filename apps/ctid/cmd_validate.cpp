// ctid validate MODEL.json DATA [--initial rest|measured|estimated] [--json OUT.json]: fit and residual tests of any
// result or model file on a record, per output (simulated by simulate(), simulate/simulate.hpp).
#include <cstdio>
#include <functional>

#include <nlohmann/json.hpp>

#include "common.hpp"

namespace ctid::cli {

namespace {
struct ValArgs {
  std::string model;
  std::vector<std::string> paths;  // several: experiments of one system, each validated
  DataArgs data;
  std::string json;
  int lags = 25;
  std::string initial;  // "": the library's default for a free run (simulate_options, SimulationPurpose::FreeRun)
  int initial_samples = 0;
  bool force = false;
};

nlohmann::ordered_json corr_json(const CorrelationTest& c) {
  return {{"lags", std::vector<int>(c.lags.begin(), c.lags.end())},
          {"values", std::vector<double>(c.values.begin(), c.values.end())},
          {"bound_99", c.bound},
          {"n_outside", c.n_outside},
          {"passed", c.passed()}};
}

// One output's fit and residual tests, printed and as JSON.
nlohmann::ordered_json validate_output(const ValArgs& a, const IdData& d, const Eigen::VectorXd& y,
                                       const Eigen::VectorXd& yhat, int n_coefficients, const std::string& path) {
  FitReport f;
  try {
    f = fit_report(y, yhat, n_coefficients);
  } catch (const InvalidArgument& e) {
    throw InputError(path + ": " + e.what());
  }
  const Eigen::VectorXd e = y - yhat;
  const CorrelationTest ac = residual_autocorrelation(e, a.lags);
  std::vector<CorrelationTest> xcs;
  for (int i = 0; i < d.nu(); ++i) xcs.push_back(input_residual_crosscorrelation(d.u().col(i), e, a.lags));
  std::printf("fit: %s %%   NRMSE %.4g   MSE %.4g   (%d samples)\n", fit_percent_text(f.fit_percent).c_str(), f.nrmse, f.mse, f.n_samples);
  std::printf("residual whiteness (lags 1..%d): %d outside the 99 %% bound %.3g -> %s\n", a.lags, ac.n_outside, ac.bound,
              ac.passed() ? "passed" : "not white");
  for (int i = 0; i < d.nu(); ++i)
    std::printf("input %s - residual independence (lags -%d..%d): %d outside -> %s\n", d.input_names()[i].c_str(), a.lags,
                a.lags, xcs[i].n_outside, xcs[i].passed() ? "passed" : "correlated (unmodelled dynamics)");
  nlohmann::ordered_json j;
  j["fit"] = {{"fit_percent", f.fit_percent}, {"nrmse", f.nrmse}, {"mse", f.mse}, {"n_samples", f.n_samples}};
  j["residual_autocorrelation"] = corr_json(ac);
  j["input_residual_crosscorrelation"] = nlohmann::ordered_json::array();
  for (const auto& xc : xcs) j["input_residual_crosscorrelation"].push_back(corr_json(xc));
  return j;
}

// One record: each output's fit and residual tests (one output: at the top level of the JSON; several: under
// "outputs", each with its name).
nlohmann::ordered_json validate_record(const ValArgs& a, const ResultFile& file, const IdData& d, const std::string& path) {
  const int ny = model_outputs(file.result.model);
  if (d.ny() != ny)
    throw UsageError(detail::format("the model has {} output(s) and {} were selected (--output, once per output)", ny,
                                    d.ny()));
  if (a.lags < 1 || a.lags >= d.size())
    throw UsageError(detail::format("--lags must be in [1, {}] for {}", d.size() - 1, path));
  const Eigen::MatrixXd yhat = simulate_result(file.result, d, SimulationPurpose::FreeRun, a.initial, a.initial_samples);
  const int n = model_coefficient_count(file.result.model);
  nlohmann::ordered_json j;
  j["data"] = path;
  if (ny == 1) {
    j.update(validate_output(a, d, d.y().col(0), yhat.col(0), n, path));
    return j;
  }
  j["outputs"] = nlohmann::ordered_json::array();
  for (int o = 0; o < ny; ++o) {
    std::printf("output %s:\n", d.output_names()[static_cast<size_t>(o)].c_str());
    nlohmann::ordered_json jo = {{"output", d.output_names()[static_cast<size_t>(o)]}};
    jo.update(validate_output(a, d, d.y().col(o), yhat.col(o), n, path));
    j["outputs"].push_back(jo);
  }
  return j;
}

int run(const ValArgs& a) {
  std::vector<std::string> inputs = a.paths;
  inputs.push_back(a.model);
  check_outputs({a.json}, inputs, a.force);
  const ResultFile file = read_result_file(a.model);
  const AnyModel& model = file.result.model;
  const std::vector<IdData> ds = columns_of(a.data, model).load_each(a.paths, true);
  std::printf("model:  %s\n", describe(model).c_str());
  // Finite on these records, but growing: the numbers below say little beyond them.
  if (const std::string unstable = unstable_poles_note(model); !unstable.empty())
    std::printf("note: the model is unstable%s\n", unstable.c_str());
  nlohmann::ordered_json records = nlohmann::ordered_json::array();
  for (std::size_t e = 0; e < ds.size(); ++e) {
    if (ds.size() > 1) std::printf("record %zu (%s):\n", e + 1, a.paths[e].c_str());
    records.push_back(validate_record(a, file, ds[e], a.paths[e]));
  }
  if (!a.json.empty()) {
    // The first record's numbers at the top level; every record's under "experiments".
    nlohmann::ordered_json j = records.front();
    j.erase("data");
    j["ctid_version"] = version();
    j["model"] = nlohmann::ordered_json::parse(result_to_json(file.result, file.method))["model"];
    j["initial"] = to_string(simulate_options_of(file.result, SimulationPurpose::FreeRun, a.initial, a.initial_samples).initial);
    j["experiments"] = records;
    write_text_file(a.json, j.dump(2) + "\n");
    std::printf("wrote %s\n", a.json.c_str());
  }
  return kOk;
}
}  // namespace

void setup_validate(CLI::App& app, Command& command) {
  auto a = std::make_shared<ValArgs>();
  app.add_option("MODEL", a->model, "Model JSON (a result file or a bare model)")->required();
  app.add_option("DATA", a->paths, "Measured data table(s) or .mat file(s); several: each validated")->required();
  a->data.add_to(app, true);
  add_initial_option(app, a->initial, &a->initial_samples, "rest; a grey-box result: its fitted initial state");
  app.add_option("--lags", a->lags, "Lags of the residual correlation tests")->capture_default_str();
  app.add_option("--json", a->json, "Write fit and residual tests to this JSON file");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &command] {
    command = [a](Provenance& prov) {
      a->data.provenance = &prov;
      return run(*a);
    };
  });
}

}  // namespace ctid::cli
