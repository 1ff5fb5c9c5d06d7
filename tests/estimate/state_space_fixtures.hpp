// Shared fixtures of the state-space tests (subspace, ssest): the two-mode MIMO system, held random
// inputs, exactly simulated noisy records, periodic multisine records and a pole distance.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "ctid/data/iddata.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/simulate/lsim.hpp"

namespace ctid::test::ss {
// Two inputs, two outputs, two lightly damped modes: wn = 2 rad/s, zeta = 0.05 and wn = 5 rad/s, zeta = 0.2
// (the system of the ssest Monte Carlo).
inline StateSpace two_modes() {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(4, 4);
  A.block(0, 0, 2, 2) << 0, 1, -4, -0.2;
  A.block(2, 2, 2, 2) << 0, 1, -25, -2;
  Eigen::MatrixXd B(4, 2), C(2, 4), D = Eigen::MatrixXd::Zero(2, 2);
  B << 0, 0, 1, 0.5, 0, 0, -0.4, 1;
  C << 4, 0.5, 10, 0, 1, -1, 20, 2;
  return StateSpace(A, B, C, D);
}

// Held random levels (each held for `hold` samples) at the times t.
inline Eigen::MatrixXd levels(int n, int nu, int hold, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> level(-1.0, 1.0);
  Eigen::MatrixXd u(n, nu);
  for (int i = 0; i < nu; ++i)
    for (int k = 0; k < n; ++k) u(k, i) = k % hold == 0 ? level(rng) : u(k - 1, i);
  return u;
}

// The record of m under u at times t from x0, with white noise of the given SNR (dB) per output (inf: none).
inline IdData record(const StateSpace& m, const Eigen::MatrixXd& u, const Eigen::VectorXd& t, const Eigen::VectorXd& x0,
              double snr_db, unsigned seed) {
  LsimOptions lo;
  lo.x0 = x0;
  Eigen::MatrixXd y = lsim(m, u, t, std::vector<Intersample>(static_cast<size_t>(u.cols()), Intersample::Zoh), lo);
  if (std::isfinite(snr_db)) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> e(0.0, 1.0);
    for (Eigen::Index j = 0; j < y.cols(); ++j) {
      const double s = std::sqrt((y.col(j).array() - y.col(j).mean()).square().mean() / std::pow(10.0, snr_db / 10));
      for (Eigen::Index k = 0; k < y.rows(); ++k) y(k, j) += s * e(rng);
    }
  }
  return IdData(u, y, t);
}

// The largest relative distance from each true pole to the nearest estimated one.
inline double pole_error(const StateSpace& truth, const StateSpace& est) {
  const Eigen::VectorXcd p = truth.poles(), q = est.poles();
  EXPECT_EQ(p.size(), q.size());
  double worst = 0.0;
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    double best = INFINITY;
    for (Eigen::Index j = 0; j < q.size(); ++j) best = std::min(best, std::abs(p(i) - q(j)) / std::abs(p(i)));
    worst = std::max(worst, best);
  }
  return worst;
}
// Samples of the steady-state response of m to the multisine u(t) = sum_l cos(w_l t + phi_l) (one input) plus a
// decaying transient C e^{At} x0, with white noise of standard deviation `noise` on every output.
inline IdData periodic_record(const StateSpace& m, int period, int periods, double ts, int input, unsigned seed, double noise) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> phase(0.0, 2 * std::numbers::pi);
  std::normal_distribution<double> e(0.0, 1.0);
  const int N = period * periods, nu = m.nu(), ny = m.ny();
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(N, nu), y = Eigen::MatrixXd::Zero(N, ny);
  const double w0 = 2 * std::numbers::pi / (period * ts);
  for (int l = 2; l <= 60; ++l) {  // lines 2..60 excited
    const double w = l * w0, ph = phase(rng);
    const Eigen::MatrixXcd G = frequency_response(m, Eigen::VectorXd::Constant(1, w)).front();
    for (int k = 0; k < N; ++k) {
      const double t = k * ts;
      u(k, input) += std::cos(w * t + ph);
      for (int i = 0; i < ny; ++i) y(k, i) += std::abs(G(i, input)) * std::cos(w * t + ph + std::arg(G(i, input)));
    }
  }
  Eigen::VectorXd x0 = Eigen::VectorXd::Ones(m.nx());
  const Eigen::MatrixXd A = m.A();
  for (int k = 0; k < N; ++k) {
    y.row(k) += (m.C() * expm(A * (k * ts)) * x0).transpose();
    for (int i = 0; i < ny; ++i) y(k, i) += noise * e(rng);
  }
  return IdData(u, y, ts);
}

}  // namespace ctid::test::ss
