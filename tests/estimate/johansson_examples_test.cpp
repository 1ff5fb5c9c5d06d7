// Johansson (1986) Examples 1 and 2 reproduced with stand-ins (docs/methods/johansson.md).
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "ctid/data/input_design.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/estimate/svf/rls_svf.hpp"
#include "ctid/simulate/lsim.hpp"

using namespace ctid;

namespace {
double sgn(double v) { return v >= 0 ? 1.0 : -1.0; }

// Example 1: y = b1/(p + a1) u, a1 = 2, b1 = 1; square wave +-1 with period 10 s (stand-in),
// simulated exactly on a fine grid dt; the filters run at dt, the regression every h.
struct Example1 {
  double dt;
  Eigen::VectorXd t, u, y;
  explicit Example1(double dt_) : dt(dt_) {
    const int N = static_cast<int>(std::lround(50 / dt)) + 1;
    t = time_grid(dt, N);
    u.resize(N);
    for (int k = 0; k < N; ++k) u(k) = std::fmod(t(k), 10.0) < 5.0 ? 1.0 : -1.0;
    y = lsim(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 2.0}}), u, t, Intersample::Zoh);
  }
  Eigen::VectorXd run(double h, double tau, double p0, double until = 1e9) const {
    RlsSvfOptions o;
    o.tau = tau;
    o.p0 = p0;
    o.regression_interval = h;
    RlsSvf rls(TfOrders{1, 1, 0}, o);
    for (Eigen::Index k = 0; k < t.size() && t(k) <= until + dt / 2; ++k) rls.update(t(k), u(k), y(k));
    return rls.parameters();
  }
};
}  // namespace

TEST(JohanssonExample1, RlsMatchesRecomputedValuesWithSmallPrior) {
  // Example 1 stand-in, P(0) = 100 I: (a1, b1) at t = 50 s from an independent recomputation, to 3 decimals —
  // regression values, not printed (the report shows these runs as Figures 2-7 only).
  // Tolerance 1.5e-3: half a unit of the last printed digit plus the O(dt^2) error of
  // filtering the sampled output (dt = 1 ms) instead of simulating the system and the filters jointly.
  const Example1 ex(0.001);
  struct Row { double h, tau, a1, b1; };
  const Row rows[] = {{0.03, 0.03, 2.005, 1.002}, {0.03, 0.3, 2.000, 1.000}, {0.03, 3.0, 1.997, 0.998},
                      {0.3, 0.03, 2.056, 1.023},  {0.3, 0.3, 2.002, 1.001},  {0.3, 3.0, 1.967, 0.985}};
  for (const Row& r : rows) {
    const Eigen::VectorXd p = ex.run(r.h, r.tau, 100.0);
    EXPECT_NEAR(p(0), r.a1, 1.5e-3) << "h=" << r.h << " tau=" << r.tau;
    EXPECT_NEAR(p(1), r.b1, 1.5e-3) << "h=" << r.h << " tau=" << r.tau;
  }
}

TEST(JohanssonExample1, LargePriorGivesExactValuesByTenSeconds) {
  // Example 1 stand-in: with P(0) = 1e8 all six cases give (2.000, 1.000) by t = 10 s.
  // The regression is exact; what remains is the O(dt^2) output-filtering error (measured
  // 1.1e-5 at dt = 1 ms for tau = 0.03): tolerance 3e-5.
  const Example1 ex(0.001);
  for (double h : {0.03, 0.3})
    for (double tau : {0.03, 0.3, 3.0}) {
      const Eigen::VectorXd p = ex.run(h, tau, 1e8, 10.0);
      EXPECT_NEAR(p(0), 2.0, 3e-5) << "h=" << h << " tau=" << tau;
      EXPECT_NEAR(p(1), 1.0, 3e-5) << "h=" << h << " tau=" << tau;
    }
}

TEST(JohanssonExample1, NoiseBiasesLeastSquaresAndIvRemovesMostOfIt) {
  // Noise case (RJ Figs 8-9): white output noise of variance 0.1 at dt = 0.01 s, h = tau = 0.3.
  // Johansson shows a visible bias of least squares; the auxiliary-model IV variant removes
  // most of it. 30 seeds; measured means LS (1.88, 0.946), IV (2.007, 1.000).
  const Example1 ex(0.01);
  const int R = 30;
  double ls_a = 0, ls_b = 0, iv_a = 0, iv_b = 0;
  for (int seed = 1; seed <= R; ++seed) {
    const IdData d(ex.u, ex.y + white_noise(static_cast<int>(ex.y.size()), std::sqrt(0.1), seed), ex.dt);
    LssvfOptions lo;
    lo.tau = 0.3;
    const auto ls = lssvf(d, {1, 1, 0}, lo);
    IvsvfOptions io;
    io.svf.tau = 0.3;
    const auto iv = ivsvf(d, {1, 1, 0}, io);
    ASSERT_TRUE(iv.usable()) << iv.why_not_usable();
    ls_a += ls.parameters.value("a1") / R;
    ls_b += ls.parameters.value("b0") / R;
    iv_a += iv.parameters.value("a1") / R;
    iv_b += iv.parameters.value("b0") / R;
  }
  // LS bias: the 30-run mean is far outside its Monte Carlo error (~0.005).
  EXPECT_LT(ls_a, 1.92);
  EXPECT_LT(ls_b, 0.97);
  // IV: mean within 0.03 of the truth and at least 3x less bias than LS.
  EXPECT_NEAR(iv_a, 2.0, 0.03);
  EXPECT_NEAR(iv_b, 1.0, 0.02);
  EXPECT_LT(std::abs(iv_a - 2.0), std::abs(ls_a - 2.0) / 3);
}

namespace {
// Example 2 stand-in (docs/methods/johansson.md): m = k = 1, tau = 0.5, h = 0.05, a1(t) = 1 + 0.5 sign(sin(2 pi t/60)).
struct Example2 {
  static constexpr double tau = 0.5, h = 0.05, dt = 0.005, T = 150;
  Discretization lo, hi, ref;
  Example2() {
    auto plant = [](double a1) {
      return discretize(Eigen::MatrixXd{{0, 1}, {-1, -a1}}, Eigen::MatrixXd{{0}, {1}}, dt);
    };
    lo = plant(0.5);
    hi = plant(1.5);
    // Reference model w0^2/(s^2 + 2 zeta w0 s + w0^2), zeta = 0.8, w0 = 0.7 (RJ Example 2).
    ref = discretize(Eigen::MatrixXd{{0, 1}, {-0.49, -1.12}}, Eigen::MatrixXd{{0}, {0.49}}, dt);
  }
  static double a1(double t) { return 1 + 0.5 * sgn(std::sin(2 * std::numbers::pi * t / 60)); }
  CoefficientTracker tracker() const {
    CoefficientTrackerOptions o;
    o.tau = tau;
    o.threshold = 0.1;
    o.regression_interval = h;
    return CoefficientTracker(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 1.0, 1.0}}), "a1", o);
  }
};
}  // namespace

TEST(JohanssonExample2, TracksTimeVaryingDamping) {
  // Exploratory input sign(sin(2 pi t/7)) + 0.5 sign(sin(2 pi t/3.1)); after each switch of a1
  // the tracker (RJ 78-79 with the corrected sign) returns to the true value: measured max
  // error 1.1e-3 from 5 s after a switch on. Tolerance 3e-3.
  const Example2 ex;
  CoefficientTracker tr = ex.tracker();
  Eigen::Vector2d x(0, 0);
  double max_err = 0;
  int updates = 0;
  const int N = static_cast<int>(Example2::T / Example2::dt);
  for (int k = 0; k <= N; ++k) {
    const double t = k * Example2::dt;
    const double f = sgn(std::sin(2 * std::numbers::pi * t / 7)) + 0.5 * sgn(std::sin(2 * std::numbers::pi * t / 3.1));
    tr.update(t, f, x(0));
    updates += tr.updated();
    if (std::fmod(t, 30.0) > 5.0) max_err = std::max(max_err, std::abs(tr.estimate() - Example2::a1(t)));
    const Discretization& d = Example2::a1(t) > 1 ? ex.hi : ex.lo;
    x = d.Phi * x + d.Gamma0.col(0) * f;
  }
  EXPECT_LT(max_err, 3e-3);
  EXPECT_GT(updates, 1000);  // the threshold rule lets most of the 3000 regression instants through
}

TEST(JohanssonExample2, AdaptiveControlReachesReferenceModel) {
  // f = m[w0^2 (r - x) - 2 zeta w0 v^] + d^ v^ + k x with v^ = [(1-z)x]/tau and d^ = m a1^
  // (docs/methods/johansson.md). Reference r = 2 sign(sin(2 pi t/20)). Relative RMS error between x and
  // the reference-model output after t = 30 s: measured 0.077 adaptive vs 0.31 with the
  // damping fixed at its nominal value 1. Bounds 0.1 and "less than half the fixed one".
  const Example2 ex;
  auto run = [&](bool adaptive) {
    CoefficientTracker tr = ex.tracker();
    Eigen::Vector2d x(0, 0), xr(0, 0);
    double se = 0, sr = 0;
    const int N = static_cast<int>(Example2::T / Example2::dt);
    for (int k = 0; k <= N; ++k) {
      const double t = k * Example2::dt;
      const double r = 2 * sgn(std::sin(2 * std::numbers::pi * t / 20));
      const double vhat = (x(0) - tr.filtered_output()[0]) / Example2::tau;
      const double dhat = adaptive ? tr.estimate() : 1.0;
      const double f = 0.49 * (r - x(0)) - 1.12 * vhat + dhat * vhat + x(0);
      tr.update(t, f, x(0));
      if (t > 30) {
        se += (x(0) - xr(0)) * (x(0) - xr(0));
        sr += xr(0) * xr(0);
      }
      const Discretization& d = Example2::a1(t) > 1 ? ex.hi : ex.lo;
      x = d.Phi * x + d.Gamma0.col(0) * f;
      xr = ex.ref.Phi * xr + ex.ref.Gamma0.col(0) * r;
    }
    return std::sqrt(se / sr);
  };
  const double adaptive = run(true), fixed = run(false);
  EXPECT_LT(adaptive, 0.1);
  EXPECT_LT(adaptive, 0.5 * fixed);
}
