// ctid — residual analysis: whiteness of the residuals and their independence of the input.
#pragma once

#include <Eigen/Dense>

namespace ctid {

/// Normalised correlation estimates with their 99 % confidence bound.
struct CorrelationTest {
  Eigen::VectorXi lags;      ///< 0..M (auto) or -M..M (cross)
  Eigen::VectorXd values;    ///< r(k) / normalisation, one per lag
  double bound = 0.0;        ///< 2.5758 / sqrt(N): |r(k)| below it is consistent with independence (99 %)
  int n_outside = 0;         ///< lags (excluding lag 0 for the autocorrelation) with |r(k)| > bound
  bool passed() const { return n_outside == 0; }
};

/// Autocorrelation of the residuals e, r(k) = sum e_t e_{t+k} / sum e_t^2 for k = 0..max_lag.
/// Throws InvalidArgument for max_lag < 1, max_lag >= N, or an all-zero e.
CorrelationTest residual_autocorrelation(const Eigen::VectorXd& e, int max_lag = 25);
/// Cross-correlation of input u and residuals e, r(k) = sum u_t e_{t+k} / sqrt(sum u^2 sum e^2),
/// for k = -max_lag..max_lag (k > 0: input leads residual). Both are mean-removed first.
CorrelationTest input_residual_crosscorrelation(const Eigen::VectorXd& u, const Eigen::VectorXd& e, int max_lag = 25);

}  // namespace ctid
