// ctid — what the output-error searches share (greybox, nde_oe, oe, physical; ssest draws its starts): the
// multi-start driver and the covariance of a search's estimate (Ljung 1999 §9.3: sigma^2 (J^T J)^{-1} for white
// residuals, the sandwich of internal/coloured_covariance.hpp for coloured ones), with its identifiability check.
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/diagnostics.hpp"
#include "ctid/core/types.hpp"
#include "internal/coloured_covariance.hpp"
#include "internal/levenberg_marquardt.hpp"

namespace ctid::search {

/// The starts of a multi-start search: start 0 is v0 itself; each later start draws the first `drawn` entries of
/// the search vector — uniformly within their bounds where both are finite, else log-uniformly within a decade of
/// |v0_j| (1 where v0_j = 0) with v0_j's sign, clamped to the bounds — from a 64-bit Mersenne twister seeded with
/// `seed`, and keeps the other entries of v0.
struct MultiStart {
  int starts = 1;
  std::uint64_t seed = 1;
  int drawn = 0;
};

/// The starts of `options` one after the other: the first call of next() returns v0, each later one a new draw.
class StartDraws {
 public:
  StartDraws(const Eigen::VectorXd& v0, const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
             const MultiStart& options);
  Eigen::VectorXd next();

 private:
  Eigen::VectorXd v0_, lower_, upper_;
  int drawn_;
  bool first_ = true;
  std::mt19937_64 rng_;
};

struct MultiStartResult {
  internal::LmResult best;  ///< the search of lowest cost (the first on ties); marked interrupted when one was
  Eigen::VectorXd costs;    ///< each start's final cost (NaN for starts not run after an interruption)
};

using Search = std::function<internal::LmResult(const Eigen::VectorXd& start)>;

/// Runs `search` from every start and keeps the lowest cost; an interrupted search (core/progress.hpp) ends the
/// run, its message on the result.
MultiStartResult multi_start(const Search& search, const Eigen::VectorXd& v0, const Eigen::VectorXd& lower,
                             const Eigen::VectorXd& upper, const MultiStart& options);

/// The covariance of a search's estimate set on `parameters` at `slots` (the first slots.size() entries of the
/// search vector, in order) and the scaled condition number of J on `diagnostics`. With `sequences` (the layout of the
/// residual vector) and a search that kept its Jacobian (LmOptions::keep_jacobian), the covariance allows for coloured
/// residuals (internal/coloured_covariance.hpp; entries of the search vector beyond the slots, e.g. initial
/// conditions, are estimated alongside and marginalised), with diagnostics "residual_ar_order" and "white_noise_std"
/// (the white-noise figure sigma2 (J^T J)^{-1}); otherwise it is sigma2 (J^T J)^{-1}, J^T J = lm.jtj over the slots.
/// Returns "" when the data determine every direction, else internal::unidentifiable's message (the covariance is then
/// unknown); a search that ended without a finite cost has neither (covariance unknown, condition NaN, message "").
std::string set_covariance(ParameterSet& parameters, Diagnostics& diagnostics, const internal::LmResult& lm,
                           const std::vector<int>& slots, double sigma2,
                           const std::vector<internal::ResidualSequence>& sequences = {});
/// The same with the coloured-noise covariance already formed over the search vector (a streamed search's, which
/// never holds J); an empty one gives sigma2 (J^T J)^{-1}.
std::string set_covariance(ParameterSet& parameters, Diagnostics& diagnostics, const internal::LmResult& lm,
                           const std::vector<int>& slots, double sigma2, const internal::ColouredCovariance& coloured);

}  // namespace ctid::search
