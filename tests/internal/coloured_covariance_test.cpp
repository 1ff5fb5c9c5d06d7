// The coloured-noise covariance kernel (src/internal/coloured_covariance.hpp) against independent references: the AR
// fit against the process that generated the data, the filtered Gram matrix against the explicit matrix product with
// the inverse of the AR model's convolution matrix, and the white case against sigma^2 (J^T J)^-1.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "internal/coloured_covariance.hpp"
#include "internal/least_squares.hpp"

namespace {
using namespace ctid::internal;

// The lower-triangular convolution matrix of A(q) = 1 + a_1 q^-1 + .. over n samples.
Eigen::MatrixXd convolution(const Eigen::VectorXd& a, int n) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < n; ++i)
    for (int k = 1; k <= a.size() && i - k >= 0; ++k) A(i, i - k) = a(k - 1);
  return A;
}

Eigen::MatrixXd random_matrix(int rows, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = n01(rng);
  return m;
}
}  // namespace

TEST(ResidualAutocovariance, FitsTheGeneratingArProcess) {
  // v_t = 1.2 v_{t-1} - 0.5 v_{t-2} + w_t, unit innovations, 20000 samples: A(q) = 1 - 1.2 q^-1 + 0.5 q^-2. AIC finds
  // order 2 or a little more (measured 3: -1.190, 0.486, a small third); the coefficients within 0.02 (their standard
  // error is about 0.006), the innovation variance within 3 % (measured 1.0065).
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  ResidualAutocovariance acov(40);
  double v1 = 0, v2 = 0;
  for (int t = 0; t < 20000; ++t) {
    const double v = 1.2 * v1 - 0.5 * v2 + n01(rng);
    v2 = v1;
    v1 = v;
    acov.add(v);
  }
  const ResidualAr ar = acov.fit(0);
  ASSERT_GE(ar.order(), 2);
  EXPECT_LE(ar.order(), 4);
  EXPECT_NEAR(ar.a(0), -1.2, 0.02);
  EXPECT_NEAR(ar.a(1), 0.5, 0.02);
  EXPECT_NEAR(ar.variance, 1.0, 0.03);
  // White data: order 0 and the variance RSS/(N - p) exactly.
  ResidualAutocovariance white(40);
  double ss = 0;
  for (int t = 0; t < 500; ++t) {
    const double w = n01(rng);
    ss += w * w;
    white.add(w);
  }
  const ResidualAr w0 = white.fit(3);
  if (w0.order() == 0) EXPECT_NEAR(w0.variance, ss / 497, 1e-12 * ss);
}

TEST(ColouredGram, EqualsTheFilteredJacobiansGramAndRestartsPerSequence) {
  // Two sequences (30 and 20 rows) of a 50 x 3 J, AR(2) a = (-0.9, 0.2), lambda = 0.7: the Gram of the rows filtered
  // by 1/A(q) from rest in each sequence is lambda sum_s (A_s^-1 J_s)^T (A_s^-1 J_s), to 1e-12.
  const Eigen::MatrixXd J = random_matrix(50, 3, 1);
  ResidualAr ar;
  ar.a = Eigen::Vector2d(-0.9, 0.2);
  ar.variance = 0.7;
  ColouredGram gram(ar, 3);
  Eigen::MatrixXd want = Eigen::MatrixXd::Zero(3, 3);
  for (const auto& [start, n] : {std::pair<int, int>{0, 30}, std::pair<int, int>{30, 20}}) {
    gram.start_sequence();
    for (int k = 0; k < n; ++k) gram.add(Eigen::RowVectorXd(J.row(start + k)));
    const Eigen::MatrixXd F = convolution(ar.a, n).triangularView<Eigen::Lower>().solve(J.middleRows(start, n));
    want += 0.7 * F.transpose() * F;
  }
  EXPECT_LT((gram.gram() - want).norm(), 1e-12 * want.norm());
}

TEST(ColouredCovariance, WhiteResidualsGiveSigmaSquaredTimesTheInverseGram) {
  // Order 0: H^-1 (sigma^2 H) H^-1 = sigma^2 H^-1, to 1e-12 (sandwich against internal::covariance).
  const Eigen::MatrixXd J = random_matrix(200, 4, 2);
  ResidualAr white;
  white.variance = 0.3;
  ColouredGram gram(white, 4);
  for (int k = 0; k < 200; ++k) gram.add(Eigen::RowVectorXd(J.row(k)));
  const Eigen::MatrixXd H = J.transpose() * J;
  const Eigen::MatrixXd want = covariance(H, 0.3);
  EXPECT_LT((sandwich(H, gram.gram()) - want).norm(), 1e-12 * want.norm());
  EXPECT_EQ(sandwich(Eigen::MatrixXd::Zero(2, 2), Eigen::MatrixXd::Identity(2, 2)).size(), 0);  // singular H
}

TEST(ColouredCovariance, MatchesTheStationaryNoiseCovarianceOnALongRecord) {
  // The exact covariance of J^T v for stationary AR(1) noise (pole 0.9, unit innovations) is J^T R J with the Toeplitz
  // R_ij = 0.9^|i-j| / (1 - 0.81). The forward-filtered Gram with the known AR model equals it up to edge terms: on
  // 2000 rows of a smooth J (sinusoids), within 2 % (measured 0.25 %).
  const int n = 2000;
  Eigen::MatrixXd J(n, 2);
  for (int k = 0; k < n; ++k) J.row(k) << std::sin(0.01 * k), std::cos(0.023 * k);
  ResidualAr ar;
  ar.a = Eigen::VectorXd::Constant(1, -0.9);
  ar.variance = 1.0;
  ColouredGram gram(ar, 2);
  for (int k = 0; k < n; ++k) gram.add(Eigen::RowVectorXd(J.row(k)));
  Eigen::MatrixXd R(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) R(i, j) = std::pow(0.9, std::abs(i - j)) / (1 - 0.81);
  const Eigen::MatrixXd want = J.transpose() * R * J;
  EXPECT_LT((gram.gram() - want).norm(), 0.02 * want.norm());
}
