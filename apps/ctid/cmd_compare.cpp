// ctid compare MODEL.json... DATA [--report OUT.html] [--json OUT.json] [--initial ...]: several result or model files
// of any type on one record side by side (validate/compare.hpp: each simulated from its validation initial condition,
// its fit per output and residual tests; io/report.hpp html_comparison_report).
#include <algorithm>
#include <cstdio>
#include <functional>
#include <optional>

#include "common.hpp"

namespace ctid::cli {

namespace {
struct CompareArgs {
  std::vector<std::string> files;  // the models, then the record
  DataArgs data;
  std::string initial;  // "": each model's validation_initial_condition
  std::string report, json, title;
  int lags = 25;
  bool force = false;
};

int run(const CompareArgs& a) {
  if (a.files.size() < 2) throw UsageError("give one or more model files and then the record: ctid compare MODEL.json... DATA");
  const std::vector<std::string> models(a.files.begin(), a.files.end() - 1);
  const std::string path = a.files.back();
  check_output_files({a.report, a.json}, a.files, a.force);
  std::vector<std::pair<std::string, AnyModel>> named;
  for (const auto& m : models) named.emplace_back(m, read_result_file(m).result.model);
  const IdData d = columns_of(a.data, named.front().second).load_each({path}, true).front();
  if (a.data.detrend == "none" &&
      std::all_of(named.begin(), named.end(), [](const auto& m) { return is_linear(m.second); }))
    warn_offsets(d);
  std::optional<InitialCondition> initial;
  if (!a.initial.empty()) initial = initial_condition_from_string(a.initial);
  if (a.lags < 1) throw UsageError(detail::format("--lags must be >= 1 (got {})", a.lags));
  const std::vector<ModelComparison> cs = compare_models(d, named, initial, a.lags);
  std::printf("data: %s (%d samples)\n%s", path.c_str(), d.size(), comparison_text(d, cs).c_str());
  if (!a.json.empty()) {
    write_text_file(a.json, comparison_to_json(path, d, cs));
    std::printf("wrote %s\n", a.json.c_str());
  }
  if (!a.report.empty()) {
    ReportOptions o;
    o.title = a.title.empty() ? "ctid compare: " + path : a.title;
    o.data_source = path;
    if (a.data.provenance) o.provenance = *a.data.provenance;
    o.max_lag = a.lags;
    write_text_file(a.report, html_comparison_report(d, cs, o));
    std::printf("wrote %s\n", a.report.c_str());
  }
  // A model that does not stay finite on the record has no fit: the comparison is complete (its row says so), but the
  // command does not end as if every model had been scored.
  for (const ModelComparison& c : cs)
    if (!c.simulation.ok()) throw NotUsable(c.name + " on " + path + ": " + c.simulation.problem);
  return kOk;
}
}  // namespace

void setup_compare(CLI::App& app, Command& command) {
  auto a = std::make_shared<CompareArgs>();
  app.add_option("FILES", a->files,
                 "Model or result files (any type ctid writes), then the record to compare them on (CSV/.dat or .mat)")
      ->required()
      ->expected(2, -1);
  a->data.add_to(app, true);
  add_initial_option(app, a->initial, nullptr,
                     "each model's validation condition: estimated for linear and grey-box models, measured for NARX "
                     "and NDE, rest for FSF");
  app.add_option("--report", a->report, "Write the side-by-side HTML report to this file");
  app.add_option("--json", a->json, "Write every model's fit and residual tests to this JSON file");
  app.add_option("--title", a->title, "Report title");
  app.add_option("--lags", a->lags, "Lags of the residual correlation tests")->capture_default_str();
  app.add_flag("--force", a->force, "Overwrite an existing output file");
  app.callback([a, &command] {
    command = [a](Provenance& prov) {
      a->data.provenance = &prov;
      return run(*a);
    };
  });
}

}  // namespace ctid::cli
