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

/// Bounds of the first entries of a search vector that the user set (a model's declared bounds, bounds.NAME); a
/// parameter the search leaves on one of them is reported (CovarianceVerdict::at_bound). Empty: none.
struct UserBounds {
  Eigen::VectorXd lower, upper;
};

/// A parameter left on a bound the data push it beyond, and the text that names such parameters ("fc is at its upper
/// bound 0.1, and the data would move it further: ... (fixed.fc=0.1)").
struct HeldAtBound {
  std::string name;
  bool lower = true;
  double bound = 0.0;
};
std::string at_bound_text(const std::vector<HeldAtBound>& held);

/// What set_covariance found besides the covariance.
struct CovarianceVerdict {
  std::string unidentifiable;  ///< internal::unidentifiable's message when a direction is not determined, else ""
  /// When parameters end on a user bound with the cost's gradient pointing beyond it (the data would move them
  /// further): "fv is at its lower bound 0, and the data would move it further: ..." naming each, else "".
  std::string at_bound;
};

/// The covariance of a search's estimate set on `parameters` at `slots` (the first slots.size() entries of the
/// search vector, in order) and the scaled condition number of J on `diagnostics`. With `sequences` (the layout of the
/// residual vector) and a search that kept its Jacobian (LmOptions::keep_jacobian), the covariance allows for coloured
/// residuals (internal/coloured_covariance.hpp; entries of the search vector beyond the slots, e.g. initial
/// conditions, are estimated alongside and marginalised), with diagnostics "residual_ar_order" and "white_noise_std"
/// (the white-noise figure sigma2 (J^T J)^{-1}); otherwise it is sigma2 (J^T J)^{-1}, J^T J = lm.jtj over the slots.
/// A parameter at a user bound has no standard deviation (NaN) and the others' are those with it held there. The
/// covariance is unknown when a direction is not determined; a search that ended without a finite cost has neither
/// (covariance unknown, condition NaN, verdict empty). Pass the verdict to internal::set_termination.
CovarianceVerdict set_covariance(ParameterSet& parameters, Diagnostics& diagnostics, const internal::LmResult& lm,
                                 const std::vector<int>& slots, double sigma2, const UserBounds& bounds = {},
                                 const std::vector<internal::ResidualSequence>& sequences = {});
/// The same with the score covariance already formed over the search vector (a streamed search's, which never holds
/// J); an empty one gives sigma2 (J^T J)^{-1}.
CovarianceVerdict set_covariance(ParameterSet& parameters, Diagnostics& diagnostics, const internal::LmResult& lm,
                                 const std::vector<int>& slots, double sigma2, const UserBounds& bounds,
                                 const internal::ColouredCovariance& coloured);

}  // namespace ctid::search
