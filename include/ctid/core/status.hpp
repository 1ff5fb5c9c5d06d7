// ctid — how an estimator ended (error tier 2, docs/architecture.md, "Errors").
#pragma once

#include <string>

namespace ctid {

/// Why an estimator stopped. Only `Converged` and `Completed` mean the algorithm did
/// what it set out to do; the others come with a message in Summary::message.
enum class Termination {
  Completed,          ///< a non-iterative method ran to the end
  Converged,          ///< an iterative method met its convergence test
  MaxIterations,      ///< the iteration cap was reached before convergence
  RankDeficient,      ///< the regressor / information matrix is singular to working precision
  Unstable,           ///< the estimate is an unstable model where a stable one was required
  NumericalFailure,   ///< NaN/Inf appeared during the computation
  Interrupted,        ///< the progress callback asked to stop
  Unidentifiable,     ///< the estimate is not determined by the data (e.g. a pole-zero pair that cancels)
  AtBound,            ///< a parameter ended on a bound the data push it beyond: the bound's value, not the data's
};

/// Lower-case identifier used in JSON files and the CLI ("converged", "max_iterations", ...).
const char* to_string(Termination t);
/// Inverse of to_string; throws InvalidArgument for an unknown name.
Termination termination_from_string(const std::string& name);

/// How the run ended.
struct Summary {
  Termination termination = Termination::Completed;
  std::string message;      ///< human-readable detail (empty when all went well)
  int iterations = 0;       ///< iterations performed (1 for one-shot methods)
  double seconds = 0.0;     ///< wall-clock time of the estimator
  /// True when the termination is Completed or Converged.
  bool succeeded() const {
    return termination == Termination::Completed || termination == Termination::Converged;
  }
};

}  // namespace ctid
