// ctid — what the output-error searches share (see search.hpp).
#include "estimate/search.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "internal/least_squares.hpp"

namespace ctid::search {

MultiStartResult multi_start(const Search& search, const Eigen::VectorXd& v0, const Eigen::VectorXd& lower,
                             const Eigen::VectorXd& upper, const MultiStart& options) {
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  MultiStartResult out;
  out.best.cost = INFINITY;
  out.costs = Eigen::VectorXd::Constant(options.starts, NAN);
  for (int s = 0; s < options.starts; ++s) {
    Eigen::VectorXd v = v0;
    if (s > 0)
      for (int j = 0; j < options.drawn; ++j) {
        if (std::isfinite(lower(j)) && std::isfinite(upper(j))) v(j) = lower(j) + (upper(j) - lower(j)) * unit(rng);
        else {
          const double mag = v0(j) != 0.0 ? std::abs(v0(j)) : 1.0;
          const double sign = v0(j) < 0 ? -1.0 : 1.0;
          v(j) = std::clamp(sign * mag * std::pow(10.0, 2.0 * unit(rng) - 1.0), lower(j), upper(j));
        }
      }
    internal::LmResult lm = search(v);
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
                           const std::vector<int>& slots, double sigma2) {
  const bool finite = std::isfinite(lm.cost);
  std::vector<std::string> names;
  for (int j : slots) names.push_back(parameters.names[static_cast<size_t>(j)]);
  const std::string unidentifiable = finite ? internal::unidentifiable(lm.jtj, lm.x, names) : std::string();
  parameters.set_covariance(finite && unidentifiable.empty() ? internal::covariance(lm.jtj, sigma2) : Eigen::MatrixXd(),
                            slots);
  diagnostics.condition_number = finite ? internal::gram_condition(lm.jtj) : NAN;
  return unidentifiable;
}

}  // namespace ctid::search
