#include "ctid/validate/residuals.hpp"

#include <cmath>

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
constexpr double kZ99 = 2.5758293035489;  // two-sided 99 % normal quantile
}

CorrelationTest residual_autocorrelation(const Eigen::VectorXd& e_in, int M) {
  const Eigen::Index N = e_in.size();
  CTID_REQUIRE(M >= 1 && M < N, "residual_autocorrelation: max_lag must be in [1, N-1] = [1, {}] (got {})", N - 1, M);
  const Eigen::VectorXd e = e_in.array() - e_in.mean();
  const double r0 = e.squaredNorm();
  CTID_REQUIRE(std::isfinite(r0), "residual_autocorrelation: the residuals are not finite or overflow (a diverging simulation?)");
  CTID_REQUIRE(r0 > 0, "residual_autocorrelation: the residuals are identically zero");
  CorrelationTest r;
  r.lags = Eigen::VectorXi::LinSpaced(M + 1, 0, M);
  r.values.resize(M + 1);
  r.bound = kZ99 / std::sqrt(double(N));
  for (int k = 0; k <= M; ++k) {
    r.values(k) = e.head(N - k).dot(e.tail(N - k)) / r0;
    if (k > 0 && std::abs(r.values(k)) > r.bound) ++r.n_outside;
  }
  return r;
}

CorrelationTest input_residual_crosscorrelation(const Eigen::VectorXd& u_in, const Eigen::VectorXd& e_in, int M) {
  const Eigen::Index N = e_in.size();
  CTID_REQUIRE(u_in.size() == N, "input_residual_crosscorrelation: u has {} samples, e has {}", u_in.size(), N);
  CTID_REQUIRE(M >= 0 && M < N, "input_residual_crosscorrelation: max_lag must be in [0, {}] (got {})", N - 1, M);
  const Eigen::VectorXd e = e_in.array() - e_in.mean();
  const Eigen::VectorXd u = u_in.array() - u_in.mean();
  const double norm = std::sqrt(u.squaredNorm() * e.squaredNorm());
  CTID_REQUIRE(std::isfinite(norm),
               "input_residual_crosscorrelation: the input or the residuals are not finite or overflow (a diverging simulation?)");
  CTID_REQUIRE(norm > 0, "input_residual_crosscorrelation: the input or the residuals are constant");
  CorrelationTest r;
  r.lags = Eigen::VectorXi::LinSpaced(2 * M + 1, -M, M);
  r.values.resize(2 * M + 1);
  r.bound = kZ99 / std::sqrt(double(N));
  for (int i = 0; i < 2 * M + 1; ++i) {
    const int k = i - M;
    const double v = k >= 0 ? u.head(N - k).dot(e.tail(N - k)) : e.head(N + k).dot(u.tail(N + k));
    r.values(i) = v / norm;
    if (std::abs(r.values(i)) > r.bound) ++r.n_outside;
  }
  return r;
}

namespace {
// sum_t a(t) b(t + k) / sqrt(sum a^2 sum b^2) for k = k_min..k_max, a and b mean-removed; 95 % bound.
CorrelationTest normalised_cross(Eigen::VectorXd a, Eigen::VectorXd b, int k_min, int k_max, bool skip_zero,
                                 const char* what) {
  const Eigen::Index N = a.size();
  a.array() -= a.mean();
  b.array() -= b.mean();
  const double na = a.norm(), nb = b.norm();
  CTID_REQUIRE(na > 0 && nb > 0, "nonlinear_correlation_tests: {} involves a constant signal", what);
  CorrelationTest t;
  t.lags = Eigen::VectorXi::LinSpaced(k_max - k_min + 1, k_min, k_max);
  t.values.resize(t.lags.size());
  t.bound = 1.96 / std::sqrt(static_cast<double>(N));
  for (Eigen::Index i = 0; i < t.lags.size(); ++i) {
    const int k = t.lags(i);
    const Eigen::Index n = N - std::abs(k);
    const double s = k >= 0 ? a.head(n).dot(b.tail(n)) : a.tail(n).dot(b.head(n));
    t.values(i) = s / (na * nb);
    if (!(skip_zero && k == 0) && std::abs(t.values(i)) > t.bound) ++t.n_outside;
  }
  return t;
}
}  // namespace

NonlinearCorrelationTests nonlinear_correlation_tests(const Eigen::VectorXd& u, const Eigen::VectorXd& e, int max_lag) {
  CTID_REQUIRE(u.size() == e.size(), "nonlinear_correlation_tests: u has {} samples, e has {}", u.size(), e.size());
  CTID_REQUIRE(max_lag >= 1 && max_lag + 2 < e.size(), "nonlinear_correlation_tests: max_lag = {} must be in [1, {})",
               max_lag, e.size() - 2);
  NonlinearCorrelationTests r;
  r.ee = normalised_cross(e, e, 0, max_lag, true, "phi_ee");
  r.ue = normalised_cross(u, e, -max_lag, max_lag, false, "phi_ue");
  // phi_e(eu)(k) = E[e(t) (e u)(t - 1 - k)]: the product leads e by 1 + k.
  const Eigen::VectorXd eu = e.cwiseProduct(u);
  CorrelationTest x = normalised_cross(eu, e, 1, max_lag + 1, false, "phi_e(eu)");
  x.lags.array() -= 1;
  r.e_eu = x;
  const Eigen::VectorXd u2 = u.cwiseAbs2(), e2 = e.cwiseAbs2();
  r.u2_e = normalised_cross(u2, e, -max_lag, max_lag, false, "phi_(u^2)'e");
  r.u2_e2 = normalised_cross(u2, e2, -max_lag, max_lag, false, "phi_(u^2)'e^2");
  return r;
}

}  // namespace ctid
