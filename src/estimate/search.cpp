// ctid — what the output-error searches share (see search.hpp).
#include "estimate/search.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "ctid/core/check.hpp"
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

std::string at_bound_text(const std::vector<HeldAtBound>& held) {
  if (held.empty()) return "";
  std::string list, fixes;
  for (size_t k = 0; k < held.size(); ++k) {
    const std::string bound = detail::significant(held[k].bound, 6);
    list += (k == 0 ? "" : k + 1 == held.size() ? " and " : ", ") +
            detail::format("{} is at its {} bound {}", held[k].name, held[k].lower ? "lower" : "upper", bound);
    fixes += (k == 0 ? "" : ", ") + detail::format("fixed.{}={}", held[k].name, bound);
  }
  const bool many = held.size() > 1;
  return detail::format("{}, and the data would move {} further: the estimate{} the bound's value, not the data's (the "
                        "other standard deviations take {} as fixed there); widen the bound, or fix {} if that value "
                        "is known ({})",
                        list, many ? "them" : "it", many ? "s are" : " is", many ? "them" : "it", many ? "them" : "it",
                        fixes);
}

CovarianceVerdict set_covariance(ParameterSet& parameters, Diagnostics& diagnostics, const internal::LmResult& lm,
                                 const std::vector<int>& slots, double sigma2, const UserBounds& bounds,
                                 const std::vector<internal::ResidualSequence>& sequences) {
  internal::ColouredCovariance coloured;
  if (!sequences.empty() && std::isfinite(lm.cost) && lm.jacobian.rows() > 0)
    coloured = internal::coloured_covariance(lm.jacobian, lm.residual, sequences, static_cast<int>(lm.jacobian.cols()));
  return set_covariance(parameters, diagnostics, lm, slots, sigma2, bounds, coloured);
}

namespace {
// The slots held on a user bound with the gradient of the cost pointing beyond it, and the message naming them.
std::pair<std::vector<Eigen::Index>, std::string> held_at_bounds(const ParameterSet& parameters,
                                                                  const internal::LmResult& lm,
                                                                  const std::vector<int>& slots, const UserBounds& b) {
  std::vector<Eigen::Index> held;
  std::vector<HeldAtBound> named;
  const auto p = static_cast<Eigen::Index>(slots.size());
  if (b.lower.size() < p || b.upper.size() < p || lm.gradient.size() < p || lm.x.size() < p) return {};
  for (Eigen::Index i = 0; i < p; ++i) {
    const bool low = std::isfinite(b.lower(i)) && lm.x(i) <= b.lower(i) && lm.gradient(i) > 0;
    const bool high = std::isfinite(b.upper(i)) && lm.x(i) >= b.upper(i) && lm.gradient(i) < 0;
    if (!low && !high) continue;
    held.push_back(i);
    named.push_back({parameters.names[static_cast<size_t>(slots[static_cast<size_t>(i)])], low,
                     low ? b.lower(i) : b.upper(i)});
  }
  return {held, at_bound_text(named)};
}

// The rows and columns `keep` of M.
Eigen::MatrixXd sub(const Eigen::MatrixXd& M, const std::vector<Eigen::Index>& keep) {
  Eigen::MatrixXd out(keep.size(), keep.size());
  for (size_t i = 0; i < keep.size(); ++i)
    for (size_t j = 0; j < keep.size(); ++j) out(i, j) = M(keep[i], keep[j]);
  return out;
}

// The covariance of the parameters estimated freely (`keep_slots`), the rows and columns of those held on a bound NaN
// (no two-sided standard deviation).
void set_with_held(ParameterSet& parameters, const Eigen::MatrixXd& c, const std::vector<int>& keep_slots,
                   const std::vector<int>& held_slots) {
  parameters.set_covariance(c, keep_slots);
  for (int j : held_slots) {
    parameters.covariance.row(j).setConstant(NAN);
    parameters.covariance.col(j).setConstant(NAN);
    parameters.std(j) = NAN;
  }
}
}  // namespace

CovarianceVerdict set_covariance(ParameterSet& parameters, Diagnostics& diagnostics, const internal::LmResult& lm,
                                 const std::vector<int>& slots, double sigma2, const UserBounds& bounds,
                                 const internal::ColouredCovariance& coloured) {
  CovarianceVerdict verdict;
  const bool finite = std::isfinite(lm.cost);
  std::vector<std::string> names;
  for (int j : slots) names.push_back(parameters.names[static_cast<size_t>(j)]);
  diagnostics.condition_number = finite ? internal::gram_condition(lm.jtj) : NAN;
  if (finite) verdict.unidentifiable = internal::unidentifiable(lm.jtj, lm.x, names);
  if (!finite || !verdict.unidentifiable.empty()) {
    parameters.set_covariance({}, slots);
    return verdict;
  }
  std::vector<Eigen::Index> held;
  std::tie(held, verdict.at_bound) = held_at_bounds(parameters, lm, slots, bounds);
  // The slots estimated freely (in the search vector's order), then the nuisance entries a coloured score covers.
  const auto p = static_cast<Eigen::Index>(slots.size());
  std::vector<Eigen::Index> keep;
  std::vector<int> keep_slots, held_slots;
  for (Eigen::Index i = 0; i < p; ++i) {
    const bool free = std::find(held.begin(), held.end(), i) == held.end();
    (free ? keep_slots : held_slots).push_back(slots[static_cast<size_t>(i)]);
    if (free) keep.push_back(i);
  }
  const Eigen::MatrixXd white = internal::covariance(held.empty() ? lm.jtj : sub(lm.jtj, keep), sigma2);
  set_with_held(parameters, white, keep_slots, held_slots);
  // The coloured sandwich over the free slots and every nuisance entry (q > p), then the free slots' block. J^T J over
  // the whole search vector: from the kept Jacobian, or the search's own (a streamed search has no nuisance entries).
  const Eigen::Index q = coloured.score.rows();
  const Eigen::MatrixXd H =
      lm.jacobian.cols() == q && q > 0 ? Eigen::MatrixXd(lm.jacobian.transpose() * lm.jacobian) : lm.jtj;
  if (white.size() == 0 || q < p || H.rows() != q) return verdict;
  std::vector<Eigen::Index> all = keep;
  for (Eigen::Index i = p; i < q; ++i) all.push_back(i);
  const Eigen::MatrixXd S = internal::sandwich(sub(H, all), sub(coloured.score, all));
  if (S.size() == 0) return verdict;
  diagnostics.set(diagnostic::white_noise_std, parameters.std);
  diagnostics.set(diagnostic::residual_ar_order, coloured.largest_order());
  set_with_held(parameters,
                S.topLeftCorner(static_cast<Eigen::Index>(keep.size()), static_cast<Eigen::Index>(keep.size())),
                keep_slots, held_slots);
  return verdict;
}

}  // namespace ctid::search
