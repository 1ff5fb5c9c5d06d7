// ctid compare MODEL.json... DATA [--report OUT.html] [--json OUT.json] [--initial ...]: several result or model files
// of any type on one record side by side (validate/compare.hpp: each simulated from its validation initial condition,
// its fit per output and residual tests; io/report.hpp html_comparison_report).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>

#include <nlohmann/json.hpp>

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

std::string two_decimals(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

std::string fit_text(const FitReport& f) { return std::isfinite(f.fit_percent) ? two_decimals(f.fit_percent) : "diverges"; }

std::string tests_text(const ModelComparison& c) {
  int failed = 0, run = 0;
  for (std::size_t j = 0; j < c.whiteness.size(); ++j) {
    if (c.whiteness[j].lags.size() == 0) continue;
    ++run;
    failed += !c.whiteness[j].passed();
    for (const auto& x : c.independence[j]) failed += !x.passed();
  }
  if (run == 0) return "-";
  return failed == 0 ? "passed" : std::to_string(failed) + " failed";
}

int run(const CompareArgs& a) {
  if (a.files.size() < 2) throw UsageError("give one or more model files and then the record: ctid compare MODEL.json... DATA");
  const std::vector<std::string> models(a.files.begin(), a.files.end() - 1);
  const std::string path = a.files.back();
  check_outputs({a.report, a.json}, a.files, a.force);
  std::vector<std::pair<std::string, AnyModel>> named;
  for (const auto& m : models) named.emplace_back(m, read_result(m).result.model);
  const IdData d = columns_of(a.data, named.front().second).load_each({path}, true).front();
  if (a.data.detrend == "none" &&
      std::all_of(named.begin(), named.end(), [](const auto& m) { return is_linear(m.second); }))
    warn_offsets(d);
  std::optional<InitialCondition> initial;
  if (!a.initial.empty()) initial = initial_condition_from_string(a.initial);
  if (a.lags < 1) throw UsageError(detail::format("--lags must be >= 1 (got {})", a.lags));
  std::vector<ModelComparison> cs;
  try {
    cs = compare_models(d, named, initial, a.lags);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  std::printf("data: %s (%d samples)\n", path.c_str(), d.size());
  std::size_t width = 5;
  for (const auto& m : models) width = std::max(width, m.size());
  std::printf("%-*s  %-17s  %-9s", static_cast<int>(width), "model", "type", "initial");
  for (int j = 0; j < d.ny(); ++j)
    std::printf("  %9s", d.ny() > 1 ? ("fit% " + channel_name(d.output_names(), j)).c_str() : "fit %");
  std::printf("  %9s  %10s  %s\n", "NRMSE", "AIC", "residual tests");
  for (const ModelComparison& c : cs) {
    std::printf("%-*s  %-17s  %-9s", static_cast<int>(width), c.name.c_str(), model_type_name(c.model), to_string(c.initial));
    for (const FitReport& f : c.fits) std::printf("  %9s", fit_text(f).c_str());
    std::printf("  %9.4g  %10.5g  %s\n", c.mean_nrmse(), c.total_aic(), tests_text(c).c_str());
  }
  const std::size_t best = best_comparison(cs);
  std::printf("best: %s (%s %%%s)\n", cs[best].name.c_str(), two_decimals(cs[best].mean_fit()).c_str(),
              d.ny() > 1 ? ", mean over the outputs" : "");
  if (!a.json.empty()) {
    nlohmann::ordered_json j;
    j["ctid_version"] = version();
    j["data"] = path;
    j["n_samples"] = d.size();
    j["best"] = cs[best].name;
    j["models"] = nlohmann::ordered_json::array();
    for (const ModelComparison& c : cs) {
      nlohmann::ordered_json m = {{"name", c.name}, {"type", model_type_name(c.model)}, {"initial", to_string(c.initial)}};
      m["outputs"] = nlohmann::ordered_json::array();
      for (std::size_t o = 0; o < c.fits.size(); ++o) {
        const FitReport& f = c.fits[o];
        auto num = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr); };
        nlohmann::ordered_json jo = {{"output", channel_name(d.output_names(), static_cast<int>(o))},
                                     {"fit_percent", num(f.fit_percent)}, {"nrmse", num(f.nrmse)},
                                     {"mse", num(f.mse)}, {"aic", num(f.aic)}};
        if (c.whiteness[o].lags.size() > 0) {
          jo["whiteness_lags_outside"] = c.whiteness[o].n_outside;
          jo["independence_lags_outside"] = nlohmann::ordered_json::array();
          for (const auto& x : c.independence[o]) jo["independence_lags_outside"].push_back(x.n_outside);
        }
        m["outputs"].push_back(jo);
      }
      m["problem"] = c.simulation.problem;
      j["models"].push_back(m);
    }
    write_text_file(a.json, j.dump(2) + "\n");
    std::printf("wrote %s\n", a.json.c_str());
  }
  if (!a.report.empty()) {
    ReportOptions o;
    o.title = a.title.empty() ? "ctid compare: " + path : a.title;
    o.data_source = path;
    if (a.data.provenance) o.provenance = *a.data.provenance;
    o.max_lag = a.lags;
    try {
      write_text_file(a.report, html_comparison_report(d, cs, o));
    } catch (const FileError& e) {
      throw InputError(e.what());
    }
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
