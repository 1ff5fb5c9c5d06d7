// ctid internal — adaptive Dormand-Prince 5(4) integration of x' = f(t, x, u) over a sample grid, the inputs
// held (ZOH) or interpolated linearly (FOH) between samples (Dormand & Prince 1980; Hairer, Norsett &
// Wanner, Solving ODEs I, II.4-5: FSAL, error estimate of the embedded 4th-order solution, step-size
// control h *= clamp(0.9 err^{-1/5}, 0.2, 5)). Every sample instant ends a step (a held input jumps there).
// A kink of f inside a sample interval (sign, abs, min, max of a grey-box model) is not stepped over blindly:
// the embedded error estimate of a step across it is large, so the step is rejected and shrunk until the kink
// is passed within the tolerance (step control rather than event location; Hairer, Norsett & Wanner II.6).
// Used by NdeModel::simulate, GreyboxModel::simulate and the sensitivity simulations of nde_oe and greybox.
#pragma once

#include <functional>

#include <Eigen/Dense>

namespace ctid::internal {

/// dx = f(t, x, u) for the input values u[0 .. nu-1] at the time t (the scale of the times given).
using OdeRhs = std::function<void(double t, const Eigen::VectorXd& x, const double* u, Eigen::VectorXd& dx)>;
/// Called with the sample index k and the state at t(k), for k = 0 .. N-1.
using OdeSample = std::function<void(Eigen::Index k, const Eigen::VectorXd& x)>;

struct OdeOutcome {
  bool ok = true;     ///< false: the solution escaped (|x| > 1e12, non-finite, or the step size collapsed)
  bool budget = false;  ///< false with ok false: it escaped; true: it needed more than max_steps steps (stiff)
  bool collapsed = false;  ///< the step size collapsed with the state finite (a discontinuity it cannot pass)
  double t = 0.0;     ///< where it escaped
  double xmax = 0.0;  ///< max |x| there
};

/// Integrates from x0 at t(0) through the increasing times t, the inputs u (N x nu, one row per time) held
/// (hold) or linear between samples, calling sample at each time. The error is
/// controlled on the first n_control components (the rest — e.g. sensitivities — ride along on the same
/// steps); rtol relative, atol absolute tolerance. At most max_steps accepted and rejected steps in all (0: 10^6 plus
/// 1000 per sample) — an explicit method on a stiff system stops there instead of creeping on.
OdeOutcome dopri45(const OdeRhs& f, const Eigen::VectorXd& x0, const Eigen::MatrixXd& u, const Eigen::VectorXd& t,
                   bool hold, double rtol, double atol, Eigen::Index n_control, const OdeSample& sample,
                   long max_steps = 0);

}  // namespace ctid::internal
