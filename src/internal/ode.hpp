// ctid internal — adaptive Dormand-Prince 5(4) integration of x' = f(t, x, u) over a sample grid, the inputs
// held (ZOH) or interpolated linearly (FOH) between samples (Dormand & Prince 1980; Hairer, Norsett &
// Wanner, Solving ODEs I, II.4-5: FSAL, error estimate of the embedded 4th-order solution, step-size
// control h *= clamp(0.9 err^{-1/5}, 0.2, 5)). Every sample instant ends a step (a held input jumps there).
// A kink of f inside a sample interval (abs, min, max of a grey-box model) is not stepped over blindly: the embedded
// error estimate of a step across it is large, so the step is rejected and shrunk until the kink is passed within
// the tolerance (step control; Hairer, Norsett & Wanner II.6). Discontinuities that the caller tracks (sign() of a
// state function: model/greybox.cpp) are state events: the caller keeps f smooth between them, the integrator
// locates the first sign change of an event function inside an accepted step on the cubic Hermite interpolant of
// the step (Hairer, Norsett & Wanner II.6, dense output; Illinois root finding), repeats the step to end there and
// lets the caller switch (and jump the sensitivities) before going on.
// Used by NdeModel::simulate, GreyboxModel::simulate and the sensitivity simulations of nde_oe and greybox.
#pragma once

#include <functional>

#include <Eigen/Dense>

namespace ctid::internal {

/// How the inputs are read between samples (ctid::Intersample without the data layer).
enum class Between { Hold, Linear, BandLimited };

/// The inputs u (N x nu, one row per time t) between samples: held, linear, or band-limited — the
/// windowed-sinc interpolation of the samples (Lanczos kernel, 16 samples each side, weights normalised to sum 1;
/// Shannon reconstruction of a signal without content above the Nyquist frequency: a generator with a
/// reconstruction filter, e.g. the Silverbox's), which needs uniformly spaced times; the record is extended by
/// its end values. No allocation per call.
class InputReader {
 public:
  InputReader(const Eigen::MatrixXd& u, const Eigen::VectorXd& t, Between mode);
  /// The inputs at time tt of the interval [t(k), t(k + 1)] (nu values; at t(k) exactly u(k, .)).
  const double* at(Eigen::Index k, double tt);
  Between mode() const { return mode_; }

 private:
  static constexpr int kTaps = 16;
  const Eigen::MatrixXd& u_;
  const Eigen::VectorXd& t_;
  Between mode_;
  Eigen::VectorXd ui_;
  double w_[2 * kTaps];
};

/// dx = f(t, x, u) for the input values u[0 .. nu-1] at the time t (the scale of the times given).
using OdeRhs = std::function<void(double t, const Eigen::VectorXd& x, const double* u, Eigen::VectorXd& dx)>;
/// Called with the sample index k and the state at t(k), for k = 0 .. N-1.
using OdeSample = std::function<void(Eigen::Index k, const Eigen::VectorXd& x)>;

/// State events (optional): `count` functions g_i(t, x, u) of the controlled components x; event i fires where g_i
/// goes from > 0 to <= 0 inside a step, and at the start of a sample interval where g_i <= 0 already (an input that
/// jumps there). fire(i, t, x, u) may change the right-hand side from then on and the whole vector x (a jump);
/// false stops the integration (OdeOutcome::refused).
struct OdeEvents {
  int count = 0;
  std::function<void(double t, const double* x, const double* u, double* g)> values;
  std::function<bool(int i, double t, Eigen::VectorXd& x, const double* u)> fire;
};

struct OdeOutcome {
  bool ok = true;     ///< false: the solution escaped (|x| > 1e12, non-finite, or the step size collapsed)
  bool budget = false;  ///< false with ok false: it escaped; true: it needed more than max_steps steps (stiff)
  bool collapsed = false;  ///< the step size collapsed with the state finite (a discontinuity it cannot pass)
  double t = 0.0;     ///< where it escaped
  double xmax = 0.0;  ///< max |x| there
  bool chatter = false;  ///< with ok false: more than 1000 events in one sample interval
  bool refused = false;  ///< with ok false: an event handler stopped the integration
};

/// Integrates from x0 at t(0) through the increasing times t, the inputs u (N x nu, one row per time) read between
/// samples as `intersample` says (InputReader), calling sample at each time. The error is
/// controlled on the first n_control components (the rest — e.g. sensitivities — ride along on the same
/// steps); rtol relative, atol absolute tolerance. At most max_steps accepted and rejected steps in all (0: 10^6 plus
/// 1000 per sample) — an explicit method on a stiff system stops there instead of creeping on. `events`: state
/// events (above), or none.
OdeOutcome dopri45(const OdeRhs& f, const Eigen::VectorXd& x0, const Eigen::MatrixXd& u, const Eigen::VectorXd& t,
                   Between intersample, double rtol, double atol, Eigen::Index n_control, const OdeSample& sample,
                   long max_steps = 0, const OdeEvents* events = nullptr);

/// A system with its derivatives for the stiff integrator: dx = f(t, x, u) (n states); when J is given also the
/// Jacobian df/dx (n x n), when B is given the direct derivatives df/dq (n x q) of the q quantities whose
/// sensitivities S (n x q, dS/dt = J S + B) ride along.
using OdeJacobianRhs =
    std::function<void(double t, const double* x, const double* u, double* dx, Eigen::MatrixXd* J, Eigen::MatrixXd* B)>;

/// Stiff integration (internal/bdf.cpp): the variable-order (1-5) BDF of CVODES (SUNDIALS; Hindmarsh et al. 2005,
/// ACM TOMS 31(3) 363-396) with Newton iterations on the exact Jacobian, and the forward sensitivities by CVODES's
/// staggered corrector (Feehery, Tolsma & Barton 1997) kept out of the error test (as in dopri45). a0 = [x0; S0
/// column by column] (n (1 + q) entries); sample, events, inputs, tolerances and the outcome as for dopri45, the
/// vector passed to sample and fire being the same [x; S]. The method restarts (order 1) where a held input jumps
/// and after each event. max_steps: 0 for 10^6 plus 1000 per sample.
OdeOutcome bdf(const OdeJacobianRhs& f, Eigen::Index n, const Eigen::VectorXd& a0, const Eigen::MatrixXd& u,
               const Eigen::VectorXd& t, Between intersample, double rtol, double atol, const OdeSample& sample,
               long max_steps = 0, const OdeEvents* events = nullptr);

}  // namespace ctid::internal
