#include "common.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <cstdio>
#include <filesystem>
#include <unistd.h>
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

namespace {
// --samples A:B as [begin, end) of a record of n rows; UsageError naming the option, its value and the record size.
std::pair<int, int> row_range(const std::string& option, const std::string& text, int n) {
  const auto colon = text.find(':');
  auto bad = [&](const std::string& why) {
    return UsageError(option + " " + text + ": " + why + " (the record has " + std::to_string(n) + " rows)");
  };
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos)
    throw bad("give A:B, the first and last row (1-based; '1:500', '501:')");
  auto number = [&](const std::string& part, int fallback) {
    if (part.empty()) return fallback;
    size_t used = 0;
    long v = 0;
    try {
      v = std::stol(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != part.size() || v < 1 || v > n) throw bad("'" + part + "' is not a row number from 1 to " + std::to_string(n));
    return static_cast<int>(v);
  };
  const int first = number(text.substr(0, colon), 1), last = number(text.substr(colon + 1), n);
  if (last - first + 1 < 2) throw bad("the range holds fewer than 2 rows");
  return {first - 1, last};
}
}  // namespace

IdData DataArgs::load(bool need_output, TrendInfo* removed_trend, std::pair<int, int>* rows) const {
  if (detrend != "none" && detrend != "mean" && detrend != "linear")
    throw UsageError("--detrend must be none, mean or linear (got '" + detrend + "')");
  if (!(ts >= 0) || !std::isfinite(ts)) throw UsageError("--ts must be a positive number of seconds (got " + std::to_string(ts) + ")");
  DataSpec spec;
  spec.ts = ts;
  try {
    spec.intersample = intersample_from_string(intersample);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  spec.inputs = inputs;
  spec.outputs = outputs;
  try {
    // Column (CSV) or variable (.mat) names; the table is read once.
    const bool is_mat = is_mat_file(path);
    std::optional<CsvTable> tab;
    std::vector<std::string> names;
    if (is_mat) {
      names = mat_variable_names(path);
    } else {
      tab = read_csv(path);
      names = tab->names;
    }
    // Two selections are the same column when they name the same position (CSV) or variable (.mat).
    auto same = [&](const std::string& a, const std::string& b) { return tab ? tab->column(a) == tab->column(b) : a == b; };
    // Without --time and --ts, a column named t or time (any case) is the time axis, said on stderr.
    std::string time_col = time;
    if (time_col.empty() && ts == 0.0) {
      for (const auto& n : names) {
        std::string lower = n;
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
        if (lower != "t" && lower != "time") continue;
        if (!time_col.empty())
          throw UsageError(path + ": columns '" + time_col + "' and '" + n + "' could both be the time axis; give --time");
        time_col = n;
      }
      if (time_col.empty())
        throw UsageError("give the time axis: --time COLUMN or --ts SECONDS (no column is named t or time)");
      if (!quiet)
        std::fprintf(stderr, "note: column '%s' is the time axis (no --time or --ts given)\n", time_col.c_str());
    }
    spec.time = time_col;
    if (inputs.empty() || (need_output && outputs.empty())) {
      // Default columns (documented in --help and docs/guide.md): everything that is not the time column, inputs
      // first, output last.
      std::vector<std::string> rest;
      for (const auto& n : names)
        if (time_col.empty() || !same(n, time_col)) rest.push_back(n);
      if (need_output && outputs.empty()) {
        if (rest.size() != 2 && inputs.empty()) {
          std::string cols;
          for (const auto& n : names) cols += (cols.empty() ? "" : ", ") + n;
          throw UsageError(path + ": choose columns with --input and --output (" + (is_mat ? "variables: " : "columns: ") +
                           cols + ")");
        }
        if (rest.empty()) throw UsageError(path + ": no column left for the output; use --output");
        spec.outputs = {rest.back()};
        rest.pop_back();
      }
      if (inputs.empty()) {
        if (need_output)
          std::erase_if(rest, [&](const std::string& n) { return same(n, spec.outputs.front()); });
        if (rest.empty()) throw UsageError(path + ": no column left for the input; use --input");
        spec.inputs = need_output ? rest : std::vector<std::string>{rest.front()};
      }
    }
    if (need_output)
      for (const auto& o : spec.outputs)
        for (const auto& in : spec.inputs)
          if (same(o, in)) throw UsageError(detail::format("'{}' is selected both as an input and as the output", o));
    if (!need_output) spec.outputs = {spec.inputs.front()};  // placeholder output for loading only
    IdData d = tab ? iddata_from_table(*tab, spec) : load_iddata(path, spec);
    const int n_rows = d.size();
    std::pair<int, int> used{1, n_rows};
    if (!samples.empty()) {
      const auto [begin, end] = row_range(samples_option, samples, d.size());
      d = d.slice(begin, end);
      used = {begin + 1, end};
    }
    if (rows) *rows = used;
    if (d.uniform_time_deviation() > 1e-9 && !quiet)
      std::fprintf(stderr, "note: %s: the sample times are within %.2g Ts of a uniform grid (threshold %g Ts): read as "
                   "uniform, Ts = %.10g s\n", path.c_str(), d.uniform_time_deviation(), IdData::kUniformTimeTolerance,
                   d.ts());
    // What was done to this record, for the report and the result file.
    std::string* done = nullptr;
    if (provenance) {
      provenance->add_data_file(path, n_rows);
      provenance->preprocessing.push_back(
          path + ": " +
          (samples.empty() ? "all " + std::to_string(n_rows) + " rows"
                           : detail::format("rows {}..{} of {}", used.first, used.second, n_rows)) +
          (detrend == "none" ? "; no detrending" : ""));
      done = &provenance->preprocessing.back();
    }
    if (detrend == "none") return d;
    TrendInfo removed;
    IdData out = d.detrend(detrend == "mean" ? Detrend::Mean : Detrend::Linear, &removed);
    if (removed_trend) *removed_trend = removed;
    // What was removed, channel by channel: "input 1 4.994, output 2 4.84337" (linear: offset + slope (t - t_ref)).
    std::string what;
    char value[64];
    for (int j = 0; j < d.nu() + d.ny(); ++j) {
      const bool in = j < d.nu();
      const int k = in ? j : j - d.nu();
      if (detrend == "mean")
        std::snprintf(value, sizeof value, "%.6g", in ? removed.u_offset(k) : removed.y_offset(k));
      else
        std::snprintf(value, sizeof value, "%.6g + %.6g (t - %.6g)", in ? removed.u_offset(k) : removed.y_offset(k),
                      in ? removed.u_slope(k) : removed.y_slope(k), removed.t_ref);
      what += detail::format("{}{} {} {}", j > 0 ? ", " : "", in ? "input" : "output",
                             channel_name(in ? d.input_names() : d.output_names(), k), value);
    }
    if (done) *done += detail::format("; {} removed ({})", detrend == "mean" ? "means" : "linear trends", what);
    if (announce_means && detrend == "mean" && !quiet)
      std::fprintf(stderr, "note: the means were removed (%s); --detrend none keeps them\n", what.c_str());
    return out;
  } catch (const FileError& e) {
    throw InputError(e.what());
  } catch (const ColumnSelectionError& e) {
    throw UsageError(e.what());  // a column the file does not have, or one selected twice: the options' problem
  } catch (const InvalidArgument& e) {
    throw InputError(path + ": " + e.what());  // the file's content
  }
}

std::string channel_name(const std::vector<std::string>& names, int j) {
  const auto k = static_cast<size_t>(j);
  return k < names.size() && !names[k].empty() ? names[k] : std::to_string(j + 1);
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

void check_outputs(const std::vector<std::string>& outs_in, const std::vector<std::string>& inputs, bool force) {
  namespace fs = std::filesystem;
  std::vector<std::string> outs;
  for (const auto& o : outs_in)
    if (!o.empty()) outs.push_back(o);
  std::error_code ec;
  // Where each output lands (a symlink is written through; a device, FIFO or directory is refused).
  std::vector<fs::path> lands;
  for (const auto& out : outs) {
    std::string target;
    try {
      target = resolve_output_file(out);
    } catch (const FileError& e) {
      throw UsageError(e.what());
    }
    const fs::path abs = fs::weakly_canonical(fs::absolute(target, ec), ec);
    for (size_t k = 0; k < lands.size(); ++k)
      if (lands[k] == abs) throw UsageError("two outputs of this command name the same file '" + out + "' (and '" + outs[k] + "')");
    lands.push_back(abs);
    for (const auto& in : inputs)
      if (!in.empty() && fs::exists(in, ec) && fs::exists(target, ec) && fs::equivalent(in, target, ec))
        throw UsageError("refusing to write '" + out + "': it is the input file '" + in + "'");
    if (fs::exists(target, ec) && !force) throw UsageError("'" + out + "' exists; use --force to overwrite it");
    const fs::path dir = abs.has_parent_path() ? abs.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec)) throw UsageError("cannot write '" + out + "': the directory '" + dir.string() + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0)
      throw UsageError("cannot write '" + out + "': the directory '" + dir.string() + "' is not writable");
  }
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

ResultFile read_result(const std::string& path) {
  try {
    return read_result_file(path);
  } catch (const FileError& e) {
    throw InputError(e.what());
  }
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
      ->check(CLI::PositiveNumber);
}

SimulateOptions simulate_options_of(const Result<AnyModel>& r, SimulationPurpose purpose, const std::string& initial,
                                    int initial_samples) {
  try {
    const std::optional<InitialCondition> given =
        initial.empty() ? std::nullopt : std::optional(initial_condition_from_string(initial));
    if (initial_samples > 0 &&
        (simulate_options(r, purpose, given).initial != InitialCondition::Estimated || !std::holds_alternative<GreyboxModel>(r.model)))
      throw UsageError("--initial-samples needs --initial estimated and a grey-box model");
    return simulate_options(r, purpose, given, initial_samples);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
}

Eigen::MatrixXd simulate_result(const Result<AnyModel>& r, const IdData& d, SimulationPurpose purpose,
                                const std::string& initial, int initial_samples) {
  const SimulateOptions o = simulate_options_of(r, purpose, initial, initial_samples);
  Simulation s;
  try {
    s = simulate(r.model, d, o);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  if (!s.ok()) throw NotUsable(s.problem);
  return s.y;
}

// The library's parsers of setting values (estimate/options.hpp), with the CLI's exit code for a bad value.
double to_double(const std::string& key, const std::string& value) {
  try {
    const double v = options_detail::parse_real("--set", key, value);
    if (!std::isfinite(v)) throw UsageError("--set " + key + ": '" + value + "' is not a finite number");
    return v;
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
}
int to_int(const std::string& key, const std::string& value) {
  try {
    return options_detail::parse_int("--set", key, value);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
}

void warn_offsets(const IdData& d) {
  auto check = [](const Eigen::VectorXd& x, const std::string& name) {
    const double m = x.mean(), sd = std::sqrt((x.array() - m).square().mean());
    if (std::abs(m) > 0.5 * sd && sd > 0)
      std::fprintf(stderr, "warning: %s has a mean of %.4g, %.2g times its standard deviation: a linear model "
                   "through the origin cannot fit that offset; add --detrend mean (or linear)\n", name.c_str(), m,
                   std::abs(m) / sd);
  };
  for (int j = 0; j < d.nu(); ++j) check(d.u().col(j), "input " + channel_name(d.input_names(), j));
  for (int j = 0; j < d.ny(); ++j) check(d.y().col(j), "output " + channel_name(d.output_names(), j));
}

}  // namespace ctid::cli
