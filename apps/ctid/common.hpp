// ctid command line — shared pieces: exit codes, data loading options, output files.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "ctid/ctid.hpp"

namespace ctid::cli {

// Exit codes (docs/guide.md, "Exit codes"). The library's exceptions reach main unchanged and are classified there
// by type: FileError is exit 3, InvalidArgument (with InvalidOptions and ColumnSelectionError) exit 2. A command
// converts one only where the exit code differs (a file's content is exit 3) or a flag must be named.
constexpr int kOk = 0;
constexpr int kNotUsable = 1;
constexpr int kUsage = 2;
constexpr int kInputFile = 3;

/// A usage problem detected after parsing (bad --set key, inconsistent options): exit 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// The computation ran but its result cannot be used (e.g. a simulation that escapes): exit 1.
struct NotUsable : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// A problem with an input file or its contents: exit 3.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// What a subcommand runs once its options are parsed: its job, given the run's provenance (the command line and the
/// library build, made by main) to record the data it reads in and to pass to what it writes. Returns the exit code.
using Command = std::function<int(Provenance&)>;

/// Options that select an experiment from a data file.
struct DataArgs {
  std::string path;
  std::vector<std::string> inputs;
  std::vector<std::string> outputs;
  std::string time;
  double ts = 0.0;
  std::string intersample = "zoh";
  std::string detrend = "none";
  /// --samples A:B: only rows A..B (1-based, inclusive; either end may be left out) of the file; "" = all.
  std::string samples;
  std::string samples_option = "--samples";  ///< the option's name in messages (--validate-samples for a validation record)
  /// With detrend "mean": say on stderr which means were removed (a command's own default, not the user's option).
  bool announce_means = false;
  /// No notes on stderr (ctid batch: many records on threads).
  bool quiet = false;
  /// Where each file read is recorded (its content hash and rows) with what was done to it; null: not recorded.
  Provenance* provenance = nullptr;
  void add_to(CLI::App& app, bool need_output);
  /// The library's choose_record (io/load.hpp: the default columns, the rows of --samples, the detrending; the
  /// removed trend in `removed`, left empty with --detrend none) with its notes on stderr and the provenance
  /// recorded; a file's content it cannot read is an InputError naming the file (the library's FileError,
  /// InvalidOptions and ColumnSelectionError pass unchanged).
  /// With `rows`: the rows used, 1-based first and last.
  IdData load(bool need_output, TrendInfo* removed = nullptr, std::pair<int, int>* rows = nullptr) const;
  /// The same selection loaded from each of `paths` (several records of one system), in order.
  std::vector<IdData> load_each(const std::vector<std::string>& paths, bool need_output) const;
};

/// "KEY=VALUE" pairs from --set; UsageError for a pair without '=' or a key given twice.
std::map<std::string, std::string> parse_sets(const std::vector<std::string>& sets);
/// The same as the library's settings (text values, parsed by the method's tables).
SettingList setting_list(const std::vector<std::string>& sets);
/// `--initial rest|measured|estimated` (simulate/simulate.hpp) on a command, defaulting to `initial`'s value
/// ("" = fit_initial_condition(): the one the result's own fit used).
/// With `initial_samples` (not null) also `--initial-samples N`: the estimated initial state of a grey-box model from
/// the record's first N samples only (the nonlinear-benchmark protocol; the result's fitted x0 is then not used).
/// With `initial` empty the help states `default_doc` (what the command does without --initial).
void add_initial_option(CLI::App& app, std::string& initial, int* initial_samples = nullptr,
                        const char* default_doc = "the one the result's own fit used");
/// A grey-box model's inputs and outputs are data columns of the same names unless --input/--output map them.
DataArgs columns_of(const DataArgs& given, const AnyModel& model);
/// The library's simulation options of `r` for `purpose` (simulate/simulate.hpp: the one rule for the initial state)
/// with --initial ("" = the purpose's default) and --initial-samples; UsageError or InvalidArgument for flags that
/// do not fit the model.
SimulateOptions simulate_options_of(const Result<AnyModel>& r, SimulationPurpose purpose, const std::string& initial,
                                    int initial_samples = 0);
/// The result's model simulated on d for `purpose` (simulate_options_of). Data that do not fit the model throw
/// InvalidArgument; a simulation that stops being finite throws NotUsable naming where and why (e.g. the unstable poles):
/// a diverging simulation is never written or scored.
Eigen::MatrixXd simulate_result(const Result<AnyModel>& r, const IdData& d, SimulationPurpose purpose,
                                const std::string& initial, int initial_samples = 0);

/// A --param value as a finite number, parsed by the library's option parser; UsageError otherwise.
double to_double(const std::string& key, const std::string& value);


/// Method settings as NAME/VALUE text pairs (the report's "settings" section).
using Settings = std::vector<std::pair<std::string, std::string>>;

/// Where a method's settings are listed: "ctid fit --method M --help" for a fit, the help of the command that runs
/// a tool ("ctid poles --help"), the help of the fit it belongs to otherwise (registry: estimate/methods.hpp).
inline std::string settings_hint(const MethodInfo& m) {
  if (m.capabilities.records) return "ctid fit --method " + m.name + " --help";
  const std::string& by = m.reached_by;
  if (by.rfind("ctid ", 0) == 0) return by.substr(0, by.find(' ', 5)) + " --help";
  return "ctid fit --method " + by.substr(0, by.find(' ')) + " --help";
}
inline std::string settings_hint(const std::string& method) { return settings_hint(method_info(method)); }

/// The usage error of a setting the method does not have, given by `flag` ("--set NAME", "--delay", ..): names the
/// method, the closest setting and where the settings are listed.
inline UsageError unknown_setting(const std::string& flag, const UnknownSetting& e, const std::string& method) {
  return UsageError(flag + ": not a setting of " + e.method +
                    (e.closest.empty() ? std::string() : "; did you mean '" + e.closest + "'?") + " (" +
                    settings_hint(method) + " lists them)");
}

/// --report: write the HTML report of r on d (nothing when path is empty), with `settings` as the method
/// settings. A report that cannot be made (e.g. multi-channel data) is a UsageError; a write failure a FileError.
template <class M>
void write_report(const std::string& path, const IdData& d, const Result<M>& r, const std::string& method,
                  const std::vector<std::pair<std::string, std::string>>& settings, const std::string& source,
                  const Provenance& provenance, const std::vector<std::pair<std::string, IdData>>& more_records = {},
                  std::optional<InitialCondition> more_records_initial = std::nullopt) {
  if (path.empty()) return;
  ReportOptions o;
  o.more_records_initial = more_records_initial;
  o.provenance = provenance;
  o.method = method;
  o.title = "ctid " + method + " fit";
  o.data_source = source;
  o.settings = settings;
  o.more_records = more_records;
  std::string html;
  try {
    html = html_report(d, r, o);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string("--report: ") + e.what());
  }
  write_text_file(path, html);
  std::printf("wrote %s\n", path.c_str());
}

void setup_fit(CLI::App& app, Command& run);
/// `ctid fit ARGS...` run from inside another command (ctid demo): the same parsing, defaults, output and exit code.
/// A parse error is a UsageError.
int run_fit(std::vector<std::string> args, Provenance& provenance);
/// After `ctid fit --method M --help`: M's settings (names, units, ranges, defaults) from the library's registry;
/// "" without --method.
std::string fit_method_help(const CLI::App& fit);
void setup_gfrf(CLI::App& app, Command& run);
void setup_poles(CLI::App& app, Command& run);
void setup_response(CLI::App& app, Command& run);
void setup_simulate(CLI::App& app, Command& run);
void setup_validate(CLI::App& app, Command& run);
/// A linear model through the origin cannot follow an offset: for each channel of d whose mean is above half its
/// standard deviation, a warning on stderr naming it, its mean and the ratio, and suggesting --detrend mean.
void warn_offsets(const IdData& d);
void setup_compare(CLI::App& app, Command& run);

void setup_demo(CLI::App& app, Command& run);
void setup_example_data(CLI::App& app, Command& run);
void setup_order(CLI::App& app, Command& run);
void setup_report(CLI::App& app, Command& run);

/// One ctid batch run (cmd_batch.cpp): the records matched by `patterns`, each fitted by `fit_one` (ctid fit's
/// options, one record; it returns the library's outcome or throws), on `jobs` threads; one row per record written
/// to `out` (.csv or .jsonl, the library's batch rows: io/batch_file.hpp) as it arrives. `resume` fits only the records whose
/// id is not yet in `out`. Exit code: 0 when every record gave a usable fit, 1 otherwise (the rows say why).
struct BatchJob {
  std::vector<std::string> patterns;
  std::string method, out;
  int jobs = 0;  ///< 0: one per core
  bool resume = false, force = false;
  std::vector<std::string> inputs;  ///< files every fit reads besides the records (models; --out must not be one)
  std::function<FitOutcome(const std::string& path)> fit_one;
};
int run_batch(const BatchJob& job);
void setup_batch(CLI::App& app, Command& run);

}  // namespace ctid::cli
