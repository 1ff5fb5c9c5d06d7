#include "common.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <cstdio>
#include <type_traits>

namespace ctid::cli {

void DataArgs::add_to(CLI::App& app, bool need_output) {
  app.add_option("--input", inputs, "Input column(s): name or 1-based position (repeatable)");
  if (need_output) app.add_option("--output", outputs, "Output column: name or 1-based position");
  auto* t = app.add_option("--time", time,
                           "Time column (strictly increasing; irregular sampling allowed). Default without --ts: the "
                           "column named t or time (any case)");
  auto* s = app.add_option("--ts", ts, "Sampling period in seconds (when there is no time column)");
  t->excludes(s);
  app.add_option("--intersample", intersample, "Input intersample behaviour: zoh, foh or bl")->capture_default_str();
  app.add_option("--detrend", detrend, "Remove none, mean or linear trend before use")->capture_default_str();
  app.add_option("--samples", samples,
                 "Use only rows A:B of the file (1-based, inclusive; '1:500' the first 500, '501:' from row 501 on)");
}

IdData DataArgs::load(bool need_output, TrendInfo* removed_trend, std::pair<int, int>* rows) const {
  if (detrend != "none" && detrend != "mean" && detrend != "linear")
    throw UsageError("--detrend must be none, mean or linear (got '" + detrend + "')");
  if (!(ts >= 0) || !std::isfinite(ts)) throw UsageError("--ts must be a positive number of seconds (got " + std::to_string(ts) + ")");
  RecordChoice c;
  c.inputs = inputs;
  c.outputs = outputs;
  c.time = time;
  c.ts = ts;
  c.need_output = need_output;
  c.rows = samples;
  c.rows_name = samples_option;
  if (detrend != "none") c.detrend = detrend == "mean" ? Detrend::Mean : Detrend::Linear;
  ChosenRecord r;
  c.intersample = intersample_from_string(intersample);
  try {
    r = choose_record(path, c);
  } catch (const InvalidOptions&) {
    throw;  // the rows asked for (exit 2)
  } catch (const ColumnSelectionError&) {
    throw;  // a column the file does not have, or one chosen twice: the options' problem (exit 2)
  } catch (const InvalidArgument& e) {
    throw InputError(path + ": " + e.what());  // the file's content
  }
  for (const auto& note : r.notes)
    if (!quiet) std::fprintf(stderr, "note: %s\n", note.c_str());
  if (rows) *rows = {r.first_row, r.last_row};
  if (removed_trend) *removed_trend = r.removed;
  if (provenance) {
    provenance->add_data_file(path, r.file_rows);
    provenance->preprocessing.push_back(path + ": " + r.preprocessing);
  }
  if (announce_means && detrend == "mean" && !quiet)
    std::fprintf(stderr, "note: the means were removed (%s); --detrend none keeps them\n", r.removed_text.c_str());
  return r.data;
}


std::vector<IdData> DataArgs::load_each(const std::vector<std::string>& paths, bool need_output) const {
  std::vector<IdData> ds;
  for (const auto& p : paths) {
    DataArgs one = *this;
    one.path = p;
    ds.push_back(one.load(need_output));
  }
  return ds;
}

std::map<std::string, std::string> parse_sets(const std::vector<std::string>& sets) {
  std::map<std::string, std::string> m;
  for (const auto& s : sets) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("--set needs KEY=VALUE (got '" + s + "')");
    const auto [it, fresh] = m.emplace(s.substr(0, eq), s.substr(eq + 1));
    if (!fresh)
      throw UsageError("--set " + it->first + " is given twice ('" + it->second + "' and '" + s.substr(eq + 1) +
                       "'); give it once");
  }
  return m;
}

SettingList setting_list(const std::vector<std::string>& sets) {
  SettingList list;
  for (const auto& [key, value] : parse_sets(sets)) list.emplace_back(key, value);
  return list;
}

DataArgs columns_of(const DataArgs& given, const AnyModel& model) {
  DataArgs d = given;
  if (const auto* g = std::get_if<GreyboxModel>(&model)) {
    if (d.inputs.empty()) d.inputs = g->spec().inputs;
    if (d.outputs.empty()) d.outputs = g->output_names();
  }
  return d;
}

void add_initial_option(CLI::App& app, std::string& initial, int* initial_samples, const char* default_doc) {
  auto* o = app.add_option("--initial", initial,
                           "Initial condition of the simulation: rest (zero state), measured (NARX: the first measured "
                           "outputs; NDE: y(0); grey-box: outputs that are a state give it) or estimated (linear: "
                           "least-squares initial state; NDE, grey-box: the fitted x0)" +
                               std::string(initial.empty() ? std::string("; default: ") + default_doc : ""))
                ->check(CLI::IsMember({"rest", "measured", "estimated"}));
  if (!initial.empty()) o->capture_default_str();
  if (!initial_samples) return;
  app.add_option("--initial-samples", *initial_samples,
                 "With --initial estimated, grey-box models: estimate the initial state from the first N samples of "
                 "this record only (the nonlinear-benchmark protocol), not the fitted x0")
      ->check(CLI::Validator(
          [](std::string& v) {
            double x = 1;
            try { x = std::stod(v); } catch (const std::exception&) {}  // not a number: the conversion says so
            return x >= 1 ? std::string() : "--initial-samples must be at least 1 (got " + v + ")";
          },
          "N >= 1"));
}

SimulateOptions simulate_options_of(const Result<AnyModel>& r, SimulationPurpose purpose, const std::string& initial,
                                    int initial_samples) {
  const std::optional<InitialCondition> given =
      initial.empty() ? std::nullopt : std::optional(initial_condition_from_string(initial));
  if (initial_samples > 0 &&
      (simulate_options(r, purpose, given).initial != InitialCondition::Estimated || !std::holds_alternative<GreyboxModel>(r.model)))
    throw UsageError("--initial-samples needs --initial estimated and a grey-box model");
  return simulate_options(r, purpose, given, initial_samples);
}

Eigen::MatrixXd simulate_result(const Result<AnyModel>& r, const IdData& d, SimulationPurpose purpose,
                                const std::string& initial, int initial_samples) {
  const SimulateOptions o = simulate_options_of(r, purpose, initial, initial_samples);
  const Simulation s = simulate(r.model, d, o);
  if (!s.ok()) throw NotUsable(s.problem);
  return s.y;
}

// The library's parser of setting values (estimate/options.hpp), with the CLI's exit code for a bad value.
double to_double(const std::string& key, const std::string& value) {
  const double v = options_detail::parse_real("--set", key, value);
  if (!std::isfinite(v)) throw UsageError("--set " + key + ": '" + value + "' is not a finite number");
  return v;
}

void warn_offsets(const IdData& d) {
  for (const auto& w : offset_warnings(d))
    std::fprintf(stderr, "warning: %s; add --detrend mean (or linear)\n", w.c_str());
}

}  // namespace ctid::cli
