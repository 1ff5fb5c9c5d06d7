// Exact simulation against closed-form responses (issue: "to 1e-10").
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/simulate/lsim.hpp"
#include "estimate/state_space_fixtures.hpp"
#include "test_util.hpp"

using namespace ctid;

namespace {
const TransferFunction kFirst(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 0.5}});              // 2/(s + 0.5)
const TransferFunction kSecond(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}});    // (s+3)/(s^2+1.2s+4)
// Resonant fourth order: (s^2 + 0.1 s + 1)(s^2 + 0.4 s + 25) with a zero at -2.
const TransferFunction kFourth(Polynomial{25.0, 50.0},
                               Polynomial{1.0, 0.1, 1.0} * Polynomial{1.0, 0.4, 25.0});
}  // namespace

TEST(Lsim, StepFirstOrderClosedForm) {
  const Eigen::VectorXd t = time_grid(0.05, 400);
  const Eigen::VectorXd y = step_response(kFirst, t);
  for (Eigen::Index k = 0; k < t.size(); ++k) EXPECT_NEAR(y(k), 4.0 * (1 - std::exp(-0.5 * t(k))), 1e-10);
}

TEST(Lsim, StepSecondAndResonantFourthOrderClosedForm) {
  for (const auto* g : {&kSecond, &kFourth}) {
    const Eigen::VectorXd t = time_grid(0.01, 3000);
    const Eigen::VectorXd y = step_response(*g, t);
    for (Eigen::Index k = 0; k < t.size(); k += 7) EXPECT_NEAR(y(k), test::step_by_residues(*g, t(k)), 1e-10) << k;
  }
}

TEST(Lsim, FohRampIsExact) {
  // u(t) = t, linear between samples: y = t - 1 + e^{-t} for 1/(s+1).
  const TransferFunction g(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 1.0}});
  const Eigen::VectorXd t = time_grid(0.3, 50);
  const Eigen::VectorXd y = lsim(g, t, t, Intersample::Foh);
  for (Eigen::Index k = 0; k < t.size(); ++k) EXPECT_NEAR(y(k), t(k) - 1 + std::exp(-t(k)), 1e-12);
}

TEST(Lsim, ZohPiecewiseConstantWithNonIntegerDelay) {
  TransferFunction g = kSecond;
  g.set_io_delay(0.537);  // 5.37 samples
  const double h = 0.1;
  const Eigen::VectorXd t = time_grid(h, 300);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd u(t.size());
  for (auto& v : u) v = U(rng);
  const Eigen::VectorXd y = lsim(g, u, t, Intersample::Zoh);
  for (Eigen::Index k = 0; k < t.size(); ++k) EXPECT_NEAR(y(k), test::zoh_response(g, t, u, t(k)), 1e-10) << k;
}

TEST(Lsim, IrregularTimesZoh) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> dt(0.01, 0.1), U(-1, 1);
  Eigen::VectorXd t(500), u(500);
  t(0) = 0;
  for (Eigen::Index k = 1; k < t.size(); ++k) t(k) = t(k - 1) + dt(rng);
  for (auto& v : u) v = U(rng);
  for (double delay : {0.0, 0.123}) {
    TransferFunction g = kFourth;
    g.set_io_delay(delay);
    const Eigen::VectorXd y = lsim(g, u, t, Intersample::Zoh);
    for (Eigen::Index k = 0; k < t.size(); k += 3) EXPECT_NEAR(y(k), test::zoh_response(g, t, u, t(k)), 1e-10) << k;
  }
}

TEST(Lsim, InitialStateFreeResponse) {
  // dx/dt = -2 x, x(0) = 3 -> y = 3 e^{-2t}
  const StateSpace ss(Eigen::MatrixXd{{-2.0}}, Eigen::MatrixXd{{1.0}}, Eigen::MatrixXd{{1.0}}, Eigen::MatrixXd{{0.0}});
  LsimOptions o;
  o.x0 = Eigen::VectorXd{{3.0}};
  const Eigen::VectorXd t = time_grid(0.1, 20);
  const Eigen::MatrixXd y = lsim(ss, Eigen::MatrixXd::Zero(20, 1), t, {Intersample::Zoh}, o);
  for (int k = 0; k < 20; ++k) EXPECT_NEAR(y(k, 0), 3 * std::exp(-2 * t(k)), 1e-13);
}

TEST(Lsim, ImpulseResponseFirstOrderWithDelay) {
  TransferFunction g = kFirst;
  g.set_io_delay(0.25);
  const Eigen::VectorXd t = time_grid(0.1, 50);
  const Eigen::VectorXd h = impulse_response(g, t);
  for (Eigen::Index k = 0; k < t.size(); ++k)
    EXPECT_NEAR(h(k), t(k) < 0.25 ? 0.0 : 2.0 * std::exp(-0.5 * (t(k) - 0.25)), 1e-12);
}

TEST(Lsim, BadInputsAreReported) {
  const Eigen::VectorXd t = time_grid(0.1, 10);
  EXPECT_THROW(lsim(kFirst, Eigen::VectorXd::Ones(9), t), InvalidArgument);
  Eigen::VectorXd tb = t;
  tb(5) = tb(4);
  EXPECT_THROW(lsim(kFirst, Eigen::VectorXd::Ones(10), tb), InvalidArgument);
  EXPECT_THROW(discretize(Eigen::MatrixXd{{-1.0}}, Eigen::MatrixXd{{1.0}}, 0.0), InvalidArgument);
}

TEST(Lsim, ASamplingPeriodIsItsTimeGrid) {
  // lsim_into(tf, u, ts, ...) simulates at t_k = k ts without sample times to read: the same arithmetic as
  // time_grid(ts, N) (which the check finds uniform with the same ts), so the same numbers bit for bit - dense path
  // (order 2), modal path (order 4), a delay of 0.37 samples' worth, ZOH and FOH.
  std::mt19937_64 rng(8);
  std::normal_distribution<double> g;
  const int N = 3001;
  Eigen::VectorXd u(N);
  for (int k = 0; k < N; ++k) u(k) = g(rng);
  const Eigen::VectorXd t = time_grid(0.01, N);
  TransferFunction delayed = kSecond;
  delayed.set_io_delay(0.0037);
  for (const TransferFunction& tf : {kSecond, kFourth, delayed})
    for (Intersample is : {Intersample::Zoh, Intersample::Foh}) {
      Eigen::VectorXd y(N);
      lsim_into(tf, u, 0.01, is, y);
      EXPECT_EQ(y, lsim(tf, u, t, is)) << tf.to_string(4);
    }
  Eigen::VectorXd y(N);
  for (double ts : {0.0, -0.01, std::nan("")})
    EXPECT_THROW(
        {
          try {
            lsim_into(kSecond, u, ts, Intersample::Zoh, y);
          } catch (const InvalidArgument& e) {
            EXPECT_NE(std::string(e.what()).find("sampling period must be positive and finite"), std::string::npos);
            throw;
          }
        },
        InvalidArgument);
}

TEST(Lsim, GeneratedInputIsSimulatedExactly) {
  // 1/(s + 2) driven by sin 3t from rest: y = (3 e^{-2t} + 2 sin 3t - 3 cos 3t)/13 (closed form).
  const StateSpace ss = TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 2.0}}).to_state_space();
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(301, 0.0, 6.0);
  const Eigen::VectorXd y = lsim(ss, InputGenerator::sinusoid(3.0, 1.0), t);
  for (Eigen::Index i = 0; i < t.size(); ++i)
    EXPECT_NEAR(y(i), (3 * std::exp(-2 * t(i)) + 2 * std::sin(3 * t(i)) - 3 * std::cos(3 * t(i))) / 13, 1e-12);
  // Irregular times and an initial state: x(0) = 1 adds e^{-2t}.
  const Eigen::VectorXd ti{{0.0, 0.1, 0.35, 1.2, 2.0}};
  const Eigen::VectorXd yi = lsim(ss, InputGenerator::constant(0.0), ti, Eigen::VectorXd::Ones(1));
  for (Eigen::Index i = 0; i < ti.size(); ++i)
    EXPECT_NEAR(yi(i), std::exp(-2 * ti(i)) * (ss.C() * Eigen::VectorXd::Ones(1))(0), 1e-12);
  EXPECT_THROW(lsim(ss, InputGenerator::constant(1.0), Eigen::Vector2d(1.0, 0.5)), InvalidArgument);
}

// MIMO responses of the two-mode 2x2 system: the step response equals the exact simulation of a step input
// (lsim, ZOH), tends to the DC gain -C A^-1 B + D, the impulse response equals each channel's transfer function's,
// and the frequency-response matrix equals StateSpace::frequency_response channel by channel.
TEST(Lsim, ModalStepOfOrdersFourToEightEqualsTheDenseStep) {
  // Stable single-input models of order 4-8 on uniform samples take lsim's modal path (2 x 2 blocks, one sample per
  // step); the same model with a second, zero input takes the dense path (one n x n step per sample). Both are exact
  // discretisations, so they agree to rounding: 1e-10 of the output's range (ZOH and FOH, even and odd N).
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  for (int order : {4, 5, 7, 8}) {
    Polynomial den{1.0};
    for (int i = 0; i < order / 2; ++i) den = den * Polynomial{1.0, 0.2 + 0.3 * i, 4.0 + 9.0 * i};  // resonant pairs
    if (order % 2) den = den * Polynomial{1.0, 1.5};
    const TransferFunction tf(Polynomial{0.5, 2.0, den.coefficients()(order)}, den);
    const StateSpace ss = tf.to_state_space();
    const StateSpace two(ss.A(), (Eigen::MatrixXd(order, 2) << ss.B(), Eigen::VectorXd::Zero(order)).finished(), ss.C(),
                         (Eigen::MatrixXd(1, 2) << ss.D(), 0.0).finished());
    for (Eigen::Index N : {2001, 2000}) {
      Eigen::MatrixXd u(N, 1), u2 = Eigen::MatrixXd::Zero(N, 2);
      for (Eigen::Index k = 0; k < N; ++k) u(k, 0) = u2(k, 0) = g(rng);
      const Eigen::VectorXd t = time_grid(0.01, static_cast<int>(N));
      for (Intersample is : {Intersample::Zoh, Intersample::Foh}) {
        const Eigen::MatrixXd modal = lsim(ss, u, t, {is});
        const Eigen::MatrixXd dense = lsim(two, u2, t, {is, is});
        const double range = dense.maxCoeff() - dense.minCoeff();
        EXPECT_LT((modal - dense).cwiseAbs().maxCoeff(), 1e-10 * range) << "order " << order << ", N " << N;
      }
    }
  }
}

TEST(Lsim, MimoStepImpulseAndFrequencyResponseMatrices) {
  const StateSpace m = ctid::test::ss::two_modes();
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(401, 0.0, 40.0);
  const std::vector<Eigen::MatrixXd> step = step_response(m, t), imp = impulse_response(m, t);
  ASSERT_EQ(step.size(), 2u);
  const Eigen::MatrixXd dc = -m.C() * m.A().partialPivLu().solve(m.B()) + m.D();
  for (int i = 0; i < 2; ++i) {
    Eigen::MatrixXd u = Eigen::MatrixXd::Zero(t.size(), 2);
    u.col(i).setOnes();
    const Eigen::MatrixXd y = lsim(m, u, t, {Intersample::Zoh, Intersample::Zoh});
    EXPECT_LT((step[static_cast<size_t>(i)] - y).cwiseAbs().maxCoeff(), 1e-10) << "input " << i;
    // After 40 s the slow mode (decay 0.1 1/s) is down to e^-4: the step is within 5 % of the DC gain.
    for (int j = 0; j < 2; ++j) {
      EXPECT_NEAR(step[static_cast<size_t>(i)](400, j), dc(j, i), 0.05 * dc.cwiseAbs().maxCoeff());
      const Eigen::VectorXd g = impulse_response(m.to_transfer_function(j, i), t);
      EXPECT_LT((imp[static_cast<size_t>(i)].col(j) - g).cwiseAbs().maxCoeff(), 1e-9) << j << i;
    }
  }
  const Eigen::VectorXd w = Eigen::VectorXd::LinSpaced(4, 0.5, 6.0);
  const std::vector<Eigen::MatrixXcd> G = frequency_response(m, w);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const Eigen::VectorXcd g = m.frequency_response(w, j, i);
      for (Eigen::Index k = 0; k < w.size(); ++k) EXPECT_LT(std::abs(G[static_cast<size_t>(k)](j, i) - g(k)), 1e-12);
    }
  EXPECT_THROW(step_response(m, (Eigen::VectorXd(2) << 1.0, 0.5).finished()), InvalidArgument);
}
