// ctid validate MODEL.json DATA [--initial rest|measured|estimated] [--json OUT.json]: fit and residual tests of any
// single-output result or model file on a record (simulated by simulate(), simulate/simulate.hpp).
#include <cstdio>
#include <functional>

#include <nlohmann/json.hpp>

#include "common.hpp"

namespace ctid::cli {
extern std::function<int()> g_run;

namespace {
struct ValArgs {
  std::string model;
  DataArgs data;
  std::string json;
  int lags = 25;
  std::string initial = "rest";
  bool force = false;
};

nlohmann::json corr_json(const CorrelationTest& c) {
  return {{"lags", std::vector<int>(c.lags.begin(), c.lags.end())},
          {"values", std::vector<double>(c.values.begin(), c.values.end())},
          {"bound_99", c.bound},
          {"n_outside", c.n_outside},
          {"passed", c.passed()}};
}

int run(const ValArgs& a) {
  check_outputs({a.json}, {a.data.path, a.model}, a.force);
  const ResultFile file = read_result(a.model);
  const AnyModel& model = file.result.model;
  if (model_outputs(model) != 1) throw UsageError("validate compares one output; the model has " + std::to_string(model_outputs(model)));
  const IdData d = a.data.load(true);
  if (d.ny() != 1) throw UsageError(detail::format("validate compares one output; {} were selected", d.ny()));
  if (a.lags < 1 || a.lags >= d.size()) throw UsageError(detail::format("--lags must be in [1, {}]", d.size() - 1));
  const Eigen::VectorXd yhat = simulate_result(file.result, d, a.initial).col(0);
  const std::string description = describe(model), unstable = unstable_poles_note(model);
  const Eigen::VectorXd y = d.y().col(0);
  FitReport f;
  try {
    f = fit_report(y, yhat, model_coefficient_count(model));
  } catch (const InvalidArgument& e) {
    throw InputError(a.data.path + ": " + e.what());
  }
  const Eigen::VectorXd e = y - yhat;
  const CorrelationTest ac = residual_autocorrelation(e, a.lags);
  std::vector<CorrelationTest> xcs;
  for (int i = 0; i < d.nu(); ++i) xcs.push_back(input_residual_crosscorrelation(d.u().col(i), e, a.lags));
  std::printf("model:  %s\n", description.c_str());
  if (!unstable.empty())  // finite on this record, but growing: the numbers below say little beyond it
    std::printf("note: the model is unstable%s\n", unstable.c_str());
  std::printf("fit: %.2f %%   NRMSE %.4g   MSE %.4g   (%d samples)\n", f.fit_percent, f.nrmse, f.mse, f.n_samples);
  std::printf("residual whiteness (lags 1..%d): %d outside the 99 %% bound %.3g -> %s\n", a.lags, ac.n_outside, ac.bound,
              ac.passed() ? "passed" : "not white");
  for (int i = 0; i < d.nu(); ++i)
    std::printf("input %s - residual independence (lags -%d..%d): %d outside -> %s\n", d.input_names()[i].c_str(), a.lags,
                a.lags, xcs[i].n_outside, xcs[i].passed() ? "passed" : "correlated (unmodelled dynamics)");
  if (!a.json.empty()) {
    nlohmann::json j;
    j["ctid_version"] = version();
    j["model"] = nlohmann::json::parse(result_to_json(file.result, file.method))["model"];
    j["initial"] = a.initial;
    j["fit"] = {{"fit_percent", f.fit_percent}, {"nrmse", f.nrmse}, {"mse", f.mse}, {"n_samples", f.n_samples}};
    j["residual_autocorrelation"] = corr_json(ac);
    j["input_residual_crosscorrelation"] = nlohmann::json::array();
    for (const auto& xc : xcs) j["input_residual_crosscorrelation"].push_back(corr_json(xc));
    write_text_file(a.json, j.dump(2) + "\n");
    std::printf("wrote %s\n", a.json.c_str());
  }
  return kOk;
}
}  // namespace

void setup_validate(CLI::App& app) {
  auto a = std::make_shared<ValArgs>();
  app.add_option("MODEL", a->model, "Model JSON (a result file or a bare model)")->required();
  app.add_option("DATA", a->data.path, "Measured data table or .mat file")->required();
  a->data.add_to(app, true);
  add_initial_option(app, a->initial);
  app.add_option("--lags", a->lags, "Lags of the residual correlation tests")->capture_default_str();
  app.add_option("--json", a->json, "Write fit and residual tests to this JSON file");
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a] { g_run = [a] { return run(*a); }; });
}

}  // namespace ctid::cli
