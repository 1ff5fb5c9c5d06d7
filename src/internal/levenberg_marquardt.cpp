#include "internal/levenberg_marquardt.hpp"

#include <cmath>
#include <type_traits>

#include <Eigen/SparseCholesky>

#include "ctid/core/check.hpp"
#include "ctid/core/progress.hpp"

namespace ctid::internal {

void set_termination(Summary& s, const LmResult& lm, const std::string& failure, const std::string& unidentifiable,
                     const std::string& at_bound) {
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
  } else if (!at_bound.empty() && (s.succeeded() || s.termination == Termination::MaxIterations)) {
    s.termination = Termination::AtBound;
    s.message = at_bound;
  }
}

namespace {
using Sparse = Eigen::SparseMatrix<double>;

bool finite(const Eigen::MatrixXd& J) { return J.allFinite(); }
bool finite(const Sparse& J) { return Eigen::Map<const Eigen::VectorXd>(J.valuePtr(), J.nonZeros()).allFinite(); }

// (A + lambda diag(d)) step = -g, dense or sparse.
Eigen::VectorXd solve(const Eigen::MatrixXd& A, const Eigen::VectorXd& d, double lambda, const Eigen::VectorXd& g) {
  Eigen::MatrixXd M = A;
  M.diagonal() += lambda * d;
  return -M.ldlt().solve(g);
}
Eigen::VectorXd solve(const Sparse& A, const Eigen::VectorXd& d, double lambda, const Eigen::VectorXd& g) {
  Sparse D(A.rows(), A.cols());
  D.setIdentity();
  const Sparse M = A + Sparse(Eigen::VectorXd(lambda * d).asDiagonal() * D);
  Eigen::SimplicialLDLT<Sparse> ldlt(M);
  if (ldlt.info() != Eigen::Success) return Eigen::VectorXd::Constant(g.size(), NAN);
  return -ldlt.solve(g);
}
Eigen::VectorXd diagonal(const Eigen::MatrixXd& A) { return A.diagonal(); }
Eigen::VectorXd diagonal(const Sparse& A) { return A.diagonal(); }

// The search on the normal equations: normal(x, cost, A, g) sets cost = 1/2 ||r||^2 and, when A and g are not null,
// A = J^T J and g = J^T r (Normal: dense or sparse).
template <class Normal, class Evaluate>
LmResult lm(const Evaluate& evaluate, Eigen::VectorXd x, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
            const LmOptions& o) {
  const Eigen::Index p = x.size();
  LmResult res;
  auto normal = [&](const Eigen::VectorXd& xv, double& c, Normal* A, Eigen::VectorXd* g) {
    ++res.evaluations;
    if (A) ++res.jacobians;
    return evaluate(xv, c, A, g);
  };
  x = x.cwiseMax(lo).cwiseMin(hi);
  double cost = INFINITY;
  Normal A;
  Eigen::VectorXd g;
  if (!normal(x, cost, &A, &g) || !std::isfinite(cost) || !finite(A) || !g.allFinite()) {
    res.x = x;
    res.cost = INFINITY;
    res.message = "the model cannot be evaluated at the initial parameters";
    return res;
  }
  double lambda = o.lambda0, last_rel = NAN;
  for (int it = 1; it <= o.max_iterations; ++it) {
    if (!report_progress("levenberg_marquardt", it, cost)) {
      res.interrupted = true;
      res.message = detail::format("interrupted after {} iterations", it - 1);
      break;
    }
    res.iterations = it;
    Eigen::VectorXd d = diagonal(A).cwiseMax(1e-300);
    // Active bounds: a parameter at a bound whose gradient pushes it outward stays there this iteration (its row and
    // column are decoupled), so the others move as if it were fixed instead of being projected back every time.
    Eigen::VectorXd keep = Eigen::VectorXd::Ones(p);
    for (Eigen::Index i = 0; i < p; ++i)
      if ((x(i) <= lo(i) && g(i) > 0) || (x(i) >= hi(i) && g(i) < 0)) keep(i) = 0.0;
    const Normal Ak = keep.asDiagonal() * A * keep.asDiagonal();
    const Eigen::VectorXd gk = keep.cwiseProduct(g);
    bool accepted = false;
    for (int tries = 0; tries < 30 && !accepted; ++tries) {
      const Eigen::VectorXd step = solve(Ak, d, lambda, gk);
      const Eigen::VectorXd xt = (x + step).cwiseMax(lo).cwiseMin(hi);
      if (!step.allFinite()) { lambda *= 10; continue; }
      double ct = INFINITY;
      if (normal(xt, ct, nullptr, nullptr) && std::isfinite(ct) && ct < cost) {
        double dx = 0;
        for (Eigen::Index i = 0; i < p; ++i) dx = std::max(dx, std::abs(xt(i) - x(i)) / std::max(std::abs(xt(i)), 1e-8));
        const double rel = (cost - ct) / std::max(cost, 1e-300);
        x = xt;
        lambda = std::max(lambda / 10, 1e-12);
        accepted = true;
        last_rel = rel;
        if (rel < o.ftol || dx < o.xtol) res.converged = true;
        if (!o.final_normal && (res.converged || it == o.max_iterations)) {
          cost = ct;  // the search ends here and the caller needs no J^T J
          continue;
        }
        if (!normal(x, cost, &A, &g)) { res.message = "evaluation failed at an accepted point"; break; }
        continue;
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
  if (!res.converged && res.message.empty())
    res.message = detail::format("the iteration limit ended the search, not convergence: {} iterations, the cost still "
                                 "falling (by a relative {} in the last); raise max_iterations (e.g. {}) or check the "
                                 "start and the scaling",
                                 o.max_iterations, detail::significant(last_rel, 2), 4 * o.max_iterations);
  res.x = x;
  res.cost = cost;
  res.lambda = lambda;
  res.jtj = Eigen::MatrixXd(A);
  res.gradient = g;
  return res;
}

// The residual form: the normal equations formed from r and J.
template <class Jacobian, class Evaluate>
LmResult lm_residuals(const Evaluate& evaluate, Eigen::VectorXd x, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                      const LmOptions& o) {
  using Normal = std::conditional_t<std::is_same_v<Jacobian, Sparse>, Sparse, Eigen::MatrixXd>;
  Eigen::VectorXd r, r_at_J;
  Eigen::VectorXd x_at_J;  // where J and r_at_J were evaluated (keep_jacobian)
  Jacobian J;
  auto normal = [&](const Eigen::VectorXd& xv, double& cost, Normal* A, Eigen::VectorXd* g) {
    if (!evaluate(xv, r, A ? &J : nullptr) || !r.allFinite() || (A && !finite(J))) return false;
    cost = 0.5 * r.squaredNorm();
    if (A) {
      if constexpr (std::is_same_v<Jacobian, Sparse>) *A = Normal(J.transpose()) * J;
      else A->noalias() = J.transpose() * J;  // no transposed copy of J (N x p) per evaluation
      g->noalias() = J.transpose() * r;
      if (o.keep_jacobian) {
        r_at_J = r;
        x_at_J = xv;
      }
    }
    return true;
  };
  LmResult res = lm<Normal>(normal, std::move(x), lo, hi, o);
  if constexpr (std::is_same_v<Jacobian, Eigen::MatrixXd>)
    if (o.keep_jacobian && std::isfinite(res.cost) && x_at_J.size() == res.x.size() && x_at_J == res.x) {
      res.residual = std::move(r_at_J);
      res.jacobian = std::move(J);
    }
  return res;
}
}  // namespace

LmResult levenberg_marquardt(const LmEvaluate& evaluate, Eigen::VectorXd x, const Eigen::VectorXd& lo,
                             const Eigen::VectorXd& hi, const LmOptions& o) {
  return lm_residuals<Eigen::MatrixXd>(evaluate, std::move(x), lo, hi, o);
}
LmResult levenberg_marquardt(const LmSparseEvaluate& evaluate, Eigen::VectorXd x, const Eigen::VectorXd& lo,
                             const Eigen::VectorXd& hi, const LmOptions& o) {
  return lm_residuals<Sparse>(evaluate, std::move(x), lo, hi, o);
}
LmResult levenberg_marquardt(const LmNormalEvaluate& evaluate, Eigen::VectorXd x, const Eigen::VectorXd& lo,
                             const Eigen::VectorXd& hi, const LmOptions& o) {
  return lm<Eigen::MatrixXd>(evaluate, std::move(x), lo, hi, o);
}

}  // namespace ctid::internal
