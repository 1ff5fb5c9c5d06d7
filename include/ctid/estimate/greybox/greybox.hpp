// ctid — nonlinear continuous-time grey-box identification: the parameters and the estimated initial
// states of a GreyboxModel (model/greybox.hpp) that minimise the simulation (output) error
//     V(theta, x0_1..x0_E) = sum_e sum_k sum_j w_j^2 (y_j,e(t_k) - yhat_j,e(t_k; theta, x0_e))^2
// over one record or several experiments of one system (one parameter set, an initial state per experiment),
// by Levenberg-Marquardt (Marquardt's scaling by diag(J^T J): invariant to the parameters' units) within the
// bounds, with the Jacobian from the exact forward sensitivities of the model (Ljung 1999 §7.3, the
// prediction-error estimate for white output noise; Bohlin 2006, "Practical grey-box process identification").
// With several outputs w_j = 1 / (RMS deviation of output j from its mean over all records), else w = 1.
// Multi-start (`starts` > 1): the model's values, then starts - 1 points drawn (seeded) uniformly within finite
// bounds, or log-uniformly within a decade of the value where a bound is open; the lowest cost wins.
// Covariance sigma^2 (J^T J)^{-1} with sigma^2 = V / (N ny - p) for white residuals; for coloured ones (single
// shooting) the sandwich with each output's AR model of the residuals (Ljung 1999 §9.3; diagnostics
// residual_ar_order and white_noise_std, the white figure); a combination of parameters the data cannot
// separate makes the result not usable, naming the parameters (ParameterSet rules, core/types.hpp).
// Unstable and integrating plants: multiple shooting (Bock & Plitt 1984; Bock 1983) — segments with free initial
// states, continuity by penalty residuals raised until the defects are at rounding level, the block-sparse Jacobian
// solved sparse — chosen automatically when
// the free run from the start escapes or drifts, then single shooting from its estimate where the plant runs free
// (docs/methods/greybox.md#unstable-and-integrating-plants).
#pragma once

#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/model/greybox.hpp"

namespace ctid {

struct GreyboxOptions {
  int max_iterations = 500;      ///< Levenberg-Marquardt iterations per start (a well-posed fit converges long before)
  double tolerance = 1e-8;       ///< relative cost decrease or parameter change that stops a search
  int starts = 1;                ///< multi-start: the model's values plus starts - 1 drawn within the bounds
  int seed = 1;                  ///< seed of the drawn starts
  double rtol = 1e-8;            ///< relative tolerance of the simulations (absolute: 1e-3 rtol)
  /// The integrator of every simulation of the fit (model/greybox.hpp): auto (Dormand-Prince, BDF where it needs
  /// more than 200 steps per sample), explicit, bdf (stiff models).
  GreyboxIntegrator integrator = GreyboxIntegrator::Auto;
  /// Multiple shooting: each record cut into this many segments, each starting from a free state tied to the previous
  /// segment's end (continuity); 1: single shooting; 0: automatic — multiple shooting when the free run from the
  /// start escapes or drifts (fit below -900 %), with segments of 100 samples halved (down to 4) until every
  /// segment simulates from the start.
  int segments = 0;
  bool estimate_initial_state = true;  ///< false: states marked "estimate" are held at their start values
  /// Parameters held at a value by name (fixed.k1=0.05), on top of the model's own "fixed".
  FixedValues fixed;
  /// Bounds by name (bounds.k1=0,inf), replacing the model's own.
  ParameterBounds bounds;
  void validate() const;
};
template <>
const OptionTable<GreyboxOptions>& option_table<GreyboxOptions>();

/// Fits `model` to one record: its inputs are the model's inputs in order, its outputs the model's outputs in
/// order (the caller maps column names). The returned model carries the estimates and, for estimated initial
/// states, the first record's estimate. parameters: every model parameter (held ones flagged fixed), then the
/// estimated initial states "x1(0)", .. (with several records "r<e>.x1(0)"). diagnostics: x0 per record,
/// noise_variance, starts_cost (the final cost of each start), experiments, segments and continuity_defect (multiple
/// shooting; a warning when the fitted model cannot run free and the fit is that of the segments). Termination
/// Converged / MaxIterations,
/// NumericalFailure when the model cannot be simulated from any start (the message names where it escaped).
/// Throws InvalidArgument for data whose input or output count differs from the model's, records with fewer
/// samples than free quantities, names in fixed/bounds that are not parameters (the closest named); InvalidOptions
/// for bad options.
Result<GreyboxModel> greybox(const IdData& data, const GreyboxModel& model, const GreyboxOptions& options = {});
/// Several experiments of one system: one parameter set, an initial state per record, the output errors stacked.
Result<GreyboxModel> greybox(const std::vector<IdData>& data, const GreyboxModel& model, const GreyboxOptions& options = {});

}  // namespace ctid
