#include "ctid/core/types.hpp"

#include <cmath>

#include "ctid/core/check.hpp"

namespace ctid {

int ParameterSet::index(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  std::string known;
  for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
  throw InvalidArgument(detail::format("no parameter named '{}' (parameters: {})", name, known));
}

void ParameterSet::set_covariance(const Eigen::MatrixXd& c, const std::vector<int>& slots) {
  const Eigen::Index n = values.size();
  const Eigen::Index k = slots.empty() ? n : static_cast<Eigen::Index>(slots.size());
  auto slot = [&](Eigen::Index i) { return slots.empty() ? i : static_cast<Eigen::Index>(slots[static_cast<size_t>(i)]); };
  const bool known = c.rows() == k && c.cols() == k && c.allFinite();
  covariance = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < k; ++i) {
    CTID_ASSERT(slot(i) >= 0 && slot(i) < n);
    for (Eigen::Index j = 0; j < k; ++j) covariance(slot(i), slot(j)) = known ? c(i, j) : NAN;
  }
  std = covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
}

std::string usability_problem(const Summary& summary, const ParameterSet& p, const FitReport& fit) {
  if (!summary.succeeded())
    return summary.message.empty() ? std::string("the estimator ended with '") + to_string(summary.termination) + "'"
                                   : summary.message;
  auto name = [&](Eigen::Index i) {
    return i < static_cast<Eigen::Index>(p.names.size()) ? p.names[static_cast<size_t>(i)] : "#" + std::to_string(i);
  };
  for (Eigen::Index i = 0; i < p.values.size(); ++i)
    if (!std::isfinite(p.values(i))) return detail::format("parameter {} is not finite ({})", name(i), p.values(i));
  if (fit.n_samples > 0 && !(fit.fit_percent > 0))
    return std::isfinite(fit.fit_percent)
               ? detail::format("the model's output fits the data worse than the output's mean does (fit {} %)",
                                std::round(fit.fit_percent * 100) / 100)
               : std::string("the model's output is not finite on the data (it diverges; fit -Inf)");
  // Jointly significant parameters: the overall F test of the fit, R^2 = 1 - nrmse^2 with d free parameters
  // and N samples, F = (R^2 / d) / ((1 - R^2) / (N - d)) against its 95 % point (Wilson-Hilferty for
  // chi-square / d, a little lenient for small N - d). It depends on the model's output only, not on how the
  // model is parameterised: an over-parameterised model that fits well passes, a fit to pure noise does not.
  if (fit.n_samples > 0 && fit.n_parameters > 0 && fit.n_samples > fit.n_parameters && fit.nrmse >= 1e-6) {
    const double r2 = 1.0 - fit.nrmse * fit.nrmse, dd = fit.n_parameters;
    const double F = (r2 / dd) / ((1.0 - r2) / (fit.n_samples - dd));
    const double a = 2.0 / (9.0 * dd);
    const double f95 = std::pow(1.0 - a + 1.6448536269514722 * std::sqrt(a), 3);
    if (!(F >= f95))
      return detail::format("the model explains no more of the output than {} parameters fitted to noise would (fit {} %, "
                            "F = {} below its 95 % point {}): the data cannot tell this model from no model",
                            fit.n_parameters, std::round(fit.fit_percent * 100) / 100, std::round(F * 100) / 100,
                            std::round(f95 * 100) / 100);
  }
  const Eigen::Index n = p.values.size();
  if (p.covariance.size() == 0) return "";
  if (p.covariance.rows() != n || p.covariance.cols() != n)
    return detail::format("the parameter covariance is {} x {} for {} parameters", p.covariance.rows(), p.covariance.cols(), n);
  auto is_fixed = [&](Eigen::Index i) { return i < static_cast<Eigen::Index>(p.fixed.size()) && p.fixed[static_cast<size_t>(i)]; };
  std::vector<Eigen::Index> free;
  for (Eigen::Index i = 0; i < n; ++i)
    if (!is_fixed(i)) free.push_back(i);
  if (free.empty()) return "";
  Eigen::MatrixXd c(free.size(), free.size());
  for (size_t i = 0; i < free.size(); ++i)
    for (size_t j = 0; j < free.size(); ++j) c(i, j) = p.covariance(free[i], free[j]);
  if (!c.allFinite()) return "the parameter covariance is not finite: the information matrix is singular";
  // Noise-free data fitted exactly have a zero residual variance and so zero standard deviations.
  const bool exact = fit.n_samples > 0 && fit.nrmse < 1e-6;
  if (exact && c.cwiseAbs().maxCoeff() == 0) return "";
  for (size_t i = 0; i < free.size(); ++i) {
    const double sd = std::sqrt(std::max(c(i, i), 0.0));
    if ((!(sd > 0) && !exact) || !std::isfinite(sd))
      return detail::format("the standard deviation of {} is {}: the information matrix is singular, the data do not "
                            "determine {}",
                            name(free[i]), sd, name(free[i]));
  }
  // Positive semi-definite, judged on the correlation matrix (scale-free).
  const Eigen::VectorXd d = c.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd r = d.asDiagonal() * c * d.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (r + r.transpose()));
  const Eigen::VectorXd& lam = es.eigenvalues();
  if (es.info() != Eigen::Success || lam.minCoeff() < -1e-8 * std::max(1.0, lam.maxCoeff()))
    return "the parameter covariance is not positive semi-definite: the information matrix is not that of a minimum";
  // Collinear estimates: a combination of parameters that the data do not determine (e.g. k/(m s^2 + c s + k), where
  // only m/k and c/k matter) makes the correlation matrix singular to working precision: smallest eigenvalue below
  // 1e-13 of the largest (measured: 6e-16 for that model on the hair-dryer record; a well-determined 6th-order
  // polynomial parameterisation of the F-16 frequency response, correlations near 1 but real, has 1e-10).
  // The parameters named are those with a share (> 1 %) of the null space: the eigenvectors of the eigenvalues
  // below that bound (ascending order).
  const double bound = 1e-13 * lam(lam.size() - 1);
  if (!exact && free.size() >= 2 && lam(0) < bound) {
    Eigen::VectorXd share = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(free.size()));
    for (Eigen::Index k = 0; k < lam.size() && lam(k) < bound; ++k) share += es.eigenvectors().col(k).cwiseAbs2();
    std::string which;
    int count = 0;
    for (size_t i = 0; i < free.size(); ++i)
      if (share(static_cast<Eigen::Index>(i)) > 0.01) {
        which += (which.empty() ? "" : ", ") + name(free[i]);
        ++count;
      }
    return detail::format("the data do not determine {} separately: {} estimates are collinear (the correlation "
                          "matrix is singular, smallest eigenvalue {}); fix {} or reparameterise the model",
                          which, count == 2 ? "their" : "the", lam(0), count == 2 ? "one of the two" : "one of them");
  }
  return "";
}

}  // namespace ctid
