// ctid — output-error refinement of a nonlinear differential-equation (NDE) model: the coefficients of a
// given term structure (e.g. the one the Kernel Invariance Algorithm selected, Billings & Li 1999) and
// the initial state are adjusted to minimise the simulation error
//     V(theta) = sum_k (y(t_k) - yhat(t_k; theta))^2,   yhat = NdeModel::simulate (adaptive Dormand-Prince),
// by Levenberg-Marquardt with exact forward sensitivities integrated alongside the state (Ljung 1999,
// ch. 7: the prediction-error estimate for white output noise, consistent where equation-error estimates
// such as the NARX/KIA chain are biased by noise). It plays the role of MATLAB's `pem`/`nlgreyest` refinement after an initial
// estimate. Covariance of the free parameters: sigma^2 (J^T J)^{-1} for white residuals, the sandwich with the
// residuals' AR model for coloured ones (as oe.hpp; diagnostics residual_ar_order, white_noise_std).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/nde.hpp"
#include "ctid/estimate/options.hpp"

namespace ctid {

struct NdeOeOptions {
  int max_iterations = 500;  ///< Levenberg-Marquardt iterations (a well-posed fit converges long before)
  double tolerance = 1e-9;             ///< relative cost decrease or parameter change that stops the search
  bool estimate_initial_state = true;  ///< estimate [y, Dy, .., D^{L-1}y] at the first sample; false: from rest
  /// Coefficients held at a value, by term name (fixed.u=-1.1) — the constraint vocabulary of oe, lssvf and
  /// physical — in the returned model's scale (the reference term's coefficient 1); the reference term always is.
  FixedValues fixed;
  /// Bounds [lower, upper] on free coefficients by term name (bounds.y^2=0,inf), in the same scale.
  ParameterBounds bounds;
  double rtol = 1e-10;                 ///< relative tolerance of the simulations
  /// Multi-start: the starting model plus starts - 1 coefficient sets drawn (seeded) uniformly within finite
  /// bounds, or log-uniformly within a decade of the start's value where a bound is open; the lowest cost wins.
  int starts = 1;
  int seed = 1;  ///< seed of the drawn starts
  void validate() const;
};
template <>
const OptionTable<NdeOeOptions>& option_table<NdeOeOptions>();

/// Refine the coefficients of `initial` on SISO data (input held or linear between samples as the data's
/// intersample says; BandLimited is treated as linear). The reference term — y, or the highest derivative
/// of y when y is absent — keeps its coefficient; the returned model is scaled so that y has coefficient
/// +1 when present. When the starting model's simulation escapes, its nonlinear (degree >= 2) coefficients
/// are shrunk by halves (down to 0) until it does not; the factor is diagnostics.scalars "start_scale"
/// (1: none) and a warning says so. parameters: every term's coefficient (reference and `fixed` ones
/// flagged fixed, with zero variance), then "y(0)", "Dy(0)", .. when estimated. diagnostics: vector "x0"
/// (initial state), scalars "noise_variance", "start_scale", vector "starts_cost" (starts > 1). Termination Converged / MaxIterations, or
/// NumericalFailure (fit infinite) when no shrunk start can be simulated.
/// Throws InvalidArgument for data that are not SISO, fewer samples than free parameters, a model that
/// NdeModel::simulate rejects, names in `fixed`/`bounds` that are not terms (the closest named), a bound on a
/// held term; InvalidOptions for bad options.
Result<NdeModel> nde_oe(const IdData& data, const NdeModel& initial, const NdeOeOptions& options = {});
/// Several experiments of one system: one set of coefficients, each record with its own estimated initial
/// state (parameters "r<e>.y(0)", ..; diagnostics "x0" of record 1, "x0_<e>" of the others), the output error
/// summed over the records, the fit pooled.
Result<NdeModel> nde_oe(const std::vector<IdData>& data, const NdeModel& initial, const NdeOeOptions& options = {});

}  // namespace ctid
