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

}  // namespace ctid
