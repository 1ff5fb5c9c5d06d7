// ctid validate MODEL.json DATA [--initial rest|measured|estimated] [--json OUT.json]: fit and residual tests of any
// result or model file on a record, per output (simulated by simulate(), simulate/simulate.hpp).
#include <cstdio>
#include <functional>

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

// One record: the model simulated on it and each output scored (score_outputs), the library's text printed.
std::vector<OutputScore> validate_record(const ValArgs& a, const ResultFile& file, const IdData& d, const std::string& path) {
  const int ny = model_outputs(file.result.model);
  if (d.ny() != ny)
    throw UsageError(detail::format("the model has {} output(s) and {} were selected (--output, once per output)", ny,
                                    d.ny()));
  if (a.lags < 1 || a.lags >= d.size())
    throw UsageError(detail::format("--lags must be in [1, {}] for {}", d.size() - 1, path));
  const Eigen::MatrixXd yhat = simulate_result(file.result, d, SimulationPurpose::FreeRun, a.initial, a.initial_samples);
  std::vector<OutputScore> scores;
  try {
    scores = score_outputs(d, yhat, model_coefficient_count(file.result.model), a.lags);
  } catch (const InvalidArgument& e) {
    throw InputError(path + ": " + e.what());
  }
  std::fputs(validation_text(d, scores).c_str(), stdout);
  return scores;
}

int run(const ValArgs& a) {
  std::vector<std::string> inputs = a.paths;
  inputs.push_back(a.model);
  check_output_files({a.json}, inputs, a.force);
  const ResultFile file = read_result_file(a.model);
  const AnyModel& model = file.result.model;
  const std::vector<IdData> ds = columns_of(a.data, model).load_each(a.paths, true);
  std::printf("model:  %s\n", describe(model).c_str());
  // Finite on these records, but growing: the numbers below say little beyond them.
  if (const std::string unstable = unstable_poles_note(model); !unstable.empty())
    std::printf("note: the model is unstable%s\n", unstable.c_str());
  std::vector<std::pair<std::string, std::vector<OutputScore>>> records;
  for (std::size_t e = 0; e < ds.size(); ++e) {
    if (ds.size() > 1) std::printf("record %zu (%s):\n", e + 1, a.paths[e].c_str());
    records.emplace_back(a.paths[e], validate_record(a, file, ds[e], a.paths[e]));
  }
  if (!a.json.empty()) {
    const InitialCondition initial =
        simulate_options_of(file.result, SimulationPurpose::FreeRun, a.initial, a.initial_samples).initial;
    write_text_file(a.json, validation_to_json(file, initial, records));
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
