#include "ctid/validate/metrics.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
void check_pair(const Eigen::Ref<const Eigen::VectorXd>& y, const Eigen::Ref<const Eigen::VectorXd>& yhat, const char* what) {
  CTID_REQUIRE(y.size() == yhat.size(), "{}: y has {} samples but the model output has {}", what, y.size(), yhat.size());
  CTID_REQUIRE(y.size() >= 2, "{}: need at least 2 samples (got {})", what, y.size());
}
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

std::string fit_percent_text(double v) {
  if (std::isnan(v)) return "nan";  // printf may write "-nan"
  char b[32];
  std::snprintf(b, sizeof b, std::isfinite(v) && std::abs(v) >= 1e4 ? "%.3g" : "%.2f", v);
  return b;
}

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

namespace {
// Two passes: the mean of y, then the sums of squares of y - yhat (*se) and of y - mean (*sd).
void sums(const Eigen::Ref<const Eigen::VectorXd>& y, const Eigen::Ref<const Eigen::VectorXd>& yhat, double* se_out,
          double* sd_out) {
  const double m = y.mean();
  double se = 0, sd = 0;
  for (Eigen::Index k = 0; k < y.size(); ++k) {
    const double e = y(k) - yhat(k), c = y(k) - m;
    se += e * e;
    sd += c * c;
  }
  *se_out = se;
  *sd_out = sd;
}

FitReport fill(double se, double sd, int n, int d) {
  FitReport r;
  r.n_samples = n;
  r.n_parameters = d;
  r.mse = se / double(n);
  r.nrmse = std::sqrt(se / sd);
  r.fit_percent = 100.0 * (1.0 - r.nrmse);
  r.fpe = fpe(r.mse, n, d);
  r.aic = aic(r.mse, n, d);
  r.aicc = aicc(r.mse, n, d);
  r.bic = bic(r.mse, n, d);
  return r;
}
}  // namespace

FitReport fit_report(const Eigen::Ref<const Eigen::VectorXd>& y, const Eigen::Ref<const Eigen::VectorXd>& yhat, int d) {
  check_pair(y, yhat, "fit_report");
  double se = 0, sd = 0;
  sums(y, yhat, &se, &sd);
  CTID_REQUIRE(sd > 0, "fit_report: the measured output is constant; the normalisation is zero");
  return fill(se, sd, static_cast<int>(y.size()), d);
}

FitReport fit_report_or_inf(const Eigen::Ref<const Eigen::VectorXd>& y, const Eigen::Ref<const Eigen::VectorXd>& yhat, int d) {
  check_pair(y, yhat, "fit_report");
  double se = 0, sd = 0;
  sums(y, yhat, &se, &sd);
  return fit_report_from_sums(se, sd, static_cast<int>(y.size()), d);
}

FitReport fit_report_from_sums(double sse, double sst, int n_samples, int d) {
  FitReport r = fill(sse, sst, n_samples, d);
  if (!(sst > 0) || !std::isfinite(r.mse)) {
    r.fit_percent = -kInf;
    r.nrmse = r.mse = r.fpe = r.aic = r.aicc = r.bic = kInf;
  }
  return r;
}

}  // namespace ctid
