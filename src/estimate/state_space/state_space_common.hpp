// ctid internal — what the state-space estimators (subspace, ssest in time and frequency domain) share: the channel
// scales they run in, the fits they report (every output on its own, and all outputs together with each scaled by its
// standard deviation), the full parametrisation in data-driven local coordinates and the real modal form of a result.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/check.hpp"
#include "ctid/core/diagnostics.hpp"
#include "ctid/core/error.hpp"
#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/state_space.hpp"
#include "internal/levenberg_marquardt.hpp"

namespace ctid::ss_detail {

/// Standard deviation of each input (outputs = false) or output over all the records together (1 where constant).
Eigen::VectorXd channel_scales(std::span<const IdData> records, bool outputs);

struct Fits {
  FitReport all;                ///< every output about its own mean, divided by its scale sy, stacked
  Eigen::VectorXd per_output;   ///< fit_percent of each output over all the records
};
/// Fits of the simulated outputs yhat (one N x ny matrix per record) against the records' outputs.
Fits fits_of(std::span<const IdData> records, std::span<const Eigen::MatrixXd> yhat, const Eigen::VectorXd& sy,
             int n_parameters);

// A model with one initial state per record, and an innovation gain K (nx x ny; empty for output error).
struct Point {
  Eigen::MatrixXd A, B, C, D;
  std::vector<Eigen::VectorXd> x0;
  Eigen::MatrixXd K;
};

// The parameter vector theta = [A | B | C | D | K (row-major; K when nk = ny) | x0 of each record].
struct Layout {
  int nx, nu, ny, E;
  int nk = 0;  ///< columns of K: ny for the prediction-error variant, 0 for output error
  Eigen::Index a(int i, int j) const { return i * nx + j; }
  Eigen::Index b(int i, int j) const { return nx * nx + i * nu + j; }
  Eigen::Index c(int i, int j) const { return nx * nx + nx * nu + i * nx + j; }
  Eigen::Index d(int i, int j) const { return nx * nx + nx * nu + ny * nx + i * nu + j; }
  Eigen::Index k(int i, int j) const { return nx * nx + nx * nu + ny * nx + ny * nu + i * nk + j; }
  Eigen::Index x0(int e, int i) const { return nx * nx + nx * nu + ny * nx + ny * nu + nx * nk + e * nx + i; }
  Eigen::Index size() const { return x0(E, 0); }
};

// Real modal form (see the header) of a model with distinct poles; the first `integrators` states keep their block
// (poles at 0) with k x k rows of C set to the identity. Returns false when the eigenvectors are too ill-conditioned
// (nearly repeated poles), leaving the model as it was.
struct ModalForm {
  Point model;
  std::vector<std::string> names;    // the parameters of A: pole<a>, sigma<a>, omega<a> (in state order)
  std::vector<std::tuple<int, int, double>> c_held;  // entries of C fixed by the normalisation (row, column, value)
};

Eigen::VectorXd pack(const Layout& L, const Point& m);
Point unpack(const Layout& L, const Eigen::VectorXd& v);
/// Data-driven local coordinates (McKelvey et al. 2004 eq. 10): an orthonormal basis (columns, in pack's layout) of
/// the free entries orthogonal to the change-of-basis tangent that keeps the held entries, plus each free x0 entry;
/// `similar` receives the dimension of the tangent removed.
Eigen::MatrixXd local_directions(const Layout& L, const Point& m, const std::vector<bool>& held, int* similar = nullptr);
std::vector<Point> directions_of(const Layout& L, const Eigen::MatrixXd& Q);
/// A change of state coordinates x = T z applied to a model.
Point transformed(const Point& m, const Eigen::MatrixXd& T);
/// Input and output scaling of a model: u = su .* u_s, y = sy .* y_s (unscaled: the inverse).
Point scaled(const Point& m, const Eigen::VectorXd& su, const Eigen::VectorXd& sy);
Point unscaled(const Point& m, const Eigen::VectorXd& su, const Eigen::VectorXd& sy);
bool modal_form(const Point& m, int integrators, ModalForm& out);
/// Every pole in the open left half plane, apart from the k held integrators.
bool stable(const Eigen::MatrixXd& A, int k);
/// "A1_2": the name of entry (i, j) of matrix M (1-based).
std::string entry_name(char M, int i, int j);

/// The result's model and parameters at `fin` (user units; fin becomes the model returned, its x0 transformed too): without user coordinates the real modal form (parameters
/// pole<a> or sigma<a>/omega<a>, B, C with each mode's normalising entries held, D when estimated, K when L.nk; a warning and
/// the search's coordinates when the poles are nearly repeated); with user coordinates the entries of A, B, C (and D),
/// `held` marking the held ones.
void describe(Result<StateSpace>& res, Point& fin, const Layout& L, const std::vector<bool>& held, bool user_coordinates,
              int integrators, bool estimate_d);
/// The leading np x np block of JtJ^-1 (computed with the columns scaled to unit diagonal); empty when JtJ is singular
/// to 1e-13 relative.
Eigen::MatrixXd inverse_normal(const Eigen::MatrixXd& JtJ, Eigen::Index np);

/// A and C's shift invariance: the least-squares A_d with O_up A_d = O_down (O has block rows of ny rows).
Eigen::MatrixXd shift_invariance(const Eigen::MatrixXd& O, int ny);
/// A with every eigenvalue re + j im of re > 0 moved to -re + j im (same eigenvectors).
Eigen::MatrixXd reflected_into_left_half_plane(const Eigen::MatrixXd& A);

/// One search of ssest (time and frequency data) at fixed weights: rounds of at most 5 Levenberg-Marquardt
/// iterations, each in the local coordinates at the round's start (theta first moved to better-conditioned state
/// coordinates by `recentre`, Point -> Point), the damping carried from round to round (lmo.lambda0); a round ends
/// when a step lowers the cost by less than `tolerance` (the cost is in noise units). Steps that make a stable start
/// unstable are rejected when check_stability (the first `integrators` poles excepted). normal_for(Q) gives the
/// round's evaluate(point, cost, JtJ, Jtr) in the directions Q (columns in pack's layout; JtJ, Jtr null: the cost
/// alone). Ends when a round converges, is interrupted, cannot evaluate (failed: theta is where that round began)
/// or the budget `left` (decremented) is spent.
struct Rounds {
  Eigen::VectorXd theta;
  int iterations = 0;
  internal::LmResult last;
  bool converged = false, failed = false;
};
template <class Recentre, class NormalFor>
Rounds lm_rounds(const Layout& L, Eigen::VectorXd theta, const std::vector<bool>& held, bool check_stability,
                 int integrators, double tolerance, int& left, internal::LmOptions& lmo, Recentre&& recentre,
                 NormalFor&& normal_for) {
  Rounds r;
  double cost = INFINITY;  // at theta (a change of state coordinates does not change it)
  while (left > 0 && !r.converged) {
    theta = pack(L, recentre(unpack(L, theta)));
    const Eigen::MatrixXd Q = local_directions(L, unpack(L, theta), held);
    auto evaluate = normal_for(Q);
    auto normal = [&](const Eigen::VectorXd& xi, double& c, Eigen::MatrixXd* A, Eigen::VectorXd* g) {
      const Point m = unpack(L, theta + Q * xi);
      if (check_stability && !stable(m.A, integrators)) return false;  // a rejected step
      return evaluate(m, c, A, g);
    };
    lmo.max_iterations = std::min(left, 5);
    lmo.final_normal = false;  // the callers' covariance is computed at the final model in its own parameters
    if (!std::isfinite(cost) && !evaluate(unpack(L, theta), cost, nullptr, nullptr)) cost = INFINITY;
    if (std::isfinite(cost) && cost > 0) lmo.ftol = tolerance / cost;
    const internal::LmResult lm = internal::levenberg_marquardt(
        internal::LmNormalEvaluate(normal), Eigen::VectorXd::Zero(Q.cols()),
        Eigen::VectorXd::Constant(Q.cols(), -INFINITY), Eigen::VectorXd::Constant(Q.cols(), INFINITY), lmo);
    r.last = lm;
    if (!std::isfinite(lm.cost)) {
      r.failed = true;
      break;
    }
    theta += Q * lm.x;
    cost = lm.cost;
    lmo.lambda0 = std::clamp(lm.lambda, 1e-12, 1e-3);
    left -= std::max(lm.iterations, 1);
    r.iterations += lm.iterations;
    r.converged = lm.converged || lm.interrupted;
    if (lm.interrupted) break;
  }
  r.theta = theta;
  return r;
}

/// The order search of ssest (time and frequency data): fit(n) for n = lo..hi and keep the least BIC among the usable
/// fits (all fits when none is usable), with diagnostics nx_grid and nx_grid_bic. An order the data cannot support
/// (fit throws InvalidArgument) ends the search; at lo it is rethrown. An interrupted fit ends the search too, and
/// the result is interrupted whatever order it keeps (the search did not see every order).
template <class Fit>
Result<StateSpace> order_search(int lo, int hi, Fit&& fit) {
  Eigen::VectorXd grid(hi - lo + 1), bic(hi - lo + 1);
  Result<StateSpace> best;
  bool best_usable = false;
  double best_bic = INFINITY;
  for (int n = lo; n <= hi; ++n) {
    Result<StateSpace> r;
    try {
      r = fit(n);
    } catch (const InvalidArgument&) {
      if (n == lo) throw;
      grid.conservativeResize(n - lo);
      bic.conservativeResize(n - lo);
      break;
    }
    grid(n - lo) = n;
    bic(n - lo) = r.fit.n_samples > 0 ? r.fit.bic : INFINITY;
    if (r.summary.termination == Termination::Interrupted) {
      const std::string why = r.summary.message;
      if (best.model.nx() == 0) best = std::move(r);
      best.summary.termination = Termination::Interrupted;
      best.summary.message = detail::format("the order search was interrupted while fitting nx = {} ({}); nx = {} is the "
                                            "best of the orders fitted before, not of {}..{}",
                                            n, why, best.model.nx(), lo, hi);
      grid.conservativeResize(n - lo + 1);
      bic.conservativeResize(n - lo + 1);
      break;
    }
    const bool usable = r.usable();
    if ((usable && !best_usable) || (usable == best_usable && bic(n - lo) < best_bic) || best.model.nx() == 0) {
      best_usable = usable;
      best_bic = bic(n - lo);
      best = std::move(r);
    }
  }
  best.diagnostics.set(diagnostic::nx_grid, grid);
  best.diagnostics.set(diagnostic::nx_grid_bic, bic);
  return best;
}

/// The modes' standard deviations (diagnostics mode_wn_std, mode_zeta_std, from the covariance) and a warning for
/// poles in the right half plane: the last step of every ssest result.
void report_modes(Result<StateSpace>& res);

}  // namespace ctid::ss_detail
