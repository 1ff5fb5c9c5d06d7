// Stage 2 of Gawthrop & Wang (2005): physical-model expressions, exact sensitivities and the
// simulated stand-ins of the experiments of Gawthrop & Wang 2005, §5.
#include <cmath>
#include <random>

#include <unsupported/Eigen/MatrixFunctions>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/estimate/fsf/fsf.hpp"
#include "ctid/estimate/fsf/physical.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/simulate/closed_loop.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/simulate/simulate.hpp"
#include "test_util.hpp"

using namespace ctid;
using test::error_of;

namespace {

// Unstable circuit stand-in: 1/(s^2 - 1) under digital PD (Gawthrop & Wang 2005, §5, simulated).
IdData circuit(double noise_sd, std::uint64_t seed, std::uint64_t reference_seed = 1, int M = 4000) {
  const double Ts = 0.01;
  std::mt19937_64 rng(reference_seed);
  std::uniform_int_distribution<int> coin(0, 1);
  Eigen::VectorXd w(M);
  for (int i = 0; i < M; ++i) w(i) = i % 150 == 0 ? (coin(rng) ? 0.5 : -0.5) : w(i - 1);
  // PD u = 3 (w - y - D), D the derivative of y filtered with 0.1 s.
  return simulate_closed_loop(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 0.0, -1.0}}),
                              RstController::pid(3.0, 0.0, 3.0, 0.1, Ts), w, Ts, white_noise(M, noise_sd, seed));
}
}  // namespace

TEST(PhysicalModel, ExpressionsExpandToTheRightTransferFunction) {
  const PhysicalModel m("(R*C*s + 1)/(L*C*s^2 + R*C*s + 1)", {"R", "L", "C"});
  const TransferFunction g = m.transfer_function(Eigen::VectorXd{{2.0, 0.5, 4.0}});
  // (8 s + 1)/(2 s^2 + 8 s + 1) -> monic: (4 s + 0.5)/(s^2 + 4 s + 0.5)
  EXPECT_LT((g.num().coefficients() - Eigen::VectorXd{{4.0, 0.5}}).norm(), 1e-14);
  EXPECT_LT((g.den().coefficients() - Eigen::VectorXd{{1.0, 4.0, 0.5}}).norm(), 1e-14);
  const PhysicalModel u("k1/(s^2 - k2)", {"k1", "k2"});
  const TransferFunction sh = u.shifted(Eigen::VectorXd{{1.0, 1.0}}, 2.0);  // 1/((s+2)^2 - 1)
  EXPECT_LT((sh.den().coefficients() - Eigen::VectorXd{{1.0, 4.0, 3.0}}).norm(), 1e-14);
  EXPECT_EQ(PhysicalModel::symbols("K/s^2 + -2*x"), (std::vector<std::string>{"K", "x"}));
  EXPECT_NEAR(PhysicalModel("K/(s+1)^3", {"K"}).transfer_function(Eigen::VectorXd{{2.0}}).dc_gain(), 2.0, 1e-14);
}

TEST(PhysicalModel, ErrorsNameTheColumn) {
  EXPECT_EQ(error_of([] { PhysicalModel("k1/(s^2 - k3)", {"k1", "k2"}); }),
            "expression \"k1/(s^2 - k3)\": unknown symbol 'k3' (parameters: k1, k2) at column 11");
  EXPECT_EQ(error_of([] { PhysicalModel("k1/(s^2 -", {"k1"}); }), "expression \"k1/(s^2 -\": unexpected end of expression at column 10");
  EXPECT_EQ(error_of([] { PhysicalModel("k1/(s^2))", {"k1"}); }), "expression \"k1/(s^2))\": unexpected ')' at column 9");
  EXPECT_NE(error_of([] { PhysicalModel("k*s^2/(s+1)", {"k"}).transfer_function(Eigen::VectorXd{{1.0}}); }).find("not a proper"),
            std::string::npos);
  EXPECT_NE(error_of([] { PhysicalModel("k/s^x", {"k", "x"}); }).find("exponent"), std::string::npos);
}

TEST(PhysicalModel, SensitivitiesMatchFiniteDifferences) {
  // dG/dTheta_k (s + a) from the gradient-carrying expansion vs central differences of G(s + a):
  // compared on the frequency response at a few points (relative error ~ h^2 ~ 1e-10).
  const PhysicalModel m("(R*C*s + 1)/(L*C*s^2 + R*C*s + 1)", {"R", "L", "C"});
  const Eigen::VectorXd th{{2.0, 0.5, 4.0}}, w{{0.1, 1.0, 7.0}};
  for (double a : {0.0, 1.5}) {
    const auto sens = m.sensitivities(th, a);
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-5 * std::abs(th(k));
      Eigen::VectorXd p = th, q = th;
      p(k) += h;
      q(k) -= h;
      const Eigen::VectorXcd fd = (m.shifted(p, a).frequency_response(w) - m.shifted(q, a).frequency_response(w)) / (2 * h);
      EXPECT_LT((fd - sens[k].frequency_response(w)).norm() / fd.norm(), 1e-8) << k << " a=" << a;
    }
  }
}

TEST(PhysicalModel, StateSpaceAndCallableFormsMatchTheTransferFunctionForm) {
  // Mass-spring-damper x'' = (f - d x' - k x)/m written three ways; the shifted transfer functions
  // and the sensitivities (sensitivity equations for the state-space forms) agree to 1e-9.
  const PhysicalModel tf("1/(m*s^2 + d*s + k)", {"m", "d", "k"});
  const PhysicalModel ss = PhysicalModel::from_state_space({{"0", "1"}, {"-k/m", "-d/m"}}, {{"0"}, {"1/m"}}, {{"1", "0"}},
                                                           {{"0"}}, {"m", "d", "k"});
  const PhysicalModel cb = PhysicalModel::from_callable(
      [](const Eigen::VectorXd& p) {
        const double m = p(0), d = p(1), k = p(2);
        StateSpaceWithGradient g{StateSpace(Eigen::MatrixXd{{0, 1}, {-k / m, -d / m}}, Eigen::MatrixXd{{0}, {1 / m}},
                                            Eigen::MatrixXd{{1, 0}}, Eigen::MatrixXd{{0}}),
                                 {}};
        const Eigen::MatrixXd Zb = Eigen::MatrixXd::Zero(2, 1);
        const Eigen::MatrixXd Zc = Eigen::MatrixXd::Zero(1, 2), Zd = Eigen::MatrixXd::Zero(1, 1);
        g.derivatives.emplace_back(Eigen::MatrixXd{{0, 0}, {k / (m * m), d / (m * m)}}, Eigen::MatrixXd{{0}, {-1 / (m * m)}}, Zc, Zd);
        g.derivatives.emplace_back(Eigen::MatrixXd{{0, 0}, {0, -1 / m}}, Zb, Zc, Zd);
        g.derivatives.emplace_back(Eigen::MatrixXd{{0, 0}, {-1 / m, 0}}, Zb, Zc, Zd);
        return g;
      },
      {"m", "d", "k"});
  const Eigen::VectorXd th{{2.0, 0.6, 3.0}}, w{{0.2, 1.1, 5.0}};
  for (double a : {0.0, 1.0}) {
    const Eigen::VectorXcd ref = tf.shifted(th, a).frequency_response(w);
    const auto sref = tf.sensitivities(th, a);
    for (const PhysicalModel* m : {&ss, &cb}) {
      EXPECT_LT((m->shifted(th, a).frequency_response(w) - ref).norm(), 1e-9 * ref.norm()) << a;
      const auto sens = m->sensitivities(th, a);
      for (int k = 0; k < 3; ++k) {
        const Eigen::VectorXcd r = sref[k].frequency_response(w);
        EXPECT_LT((sens[k].frequency_response(w) - r).norm(), 1e-9 * r.norm()) << k;
      }
    }
  }
  EXPECT_NE(error_of([] { PhysicalModel::from_state_space({{"s"}}, {{"1"}}, {{"1"}}, {{"0"}}, {}).transfer_function(Eigen::VectorXd(0)); })
                .find("must not contain s"),
            std::string::npos);
  EXPECT_NE(error_of([] { PhysicalModel::from_state_space({{"0", "1"}}, {{"1"}}, {{"1"}}, {{"0"}}, {}); }).find("square"),
            std::string::npos);
  EXPECT_NE(error_of([] { PhysicalModel::from_state_space({{"q"}}, {{"1"}}, {{"1"}}, {{"0"}}, {"k"}); }).find("unknown symbol 'q'"),
            std::string::npos);
}

TEST(GawthropWang, UnstableCircuitTwoStageReachesThePhysicalParameters) {
  // Gawthrop & Wang 2005, §5, simulated: a = 2, b = 0, T = 8 s, LM from (2, 0). Independently verified noise-free results:
  // (0.973, 1.040) for n = 11 and (0.987, 1.013) for n = 21 — reproduced here to 1e-3; the issue's
  // criterion is within 5 % of (1, 1). The frequency route (GW 30) agrees with the time-domain one
  // (measured differences 3.5 % for n = 11, 0.3 % for n = 21; bound 5 %), and the raw-data route
  // (windowed output error, simulated exactly) gives (1, 1).
  const IdData d = circuit(0.0, 0);
  const PhysicalModel m("k1/(s^2 - k2)", {"k1", "k2"});
  const std::vector<PhysicalParameter> start{{"k1", 2.0}, {"k2", 0.0}};
  const Eigen::VectorXd spec11{{0.973, 1.040}}, spec21{{0.987, 1.013}};
  for (int n : {11, 21}) {
    const auto c = fsf(d, {.T = 8.0, .n = n, .a = 2.0});
    const auto r = fit_physical_step(m, start, c.model);
    ASSERT_EQ(r.summary.termination, Termination::Converged) << r.summary.message;
    EXPECT_LT((r.parameters.values - (n == 11 ? spec11 : spec21)).cwiseAbs().maxCoeff(), 1e-3) << n;
    EXPECT_LT((r.parameters.values.array() - 1.0).abs().maxCoeff(), 0.05);
    EXPECT_LE(r.summary.iterations, 10);  // the paper: about 4 LM steps
    const auto f = fit_physical_frequency(m, start, c.model);
    EXPECT_LT((f.parameters.values - r.parameters.values).cwiseAbs().maxCoeff(), 0.05) << n;
    // fit is the simulation fit on the record, windowed by e^{-2t} as the raw route measures it;
    // the match to the compressed response is compressed_fit_percent; without the record no fit is computed.
    const auto rd = fit_physical_step(m, start, c.model, {}, &d);
    EXPECT_EQ(rd.parameters.values, r.parameters.values);
    EXPECT_EQ(r.fit.n_samples, 0);
    EXPECT_EQ(rd.fit.n_samples, d.size());
    // Measured: simulation fit 97.60 % (n = 11) and 98.86 % (n = 21), compressed 98.13 % and 99.54 %: the parameters
    // (0.973, 1.040) and (0.987, 1.013) miss (1, 1) by the FSF truncation, which the record shows.
    EXPECT_NEAR(rd.fit.fit_percent, n == 11 ? 97.60 : 98.86, 0.01) << n;
    EXPECT_NEAR(rd.diagnostics.get(diagnostic::compressed_fit_percent), n == 11 ? 98.13 : 99.54, 0.01) << n;
    EXPECT_EQ(rd.diagnostics.get(diagnostic::compressed_fit_percent), r.diagnostics.get(diagnostic::compressed_fit_percent));
    EXPECT_TRUE(rd.usable()) << rd.why_not_usable();
    EXPECT_LT((f.parameters.values.array() - 1.0).abs().maxCoeff(), 0.05) << n;
  }
  const auto raw = fit_physical_raw(m, start, d, 2.0);
  EXPECT_LT((raw.parameters.values.array() - 1.0).abs().maxCoeff(), 1e-6);
  EXPECT_NEAR(raw.diagnostics.get(diagnostic::max_pole_real_part), 1.0, 1e-6);  // poles +-1 < a = 2: no window warning
  for (const auto& w : raw.diagnostics.warnings) EXPECT_EQ(w.find("does not exceed"), std::string::npos) << w;
  // A window below the pole at +1 (a = 0.5; k2 held and k1 bounded near the truth so that the fitted plant keeps it):
  // the warning names what the raw route compares (the windowed simulation), not a compressed response, which this
  // route does not form.
  PhysicalFitOptions near;
  near.fixed = {{"k2", 1.0}};
  near.bounds = {{"k1", {0.999, 1.001}}};
  const auto narrow = fit_physical_raw(m, start, d, 0.5, near);
  EXPECT_NEAR(narrow.diagnostics.get(diagnostic::max_pole_real_part), 1.0, 2e-3);
  int named = 0;
  for (const auto& w : narrow.diagnostics.warnings)
    if (w.find("does not exceed") != std::string::npos) {
      ++named;
      EXPECT_NE(w.find("windowed simulation"), std::string::npos) << w;
      EXPECT_EQ(w.find("compressed"), std::string::npos) << w;
    }
  EXPECT_EQ(named, 1);
  // The options' constraint vocabulary (fixed.NAME, bounds.NAME, as for oe) is the declarations': k2 fixed at its
  // true value 1 leaves k1 = 1 (to 1e-6) with k2's std 0; the same through a PhysicalParameter declaration gives the
  // same numbers to 1e-12; a bound that excludes the truth holds (k1 <= 0.8: k1 ends at the bound); a name that is
  // not a parameter is refused with the closest one.
  PhysicalFitOptions fo;
  fo.fixed = {{"k2", 1.0}};
  const auto by_option = fit_physical_raw(m, start, d, 2.0, fo);
  const auto by_declaration = fit_physical_raw(m, {{"k1", 2.0}, {"k2", 1.0, -INFINITY, INFINITY, true}}, d, 2.0);
  EXPECT_NEAR(by_option.parameters.value("k1"), 1.0, 1e-6);
  EXPECT_EQ(by_option.parameters.std(1), 0.0);
  EXPECT_TRUE(by_option.parameters.fixed[1]);
  EXPECT_NEAR(by_option.parameters.value("k1"), by_declaration.parameters.value("k1"), 1e-12);
  PhysicalFitOptions bo;
  bo.bounds = {{"k1", {0.0, 0.8}}};
  EXPECT_NEAR(fit_physical_raw(m, start, d, 2.0, bo).parameters.value("k1"), 0.8, 1e-9);
  PhysicalFitOptions bad;
  bad.fixed = {{"k3", 1.0}};
  EXPECT_NE(test::error_of([&] { fit_physical_raw(m, start, d, 2.0, bad); }).find("fixed.k3: 'k3' is not a parameter"),
            std::string::npos);

  // The same plant as a state-space structure gives the same two-stage estimate. Both LM runs stop
  // at the solver tolerance and the state-space Jacobian comes from a defective 4x4 sensitivity
  // system (eigenvalue perturbations ~ sqrt(eps)), so the stopping points differ slightly:
  // measured 1.0e-6 (sanitizer build, -O1) and below that at -O3; bound 1e-5.
  const PhysicalModel ms = PhysicalModel::from_state_space({{"0", "1"}, {"k2", "0"}}, {{"0"}, {"k1"}}, {{"1", "0"}}, {{"0"}},
                                                           {"k1", "k2"});
  const auto c21 = fsf(d, {.T = 8.0, .n = 21, .a = 2.0});
  EXPECT_LT((fit_physical_step(ms, start, c21.model).parameters.values - fit_physical_step(m, start, c21.model).parameters.values)
                .cwiseAbs()
                .maxCoeff(),
            1e-5);
  // With output noise (sigma = 0.05), ten seeds: mean within 5 % of (1, 1) (spec: 0.971, 1.026).
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(2);
  for (int s = 1; s <= 10; ++s)
    mean += fit_physical_step(m, start, fsf(circuit(0.05, s), {.T = 8.0, .n = 21, .a = 2.0}).model).parameters.values / 10;
  EXPECT_LT((mean.array() - 1.0).abs().maxCoeff(), 0.05);
}

// Nothing hand-picked. With only "the plant is unstable" declared, fsf() takes a, T and n from an LSSVF
// pre-estimate (equation error, which serves a closed loop): noise-free, measured a = 1.37 (1.5 times the pre-estimate's
// unstable pole 0.91; GW used 2), T = 16.6 s, n = 33, and the two-stage estimate (0.993, 1.003) — within 5 % of (1, 1)
// as with the hand-picked settings above. With noise sigma = 0.05 the mean of ten seeds is within 5 % as well (40
// seeds: mean (0.997, 1.001), spread 0.036 / 0.023, against 0.054 / 0.060 with the hand-picked a = 2).
TEST(GawthropWang, AutomaticWindowReachesThePhysicalParametersOfTheUnstableCircuit) {
  const PhysicalModel m("k1/(s^2 - k2)", {"k1", "k2"});
  const std::vector<PhysicalParameter> start{{"k1", 2.0}, {"k2", 0.0}};
  FsfOptions o;
  o.unstable = true;
  const auto c = fsf(circuit(0.0, 0), o);
  ASSERT_TRUE(c.usable()) << c.why_not_usable();
  EXPECT_GT(c.model.shift(), 1.0);  // a must exceed the unstable pole at +1
  EXPECT_LT(c.model.shift(), 3.0);
  ASSERT_EQ(c.diagnostics.choices.size(), 3u);  // a, T, n: each stated
  EXPECT_EQ(c.diagnostics.choices[0].rfind("a = ", 0), 0u) << c.diagnostics.choices[0];
  EXPECT_EQ(c.diagnostics.choices[1].rfind("T = ", 0), 0u) << c.diagnostics.choices[1];
  EXPECT_EQ(c.diagnostics.choices[2].rfind("n = ", 0), 0u) << c.diagnostics.choices[2];
  const auto r = fit_physical_step(m, start, c.model);
  EXPECT_LT((r.parameters.values.array() - 1.0).abs().maxCoeff(), 0.05) << r.parameters.values.transpose();
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(2);
  for (int s = 1; s <= 10; ++s) mean += fit_physical_step(m, start, fsf(circuit(0.05, s), o).model).parameters.values / 10;
  EXPECT_LT((mean.array() - 1.0).abs().maxCoeff(), 0.05) << mean.transpose();
}

// Several experiments on the raw route: open-loop records of k1/(s^2 + k2 s + k3) = 4/(s^2 + 0.8 s
// + 4), PRBS inputs of different clock periods, 1000 samples at 20 ms each, white output noise of std 0.1 (about 10 %
// of the output's RMS). Noise-free the joint fit gives the truth to 1e-6. 100 runs: the joint RMS error is below
// either record's for every parameter and the reported standard deviation is within 25 % of the spread (100 runs
// estimate a spread to ~7 %).
TEST(GawthropWang, RawRouteOnSeveralRecordsIsOneFitMoreAccurateThanEither) {
  const PhysicalModel m("k1/(s^2 + k2*s + k3)", {"k1", "k2", "k3"});
  const std::vector<PhysicalParameter> start{{"k1", 3.0}, {"k2", 1.0}, {"k3", 3.0}};
  const Eigen::Vector3d truth(4.0, 0.8, 4.0);
  const TransferFunction g(Eigen::VectorXd{{4.0}}, Eigen::VectorXd{{1.0, 0.8, 4.0}});
  const int N = 1000;
  const Eigen::VectorXd t = time_grid(0.02, N);
  const Eigen::VectorXd ua = prbs(N, {.register_length = 8, .clock_period = 6});
  const Eigen::VectorXd ub = prbs(N, {.register_length = 7, .clock_period = 15, .initial_state = 9});
  const Eigen::VectorXd xa = lsim(g, ua, t), xb = lsim(g, ub, t);
  const auto exact = fit_physical_raw(m, start, std::vector<IdData>{IdData(ua, xa, 0.02), IdData(ub, xb, 0.02)});
  EXPECT_LT((exact.parameters.values - truth).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(exact.diagnostics.get(diagnostic::experiments), 2);
  const int R = 100;
  Eigen::MatrixXd e1(R, 3), e2(R, 3), ej(R, 3), sj(R, 3);
  for (int run = 0; run < R; ++run) {
    const IdData a(ua, xa + white_noise(N, 0.1, 300 + 2 * run), 0.02), b(ub, xb + white_noise(N, 0.1, 301 + 2 * run), 0.02);
    e1.row(run) = (fit_physical_raw(m, start, a).parameters.values - truth).transpose();
    e2.row(run) = (fit_physical_raw(m, start, b).parameters.values - truth).transpose();
    const auto j = fit_physical_raw(m, start, std::vector<IdData>{a, b});
    ASSERT_TRUE(j.usable()) << j.why_not_usable();
    ej.row(run) = (j.parameters.values - truth).transpose();
    sj.row(run) = j.parameters.std.transpose();
  }
  for (int i = 0; i < 3; ++i) {
    auto rmse = [&](const Eigen::MatrixXd& e) { return std::sqrt(e.col(i).squaredNorm() / R); };
    const double mean = ej.col(i).mean(), sd = std::sqrt((ej.col(i).array() - mean).square().sum() / (R - 1));
    std::printf("k%d: rmse joint %.4g, record 1 %.4g, record 2 %.4g; reported std / spread %.3f\n", i + 1, rmse(ej),
                rmse(e1), rmse(e2), sj.col(i).mean() / sd);
    EXPECT_LT(rmse(ej), std::min(rmse(e1), rmse(e2))) << "k" << i + 1;
    EXPECT_NEAR(sj.col(i).mean() / sd, 1.0, 0.25) << "k" << i + 1;
  }
}

TEST(GawthropWang, BallAndBeamWithinOnePercentAlsoWithThePapersBWhereTheFsfSpansTheRecord) {
  // Gawthrop & Wang 2005, §5, simulated: 2.5/s^2 under PID u = sat(Kp(w-y) - Kd s/(1+Tf s) y + Ki int(w-y)), |u| <= 1.5,
  // Kp = 1, Kd = 0.8, Ki = 0.1, Tf = 0.05, Ts = 0.01, square-wave set-point +-0.5 (20 s period),
  // measurement noise 0.02, 60 s (a stand-in: the paper's data are not public); a = 1, T = 10 s, n = 21: b = 0
  // gives K within 1 % of 2.5.
  const double Ts = 0.01;
  const int M = 6000;
  Eigen::VectorXd w(M);
  for (int i = 0; i < M; ++i) w(i) = std::fmod(i * Ts, 20.0) < 10.0 ? 0.5 : -0.5;
  RstController pid = RstController::pid(1.0, 0.1, 0.8, 0.05, Ts);
  pid.u_min = -1.5;
  pid.u_max = 1.5;
  const IdData data = simulate_closed_loop(TransferFunction(Eigen::VectorXd{{2.5}}, Eigen::VectorXd{{1.0, 0.0, 0.0}}),
                                           pid, w, Ts, white_noise(M, 0.02, 11));
  const PhysicalModel m("K/s^2", {"K"});
  const auto c0 = fsf(data, {.T = 10.0, .n = 21, .a = 1.0});
  EXPECT_TRUE(c0.diagnostics.warnings.empty());
  const auto r0 = fit_physical_step(m, {{"K", 1.0}}, c0.model);
  EXPECT_NEAR(r0.parameters.value("K"), 2.5, 0.025);
  // Linear in K: the paper reports one LM step; LM needs a few more to meet its stopping test.
  EXPECT_LE(r0.summary.iterations, 6);
  EXPECT_NEAR(r0.diagnostics.get(diagnostic::cost_history)(1), r0.diagnostics.get(diagnostic::cost), 1e-3 * r0.diagnostics.get(diagnostic::cost_history)(0));
  // The paper's b = 0.9 ("K ~ 2.5 in exactly one step") holds where the FSF spans the record: on the first 10 s
  // (one set-point level) with T = 10 s and n = 161 frequency samples (the saturated PID's edges need them: n = 21
  // gives 1.955, 81 gives 2.468 noise-free), K is within 1 % of 2.5 and the first step reaches the final cost.
  // The figure caption that gave the paper's T, n and record length is lost in the source.
  const auto c9 = fsf(data.slice(0, 1000), {.T = 10.0, .n = 161, .a = 1.0, .b = 0.9});
  const auto r9 = fit_physical_step(m, {{"K", 1.0}}, c9.model);
  EXPECT_NEAR(r9.parameters.value("K"), 2.5, 0.025);
  EXPECT_NEAR(r9.diagnostics.get(diagnostic::cost_history)(1), r9.diagnostics.get(diagnostic::cost), 1e-3 * r9.diagnostics.get(diagnostic::cost_history)(0));
  // On the whole 60 s record with T = 10 s, b = 0.9 weights the late data, where the windowed double integrator's
  // response beyond T (K tau e^{-tau} u_a, growing like e^{(b - a) t} t^2 in the weighted residual) is not in the
  // model: K collapses (0.57, noise-free 0.56) and ctid warns that b > 0 with a record longer than T.
  const auto c9long = fsf(data, {.T = 10.0, .n = 21, .a = 1.0, .b = 0.9});
  ASSERT_FALSE(c9long.diagnostics.warnings.empty());
  EXPECT_LT(fit_physical_step(m, {{"K", 1.0}}, c9long.model).parameters.value("K"), 1.0);
  // Without a window (a = 0) the double integrator's poles at 0 are not covered: warned about.
  const auto r_nowin = fit_physical_step(m, {{"K", 1.0}}, fsf(data, {.T = 10.0, .n = 21}).model);
  bool warned = false;
  for (const auto& w : r_nowin.diagnostics.warnings) warned = warned || w.find("does not exceed") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(GawthropWang, BadParameterSets) {
  const PhysicalModel m("k1/(s^2 - k2)", {"k1", "k2"});
  const FsfModel f(0.01, 100, 5, Eigen::VectorXd::Ones(5), {}, 2.0);
  EXPECT_THROW(fit_physical_step(m, {{"k1", 1.0}}, f), InvalidOptions);                 // k2 without initial value
  EXPECT_THROW(fit_physical_step(m, {{"k1", 1.0}, {"k9", 1.0}}, f), InvalidOptions);    // unknown name
  EXPECT_THROW(fit_physical_step(m, {{"k1", NAN}, {"k2", 0.0}}, f), InvalidOptions);    // no value
  EXPECT_THROW(fit_physical_step(m, {{"k1", 1.0, 2.0, 1.0}, {"k2", 0.0}}, f), InvalidOptions);  // empty bounds
}

TEST(GawthropWang, FastSamplingGivesTheSameParametersWhileArxDegrades) {
  // The paper's claim: the FSF coefficients converge to sampling-rate-independent values, so the
  // two-stage estimate is the same at 1 ms and 0.1 ms, whereas a discrete ARX model converted to
  // continuous time degrades as sampling gets faster. Unstable circuit under continuous-equivalent
  // PD, 40 s, output noise 0.01. Measured: (0.9949, 1.0076) at 1 ms, (0.9991, 1.0036) at 0.1 ms;
  // ARX(2,2,1) + d2c gives k1 = 660 and 61500.
  auto circuit_at = [](double Ts) {
    const int M = static_cast<int>(std::lround(40.0 / Ts));
    Eigen::VectorXd w(M);
    for (int i = 0; i < M; ++i) w(i) = static_cast<int>(i * Ts / 1.5) % 3 == 0 ? 0.5 : -0.5;
    return simulate_closed_loop(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 0.0, -1.0}}),
                                RstController::pid(3.0, 0.0, 3.0, 0.1, Ts), w, Ts, white_noise(M, 0.01, 3));
  };
  // ARX(2,2,1) by least squares, converted with the matrix logarithm (ZOH); returns k1 of k1/(s^2 - k2).
  auto arx_k1 = [](const IdData& d) {
    const Eigen::VectorXd u = d.u().col(0), y = d.y().col(0);
    const Eigen::Index N = y.size();
    Eigen::MatrixXd X(N - 2, 4);
    Eigen::VectorXd Y(N - 2);
    for (Eigen::Index k = 2; k < N; ++k) {
      X.row(k - 2) << -y(k - 1), -y(k - 2), u(k - 1), u(k - 2);
      Y(k - 2) = y(k);
    }
    const Eigen::VectorXd th = X.colPivHouseholderQr().solve(Y);
    const Eigen::MatrixXd Phi{{-th(0), 1}, {-th(1), 0}}, Gam{{th(2)}, {th(3)}};
    const Eigen::MatrixXd A = Phi.cast<std::complex<double>>().log().real() / d.ts();
    const Eigen::MatrixXd B = (Phi - Eigen::MatrixXd::Identity(2, 2)).fullPivLu().solve(A * Gam);
    return StateSpace(A, B, Eigen::MatrixXd{{1, 0}}, Eigen::MatrixXd::Zero(1, 1)).to_transfer_function().num().coefficient_of_power(0);
  };
  const PhysicalModel m("k1/(s^2 - k2)", {"k1", "k2"});
  Eigen::MatrixXd est(2, 2);
  int row = 0;
  for (double Ts : {1e-3, 1e-4}) {
    const IdData d = circuit_at(Ts);
    est.row(row++) = fit_physical_step(m, {{"k1", 2.0}, {"k2", 0.0}}, fsf(d, {.T = 8.0, .n = 21, .a = 2.0}).model)
                         .parameters.values.transpose();
    EXPECT_GT(std::abs(arx_k1(d) - 1.0), 0.5) << Ts;
  }
  EXPECT_LT((est.row(0) - est.row(1)).cwiseAbs().maxCoeff(), 0.01);
  EXPECT_LT((est.array() - 1.0).abs().maxCoeff(), 0.01);
}

// The raw route on a record that does not start at rest (initial-condition estimation for physical
// models). The mass-spring-damper 1/(m s^2 + d s + k), m = 0.5, d = 0.4, k = 2, from the state (0.8, -1.2) of the
// transfer function's realisation, PRBS force, noise-free: with estimate_initial_state both the transfer-function
// and the state-space form recover the parameters to 1e-6 and diagnostics x0 is that state to 1e-5; from rest the
// same record gives a wrong model (measured m = 11.3, d = -4.3, k = 38). The FSF routes refuse the option.
TEST(PhysicalRaw, TheInitialStateOfARecordNotAtRestIsEstimated) {
  const TransferFunction truth(Polynomial{1.0}, Polynomial{0.5, 0.4, 2.0});
  const int n = 1500;
  const Eigen::VectorXd u = prbs(n, {.register_length = 8, .clock_period = 15});
  const Eigen::VectorXd t = time_grid(0.01, n);
  LsimOptions lo;
  lo.x0 = Eigen::Vector2d(0.8, -1.2);
  const IdData d(u, lsim(truth.to_state_space(), u, t, {Intersample::Zoh}, lo).col(0), 0.01);
  const std::vector<PhysicalParameter> start = {{"m", 0.8}, {"d", 0.2}, {"k", 1.5}};
  const Eigen::Vector3d want(0.5, 0.4, 2.0);
  PhysicalFitOptions o;
  o.estimate_initial_state = true;
  const PhysicalModel tf("1/(m*s^2 + d*s + k)", {"m", "d", "k"});
  const PhysicalModel ss = PhysicalModel::from_state_space({{"0", "1"}, {"-k/m", "-d/m"}}, {{"0"}, {"1/m"}}, {{"1", "0"}},
                                                           {{"0"}}, {"m", "d", "k"});
  for (const PhysicalModel* m : {&tf, &ss}) {
    const Result<TransferFunction> r = fit_physical_raw(*m, start, d, 0.0, o);
    ASSERT_TRUE(r.usable()) << r.why_not_usable();
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(r.parameters.values(i), want(i), 1e-6 * want(i)) << m->expression() << " " << i;
    EXPECT_LT((r.diagnostics.get(diagnostic::x0) - lo.x0).cwiseAbs().maxCoeff(), 1e-5) << m->expression();
    EXPECT_GT(r.fit.fit_percent, 99.999);
  }
  const Result<TransferFunction> rest = fit_physical_raw(tf, start, d);
  EXPECT_GT((rest.parameters.values - want).cwiseQuotient(want).cwiseAbs().maxCoeff(), 0.1);
  const FsfModel compressed = fsf(d, {.T = 15.0, .n = 21}).model;
  EXPECT_NE(error_of([&] { fit_physical_step(tf, start, compressed, o); }).find("applies to the raw route"), std::string::npos);
}
