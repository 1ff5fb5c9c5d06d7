// Shared fixtures of the state-space tests (subspace, ssest): the two-mode MIMO system of issue 16, held random
// inputs, exactly simulated noisy records and a pole distance.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "ctid/data/iddata.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/simulate/lsim.hpp"

namespace ctid::test::ss {
// Two inputs, two outputs, two lightly damped modes: wn = 2 rad/s, zeta = 0.05 and wn = 5 rad/s, zeta = 0.2
// (the system of issue 16's Monte Carlo).
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
}  // namespace ctid::test::ss
