#include "internal/levenberg_marquardt.hpp"

#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/core/progress.hpp"

namespace ctid::internal {

void set_termination(Summary& s, const LmResult& lm, const std::string& failure, const std::string& unidentifiable) {
  s.iterations = lm.iterations;
  if (!std::isfinite(lm.cost)) {
    s.termination = Termination::NumericalFailure;
    s.message = failure.empty() ? lm.message : failure;
    return;
  }
  s.termination = lm.interrupted ? Termination::Interrupted
                  : lm.converged ? Termination::Converged
                                 : Termination::MaxIterations;
  s.message = lm.converged && !lm.interrupted ? "" : lm.message;
  // A flat direction is the real cause of a search that ended without converging too.
  if (!unidentifiable.empty() && (s.succeeded() || s.termination == Termination::MaxIterations)) {
    s.termination = Termination::Unidentifiable;
    s.message = unidentifiable;
  }
}

LmResult levenberg_marquardt(const LmEvaluate& evaluate, Eigen::VectorXd x, const Eigen::VectorXd& lo,
                             const Eigen::VectorXd& hi, const LmOptions& o) {
  const Eigen::Index p = x.size();
  LmResult res;
  x = x.cwiseMax(lo).cwiseMin(hi);
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  if (!evaluate(x, r, &J) || !r.allFinite() || !J.allFinite()) {
    res.x = x;
    res.cost = INFINITY;
    res.message = "the model cannot be evaluated at the initial parameters";
    return res;
  }
  double cost = 0.5 * r.squaredNorm();
  double lambda = o.lambda0;
  Eigen::VectorXd rt;
  for (int it = 1; it <= o.max_iterations; ++it) {
    if (!report_progress("levenberg_marquardt", it, cost)) {
      res.interrupted = true;
      res.message = detail::format("interrupted after {} iterations", it - 1);
      break;
    }
    res.iterations = it;
    const Eigen::MatrixXd A = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * r;  // gradient of the cost
    Eigen::VectorXd d = A.diagonal().cwiseMax(1e-300);
    // Active bounds: a parameter at a bound whose gradient pushes it outward stays there this iteration (its row and
    // column are decoupled), so the others move as if it were fixed instead of being projected back every time.
    Eigen::VectorXd keep = Eigen::VectorXd::Ones(p);
    for (Eigen::Index i = 0; i < p; ++i)
      if ((x(i) <= lo(i) && g(i) > 0) || (x(i) >= hi(i) && g(i) < 0)) keep(i) = 0.0;
    const Eigen::MatrixXd Ak = keep.asDiagonal() * A * keep.asDiagonal();
    const Eigen::VectorXd gk = keep.cwiseProduct(g);
    bool accepted = false;
    for (int tries = 0; tries < 30 && !accepted; ++tries) {
      Eigen::MatrixXd M = Ak;
      M.diagonal() += lambda * d;
      const Eigen::VectorXd step = -M.ldlt().solve(gk);
      const Eigen::VectorXd xt = (x + step).cwiseMax(lo).cwiseMin(hi);
      if (!step.allFinite()) { lambda *= 10; continue; }
      if (evaluate(xt, rt, nullptr) && rt.allFinite()) {
        const double ct = 0.5 * rt.squaredNorm();
        if (ct < cost) {
          double dx = 0;
          for (Eigen::Index i = 0; i < p; ++i) dx = std::max(dx, std::abs(xt(i) - x(i)) / std::max(std::abs(xt(i)), 1e-8));
          const double rel = (cost - ct) / std::max(cost, 1e-300);
          x = xt;
          cost = ct;
          if (!evaluate(x, r, &J)) { res.message = "evaluation failed at an accepted point"; break; }
          lambda = std::max(lambda / 10, 1e-12);
          accepted = true;
          if (rel < o.ftol || dx < o.xtol) {
            res.converged = true;
          }
          continue;
        }
      }
      lambda *= 10;
    }
    if (!accepted) {
      // No decrease possible even with a tiny step: a (local) minimum to working precision.
      res.converged = true;
      res.message = "no further decrease of the cost";
      break;
    }
    if (res.converged) break;
  }
  if (!res.converged && res.message.empty()) res.message = "iteration limit reached";
  res.x = x;
  res.cost = cost;
  res.jtj = J.transpose() * J;
  return res;
}

}  // namespace ctid::internal
