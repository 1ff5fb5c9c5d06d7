// ctid — the common result envelope of every estimator (DESIGN.md §1).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Dense>

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
};

/// Quality of fit of the model's simulated output against measured data.
/// Definitions (N samples, d free parameters, e = y - y_model, V = mean(e^2)):
///   fit_percent = 100 (1 - ||e|| / ||y - mean(y)||)   (MATLAB's compare/goodnessOfFit 'NRMSE' form)
///   nrmse = ||e|| / ||y - mean(y)||,  mse = V
///   fpe = V (1 + d/N)/(1 - d/N),  aic = N ln V + 2 d,  aicc = aic + 2 d (d+1)/(N-d-1),
///   bic = N ln V + d ln N.
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

/// Numerical diagnostics of a fit.
struct Diagnostics {
  double condition_number = 0.0;             ///< of the column-scaled regressor / information matrix
  std::vector<std::string> warnings;         ///< things the user should look at; empty when none
  std::map<std::string, double> scalars;     ///< method-specific numbers (e.g. "tau")
  std::map<std::string, Eigen::VectorXd> vectors;  ///< method-specific vectors (e.g. "theta_tau")
};

/// What every estimator returns: the model plus everything needed to judge it.
template <class Model>
struct Result {
  Model model;
  ParameterSet parameters;
  FitReport fit;
  Summary summary;
  Diagnostics diagnostics;

  /// Whether the estimate can be trusted: the algorithm succeeded and every free
  /// parameter is finite. Warnings do not make a result unusable.
  bool usable() const {
    if (!summary.succeeded()) return false;
    return parameters.values.allFinite();
  }
};

}  // namespace ctid
