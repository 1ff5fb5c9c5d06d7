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

/// Billings & Voon (1986) correlation validity tests for nonlinear (NARX/NARMAX) models, with 95 %
/// bounds 1.96/sqrt(N) (Billings & Li 1999, §2). Every signal is mean-removed and each correlation normalised
/// by the two signals' norms. A model is adequate when all five stay inside the bound (for ee: lags >= 1).
struct NonlinearCorrelationTests {
  CorrelationTest ee;     ///< phi_ee(k) = delta(k), k = 0..M
  CorrelationTest ue;     ///< phi_ue(k) = 0, k = -M..M
  CorrelationTest e_eu;   ///< phi_e(eu)(k) = E[e(t) e(t-1-k) u(t-1-k)] = 0, k = 0..M
  CorrelationTest u2_e;   ///< phi_(u^2)'e(k) = 0, k = -M..M
  CorrelationTest u2_e2;  ///< phi_(u^2)'e^2(k) = 0, k = -M..M
  bool passed() const { return ee.passed() && ue.passed() && e_eu.passed() && u2_e.passed() && u2_e2.passed(); }
};
/// Throws InvalidArgument for size mismatches, max_lag < 1 or >= N, or a constant signal.
NonlinearCorrelationTests nonlinear_correlation_tests(const Eigen::VectorXd& u, const Eigen::VectorXd& e,
                                                      int max_lag = 20);

}  // namespace ctid
