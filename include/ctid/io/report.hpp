// ctid — self-contained HTML reports of a fit: one file that opens offline (the uPlot plotting library,
// MIT, is inlined; no CDN, no network at view time). Sections: data overview, measured vs simulated
// output with the fit, residual auto- and cross-correlation with their 99 % bounds, Bode magnitude and
// phase (with a confidence band where a covariance exists), step and impulse responses, the parameter
// table with standard deviations, the method settings and warnings — and per model type: FSF compressed
// responses with +-2 std bands; ERR tables for NARX; coefficient tables and GFRF (|H_2|) maps for NARX
// and NDE models.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/any_model.hpp"
#include "ctid/model/fsf.hpp"
#include "ctid/model/miso.hpp"
#include "ctid/io/provenance.hpp"
#include "ctid/model/narx.hpp"
#include "ctid/model/nde.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/simulate/simulate.hpp"
#include "ctid/validate/compare.hpp"

namespace ctid {

struct ReportOptions {
  std::string title;                                        ///< default: "<method> fit"
  std::string method;                                       ///< e.g. "srivc"
  std::vector<std::pair<std::string, std::string>> settings;  ///< shown as given (e.g. the CLI's --set values)
  std::string data_source;                                  ///< e.g. the data file name
  /// Where the result came from (io/provenance.hpp): the preprocessing, the command line and the data files are
  /// shown when given; the version is the library's.
  Provenance provenance;
  int max_lag = 25;                                         ///< residual correlation lags
  int max_points = 4000;                                    ///< time plots are decimated (min/max pairs) above this
  /// Initial condition of the simulation compared with the record (simulate/simulate.hpp); Estimated uses
  /// the result's diagnostics "x0" where it has one (NDE output error). Unset: fit_initial_condition(), the
  /// one the result's own fit was computed with, so that the plotted fit is the fit the estimator reported.
  std::optional<InitialCondition> initial;
  /// Further records of the same system (several experiments: name, record), each compared with the model in a
  /// section of its own after the first record's; simulated from `initial` (unset: rest, or the measured history
  /// for NARX — a fitted x0 belongs to the first record).
  std::vector<std::pair<std::string, IdData>> more_records;
  /// The initial condition of the further records' simulations when set (a held-out validation record: Estimated,
  /// the state that fits its first samples best, as MATLAB's compare does); unset: as `initial` above.
  std::optional<InitialCondition> more_records_initial;
};

/// Every report states the ctid version (and commit) and the UTC time it was made, the preprocessing, the command
/// line and the data files with their content hashes (when given), flags parameters within two standard deviations of 0 as not significant, and says under each residual test
/// what its pass or failure means.
/// Report of a result on the record `data` (single input and output — for a MisoModel one input per channel,
/// a state-space model with one input and output as its transfer function; the model is simulated on it): the
/// report of its model type. Throws InvalidArgument for data that do not match the model or are too short for the
/// correlation lags.
std::string html_report(const IdData& data, const Result<AnyModel>& result, const ReportOptions& options);
/// Shorthand for a typed result (Result<TransferFunction>, Result<NarxModel>, ...): the same report.
template <class M>
std::string html_report(const IdData& data, const Result<M>& result, const ReportOptions& options) {
  return html_report(data, to_any(result), options);
}

/// Several models on one record side by side (ctid compare): a table of each model's type, coefficient count, initial
/// condition, fit (%) per output, NRMSE and AIC; the record; the measured output with every model's simulation
/// overlaid; each model's residual tests; and, for a single-output record, the Bode magnitude and phase of the linear
/// models (up to the record's Nyquist frequency), the step responses (unit steps when every model is linear,
/// otherwise steps of each input's RMS level for all) and the poles of the linear models. `comparisons` from
/// compare_models (validate/compare.hpp) on `data`; of `options` the title (default "ctid compare"), data source,
/// preprocessing, command line and max_points are used. Throws InvalidArgument when comparisons is empty or was not
/// computed on data.
std::string html_comparison_report(const IdData& data, const std::vector<ModelComparison>& comparisons,
                                   const ReportOptions& options);

/// Whether the plotting library was found at build time (scripts/install-deps.sh fetches it); without it
/// a report still holds every table and says that its plots are missing.
bool report_has_plot_library();

}  // namespace ctid
