// ctid — the common result envelope of every estimator (docs/architecture.md).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/diagnostics.hpp"
#include "ctid/core/status.hpp"

namespace ctid {

/// Estimated parameters with their uncertainty. All vectors have the same length.
struct ParameterSet {
  std::vector<std::string> names;  ///< e.g. "a1", "b0"
  Eigen::VectorXd values;
  Eigen::MatrixXd covariance;      ///< size() x size(); zero rows/cols for fixed parameters; empty if unknown
  Eigen::VectorXd std;             ///< sqrt(diag(covariance)); NaN where unknown
  std::vector<bool> fixed;         ///< true: held at its given value, not estimated

  int size() const { return static_cast<int>(values.size()); }
  /// Index of a parameter by name; throws InvalidArgument when absent.
  int index(const std::string& name) const;
  /// Value of a parameter by name; throws InvalidArgument when absent.
  double value(const std::string& name) const { return values(index(name)); }
  /// Sets `covariance` and `std` from the covariance `c` of the estimated parameters: `c` is over the
  /// parameters at the indices `slots` (all parameters in order when `slots` is empty); the rows and columns
  /// of the others (fixed parameters) are zero. An empty, wrongly sized or non-finite `c` means "unknown":
  /// the entries of the estimated parameters become NaN (usable() then names the singular information
  /// matrix). Call after `values`.
  void set_covariance(const Eigen::MatrixXd& c, const std::vector<int>& slots = {});
};

/// Quality of fit of the model's simulated output against measured data.
/// Definitions (N samples, d free parameters, e = y - y_model, V = mean(e^2)):
///   fit_percent = 100 (1 - ||e|| / ||y - mean(y)||)   (MATLAB's compare/goodnessOfFit 'NRMSE' form)
///   nrmse = ||e|| / ||y - mean(y)||,  mse = V
///   fpe = V (1 + d/N)/(1 - d/N),  aic = N ln V + 2 d,  aicc = aic + 2 d (d+1)/(N-d-1),
///   bic = N ln V + d ln N.
/// fit is the simulation fit on the estimation data for every estimator that yields a model of the system; a
/// regression's own figure goes into Diagnostics under its own name (fsf: "regression_fit_percent"; the physical
/// FSF routes: "compressed_fit_percent", their fit is on the record when it is given). Estimators of
/// intermediate quantities (modal_estimate's modal parameters) report the fit of their regression. n_samples = 0:
/// no fit was computed (e.g. an FSF model of the exponentially windowed system G(s + a)).
struct FitReport {
  double fit_percent = 0.0;
  double nrmse = 0.0;
  double mse = 0.0;
  double fpe = 0.0;
  double aic = 0.0;
  double aicc = 0.0;
  double bic = 0.0;
  int n_samples = 0;
  int n_parameters = 0;
};


/// The rules every estimator's result is judged by (docs/guide.md, "When is a fit usable").
/// Returns "" when all hold, otherwise the first that fails, worded for the user:
///  1. the algorithm succeeded (Summary::succeeded()); otherwise Summary::message (or the termination);
///  2. every parameter value is finite;
///  3. where a fit was computed (fit.n_samples > 0): fit_percent is finite and > 0, i.e. the model's
///     output is closer to the data than the output's mean is (a diverging simulation gives -Inf);
///  4. where a covariance was computed (non-empty): it is finite and positive semi-definite over the
///     free parameters, and every free parameter's standard deviation is finite and > 0 (zero or
///     non-finite means a singular information matrix: the data do not determine that parameter);
///     zero is accepted only for an exact fit (nrmse < 1e-6: noise-free data); and the estimates are not
///     collinear: the correlation matrix's smallest eigenvalue is at least 1e-13 of its largest (otherwise
///     a combination of parameters is not determined by the data, e.g. the scale of k/(m s^2 + c s + k));
///  5. the free parameters are jointly significant: where a fit was computed, the overall F test
///     F = (R^2/d) / ((1-R^2)/(N-d)), R^2 = 1 - nrmse^2, reaches its 95 % point (otherwise the data
///     cannot tell the model from no model, as for a fit to pure noise).
std::string usability_problem(const Summary& summary, const ParameterSet& parameters, const FitReport& fit);

/// What every estimator returns: the model plus everything needed to judge it.
template <class Model>
struct Result {
  Model model;
  ParameterSet parameters;
  FitReport fit;
  Summary summary;
  Diagnostics diagnostics;

  /// Why the estimate cannot be trusted, or "" when it can (see usability_problem()).
  std::string why_not_usable() const { return usability_problem(summary, parameters, fit); }
  /// Whether the estimate can be trusted: why_not_usable() is empty. Warnings do not make a
  /// result unusable.
  bool usable() const { return why_not_usable().empty(); }
};

}  // namespace ctid
