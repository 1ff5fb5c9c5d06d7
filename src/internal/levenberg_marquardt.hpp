// ctid internal — Levenberg-Marquardt for nonlinear least squares (dense, or with a sparse Jacobian: then the normal
// equations are sparse and solved by Eigen's simplicial LDL^T — multiple shooting, whose Jacobian is block sparse)
// min 1/2 ||r(x)||^2 with simple bounds, driven by exact Jacobians supplied by the caller
// (Marquardt scaling by diag(J^T J); bounds by projection of each trial step, with the parameters at a bound whose
// gradient points outward held there for the iteration — an active set, as in projected Gauss-Newton methods,
// Kelley 1999, "Iterative methods for optimization" §5.5).
#pragma once

#include <functional>
#include <string>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "ctid/core/status.hpp"

namespace ctid::internal {

struct LmOptions {
  int max_iterations = 100;
  double ftol = 1e-12;     // stop when the relative cost decrease of an accepted step is below
  double xtol = 1e-10;     // stop when max |dx_i| / max(|x_i|, 1e-8) is below
  double lambda0 = 1e-3;
  /// false: no J^T J at the final point (the result's jtj is then the last one evaluated) — for callers that compute
  /// their covariance themselves; a search that converges or reaches max_iterations then costs one Jacobian less.
  bool final_normal = true;
  /// Residual form (LmEvaluate): keep the residuals and the Jacobian at the final point in the result (for a
  /// covariance that needs more than J^T J, internal/coloured_covariance.hpp); needs final_normal.
  bool keep_jacobian = false;
};

struct LmResult {
  Eigen::VectorXd x;
  double cost = 0.0;                // 1/2 ||r||^2 at x
  Eigen::MatrixXd jtj;              // J^T J at x
  Eigen::VectorXd gradient;         // J^T r at x (the cost's gradient)
  Eigen::VectorXd residual;         // r at x and ..
  Eigen::MatrixXd jacobian;         // .. J at x, when LmOptions::keep_jacobian (else empty)
  int iterations = 0;
  int evaluations = 0;              // residual evaluations, each a pass over the data ..
  int jacobians = 0;                // .. of which with the Jacobian
  double lambda = 0.0;              // the damping at the end (a search continued in new coordinates starts there)
  bool converged = false;
  bool interrupted = false;         // the progress callback (core/progress.hpp) asked to stop
  std::string message;
};

/// evaluate(x, r, J) fills r (and J when J != nullptr); returns false when the model
/// cannot be evaluated at x (e.g. an unstable simulation), which rejects the step.
using LmEvaluate = std::function<bool(const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J)>;

/// The same with a sparse Jacobian (J^T J of the result dense).
using LmSparseEvaluate =
    std::function<bool(const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::SparseMatrix<double>* J)>;

/// How the search ended, with its iteration count: NumericalFailure with `failure` (or the search's own
/// message when `failure` is empty) when it could not evaluate its start, else Interrupted, Converged or
/// MaxIterations (with the message); a search that converged or ran out of iterations becomes Unidentifiable with
/// `unidentifiable` when that is not empty (the message of internal::unidentifiable, least_squares.hpp), else
/// AtBound with `at_bound` when that is not empty (search::CovarianceVerdict).
void set_termination(Summary& summary, const LmResult& lm, const std::string& failure = "",
                     const std::string& unidentifiable = "", const std::string& at_bound = "");


/// The same from the normal equations: evaluate(x, cost, JtJ, Jtr) sets cost = 1/2 ||r||^2 and, when the pointers are
/// not null, J^T J and J^T r — for callers that stream the residuals and never hold J (memory O(parameters^2)).
using LmNormalEvaluate =
    std::function<bool(const Eigen::VectorXd& x, double& cost, Eigen::MatrixXd* JtJ, Eigen::VectorXd* Jtr)>;

LmResult levenberg_marquardt(const LmEvaluate& evaluate, Eigen::VectorXd x0, const Eigen::VectorXd& lower,
                             const Eigen::VectorXd& upper, const LmOptions& options);
LmResult levenberg_marquardt(const LmSparseEvaluate& evaluate, Eigen::VectorXd x0, const Eigen::VectorXd& lower,
                             const Eigen::VectorXd& upper, const LmOptions& options);
LmResult levenberg_marquardt(const LmNormalEvaluate& evaluate, Eigen::VectorXd x0, const Eigen::VectorXd& lower,
                             const Eigen::VectorXd& upper, const LmOptions& options);

}  // namespace ctid::internal
