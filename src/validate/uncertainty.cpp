#include "ctid/validate/uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "ctid/core/check.hpp"

namespace ctid {

std::vector<TfCoefficient> tf_coefficients(const TransferFunction& g, const ParameterSet& p) {
  const Eigen::VectorXd& den = g.den().coefficients();
  const Eigen::VectorXd& num = g.num().coefficients();
  if (den.size() == 0 || den(0) != 1.0) return {};
  std::vector<TfCoefficient> map(static_cast<size_t>(p.size()));
  for (int i = 0; i < p.size(); ++i) {
    const std::string& n = p.names[static_cast<size_t>(i)];
    if (n.size() < 2 || n.size() > 7 || (n[0] != 'a' && n[0] != 'b') ||
        n.find_first_not_of("0123456789", 1) != std::string::npos)
      continue;  // e.g. "delay"
    const int k = std::stoi(n.substr(1));
    const Eigen::VectorXd& c = n[0] == 'a' ? den : num;
    if (k < (n[0] == 'a' ? 1 : 0) || k >= c.size() ||
        std::abs(c(k) - p.values(i)) > 1e-9 * std::max(1.0, std::abs(c(k))))
      return {};
    map[static_cast<size_t>(i)] = {n[0], k};
  }
  return map;
}

TransferFunction with_coefficients(const TransferFunction& g, const std::vector<TfCoefficient>& map, const Eigen::VectorXd& v) {
  Eigen::VectorXd num = g.num().coefficients(), den = g.den().coefficients();
  for (size_t i = 0; i < map.size(); ++i)
    if (map[i].poly) (map[i].poly == 'a' ? den : num)(map[i].index) = v(static_cast<Eigen::Index>(i));
  return TransferFunction(num, den, g.io_delay());
}

Eigen::VectorXd frequency_grid(const Eigen::VectorXcd& poles, double w_max, int n) {
  CTID_REQUIRE(n >= 2, "frequency_grid: need at least 2 points (got {})", n);
  double lo = INFINITY, hi = 0;
  for (const auto& p : poles)
    if (std::abs(p) > 0 && std::isfinite(std::abs(p))) {
      lo = std::min(lo, std::abs(p));
      hi = std::max(hi, std::abs(p));
    }
  if (!(hi > 0)) lo = hi = 1.0;
  double a = std::log10(lo) - 2, b = std::log10(hi) + 2;
  if (w_max > 0 && std::isfinite(w_max)) b = std::min(b, std::log10(w_max));
  if (b <= a) a = b - 3;
  Eigen::VectorXd w(n);
  for (int i = 0; i < n; ++i) w(i) = std::pow(10.0, a + (b - a) * i / (n - 1));
  return w;
}

double response_horizon(const std::vector<TransferFunction>& models, double fallback) {
  double slow = INFINITY, delay = 0;
  for (const auto& g : models) {
    for (const auto& p : g.poles())
      if (p.real() < 0) slow = std::min(slow, -p.real());
    delay = std::max(delay, g.io_delay());
  }
  return std::isfinite(slow) ? 8.0 / slow + delay : fallback;
}

MagnitudeBand magnitude_band(const Result<TransferFunction>& r, const Eigen::VectorXd& w, double level, int draws,
                             unsigned seed) {
  CTID_REQUIRE(level > 0 && level < 1, "magnitude_band: level must be in (0, 1) (got {})", level);
  CTID_REQUIRE(draws >= 10, "magnitude_band: need at least 10 draws (got {})", draws);
  const ParameterSet& p = r.parameters;
  const int P = p.size();
  MagnitudeBand band;
  if (P == 0 || p.covariance.rows() != P || p.covariance.cols() != P || !p.covariance.allFinite()) return band;
  const std::vector<TfCoefficient> map = tf_coefficients(r.model, p);
  if (std::none_of(map.begin(), map.end(), [](const TfCoefficient& c) { return c.poly != 0; })) return band;
  // Draws theta + L z with L L^T = covariance (eigen-decomposition: semi-definite covariances of fixed parameters
  // are fine).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (p.covariance + p.covariance.transpose()));
  const Eigen::MatrixXd L = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd mags(draws, w.size());
  Eigen::VectorXd z(P);
  for (int k = 0; k < draws; ++k) {
    for (auto& v : z) v = n01(rng);
    mags.row(k) = with_coefficients(r.model, map, p.values + L * z).frequency_response(w).cwiseAbs().transpose();
  }
  const double tail = 0.5 * (1.0 - level);
  const auto lo_i = static_cast<size_t>(std::floor(tail * draws));
  const auto hi_i = std::min(static_cast<size_t>(draws) - 1, static_cast<size_t>(std::ceil((1.0 - tail) * draws)) - 1);
  band.lower.resize(w.size());
  band.upper.resize(w.size());
  std::vector<double> c(static_cast<size_t>(draws));
  for (Eigen::Index j = 0; j < w.size(); ++j) {
    for (int k = 0; k < draws; ++k) c[static_cast<size_t>(k)] = mags(k, j);
    std::sort(c.begin(), c.end());
    band.lower(j) = c[lo_i];
    band.upper(j) = c[hi_i];
  }
  return band;
}

}  // namespace ctid
