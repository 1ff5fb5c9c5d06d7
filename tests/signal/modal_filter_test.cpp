// Modal filters, annihilating prefilters (El-Shafey 1987 ES-C6, Example 3.7 as reconstructed in
// docs/methods/el-shafey.md), quadrature rules and Walsh functions (ES-C5).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/signal/modal_filter.hpp"
#include "ctid/signal/walsh.hpp"

using namespace ctid;

namespace {
constexpr double kPi = std::numbers::pi;
}

TEST(Quadrature, SimpsonIsExactForCubicsWithEvenAndOddIntervalCounts) {
  for (int K : {1, 2, 3, 4, 5, 7, 10}) {
    const double h = 0.3;
    const Eigen::VectorXd w = quadrature_weights(K, h);
    double s = 0;
    for (int i = 0; i <= K; ++i) {
      const double t = i * h;
      s += w(i) * (1 + 2 * t - 3 * t * t + 0.5 * t * t * t);
    }
    const double T = K * h, exact = T + T * T - T * T * T + 0.125 * T * T * T * T;
    if (K >= 2) EXPECT_NEAR(s, exact, 1e-12 * (1 + std::abs(exact))) << K << " intervals";
    // Every rule integrates constants and straight lines exactly.
    EXPECT_NEAR(w.sum(), T, 1e-14);
  }
  // Trapezoid: error h^2/12 (b - a) f'' for f = t^2 on [0, 1] with h = 0.1 -> 1/600.
  const Eigen::VectorXd w = quadrature_weights(10, 0.1, Quadrature::Trapezoid);
  double s = 0;
  for (int i = 0; i <= 10; ++i) s += w(i) * (0.1 * i) * (0.1 * i);
  EXPECT_NEAR(s - 1.0 / 3.0, 1.0 / 600.0, 1e-14);
  EXPECT_THROW(quadrature_weights(0, 0.1), InvalidArgument);
}

TEST(ModalFilter, ShiftsAreSampleMultiplesAndTheFilterIsAWeightedShiftedSum) {
  const Eigen::VectorXd y = Eigen::VectorXd::LinSpaced(10, 1.0, 10.0);
  const Eigen::VectorXd f = modal_filter(y, 0.5, Eigen::Vector2d(0.5, 1.5), Eigen::Vector2d(2.0, -1.0));
  // i = 5: y(5) + 2 y(4) - y(2) = 6 + 10 - 3; i = 0: y(0) only (rest before the record).
  EXPECT_DOUBLE_EQ(f(5), 13.0);
  EXPECT_DOUBLE_EQ(f(0), 1.0);
  EXPECT_DOUBLE_EQ(f(1), 2.0 + 2.0);
  EXPECT_THROW(modal_filter(y, 0.5, Eigen::Vector2d(0.5, 1.2), Eigen::Vector2d(1, 1)), InvalidArgument);  // 2.4 periods
  EXPECT_THROW(modal_filter(y, 0.5, Eigen::Vector2d(0.5, 1.0), Eigen::Vector3d(1, 1, 1)), InvalidArgument);
}

TEST(Annihilator, Example37ReconstructedValues) {
  // u = e^{-2t} + e^{-t} sin 5t + e^{-t} cos 5t (ES Ex. 3.7; ES 3.38-3.47).
  const InputGenerator real = InputGenerator::exponential(-2.0);
  const InputGenerator pair = InputGenerator::sinusoid(5.0, 1.0, 1.0, -1.0);
  const Eigen::VectorXd l1 = annihilator(real, Eigen::VectorXd::Constant(1, kPi / 10));
  EXPECT_NEAR(l1(0), -std::exp(-kPi / 5), 1e-14);
  const Eigen::VectorXd l2 = annihilator(pair, Eigen::Vector2d(kPi / 10, kPi / 5));
  EXPECT_NEAR(l2(0), 0.0, 1e-13);
  EXPECT_NEAR(l2(1), std::exp(-kPi / 5), 1e-13);
  // Applied to the sampled input (Ts = pi/200): L_1 u = e^{-t}[(1 - e^{-pi/10}) sin 5t + (1 + e^{-pi/10}) cos 5t],
  // L_2 u = (1 + e^{pi/5}) e^{-2t}, after the largest shift.
  const double Ts = kPi / 200;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(400, 0.0, 399 * Ts);
  const Eigen::VectorXd u = (real + pair)(t);
  const Eigen::VectorXd L1u = modal_filter(u, Ts, Eigen::VectorXd::Constant(1, kPi / 10), l1);
  const Eigen::VectorXd L2u = modal_filter(u, Ts, Eigen::Vector2d(kPi / 10, kPi / 5), l2);
  const double e = std::exp(-kPi / 10);
  for (int i = 40; i < 400; ++i) {
    EXPECT_NEAR(L1u(i), std::exp(-t(i)) * ((1 - e) * std::sin(5 * t(i)) + (1 + e) * std::cos(5 * t(i))), 1e-12);
    EXPECT_NEAR(L2u(i), (1 + std::exp(kPi / 5)) * std::exp(-2 * t(i)), 1e-12);
  }
}

TEST(Annihilator, OddHarmonicsOfAPeriodAreRemovedByTheHalfPeriodFilter) {
  // ES Ex. 3.8: shifts (T_o/4, T_o/2) give l = [0, 1] for every odd harmonic of period T_o.
  const double To = 2.0;
  for (int k : {1, 3, 5}) {
    const Eigen::VectorXd l = annihilator(InputGenerator::sinusoid(k * 2 * kPi / To, 1.0), Eigen::Vector2d(To / 4, To / 2));
    EXPECT_NEAR(l(0), 0.0, 1e-12) << "harmonic " << k;
    EXPECT_NEAR(l(1), 1.0, 1e-12) << "harmonic " << k;
  }
  // Even harmonics alias at these shifts: psi_c is singular.
  EXPECT_THROW(annihilator(InputGenerator::sinusoid(2 * 2 * kPi / To, 1.0), Eigen::Vector2d(To / 4, To / 2)),
               InvalidArgument);
}

TEST(Walsh, SequencyOrderedOrthogonalAndTheFastTransformEqualsTheMatrix) {
  const Eigen::MatrixXd W = walsh_matrix(16);
  EXPECT_LT((W * W.transpose() - 16 * Eigen::MatrixXd::Identity(16, 16)).cwiseAbs().maxCoeff(), 1e-12);
  for (int k = 0; k < 16; ++k) {
    int changes = 0;
    for (int j = 1; j < 16; ++j) changes += W(k, j) != W(k, j - 1);
    EXPECT_EQ(changes, k) << "row " << k;
  }
  const Eigen::MatrixXd X = Eigen::MatrixXd::Random(16, 3);
  EXPECT_LT((walsh_transform(X) - W * X).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_THROW(walsh_matrix(12), InvalidArgument);
  EXPECT_THROW(walsh_transform(Eigen::MatrixXd::Zero(6, 1)), InvalidArgument);
}
