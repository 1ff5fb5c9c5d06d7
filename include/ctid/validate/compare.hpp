// ctid — several models on one record side by side (ctid compare, html_comparison_report): each model simulated on
// the record from its validation initial condition (validation_initial_condition: as MATLAB's compare, the state
// that fits the record's first samples best for linear and grey-box models, the measured history for NARX and NDE
// models, rest for FSF models), its fit per output and its residual tests (Ljung 1999, sec. 16.5-16.6).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/any_model.hpp"
#include "ctid/simulate/simulate.hpp"
#include "ctid/validate/residuals.hpp"

namespace ctid {

/// One model compared with a record.
struct ModelComparison {
  std::string name;          ///< as given (e.g. the model's file)
  AnyModel model;
  InitialCondition initial;  ///< the initial condition it was simulated from
  Simulation simulation;     ///< y (N x ny); `problem` says where and why it stopped being finite
  /// Per output: fit (%), NRMSE, MSE and AIC/BIC with the model's coefficient count (model_coefficient_count);
  /// fit_percent = -Inf where the simulation is not finite.
  std::vector<FitReport> fits;
  /// Per output: the residual autocorrelation test (lags 1..max_lag) and, per input, the input-residual
  /// cross-correlation test; empty (no lags) where the residuals are not finite, all zero or too short.
  std::vector<CorrelationTest> whiteness;
  std::vector<std::vector<CorrelationTest>> independence;  ///< [output][input]
  /// Mean fit over the outputs (the ranking of ctid compare).
  double mean_fit() const;
  /// Mean NRMSE over the outputs, and the AIC summed over them.
  double mean_nrmse() const;
  double total_aic() const;
};

/// The index of the comparison with the highest mean_fit (the first of equals); 0 for an empty list.
std::size_t best_comparison(const std::vector<ModelComparison>& comparisons);

/// Every model of `models` (name, model) simulated on `data` and scored, in the given order. `initial` (set) is used
/// for every model; unset, each model's validation_initial_condition. The residual tests use lags up to
/// min(max_lag, N / 4). Throws InvalidArgument for no models, a model whose input or output count differs from the
/// data's (naming it), or data the model cannot be simulated on (e.g. a NARX model on another sampling period) —
/// a simulation that diverges is not an error: its problem is recorded.
std::vector<ModelComparison> compare_models(const IdData& data,
                                            const std::vector<std::pair<std::string, AnyModel>>& models,
                                            std::optional<InitialCondition> initial = std::nullopt, int max_lag = 25);

/// One output of a model's simulation on a record, scored as `ctid validate` scores it.
struct OutputScore {
  std::string output;                         ///< the output's name (channel_name)
  FitReport fit;                              ///< fit_report with the model's coefficient count
  CorrelationTest whiteness;                  ///< residual autocorrelation at lags 1..max_lag
  std::vector<CorrelationTest> independence;  ///< per input: input-residual cross-correlation at lags -max_lag..max_lag
};

/// The simulated outputs `yhat` (N x ny, finite) of a model with `n_coefficients` scored against `data`'s outputs.
/// Throws InvalidArgument for max_lag outside [1, N - 1], a `yhat` of another size, or an output fit_report refuses
/// (a constant one).
std::vector<OutputScore> score_outputs(const IdData& data, const Eigen::MatrixXd& yhat, int n_coefficients,
                                       int max_lag);

}  // namespace ctid
