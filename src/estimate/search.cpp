// ctid — what the output-error searches share (see search.hpp).
#include "estimate/search.hpp"

#include <algorithm>
#include <cmath>

#include "internal/least_squares.hpp"

namespace ctid::search {

StartDraws::StartDraws(const Eigen::VectorXd& v0, const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                       const MultiStart& options)
    : v0_(v0), lower_(lower), upper_(upper), drawn_(options.drawn), rng_(options.seed) {}

Eigen::VectorXd StartDraws::next() {
  Eigen::VectorXd v = v0_;
  if (first_) {
    first_ = false;
    return v;
  }
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int j = 0; j < drawn_; ++j) {
    if (std::isfinite(lower_(j)) && std::isfinite(upper_(j))) v(j) = lower_(j) + (upper_(j) - lower_(j)) * unit(rng_);
    else {
      const double mag = v0_(j) != 0.0 ? std::abs(v0_(j)) : 1.0;
      const double sign = v0_(j) < 0 ? -1.0 : 1.0;
      v(j) = std::clamp(sign * mag * std::pow(10.0, 2.0 * unit(rng_) - 1.0), lower_(j), upper_(j));
    }
  }
  return v;
}

MultiStartResult multi_start(const Search& search, const Eigen::VectorXd& v0, const Eigen::VectorXd& lower,
                             const Eigen::VectorXd& upper, const MultiStart& options) {
  StartDraws draws(v0, lower, upper, options);
  MultiStartResult out;
  out.best.cost = INFINITY;
  out.costs = Eigen::VectorXd::Constant(options.starts, NAN);
  for (int s = 0; s < options.starts; ++s) {
    internal::LmResult lm = search(draws.next());
    out.costs(s) = lm.cost;
    const bool interrupted = lm.interrupted;
    const std::string message = lm.message;
    if (s == 0 || lm.cost < out.best.cost) out.best = std::move(lm);
    if (interrupted) {
      out.best.interrupted = true;
      out.best.message = message;
      break;
    }
  }
  return out;
}

std::string set_covariance(ParameterSet& parameters, Diagnostics& diagnostics, const internal::LmResult& lm,
                           const std::vector<int>& slots, double sigma2,
                           const std::vector<internal::ResidualSequence>& sequences) {
  internal::ColouredCovariance coloured;
  if (!sequences.empty() && std::isfinite(lm.cost) && lm.jacobian.rows() > 0)
    coloured = internal::coloured_covariance(lm.jacobian, lm.residual, sequences, static_cast<int>(lm.jacobian.cols()));
  return set_covariance(parameters, diagnostics, lm, slots, sigma2, coloured);
}

std::string set_covariance(ParameterSet& parameters, Diagnostics& diagnostics, const internal::LmResult& lm,
                           const std::vector<int>& slots, double sigma2, const internal::ColouredCovariance& coloured) {
  const bool finite = std::isfinite(lm.cost);
  std::vector<std::string> names;
  for (int j : slots) names.push_back(parameters.names[static_cast<size_t>(j)]);
  const std::string unidentifiable = finite ? internal::unidentifiable(lm.jtj, lm.x, names) : std::string();
  const Eigen::MatrixXd white =
      finite && unidentifiable.empty() ? internal::covariance(lm.jtj, sigma2) : Eigen::MatrixXd();
  diagnostics.condition_number = finite ? internal::gram_condition(lm.jtj) : NAN;
  parameters.set_covariance(white, slots);
  const auto p = static_cast<Eigen::Index>(slots.size());
  if (white.size() == 0 || coloured.covariance.rows() < p) return unidentifiable;
  diagnostics.set(diagnostic::white_noise_std, parameters.std);
  diagnostics.set(diagnostic::residual_ar_order, coloured.largest_order());
  parameters.set_covariance(coloured.covariance.topLeftCorner(p, p), slots);
  return unidentifiable;
}

}  // namespace ctid::search
