// Johansson (1986) on-line: recursive LSSVF with forgetting (sampled, RJ 59-60) and its
// continuous-time counterpart with exponential weighting (RJ 56-57) on a first-order plant whose
// pole moves, and the single-coefficient tracker of a mass-spring-damper with time-varying
// damping (RJ Example 2 stand-in). Prints the estimates as they evolve.
#include <cmath>
#include <cstdio>
#include <numbers>

#include <ctid/ctid.hpp>

int main() {
  using namespace ctid;
  // 1. Recursive LSSVF: y = b/(p + a) u with a = 2 -> 4 at t = 20 s, b = 1.
  RlsSvf rls({.nb = 1, .nf = 1}, {.tau = 0.2, .forgetting = 0.998});
  // The same memory in continuous time: alpha = -ln(0.998) / (2 * 10 ms) = 0.1 /s.
  RlsSvf ct({.nb = 1, .nf = 1}, {.tau = 0.2, .alpha = 0.1, .recursion = RlsRecursion::Continuous});
  const Eigen::VectorXd u = prbs(6000, {.register_length = 9, .clock_period = 20});
  double x = 0;
  for (int k = 0; k < 6000; ++k) {
    const double t = 0.01 * k, a = t < 20 ? 2.0 : 4.0;
    rls.update(t, u(k), x);
    ct.update(t, u(k), x);
    x = std::exp(-a * 0.01) * x + (1 - std::exp(-a * 0.01)) / a * u(k);  // exact ZOH step
    if (k % 1000 == 999)
      std::printf("t = %4.1f s   a^ = %.4f  b^ = %.4f   continuous a^ = %.4f   (true a = %.0f)\n", t, rls.parameters()(0),
                  rls.parameters()(1), ct.parameters()(0), a);
  }
  // 2. Tracker: x'' + a1(t) x' + x = f with a1 switching between 1.5 and 0.5 every 30 s.
  CoefficientTracker tr(TransferFunction(Polynomial{1.0}, Polynomial{1.0, 1.0, 1.0}), "a1",
                        {.tau = 0.5, .threshold = 0.1, .regression_interval = 0.05});
  Eigen::Vector2d s(0, 0);
  const double dt = 0.005;
  double a1 = 0;
  for (int k = 0; k <= 24000; ++k) {
    const double t = k * dt;
    a1 = std::sin(2 * std::numbers::pi * t / 60) >= 0 ? 1.5 : 0.5;
    const double f = (std::sin(2 * std::numbers::pi * t / 7) >= 0 ? 1 : -1) + 0.5 * (std::sin(2 * std::numbers::pi * t / 3.1) >= 0 ? 1 : -1);
    tr.update(t, f, s(0));
    const Discretization d = discretize(Eigen::MatrixXd{{0, 1}, {-1, -a1}}, Eigen::MatrixXd{{0}, {1}}, dt);
    s = d.Phi * s + d.Gamma0.col(0) * f;
    if (k % 2000 == 1999) std::printf("t = %5.1f s   a1^ = %.4f   (true %.1f)\n", t, tr.estimate(), a1);
  }
  return std::abs(tr.estimate() - a1) < 1e-2 && std::abs(rls.parameters()(0) - 4.0) < 1e-2 &&
                 std::abs(ct.parameters()(0) - 4.0) < 1e-2
             ? 0
             : 1;
}
