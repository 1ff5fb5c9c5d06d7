// SRIVC, output error, tfest, CRLB and order selection on the set-ups of docs/accuracy.md
// (exactly simulated data; seeded noise).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/estimate/transfer_function/frequency.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/estimate/transfer_function/oe.hpp"
#include "ctid/estimate/transfer_function/order_selection.hpp"
#include "ctid/estimate/transfer_function/srivc.hpp"
#include "ctid/signal/prefilter.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/simulate/simulate.hpp"
#include "ctid/validate/crlb.hpp"
#include "test_util.hpp"

using namespace ctid;

namespace {
// Set-up 1: Rao & Garnier (2002) benchmark, PRBS register 10 held 7 samples (7161 samples), Ts = 0.01 s.
const TransferFunction kRao(Eigen::VectorXd{{-6400.0, 1600.0}}, Eigen::VectorXd{{1.0, 5.0, 408.0, 416.0, 1600.0}});
const Eigen::VectorXd kRaoTheta{{5.0, 408.0, 416.0, 1600.0, -6400.0, 1600.0}};

IdData rao_data(double snr_db, std::uint64_t seed) {
  const int N = 7161;
  const Eigen::VectorXd u = prbs(N, {.register_length = 10, .clock_period = 7});
  const Eigen::VectorXd x = lsim(kRao, u, time_grid(0.01, N));
  return IdData(u, std::isinf(snr_db) ? x : add_noise_snr(x, snr_db, seed), 0.01);
}

double max_rel(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).cwiseQuotient(b.cwiseAbs()).cwiseAbs().maxCoeff();
}
}  // namespace

TEST(Srivc, NoiseFreeRaoGarnierIsExact) {
  // Noise-free set-ups recover the true parameters to 1e-6 relative. The true
  // parameters are an exact fixed point of SRIVC (see srivc.hpp); measured 2.3e-10.
  const auto r = srivc(rao_data(INFINITY, 0), {2, 4, 0});
  ASSERT_EQ(r.summary.termination, Termination::Converged) << r.summary.message;
  EXPECT_LT(max_rel(r.parameters.values, kRaoTheta), 1e-6);
  const auto t = tfest(rao_data(INFINITY, 0), {2, 4, 0});
  EXPECT_LT(max_rel(t.parameters.values, kRaoTheta), 1e-6);
}

TEST(Srivc, NoiseFreeIrregularSamplingIsExact) {
  // Set-up 2 without noise: G = 5/(s^2 + 2.8 s + 4), intervals uniform in [0.01, 0.1] s,
  // N = 3000, u = sin 0.714t + sin 1.428t + sin 2.142t (linear between samples).
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> dt(0.01, 0.1);
  Eigen::VectorXd t(3000);
  t(0) = 0;
  for (int k = 1; k < 3000; ++k) t(k) = t(k - 1) + dt(rng);
  const Eigen::VectorXd u = multisine(t, {0.714, 1.428, 2.142}, {1, 1, 1}, {0, 0, 0});
  const TransferFunction g(Eigen::VectorXd{{5.0}}, Eigen::VectorXd{{1.0, 2.8, 4.0}});
  IdData d(u, lsim(g, u, t, Intersample::Foh), t);
  d.set_intersample(Intersample::Foh);
  const auto r = srivc(d, {1, 2, 0});
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  EXPECT_LT(max_rel(r.parameters.values, Eigen::VectorXd{{2.8, 4.0, 5.0}}), 1e-6);
}

TEST(Srivc, NoiseFreeStiffSystemIsExact) {
  // Set-up 4: G = 2(100 s + 1)/((200 s + 1)(10 s + 1)), PRBS register 7 held 10 samples, Ts = 2 s.
  const TransferFunction g(Polynomial{200.0, 2.0}, Polynomial{200.0, 1.0} * Polynomial{10.0, 1.0});
  const int N = 127 * 10 * 2;
  const Eigen::VectorXd u = prbs(N, {.register_length = 7, .clock_period = 10});
  const IdData d(u, lsim(g, u, time_grid(2.0, N)), 2.0);
  const auto r = srivc(d, {2, 2, 0});
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  // Monic form: (0.1 s + 0.001)/(s^2 + 0.105 s + 0.0005).
  const Eigen::VectorXd truth{{0.105, 0.0005, 0.1, 0.001}};
  EXPECT_LT(max_rel(r.parameters.values, truth), 1e-6) << r.model.to_string(10);
}

TEST(Srivc, NoiseFreeNonIntegerDelayIsFound) {
  // Set-up 3 without noise: G = 12 e^{-8.037 s}/(s^2 + 4 s + 4), PRBS register 8 held 20
  // samples, Ts = 0.1 s. The delay search + refinement lands on the delay to 1e-6 s.
  const TransferFunction g(Eigen::VectorXd{{12.0}}, Eigen::VectorXd{{1.0, 4.0, 4.0}}, 8.037);
  const int N = 255 * 20;
  const Eigen::VectorXd u = prbs(N, {.register_length = 8, .clock_period = 20});
  const IdData d(u, lsim(g, u, time_grid(0.1, N)), 0.1);
  OeOptions o;
  o.estimate_delay = true;
  o.srivc.delay_max = 15;
  const auto r = tfest(d, {1, 2, 0}, o);
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  EXPECT_NEAR(r.model.io_delay(), 8.037, 1e-6);
  EXPECT_LT(max_rel(r.parameters.values.head(3), Eigen::VectorXd{{4.0, 4.0, 12.0}}), 1e-6);
}

TEST(Srivc, DelayWithin50msAtFifteenDecibelsAlsoFromAPoorGuess) {
  // Set-up 3 at 15 dB (delay within 0.05 s in every run, also when the initial delay
  // guess is 1 s). Measured errors: SRIVC <= 0.021 s, tfest/oe <= 0.007 s over these seeds.
  const TransferFunction g(Eigen::VectorXd{{12.0}}, Eigen::VectorXd{{1.0, 4.0, 4.0}}, 8.037);
  const int N = 255 * 20;
  const Eigen::VectorXd u = prbs(N, {.register_length = 8, .clock_period = 20});
  const Eigen::VectorXd x = lsim(g, u, time_grid(0.1, N));
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const IdData d(u, add_noise_snr(x, 15.0, seed), 0.1);
    SrivcOptions so;
    so.estimate_delay = true;
    so.delay_max = 15;
    EXPECT_NEAR(srivc(d, {1, 2, 0}, so).model.io_delay(), 8.037, 0.05) << seed;
    OeOptions oo;
    oo.estimate_delay = true;
    oo.srivc.delay_max = 15;
    oo.initial = TransferFunction(Eigen::VectorXd{{10.0}}, Eigen::VectorXd{{1.0, 3.0, 3.0}}, 1.0);
    const auto r = oe(d, {1, 2, 0}, oo);
    EXPECT_NEAR(r.model.io_delay(), 8.037, 0.05) << seed;
    EXPECT_NEAR(r.parameters.value("delay"), r.model.io_delay(), 1e-12);
  }
}

TEST(Srivc, MonteCarloMatchesTheCramerRaoBound) {
  // Set-up 1 at 10 dB, 30 runs (docs/accuracy.md has 100): for every parameter the sample
  // standard deviation is within 25 % of the CRLB (30 runs: the sample std itself has ~13 %
  // relative error) and |mean - true| < 0.5 std; every run converges from the default start.
  const int R = 30;
  const IdData clean = rao_data(INFINITY, 0);
  const Eigen::VectorXd x = clean.y().col(0);
  const double sigma2 = (x.array() - x.mean()).square().mean() / 10.0;
  const Eigen::MatrixXd bound = crlb(kRao, 2, clean, sigma2);
  Eigen::MatrixXd est(R, 6);
  for (int s = 0; s < R; ++s) {
    const auto r = srivc(rao_data(10.0, 100 + s), {2, 4, 0});
    ASSERT_EQ(r.summary.termination, Termination::Converged) << s;
    est.row(s) = r.parameters.values.transpose();
  }
  for (int i = 0; i < 6; ++i) {
    const double mean = est.col(i).mean();
    const double sd = std::sqrt((est.col(i).array() - mean).square().sum() / (R - 1));
    const double cr = std::sqrt(bound(i, i));
    EXPECT_NEAR(sd / cr, 1.0, 0.25) << "parameter " << i;
    EXPECT_LT(std::abs(mean - kRaoTheta(i)), 0.5 * sd) << "parameter " << i;
  }
}

TEST(Srivc, ReportedStdAgreesWithCrlbAndTfestMatchesSrivcAtTenDb) {
  const IdData d = rao_data(10.0, 7);
  const auto r = srivc(d, {2, 4, 0});
  const double sigma2 = r.diagnostics.get(diagnostic::noise_variance);
  const Eigen::MatrixXd bound = crlb(r.model, 2, d, sigma2);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(r.parameters.std(i) / std::sqrt(bound(i, i)), 1.0, 0.05) << i;
  // SRIVC is (asymptotically) the OE optimum: the LM refinement moves it by a fraction of a std.
  const auto t = tfest(d, {2, 4, 0});
  for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(t.parameters.values(i) - r.parameters.values(i)), 0.2 * r.parameters.std(i)) << i;
}

TEST(OutputError, SensitivitiesMatchFiniteDifferences) {
  // Analytic gradients are checked against finite differences.
  TransferFunction g(Eigen::VectorXd{{2.0, 3.0}}, Eigen::VectorXd{{1.0, 1.5, 4.0}}, 0.237);
  const int N = 600;
  const Eigen::VectorXd u = prbs(N, {.register_length = 7, .clock_period = 13});
  const IdData d(u, Eigen::VectorXd::Zero(N), 0.01);
  const Eigen::MatrixXd S = output_sensitivities(g, 2, d, true);
  const Eigen::VectorXd p0{{1.5, 4.0, 2.0, 3.0, 0.237}};
  auto sim = [&](const Eigen::VectorXd& p) {
    return lsim(TransferFunction(Eigen::VectorXd{{p(2), p(3)}}, Eigen::VectorXd{{1.0, p(0), p(1)}}, p(4)), d, 0);
  };
  for (int j = 0; j < 5; ++j) {
    const double h = 1e-6 * std::max(1.0, std::abs(p0(j)));
    Eigen::VectorXd pp = p0, pm = p0;
    pp(j) += h;
    pm(j) -= h;
    const Eigen::VectorXd fd = (sim(pp) - sim(pm)) / (2 * h);
    // Central differences: O(h^2) truncation + O(eps/h) rounding ~ 1e-9 relative. The delay
    // derivative is discontinuous at the PRBS switching instants (the held input jumps), so
    // it is compared away from them through the norm.
    const double rel = (fd - S.col(j)).norm() / S.col(j).norm();
    EXPECT_LT(rel, j < 4 ? 1e-7 : 2e-2) << "parameter " << j;
  }
}

TEST(OutputError, StreamedFitIsAStationaryPointOfTheExactJacobian) {
  // oe streams its normal equations on uniform single-input records (no N x p Jacobian). Checked against the
  // Jacobian and residuals computed independently by output_sensitivities and lsim, for held and linear inputs:
  // at the fitted point the gradient S^T r vanishes (each |S_j^T r| below 1e-7 ||S_j|| ||r||; measured: at most
  // 2e-9, what the stopping tolerance leaves) and the reported std is sqrt(sigma^2 [(S^T S)^-1]_jj) to 1e-6
  // (measured: 4e-10).
  for (Intersample is : {Intersample::Zoh, Intersample::Foh}) {
    IdData d = rao_data(10.0, 11);
    d.set_intersample(is);
    const auto r = oe(d, {2, 4, 0});
    ASSERT_TRUE(r.usable()) << r.why_not_usable();
    const Eigen::MatrixXd S = output_sensitivities(r.model, 2, d, false);
    const Eigen::VectorXd res = d.y().col(0) - lsim(r.model, d, 0);
    const double sigma2 = r.diagnostics.get(diagnostic::noise_variance);
    const Eigen::MatrixXd cov = sigma2 * (S.transpose() * S).inverse();
    for (int j = 0; j < 6; ++j) {
      EXPECT_LT(std::abs(S.col(j).dot(res)) / (S.col(j).norm() * res.norm()), 1e-7) << j;
      EXPECT_NEAR(r.parameters.std(j) / std::sqrt(cov(j, j)), 1.0, 1e-6) << j;
    }
    EXPECT_NEAR(sigma2, res.squaredNorm() / (d.size() - 6), 1e-9 * sigma2);
  }
}

TEST(OutputError, FixedParametersAndBounds) {
  const IdData d = rao_data(20.0, 3);
  OeOptions o;
  o.fixed = {{"a4", 1600.0}};
  o.bounds = {{"a1", {0.0, 6.0}}};
  const auto r = tfest(d, {2, 4, 0}, o);
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  EXPECT_EQ(r.parameters.value("a4"), 1600.0);
  EXPECT_TRUE(r.parameters.fixed[3]);
  EXPECT_EQ(r.parameters.std(3), 0.0);
  EXPECT_NEAR(r.parameters.value("a1"), 5.0, 0.1);
  // A bound below the truth (a1 = 5) holds a1 there: named in the user's units, not usable, no standard deviation.
  o.bounds = {{"a1", {0.0, 4.9}}};
  const auto held = tfest(d, {2, 4, 0}, o);
  EXPECT_EQ(held.summary.termination, Termination::AtBound);
  EXPECT_EQ(held.parameters.value("a1"), 4.9);
  EXPECT_TRUE(std::isnan(held.parameters.std(0)));
  EXPECT_NE(held.why_not_usable().find("a1 is at its upper bound 4.9, and the data would move it further"),
            std::string::npos)
      << held.why_not_usable();
  EXPECT_THROW(tfest(d, {2, 4, 0}, OeOptions{.fixed = {{"q9", 1.0}}}), InvalidOptions);
}

TEST(OrderSelection, TrueStructureRanksFirst) {
  // Set-up 8: on set-up 1 at 10 dB, nb in {1, 2}, nf in {3, 4, 5}: [2 4] first by YIC.
  for (std::uint64_t seed : {1, 2, 3}) {
    const auto c = select_order(rao_data(10.0, seed), {1, 2}, {3, 5}, {0, 0});
    ASSERT_EQ(c.size(), 6u);
    EXPECT_EQ(c[0].orders.nb, 2);
    EXPECT_EQ(c[0].orders.nf, 4);
    EXPECT_GT(c[0].rt2, 0.9);  // 10 dB: RT2 = 1 - 1/(1 + 10^-1 ...) ~ 0.909
  }
}

TEST(OrderSelection, StructuresWithoutACriterionRankLast) {
  // Noise-free set-up 1 with nf above the true 4: the over-parameterised fits are rank deficient and have no YIC
  // (NaN). Usable structures first, each group in increasing YIC, the NaN rows at the end of theirs (before the fix
  // a NaN compared as a number left them between others, the order undefined).
  const auto c = select_order(rao_data(INFINITY, 0), {2, 3}, {4, 6}, {0, 0});
  ASSERT_EQ(c.size(), 6u);
  EXPECT_EQ(c[0].orders.nf, 4);  // measured: [2 4] then [3 4], both usable with a 100 % fit
  EXPECT_TRUE(c[0].usable);
  int nan_rows = 0;
  for (size_t i = 1; i < c.size(); ++i) {
    const OrderCandidate &a = c[i - 1], &b = c[i];
    nan_rows += std::isnan(b.yic);
    EXPECT_TRUE(a.usable || !b.usable) << "row " << i;  // usable first
    if (a.usable == b.usable) {
      EXPECT_FALSE(std::isnan(a.yic) && !std::isnan(b.yic)) << "row " << i;
      if (!std::isnan(b.yic)) EXPECT_LE(a.yic, b.yic) << "row " << i;
    }
  }
  EXPECT_GE(nan_rows, 2);  // measured 4: nf = 5 and 6
}

TEST(Srivc, BadInputs) {
  const IdData d = rao_data(INFINITY, 0);
  EXPECT_THROW(srivc(d, {3, 1, 0}), InvalidOptions);  // nb > nf + 1
  SrivcOptions o;
  o.delay_min = 2;
  o.delay_max = 1;
  EXPECT_THROW(srivc(d, {1, 1, 0}, o), InvalidOptions);  // empty delay range
  o.estimate_delay = true;
  o.delay_min = 0;
  o.delay_max = 1e300;  // the grid size is computed without int overflow; the delays exceed the record
  EXPECT_THROW(srivc(d, {1, 1, 0}, o), InvalidArgument);
  o = {};
  o.delay = -1;
  EXPECT_THROW(srivc(d, {1, 1, 0}, o), InvalidOptions);
  const IdData tiny(Eigen::VectorXd{{1.0, 0.0, 1.0, 1.0, 0.0}}, Eigen::VectorXd{{0.0, 0.5, 0.2, 0.7, 0.6}}, 0.1);
  EXPECT_THROW(srivc(tiny, {2, 4, 0}), InvalidArgument);  // more parameters than data
  EXPECT_THROW(crlb(kRao, 2, d, -1.0), InvalidArgument);
}

namespace {
// Set-up 5: Y = e^{-0.03 s} 4/(s^2 + 2 s + 4) U1 + e^{-0.05 s} 1/(s^2 + s + 1) U2, Ts = 0.01 s,
// two independent PRBS inputs (registers 10 and 11, held 15 and 20 samples), 8000 samples.
struct Miso {
  TransferFunction g1{Eigen::VectorXd{{4.0}}, Eigen::VectorXd{{1.0, 2.0, 4.0}}, 0.03};
  TransferFunction g2{Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 1.0, 1.0}}, 0.05};
  Eigen::MatrixXd u;
  Eigen::VectorXd x;
  Miso() : u(8000, 2) {
    u.col(0) = prbs(8000, {.register_length = 10, .clock_period = 15});
    u.col(1) = prbs(8000, {.register_length = 11, .clock_period = 20, .initial_state = 77});
    x = lsim(MisoModel{{g1, g2}}, IdData(u, Eigen::VectorXd::Zero(8000), 0.01));
  }
};
const Eigen::VectorXd kMisoTheta{{2.0, 4.0, 4.0, 1.0, 1.0, 1.0}};
}  // namespace

TEST(SrivcMiso, DifferentDenominatorsNoiseFreeExactAndNoisyWithinUncertainty) {
  const Miso m;
  const auto r = srivc_miso(IdData(m.u, m.x, 0.01), {{1, 2, 3}, {1, 2, 5}});
  ASSERT_EQ(r.summary.termination, Termination::Converged) << r.summary.message;
  EXPECT_LT(max_rel(r.parameters.values, kMisoTheta), 1e-6);
  EXPECT_EQ(r.parameters.names[3], "u2.a1");
  EXPECT_NEAR(r.model.channels[1].io_delay(), 0.05, 1e-15);
  // 10 dB: every estimate within 3 reported standard deviations of the truth (measured: within 1.2).
  const auto n = srivc_miso(IdData(m.u, add_noise_snr(m.x, 10.0, 3), 0.01), {{1, 2, 3}, {1, 2, 5}});
  ASSERT_TRUE(n.usable()) << n.why_not_usable();
  for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(n.parameters.values(i) - kMisoTheta(i)), 3 * n.parameters.std(i)) << i;
}

TEST(SrivcMiso, SeparateDenominatorsConvergeWhateverTheInputOrder) {
  // y = (s + 3)/(s^2 + 2 s + 5) u1 + 2/(s + 1) u2, two PRBS of equal power (10-bit, clock 4 and 8-bit, clock 7),
  // Ts = 0.02 s, 3000 samples, noise-free. Regression: starting every channel from a SISO fit on y alone (the
  // other input a 0 dB "noise") gave channel 1 a pole at +0.02 and the backfitting ended rank-deficient (in
  // 12 of 72 input/order/noise combinations); with the sequential start and stabilised channel outputs all
  // 72 converge. Noise-free the estimate is exact to the convergence tolerance (1e-7; bound 1e-6).
  const double Ts = 0.02;
  const Eigen::VectorXd t = time_grid(Ts, 3000);
  const Eigen::VectorXd u1 = prbs(3000, {.register_length = 8, .clock_period = 7});
  const Eigen::VectorXd u2 = prbs(3000, {.register_length = 10, .clock_period = 4});
  const TransferFunction g1(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 2.0, 5.0}});
  const TransferFunction g2(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 1.0}});
  const Eigen::VectorXd y = lsim(g1, u1, t, Intersample::Zoh) + lsim(g2, u2, t, Intersample::Zoh);
  Eigen::MatrixXd u(3000, 2);
  u << u1, u2;
  const auto r = srivc_miso(IdData(u, y, Ts), {{2, 2, 0}, {1, 1, 0}});
  ASSERT_EQ(r.summary.termination, Termination::Converged) << r.summary.message;
  EXPECT_LT(max_rel(r.parameters.values, Eigen::VectorXd{{2.0, 5.0, 1.0, 3.0, 1.0, 2.0}}), 1e-6);
  Eigen::MatrixXd swapped(3000, 2);
  swapped << u2, u1;
  const auto s = srivc_miso(IdData(swapped, y, Ts), {{1, 1, 0}, {2, 2, 0}});
  ASSERT_EQ(s.summary.termination, Termination::Converged) << s.summary.message;
  EXPECT_LT(max_rel(s.parameters.values, Eigen::VectorXd{{1.0, 2.0, 2.0, 5.0, 1.0, 3.0}}), 1e-6);
}

// Several experiments of a two-input system: y = (s + 3)/(s^2 + 2 s + 5) u1 + 2/(s + 1) u2,
// record 1 exciting u1 more than u2 (PRBS amplitudes 1 and 0.6), record 2 the reverse, 1500 samples
// each at 20 ms, white output noise of std 0.1. Noise-free, the joint fit is exact (1e-6). Over 30 runs the joint
// estimate is more accurate than either record's for every parameter and its reported standard deviation matches
// the spread within 35 % (30 runs estimate a spread to ~13 %; measured 0.82-1.02: the backfitting covariance is
// block-diagonal across channels). Measured joint RMS error 0.69-0.93 of the better record's.
TEST(SrivcMiso, SeveralExperimentsGiveOneEstimateMoreAccurateThanEither) {
  const double Ts = 0.02;
  const int N = 1500;
  const Eigen::VectorXd t = time_grid(Ts, N);
  const TransferFunction g1(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 2.0, 5.0}});
  const TransferFunction g2(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 1.0}});
  const Eigen::VectorXd truth{{2.0, 5.0, 1.0, 3.0, 1.0, 2.0}};
  const std::vector<TfOrders> orders = {{2, 2, 0}, {1, 1, 0}};
  auto inputs = [&](double a1, double a2, std::uint32_t seed) {
    Eigen::MatrixXd u(N, 2);
    u.col(0) = a1 * prbs(N, {.register_length = 9, .clock_period = 5, .initial_state = seed});
    u.col(1) = a2 * prbs(N, {.register_length = 10, .clock_period = 3, .initial_state = seed + 7});
    return u;
  };
  const Eigen::MatrixXd u1 = inputs(1.0, 0.6, 3), u2 = inputs(0.6, 1.0, 11);
  const Eigen::VectorXd x1 = lsim(g1, Eigen::VectorXd(u1.col(0)), t) + lsim(g2, Eigen::VectorXd(u1.col(1)), t);
  const Eigen::VectorXd x2 = lsim(g1, Eigen::VectorXd(u2.col(0)), t) + lsim(g2, Eigen::VectorXd(u2.col(1)), t);
  const auto exact = srivc_miso(std::vector<IdData>{IdData(u1, x1, Ts), IdData(u2, x2, Ts)}, orders);
  ASSERT_EQ(exact.summary.termination, Termination::Converged) << exact.summary.message;
  EXPECT_LT(max_rel(exact.parameters.values, truth), 1e-6);
  EXPECT_EQ(exact.diagnostics.get(diagnostic::experiments), 2);
  const int R = 30;
  Eigen::MatrixXd e1(R, 6), e2(R, 6), ej(R, 6), sj(R, 6);
  std::mt19937_64 rng(99);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (int run = 0; run < R; ++run) {
    Eigen::VectorXd y1 = x1, y2 = x2;
    for (int k = 0; k < N; ++k) {
      y1(k) += noise(rng);
      y2(k) += noise(rng);
    }
    const IdData d1(u1, y1, Ts), d2(u2, y2, Ts);
    e1.row(run) = (srivc_miso(d1, orders).parameters.values - truth).transpose();
    e2.row(run) = (srivc_miso(d2, orders).parameters.values - truth).transpose();
    const auto j = srivc_miso(std::vector<IdData>{d1, d2}, orders);
    ASSERT_TRUE(j.usable()) << j.why_not_usable();
    ej.row(run) = (j.parameters.values - truth).transpose();
    sj.row(run) = j.parameters.std.transpose();
  }
  for (int i = 0; i < 6; ++i) {
    auto rmse = [&](const Eigen::MatrixXd& e) { return std::sqrt(e.col(i).squaredNorm() / R); };
    const double mean = ej.col(i).mean(), sd = std::sqrt((ej.col(i).array() - mean).square().sum() / (R - 1));
    std::printf("parameter %d: rmse joint %.4g, record 1 %.4g, record 2 %.4g; reported std / spread %.3f\n", i, rmse(ej),
                rmse(e1), rmse(e2), sj.col(i).mean() / sd);
    EXPECT_LT(rmse(ej), std::min(rmse(e1), rmse(e2))) << "parameter " << i;
    EXPECT_NEAR(sj.col(i).mean() / sd, 1.0, 0.3) << "parameter " << i;
  }
  EXPECT_NE(test::error_of([&] {
              srivc_miso(std::vector<IdData>{IdData(u1, x1, Ts), IdData(Eigen::MatrixXd(u1.col(0)), x1, Ts)}, orders);
            }).find("srivc_miso (record 2): 1 inputs; record 1 has 2"),
            std::string::npos);
}

TEST(SrivcMiso, CommonDenominatorNoiseFreeExact) {
  const Miso m;
  const TransferFunction c1(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 1.5, 4.0}});
  const TransferFunction c2(Eigen::VectorXd{{1.0, 1.0}}, Eigen::VectorXd{{1.0, 1.5, 4.0}});
  const IdData base(m.u, Eigen::VectorXd::Zero(8000), 0.01);
  const IdData d(m.u, lsim(MisoModel{{c1, c2}}, base), 0.01);
  SrivcMisoOptions o;
  o.common_denominator = true;
  const auto r = srivc_miso(d, {{1, 2, 0}, {2, 2, 0}}, o);
  ASSERT_EQ(r.summary.termination, Termination::Converged);
  EXPECT_LT(max_rel(r.parameters.values, Eigen::VectorXd{{1.5, 4.0, 2.0, 1.0, 1.0}}), 1e-6);
  EXPECT_EQ(r.parameters.names[2], "u1.b0");
  // Orders inconsistent with the inputs are reported.
  EXPECT_THROW(srivc_miso(d, {{1, 2, 0}}, o), InvalidArgument);
  EXPECT_THROW(srivc_miso(d, {{1, 2, 0}, {1, 3, 0}}, o), InvalidOptions);
  o.delays = {0.1};
  EXPECT_THROW(srivc_miso(d, {{1, 2, 0}, {1, 2, 0}}, o), InvalidOptions);
}

namespace {
// Set-up 6's loop: G = (s + 1)/(s^2 + 0.5 s + 1) under the PI controller C = (10 s + 15)/s implemented digitally
// (u = r - C y computed at each sample and held: the plant input is exactly ZOH), from rest; v is added to the
// measured output. Returns the record (plant input, measured output) at Ts.
IdData pi_loop(const Eigen::VectorXd& r, const Eigen::VectorXd& v, double Ts) {
  const StateSpace ss = TransferFunction(Eigen::VectorXd{{1.0, 1.0}}, Eigen::VectorXd{{1.0, 0.5, 1.0}}).to_state_space();
  const Discretization D = discretize(ss.A(), ss.B(), Ts);
  const Eigen::Index N = r.size();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2), u(N), ym(N);
  double integral = 0;
  for (Eigen::Index k = 0; k < N; ++k) {
    ym(k) = (ss.C() * x)(0) + v(k);
    u(k) = r(k) - (10 * ym(k) + 15 * integral);
    integral += Ts * ym(k);
    x = D.Phi * x + D.Gamma0 * u(k);
  }
  return IdData(u, ym, Ts);
}
}  // namespace

TEST(SrivcClosedLoop, ConsistentWhereOpenLoopSrivcIsBiased) {
  // Set-up 6: G = (s + 1)/(s^2 + 0.5 s + 1) under the PI controller C = (10 s + 15)/s,
  // implemented digitally (u = r - C y computed at each sample and held: the plant input is
  // exactly ZOH), reference PRBS added at the plant input, Ts = 0.005 s, N = 20000.
  // [STAND-IN] noise: AR(1) (pole 0.95) at 10 dB on the measured output — with white noise
  // plain SRIVC is consistent too; coloured noise is what makes u-based instruments biased.
  // Measured over 40 runs: SRIVC b0 mean 0.949 (sd 0.0096), CLSRIVC 0.998 (sd 0.011).
  const double Ts = 0.005;
  const int N = 20000, R = 30;
  const Eigen::VectorXd r = prbs(N, {.register_length = 10, .clock_period = 20});
  const IdData clean = pi_loop(r, Eigen::VectorXd::Zero(N), Ts);
  const Eigen::VectorXd y0 = clean.y().col(0);
  const double sv = std::sqrt((y0.array() - y0.mean()).square().mean() / 10.0);
  ClosedLoopOptions o;
  o.controller = TransferFunction(Eigen::VectorXd{{10.0, 15.0}}, Eigen::VectorXd{{1.0, 0.0}});
  Eigen::MatrixXd ol(R, 4), cl(R, 4);
  for (int s = 0; s < R; ++s) {
    Eigen::VectorXd v = white_noise(N, 1.0, 500 + s);
    for (int k = 1; k < N; ++k) v(k) += 0.95 * v(k - 1);
    v *= sv / std::sqrt((v.array() - v.mean()).square().mean());
    const IdData d = pi_loop(r, v, Ts);
    ol.row(s) = srivc(d, {2, 2, 0}).parameters.values.transpose();
    const auto c = srivc_closed_loop(d, r, {2, 2, 0}, o);
    ASSERT_TRUE(c.usable()) << c.why_not_usable();
    // The AR(1) noise (pole 0.95) makes the white-noise sandwich too small (about sqrt(1.95/0.05) = 6.2 times
    // for this pole): the result says so.
    ASSERT_EQ(c.diagnostics.warnings.size(), 1u);
    EXPECT_NE(c.diagnostics.warnings[0].find("the standard deviations assume white noise"), std::string::npos);
    EXPECT_NEAR(c.diagnostics.get(diagnostic::output_error_lag1_correlation), 0.95, 0.03);
    cl.row(s) = c.parameters.values.transpose();
  }
  const Eigen::VectorXd truth{{0.5, 1.0, 1.0, 1.0}};
  for (int i = 0; i < 4; ++i) {
    const double m = cl.col(i).mean();
    const double sd = std::sqrt((cl.col(i).array() - m).square().sum() / (R - 1));
    EXPECT_LT(std::abs(m - truth(i)), 3.5 * sd / std::sqrt(double(R))) << "CLSRIVC parameter " << i;
  }
  // Plain SRIVC: b0 biased by more than 10 standard errors of the mean.
  const double m = ol.col(2).mean();
  const double sd = std::sqrt((ol.col(2).array() - m).square().sum() / (R - 1));
  EXPECT_GT(std::abs(m - 1.0), 10 * sd / std::sqrt(double(R)));
  // Bad use.
  EXPECT_THROW(srivc_closed_loop(clean, r.head(10), {2, 2, 0}, o), InvalidArgument);
}

// Several experiments of one loop: set-up 6's plant and PI controller, two records of 8000
// samples with different references (PRBS clock 20; PRBS clock 40 of another register and seed) and independent
// white measurement noise at 10 dB of record 1's noise-free output (white, where the IV-sandwich covariance
// sigma^2 (Z^T Phi)^-1 Z^T Z (Phi^T Z)^-1 holds; with coloured noise it is too small). CLSRIVC on both records is
// one estimate at least as accurate as either alone — RMS error below 0.85 of the better record's for every
// parameter (measured 0.72-0.76 over 100 runs) — and the pooled standard deviation agrees with the Monte Carlo
// spread within 20 % (100 runs: the sample std has ~7 % relative error; measured 0.98-1.06; with 40 runs the
// ratio wandered up to 1.39 on one parameter, sampling alone).
TEST(SrivcClosedLoop, SeveralExperimentsGiveOneEstimateMoreAccurateThanEither) {
  const double Ts = 0.005;
  const int N = 8000, R = 100;
  const std::vector<Eigen::VectorXd> refs{prbs(N, {.register_length = 10, .clock_period = 20}),
                                          prbs(N, {.register_length = 9, .clock_period = 40, .initial_state = 77})};
  const IdData clean = pi_loop(refs[0], Eigen::VectorXd::Zero(N), Ts);
  const double sv = std::sqrt((clean.y().array() - clean.y().mean()).square().mean() / 10.0);
  ClosedLoopOptions o;
  o.controller = TransferFunction(Eigen::VectorXd{{10.0, 15.0}}, Eigen::VectorXd{{1.0, 0.0}});
  const Eigen::VectorXd truth{{0.5, 1.0, 1.0, 1.0}};
  Eigen::MatrixXd e1(R, 4), e2(R, 4), ej(R, 4), sj(R, 4);
  for (int s = 0; s < R; ++s) {
    std::vector<IdData> d;
    for (int e = 0; e < 2; ++e) {
      d.push_back(pi_loop(refs[e], white_noise(N, sv, 900 + 2 * s + e), Ts));
    }
    const auto a = srivc_closed_loop(d[0], refs[0], {2, 2, 0}, o);
    const auto b = srivc_closed_loop(d[1], refs[1], {2, 2, 0}, o);
    const auto j = srivc_closed_loop(d, refs, {2, 2, 0}, o);
    ASSERT_TRUE(j.usable()) << j.why_not_usable();
    EXPECT_EQ(j.diagnostics.get(diagnostic::experiments), 2.0);
    EXPECT_TRUE(j.diagnostics.warnings.empty()) << j.diagnostics.warnings.front();  // white noise: no caveat
    e1.row(s) = (a.parameters.values - truth).transpose();
    e2.row(s) = (b.parameters.values - truth).transpose();
    ej.row(s) = (j.parameters.values - truth).transpose();
    sj.row(s) = j.parameters.std.transpose();
  }
  for (int i = 0; i < 4; ++i) {
    auto rmse = [&](const Eigen::MatrixXd& e) { return std::sqrt(e.col(i).squaredNorm() / R); };
    const double mean = ej.col(i).mean();
    const double sd = std::sqrt((ej.col(i).array() - mean).square().sum() / (R - 1));
    std::printf("parameter %d: rmse joint %.4g, record 1 %.4g, record 2 %.4g; reported std / spread %.3f\n", i, rmse(ej),
                rmse(e1), rmse(e2), sj.col(i).mean() / sd);
    EXPECT_LT(rmse(ej), 0.85 * std::min(rmse(e1), rmse(e2))) << "parameter " << i;
    EXPECT_NEAR(sj.col(i).mean() / sd, 1.0, 0.2) << "parameter " << i;
  }
  // A record that does not start at rest (the second half of one noise-free run of 2 N samples, 40 s each): the
  // slow plant mode (damping 0.25 rad/s) leaves the instruments' error in its first seconds; transient_time = 25 s
  // takes it out of the sums: the error on a1 falls from 7.9e-3 to 1.8e-4 (measured; asserted: above 5e-3
  // without, below 5e-4 with).
  {
    const Eigen::VectorXd rr = prbs(2 * N, {.register_length = 10, .clock_period = 20});
    const IdData run = pi_loop(rr, Eigen::VectorXd::Zero(2 * N), Ts);
    const Eigen::VectorXd u = run.u().col(0), ym = run.y().col(0);
    const std::vector<IdData> halves{IdData(u.head(N), ym.head(N), Ts), IdData(u.tail(N), ym.tail(N), Ts, N * Ts)};
    const std::vector<Eigen::VectorXd> hr{rr.head(N), rr.tail(N)};
    const double raw = std::abs(srivc_closed_loop(halves, hr, {2, 2, 0}, o).parameters.value("a1") - 0.5);
    ClosedLoopOptions ot = o;
    ot.transient_time = 25.0;
    const double cut = std::abs(srivc_closed_loop(halves, hr, {2, 2, 0}, ot).parameters.value("a1") - 0.5);
    EXPECT_GT(raw, 5e-3);
    EXPECT_LT(cut, 5e-4);
  }
  // A reference that does not match its record is named by the record's position.
  EXPECT_NE(test::error_of([&] {
              srivc_closed_loop(std::vector<IdData>{clean, clean}, {refs[0], refs[1].head(10)}, {2, 2, 0}, o);
            }).find("srivc_closed_loop (record 2): the reference has 10 samples but the data have 8000"),
            std::string::npos);
  EXPECT_THROW(srivc_closed_loop(std::vector<IdData>{clean}, refs, {2, 2, 0}, o), InvalidArgument);
}

TEST(FrequencyFit, RaoGarnierFrequencyResponse) {
  // Set-up 7: the Rao-Garnier response at 250 log-spaced w in [0.1, 100] rad/s.
  Eigen::VectorXd w(250);
  for (int k = 0; k < 250; ++k) w(k) = 0.1 * std::pow(1000.0, k / 249.0);
  const Eigen::VectorXcd G = kRao.frequency_response(w);
  const auto exact = tf_from_frequency(FrequencyData(w, G), {2, 4, 0});
  ASSERT_TRUE(exact.usable()) << exact.why_not_usable();
  EXPECT_LT(max_rel(exact.parameters.values, kRaoTheta), 1e-6);  // noise-free: exact
  // Complex noise of std 1.5 on each part, 30 runs: every run converges near the truth
  // (a1 within 5 sd; measured worst 3.2) and the means are within 3.5 standard errors.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> nd(0.0, 1.5);
  const int R = 30;
  Eigen::MatrixXd est(R, 6);
  for (int s = 0; s < R; ++s) {
    Eigen::VectorXcd Gn = G;
    for (auto& v : Gn) v += std::complex<double>(nd(rng), nd(rng));
    const auto r = tf_from_frequency(FrequencyData(w, Gn), {2, 4, 0});
    ASSERT_TRUE(r.usable()) << s;
    est.row(s) = r.parameters.values.transpose();
    EXPECT_LT(std::abs(r.parameters.values(0) - 5.0), 5 * r.parameters.std(0)) << s;
  }
  for (int i = 0; i < 6; ++i) {
    const double m = est.col(i).mean();
    const double sd = std::sqrt((est.col(i).array() - m).square().sum() / (R - 1));
    EXPECT_LT(std::abs(m - kRaoTheta(i)), 3.5 * sd / std::sqrt(double(R))) << i;
  }
  // Delay estimation on noise-free data, and bad data.
  TransferFunction gd = kRao;
  gd.set_io_delay(0.013);
  FrequencyFitOptions o;
  o.estimate_delay = true;
  const auto rd = tf_from_frequency(FrequencyData(w, gd.frequency_response(w)), {2, 4, 0}, o);
  EXPECT_NEAR(rd.parameters.value("delay"), 0.013, 1e-6);
  EXPECT_THROW(FrequencyData(Eigen::VectorXd{{1.0, 0.5}}, Eigen::VectorXcd::Ones(2)), InvalidArgument);
  EXPECT_THROW(tf_from_frequency(FrequencyData(w.head(2), G.head(2)), {2, 4, 0}), InvalidArgument);
}

namespace {
// The two-experiment set-up: G = (s + 3)/(s^2 + 1.2 s + 4), Ts = 0.05 s, 1000 samples per record;
// record 1: a PRBS from rest; record 2: a two-tone multisine starting 10 s into a run (not at rest); white output
// noise of std 0.05. draw() gives a new noisy pair from the seeded generator.
struct TwoRecords {
  static constexpr int N = 1000, skip = 200;
  static constexpr double Ts = 0.05, sigma = 0.05;
  const Eigen::VectorXd truth{{1.2, 4.0, 1.0, 3.0}};
  Eigen::VectorXd u1, x1, u2, x2;
  std::mt19937_64 rng;
  explicit TwoRecords(std::uint64_t seed) : rng(seed) {
    const TransferFunction g(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}});
    u1 = prbs(N, {.register_length = 8, .clock_period = 4});
    x1 = lsim(g, u1, time_grid(Ts, N));
    Eigen::VectorXd u(N + skip);
    for (int k = 0; k < N + skip; ++k) u(k) = std::sin(0.7 * k * Ts) + 0.8 * std::sin(2.9 * k * Ts + 1.0);
    x2 = lsim(g, u, time_grid(Ts, N + skip)).tail(N);
    u2 = u.tail(N);
  }
  Eigen::VectorXd noisy(const Eigen::VectorXd& x) {
    std::normal_distribution<double> noise(0.0, sigma);
    Eigen::VectorXd y = x;
    for (Eigen::Index k = 0; k < y.size(); ++k) y(k) += noise(rng);
    return y;
  }
  std::pair<IdData, IdData> draw() { return {IdData(u1, noisy(x1), Ts), IdData(u2, noisy(x2), Ts, skip * Ts)}; }

  // R runs of fit(record) on each record alone and fit(both) jointly: the parameter errors of each (rows = runs) and
  // the joint fit's reported standard deviations.
  struct Runs {
    Eigen::MatrixXd e1, e2, ej, sj;
  };
  template <class Fit>
  Runs monte_carlo(int R, Fit fit) {
    Runs m{Eigen::MatrixXd(R, 4), Eigen::MatrixXd(R, 4), Eigen::MatrixXd(R, 4), Eigen::MatrixXd(R, 4)};
    for (int s = 0; s < R; ++s) {
      const auto [a, b] = draw();
      const auto r1 = fit(std::vector<IdData>{a}), r2 = fit(std::vector<IdData>{b}), rj = fit(std::vector<IdData>{a, b});
      EXPECT_TRUE(r1.usable() && r2.usable() && rj.usable()) << s << ": " << rj.why_not_usable();
      EXPECT_EQ(rj.diagnostics.get(diagnostic::experiments), 2.0);
      m.e1.row(s) = (r1.parameters.values - truth).transpose();
      m.e2.row(s) = (r2.parameters.values - truth).transpose();
      m.ej.row(s) = (rj.parameters.values - truth).transpose();
      m.sj.row(s) = rj.parameters.std.transpose();
    }
    return m;
  }
};
}  // namespace

// Several experiments. Two records of G = (s + 3)/(s^2 + 1.2 s + 4) with different inputs (a
// PRBS; a two-tone multisine) and different initial states (the second record starts 10 s into a run, not at rest),
// Ts = 0.05 s, 1000 samples each, white output noise of std 0.05 (about 10 % of the output's RMS); every fit leaves
// out the first 8 s of each record (transient_time: the filters start at rest, record 2 does not; its free
// response has decayed to e^{-0.6 * 8} = 1 % by then). Over R = 100 seeded runs: the joint estimate is at least
// as accurate as either record alone — its root mean squared error below 0.85 of the better single record's for
// every parameter (two records of similar information: 1/sqrt(2) = 0.71 expected; measured 0.68-0.72) — and its reported standard deviation agrees with the Monte Carlo spread within 25 % (100
// runs: the sample std has ~7 % relative error), its mean error within 3 standard errors (+ 10 % of a std).
// Without transient_time the joint estimate is biased by record 2's initial state (measured: 0.020 on a1, 8
// standard errors), which the last check shows.
TEST(Srivc, SeveralExperimentsGiveOneEstimateBetterThanEitherWithTheRightCovariance) {
  TwoRecords set(2026);
  const int R = 100, N = TwoRecords::N;
  SrivcOptions o;
  o.transient_time = 8.0;
  const auto mc = set.monte_carlo(R, [&](const std::vector<IdData>& d) { return srivc(d, {2, 2, 0}, o); });
  const Eigen::MatrixXd &e1 = mc.e1, &e2 = mc.e2, &ej = mc.ej, &sj = mc.sj;
  for (int i = 0; i < 4; ++i) {
    auto rmse = [&](const Eigen::MatrixXd& e) { return std::sqrt(e.col(i).squaredNorm() / R); };
    const double best_single = std::min(rmse(e1), rmse(e2));
    const double combined = 1.0 / std::sqrt(1.0 / (rmse(e1) * rmse(e1)) + 1.0 / (rmse(e2) * rmse(e2)));
    EXPECT_LT(rmse(ej), 1.15 * combined) << "parameter " << i << ": joint " << rmse(ej) << ", combined " << combined;
    EXPECT_LT(rmse(ej), 0.85 * best_single) << "parameter " << i << ": joint " << rmse(ej) << ", records " << rmse(e1)
                                            << ", " << rmse(e2);
    const double mean = ej.col(i).mean();
    const double sd = std::sqrt((ej.col(i).array() - mean).square().sum() / (R - 1));
    std::printf("parameter %d: rmse joint %.4g, record 1 %.4g, record 2 %.4g; reported std / spread %.3f; bias %.2f se\n", i,
                rmse(ej), rmse(e1), rmse(e2), sj.col(i).mean() / sd, mean / (sd / std::sqrt(double(R))));
    EXPECT_NEAR(sj.col(i).mean() / sd, 1.0, 0.25) << "parameter " << i << ": reported " << sj.col(i).mean() << ", spread " << sd;
    EXPECT_LT(std::abs(mean), 3.0 * sd / std::sqrt(double(R)) + 0.1 * sd) << "parameter " << i << " biased";
  }
  // A record that cannot be used is named by its position.
  const IdData flat(Eigen::VectorXd::Zero(N), set.draw().first.y(), TwoRecords::Ts);
  EXPECT_NE(test::error_of([&] { srivc(std::vector<IdData>{set.draw().first, flat}, {2, 2, 0}); })
                .find("srivc (record 2): input 'u1' is constant (0)"),
            std::string::npos);
  EXPECT_THROW(srivc(std::vector<IdData>{}, {2, 2, 0}), InvalidArgument);
}

// The same two-record set-up (30 runs) for output error: tfest (joint SRIVC start, then output error on the summed
// cost) on both records is at least as accurate as on either alone, and within 15 % of the accuracy the two
// records' information combined gives, (rmse_1^-2 + rmse_2^-2)^-1/2 (measured 0.86-1.06 of it; 30 runs: the RMS
// errors have ~13 % relative error), and its reported standard deviation agrees with the spread within 35 %
// (measured 0.93-1.02).
TEST(OutputError, SeveralExperimentsGiveOneEstimateBetterThanEither) {
  TwoRecords set(2027);
  const int R = 30;
  OeOptions o;
  o.transient_time = 8.0;
  const auto mc = set.monte_carlo(R, [&](const std::vector<IdData>& d) { return tfest(d, {2, 2, 0}, o); });
  const Eigen::MatrixXd &e1 = mc.e1, &e2 = mc.e2, &ej = mc.ej, &sj = mc.sj;
  for (int i = 0; i < 4; ++i) {
    auto rmse = [&](const Eigen::MatrixXd& e) { return std::sqrt(e.col(i).squaredNorm() / R); };
    const double mean = ej.col(i).mean();
    const double sd = std::sqrt((ej.col(i).array() - mean).square().sum() / (R - 1));
    std::printf("parameter %d: rmse joint %.4g, record 1 %.4g, record 2 %.4g; reported std / spread %.3f\n", i, rmse(ej),
                rmse(e1), rmse(e2), sj.col(i).mean() / sd);
    const double combined = 1.0 / std::sqrt(1.0 / (rmse(e1) * rmse(e1)) + 1.0 / (rmse(e2) * rmse(e2)));
    EXPECT_LT(rmse(ej), std::min(rmse(e1), rmse(e2))) << "parameter " << i;
    EXPECT_LT(rmse(ej), 1.15 * combined) << "parameter " << i;
    EXPECT_NEAR(sj.col(i).mean() / sd, 1.0, 0.3) << "parameter " << i;
  }
}

// The same two-record set-up (30 runs) for Johansson's IVSVF (tau = 0.3 s; transient_time = 8 s). IVSVF sums the
// two records' IV equations unweighted and is not statistically efficient, so the joint estimate need not beat the
// better record: measured, its RMS error lies between the two records' (0.47-0.70 of the worse one's, 0.97-1.38 of
// the better one's). Asserted: below the worse record's for every parameter (a record whose transient or delay were
// mishandled would make it worse than both) — for the best accuracy from several records use srivc or tfest.
TEST(Ivsvf, SeveralExperimentsGiveOneEstimateBetweenTheRecords) {
  TwoRecords set(2028);
  const int R = 30;
  IvsvfOptions o;
  o.svf.tau = 0.3;
  o.svf.transient_time = 8.0;
  const auto mc = set.monte_carlo(R, [&](const std::vector<IdData>& d) { return ivsvf(d, {2, 2, 0}, o); });
  for (int i = 0; i < 4; ++i) {
    auto rmse = [&](const Eigen::MatrixXd& e) { return std::sqrt(e.col(i).squaredNorm() / R); };
    const double combined = 1.0 / std::sqrt(1.0 / (rmse(mc.e1) * rmse(mc.e1)) + 1.0 / (rmse(mc.e2) * rmse(mc.e2)));
    std::printf("parameter %d: rmse joint %.4g, record 1 %.4g, record 2 %.4g, combined %.4g\n", i, rmse(mc.ej),
                rmse(mc.e1), rmse(mc.e2), combined);  // the efficient combination, for comparison
    EXPECT_LT(rmse(mc.ej), 0.85 * std::max(rmse(mc.e1), rmse(mc.e2))) << "parameter " << i;
  }
}

// A record that does not start at rest (initial-condition estimation for linear models). The data are
// the exact ZOH simulation of G = (s + 3)/(s^2 + 1.2 s + 4) from the state x0 = (1.5, -0.7) of its realisation.
// Noise-free, estimate_initial_state recovers the parameters to 1e-6 and x0 to 1e-5 (the equivalent state of the
// free response, diagnostics x0), and simulate from that x0 is the fit's simulation; from rest the same record
// gives parameters biased by more than 1e-2 (measured: a1 12 %, a2 4 %, b0 57 %, b1 24 %). With noise (std 0.05) every
// parameter lies within 3.5 reported standard deviations (single seeded run; measured 0.16-0.49).
TEST(OutputError, TheInitialConditionOfARecordNotAtRestIsEstimated) {
  const TransferFunction truth(Polynomial{1.0, 3.0}, Polynomial{1.0, 1.2, 4.0});
  const int n = 2000;
  const Eigen::VectorXd u = prbs(n, {.register_length = 9, .clock_period = 12});
  const Eigen::VectorXd t = time_grid(0.01, n);
  LsimOptions lo;
  lo.x0 = Eigen::Vector2d(1.5, -0.7);
  const Eigen::VectorXd y = lsim(truth.to_state_space(), u, t, {Intersample::Zoh}, lo).col(0);
  const IdData d(u, y, 0.01);
  const Eigen::Vector4d want(1.2, 4.0, 1.0, 3.0);  // a1, a2, b0, b1
  OeOptions o;
  o.estimate_initial_state = true;
  for (const bool with_tfest : {true, false}) {
    const Result<TransferFunction> r = with_tfest ? tfest(d, {2, 2, 0}, o) : oe(d, {2, 2, 0}, o);
    ASSERT_TRUE(r.usable()) << r.why_not_usable();
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(r.parameters.values(i), want(i), 1e-6 * std::abs(want(i))) << i;
    const Eigen::VectorXd x0 = r.diagnostics.get(diagnostic::x0);
    EXPECT_LT((x0 - lo.x0).cwiseAbs().maxCoeff(), 1e-5) << x0.transpose();
    SimulateOptions so;
    so.initial = InitialCondition::Estimated;
    so.x0 = x0;
    EXPECT_LT((simulate(AnyModel(r.model), d, so).y.col(0) - y).cwiseAbs().maxCoeff(), 1e-6);
  }
  const Result<TransferFunction> rest = tfest(d, {2, 2, 0});
  EXPECT_GT((rest.parameters.values - want).cwiseQuotient(want).cwiseAbs().maxCoeff(), 1e-2);

  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  Eigen::VectorXd yn = y;
  for (Eigen::Index k = 0; k < n; ++k) yn(k) += noise(rng);
  const Result<TransferFunction> r = tfest(IdData(u, yn, 0.01), {2, 2, 0}, o);
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  for (int i = 0; i < 4; ++i) EXPECT_LT(std::abs(r.parameters.values(i) - want(i)), 3.5 * r.parameters.std(i)) << i;
  o.transient_time = 1.0;
  const std::string both = ctid::test::error_of([&] { tfest(d, {2, 2, 0}, o); });
  EXPECT_NE(both.find("estimate_initial_state and transient_time = 1 s are alternatives"), std::string::npos) << both;
}

// The same record not at rest, 50 noise realisations (std 0.05): the estimates with estimate_initial_state are
// unbiased (|mean error| < 0.5 spread: 3.5 standard errors of the mean of 50) and the reported standard deviation,
// with the initial conditions eliminated by the Schur complement, is the spread within 30 %. Measured here: |bias|
// 0.05-0.08 spread, reported std / spread 0.95-1.06 (and 0.86-1.02 over 100 runs of another seed).
TEST(OutputError, InitialConditionMonteCarloCovarianceIsTheSpread) {
  const TransferFunction truth(Polynomial{1.0, 3.0}, Polynomial{1.0, 1.2, 4.0});
  const int n = 2000, R = 50;
  const Eigen::VectorXd u = prbs(n, {.register_length = 9, .clock_period = 12});
  LsimOptions lo;
  lo.x0 = Eigen::Vector2d(1.5, -0.7);
  const Eigen::VectorXd y = lsim(truth.to_state_space(), u, time_grid(0.01, n), {Intersample::Zoh}, lo).col(0);
  const Eigen::Vector4d want(1.2, 4.0, 1.0, 3.0);
  OeOptions o;
  o.estimate_initial_state = true;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.05);
  Eigen::MatrixXd err(R, 4), sd(R, 4);
  for (int k = 0; k < R; ++k) {
    Eigen::VectorXd yn = y;
    for (Eigen::Index i = 0; i < n; ++i) yn(i) += noise(rng);
    const Result<TransferFunction> r = tfest(IdData(u, yn, 0.01), {2, 2, 0}, o);
    ASSERT_TRUE(r.usable()) << r.why_not_usable();
    err.row(k) = (r.parameters.values.head(4) - want).transpose();
    sd.row(k) = r.parameters.std.head(4).transpose();
  }
  for (int i = 0; i < 4; ++i) {
    const double mean = err.col(i).mean();
    const double spread = std::sqrt((err.col(i).array() - mean).square().sum() / (R - 1));
    std::printf("parameter %d: bias / spread %.3f, reported std / spread %.3f\n", i, mean / spread, sd.col(i).mean() / spread);
    EXPECT_LT(std::abs(mean), 0.5 * spread) << i;
    EXPECT_NEAR(sd.col(i).mean() / spread, 1.0, 0.3) << i;
  }
}
