// Johansson's filter bank and parameter transform (RJ 7-23; the
// M_tau/G_tau identities to 1e-12).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/signal/svf.hpp"
#include "ctid/simulate/lsim.hpp"

using namespace ctid;

TEST(SvfTransform, WorkedChecksFromSpec) {
  // n = 2, a = (3, 2), b = (1, 4), tau = 0.5 => alpha = (-0.5, 0), beta = (0.5, 0.5) (RJ 18-23).
  const Eigen::VectorXd th = theta_tau_from_ab(Eigen::VectorXd{{3.0, 2.0}}, Eigen::VectorXd{{1.0, 4.0}}, 0.5);
  EXPECT_NEAR(th(0), 0.5, 1e-15);  // -alpha_1
  EXPECT_NEAR(th(1), 0.0, 1e-15);  // -alpha_2
  EXPECT_NEAR(th(2), 0.5, 1e-15);
  EXPECT_NEAR(th(3), 0.5, 1e-15);
  const Eigen::MatrixXd M3 = svf_m_tau(3, 2.0);
  const Eigen::MatrixXd M3ref{{2.0, 0, 0}, {-4.0, 4.0, 0}, {2.0, -4.0, 8.0}};  // [[t,0,0],[-2t,t^2,0],[t,-t^2,t^3]]
  EXPECT_LT((M3 - M3ref).norm(), 1e-15);
  EXPECT_EQ(svf_g_tau(3), (Eigen::VectorXd{{3.0, -3.0, 1.0}}));
  EXPECT_EQ(svf_g_tau(1), (Eigen::VectorXd{{1.0}}));  // n = 1 requires g_1 = +1 (RJ 69)
}

TEST(SvfTransform, IdentitiesForOrdersOneToFour) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-3, 3);
  for (int n = 1; n <= 4; ++n)
    for (double tau : {0.03, 0.3, 1.0, 3.0}) {
      Eigen::VectorXd a(n), b(n);
      for (int i = 0; i < n; ++i) { a(i) = U(rng); b(i) = U(rng); }
      // Closed-form inverse of M_tau.
      EXPECT_LT((svf_m_tau(n, tau) * svf_m_tau_inverse(n, tau) - Eigen::MatrixXd::Identity(n, n)).norm(), 1e-12);
      Eigen::VectorXd a2, b2;
      ab_from_theta_tau(theta_tau_from_ab(a, b, tau), tau, a2, b2);
      // Round trip: theta_tau holds a_k tau^k next to binomials up to 2^n, so a_k comes back
      // with an absolute error of about eps 2^n tau^{-k}; tolerance 50x that bound (or 1e-12).
      for (int k = 1; k <= n; ++k) {
        const double tol = std::max(1e-12, 50 * 2.2e-16 * std::pow(2.0, n) * std::pow(tau, -k)) * (1 + a.cwiseAbs().maxCoeff());
        EXPECT_NEAR(a(k - 1), a2(k - 1), tol) << n << " " << tau << " " << k;
        EXPECT_NEAR(b(k - 1), b2(k - 1), tol);
      }
      // Coefficient identity (RJ 18-20): A*(z) = sum_k a_k tau^k z^k (1-z)^{n-k}, B*(z) likewise,
      // expanded independently here in ascending powers of z.
      const Eigen::VectorXd th = theta_tau_from_ab(a, b, tau);
      Eigen::VectorXd Astar = Eigen::VectorXd::Zero(n + 1), Bstar = Eigen::VectorXd::Zero(n + 1);
      for (int k = 0; k <= n; ++k) {
        const double ak = k == 0 ? 1.0 : a(k - 1);
        const double bk = k == 0 ? 0.0 : b(k - 1);
        for (int m = 0; m <= n - k; ++m) {  // (1-z)^{n-k} = sum_m C(n-k, m) (-z)^m
          double c = 1.0;
          for (int r = 1; r <= m; ++r) c = c * (n - k - m + r) / r;
          const double term = c * ((m % 2) ? -1.0 : 1.0) * std::pow(tau, k);
          Astar(k + m) += ak * term;
          Bstar(k + m) += bk * term;
        }
      }
      const double scale = std::max(1.0, std::max(Astar.cwiseAbs().maxCoeff(), Bstar.cwiseAbs().maxCoeff()));
      EXPECT_NEAR(Astar(0), 1.0, 1e-12 * scale);
      for (int i = 1; i <= n; ++i) {
        EXPECT_NEAR(-th(i - 1), Astar(i), 1e-12 * scale) << n << " " << tau;  // theta_tau holds -alpha_i
        EXPECT_NEAR(th(n + i - 1), Bstar(i), 1e-12 * scale);
      }
    }
}

TEST(SvfFilterBank, ClosedFormMatchesMatrixExponential) {
  // Chain A = (1/tau)(-I + subdiag), B = e1/tau discretised by expm (lsim's path).
  for (int n : {1, 2, 4, 6})
    for (double x : {1e-4, 0.05, 1.0, 7.0, 45.0}) {
      const double tau = 0.7, h = x * tau;
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
      for (int k = 0; k < n; ++k) {
        A(k, k) = -1 / tau;
        if (k) A(k, k - 1) = 1 / tau;
      }
      Eigen::MatrixXd B = Eigen::MatrixXd::Zero(n, 1);
      B(0, 0) = 1 / tau;
      const Discretization d = discretize(A, B, h);
      SvfFilterBank bank(n, tau, {Intersample::Foh});
      // From rest with s going 1 -> 3 over h: x = Gamma0 * 1 + Gamma1 * 2.
      const double s0 = 1.0, s1 = 3.0;
      bank.step(h, &s0, &s1);
      const Eigen::VectorXd ref = d.Gamma0.col(0) * s0 + d.Gamma1.col(0) * (s1 - s0);
      for (int k = 0; k < n; ++k) EXPECT_NEAR(bank.chain(0)[k], ref(k), 1e-13 * std::max(1.0, std::abs(ref(k)))) << n << " " << x;
      // A second step exercises Phi.
      const double s2 = -2.0;
      bank.step(h, &s1, &s2);
      const Eigen::VectorXd ref2 = d.Phi * ref + d.Gamma0.col(0) * s1 + d.Gamma1.col(0) * (s2 - s1);
      for (int k = 0; k < n; ++k) EXPECT_NEAR(bank.chain(0)[k], ref2(k), 1e-13 * std::max(1.0, std::abs(ref2(k))));
    }
}

TEST(SvfFilterBank, ExtraFilterEqualsCascadeSimulation) {
  // With an extra filter F, [z^k F s] equals simulating F(s)/(1+tau s)^k exactly.
  const TransferFunction F(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 2.0}});
  const double tau = 0.4, h = 0.05;
  const int N = 200, n = 3;
  const Eigen::VectorXd t = time_grid(h, N);
  const Eigen::VectorXd s = (1.3 * t.array()).sin();
  IdData d(s, s, h);
  d.set_intersample(Intersample::Foh);
  const Eigen::MatrixXd phi = svf_filter(d, n, tau, 0, -1, F);
  for (int k = 1; k <= n; ++k) {
    Polynomial den{1.0};
    for (int i = 0; i < k; ++i) den = den * Polynomial{tau, 1.0};
    const TransferFunction cascade(F.num(), F.den() * den);
    const Eigen::VectorXd ref = lsim(cascade, s, t, Intersample::Foh);
    EXPECT_LT((phi.col(k - 1) - ref).cwiseAbs().maxCoeff(), 1e-12) << k;
  }
}

TEST(SvfTransform, BadArguments) {
  EXPECT_THROW(svf_m_tau(0, 1.0), InvalidArgument);
  EXPECT_THROW(svf_m_tau(2, 0.0), InvalidArgument);
  EXPECT_THROW(svf_m_tau(2, -1.0), InvalidArgument);
  EXPECT_THROW(SvfFilterBank(2, -0.1, {Intersample::Zoh}), InvalidArgument);
}
