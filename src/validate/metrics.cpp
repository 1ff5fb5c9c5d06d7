#include "ctid/validate/metrics.hpp"

#include <cmath>
#include <limits>

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
void check_pair(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat, const char* what) {
  CTID_REQUIRE(y.size() == yhat.size(), "{}: y has {} samples but the model output has {}", what, y.size(), yhat.size());
  CTID_REQUIRE(y.size() >= 2, "{}: need at least 2 samples (got {})", what, y.size());
}
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

double nrmse(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat) {
  check_pair(y, yhat, "nrmse");
  const double den = (y.array() - y.mean()).matrix().norm();
  CTID_REQUIRE(den > 0, "nrmse: the measured output is constant; the normalisation is zero");
  return (y - yhat).norm() / den;
}

double fit_percent(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat) { return 100.0 * (1.0 - nrmse(y, yhat)); }

double mse(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat) {
  check_pair(y, yhat, "mse");
  return (y - yhat).squaredNorm() / double(y.size());
}

double fpe(double v, int N, int d) { return d >= N ? kInf : v * (1.0 + double(d) / N) / (1.0 - double(d) / N); }
double aic(double v, int N, int d) { return N * std::log(v) + 2.0 * d; }
double aicc(double v, int N, int d) {
  return (N - d - 1 <= 0) ? kInf : aic(v, N, d) + 2.0 * d * (d + 1.0) / double(N - d - 1);
}
double bic(double v, int N, int d) { return N * std::log(v) + d * std::log(double(N)); }

FitReport fit_report(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat, int d) {
  FitReport r;
  r.n_samples = static_cast<int>(y.size());
  r.n_parameters = d;
  r.mse = mse(y, yhat);
  r.nrmse = nrmse(y, yhat);
  r.fit_percent = 100.0 * (1.0 - r.nrmse);
  r.fpe = fpe(r.mse, r.n_samples, d);
  r.aic = aic(r.mse, r.n_samples, d);
  r.aicc = aicc(r.mse, r.n_samples, d);
  r.bic = bic(r.mse, r.n_samples, d);
  return r;
}

}  // namespace ctid
