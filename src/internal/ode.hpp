// ctid internal — adaptive Dormand-Prince 5(4) integration of x' = f(x, u) over a sample grid, the input
// held (ZOH) or interpolated linearly (FOH) between samples (Dormand & Prince 1980; Hairer, Norsett &
// Wanner, Solving ODEs I, II.4-5: FSAL, error estimate of the embedded 4th-order solution, step-size
// control h *= clamp(0.9 err^{-1/5}, 0.2, 5)). Used by NdeModel::simulate and the sensitivity
// simulations of nde_oe.
#pragma once

#include <functional>

#include <Eigen/Dense>

namespace ctid::internal {

/// dx = f(x, u) for the input value u at that instant.
using OdeRhs = std::function<void(const Eigen::VectorXd& x, double u, Eigen::VectorXd& dx)>;
/// Called with the sample index k and the state at t(k), for k = 0 .. N-1.
using OdeSample = std::function<void(Eigen::Index k, const Eigen::VectorXd& x)>;

struct OdeOutcome {
  bool ok = true;     ///< false: the solution escaped (|x| > 1e12, non-finite, or the step size collapsed)
  double t = 0.0;     ///< where it escaped
  double xmax = 0.0;  ///< max |x| there
};

/// Integrates from x0 at t(0) through the increasing times t, calling sample at each of them. The error is
/// controlled on the first n_control components (the rest — e.g. sensitivities — ride along on the same
/// steps); rtol relative, atol absolute tolerance.
OdeOutcome dopri45(const OdeRhs& f, const Eigen::VectorXd& x0, const Eigen::VectorXd& u, const Eigen::VectorXd& t,
                   bool hold, double rtol, double atol, Eigen::Index n_control, const OdeSample& sample);

}  // namespace ctid::internal
