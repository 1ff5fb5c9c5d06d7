// simulate(AnyModel, IdData, initial condition): the one simulation of every front end.
// Expected values are closed forms or the model classes' own simulations, tolerances stated per check.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/simulate/simulate.hpp"
#include "test_util.hpp"

using namespace ctid;

namespace {
const TransferFunction kSecondSim(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}});  // (s+3)/(s^2+1.2s+4)
const TransferFunction kFirstDelayed(Eigen::VectorXd{{2.0}}, Eigen::VectorXd{{1.0, 0.5}}, 0.13);       // 2 e^{-0.13s}/(s+0.5)

Eigen::VectorXd random_input(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  Eigen::VectorXd u(n);
  for (int k = 0; k < n; ++k) u(k) = k % 20 == 0 || k == 0 ? g(rng) : u(k - 1);  // held steps
  return u;
}

template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "(no exception)";
}
}  // namespace

// A record started from a non-zero state: "estimated" recovers that state (noise-free: to 1e-7 of its size, the
// output to 1e-9 of its range); "rest" does not fit the start; "measured" has no meaning for a transfer function.
TEST(Simulate, EstimatedInitialStateOfLinearModelsIsTheOneThatMadeTheRecord) {
  const int n = 800;
  const double ts = 0.02;
  const Eigen::VectorXd u1 = random_input(n, 1), u2 = random_input(n, 2), t = time_grid(ts, n);
  // SISO: the state of the transfer function's realisation.
  const Eigen::VectorXd x0{{0.8, -1.5}};
  LsimOptions o;
  o.x0 = x0;
  const Eigen::MatrixXd y = lsim(kSecondSim.to_state_space(), Eigen::MatrixXd(u1), t, {Intersample::Zoh}, o);
  const IdData d(u1, y, ts);
  const Simulation est = simulate(kSecondSim, d, {InitialCondition::Estimated, {}});
  ASSERT_TRUE(est.ok()) << est.problem;
  EXPECT_LT((est.x0 - x0).norm(), 1e-7 * x0.norm());
  EXPECT_LT((est.y - y).cwiseAbs().maxCoeff(), 1e-9 * (y.maxCoeff() - y.minCoeff()));
  const Simulation rest = simulate(kSecondSim, d);
  EXPECT_EQ(rest.x0.size(), 0);
  EXPECT_GT(std::abs(rest.y(0, 0) - y(0, 0)), 0.5);  // y(0) = C x0 = -1.5 + 3 * 0.8 = 0.9 against 0 from rest
  EXPECT_NE(message_of([&] { simulate(kSecondSim, d, {InitialCondition::Measured, {}}); }).find("no output history"),
            std::string::npos);
  // MISO with a delayed channel: the channels' states stacked (2 + 1).
  const MisoModel miso{{kSecondSim, kFirstDelayed}};
  Eigen::MatrixXd u(n, 2);
  u << u1, u2;
  const IdData d2(u, Eigen::VectorXd::Zero(n), ts);
  const Eigen::VectorXd x0m{{0.8, -1.5, 2.0}};
  const Simulation made = simulate(miso, d2, {InitialCondition::Estimated, x0m});  // a given x0 is used as given
  EXPECT_EQ(made.x0, x0m);
  const Simulation back = simulate(miso, IdData(u, made.y, ts), {InitialCondition::Estimated, {}});
  EXPECT_LT((back.x0 - x0m).norm(), 1e-7 * x0m.norm());
  // The same outputs as lsim from rest when x0 is zero (the blocks are lsim's).
  EXPECT_LT((simulate(miso, d2).y.col(0) - lsim(miso, d2)).cwiseAbs().maxCoeff(), 1e-12);
}

// NARX: rest = zero output history, measured/estimated = the record's first max_lag outputs (both are the
// model's own simulate()); a record at another sampling period is refused naming it.
TEST(Simulate, NarxHistoryIsRestOrTheMeasuredOutputs) {
  const NarxModel m({NarxTerm::parse("y(k-1)"), NarxTerm::parse("u(k-2)"), NarxTerm::parse("y(k-2)*u(k-1)")},
                    Eigen::VectorXd{{0.6, 1.0, -0.1}}, 0.1);
  const int n = 300;
  const Eigen::VectorXd u = 0.5 * random_input(n, 3);
  Eigen::VectorXd y = m.simulate(u, Eigen::VectorXd{{1.0, 2.0}});
  const IdData d(u, y, 0.1);
  EXPECT_EQ(simulate(m, d).y.col(0), m.simulate(u));
  const Simulation meas = simulate(m, d, {InitialCondition::Measured, {}});
  EXPECT_EQ(meas.y.col(0), y);
  EXPECT_EQ(meas.x0, y.head(2));
  EXPECT_EQ(simulate(m, d, {InitialCondition::Estimated, {}}).y.col(0), y);
  EXPECT_NE(message_of([&] { simulate(m, IdData(u, y, 0.05)); }).find("Ts = 0.1 s"), std::string::npos);
}

// NDE: measured = y(0) from the record with zero derivatives (closed form y = 1 + (y0 - 1) e^{-2t} for
// 0.5 Dy + y = u, u = 1, to 1e-7); estimated needs the fitted x0; rest starts at 0.
TEST(Simulate, NdeStartsAtRestAtTheMeasuredOutputOrAtAGivenState) {
  const NdeModel m({NdeTerm::parse("Dy"), NdeTerm::parse("y"), NdeTerm::parse("u")}, Eigen::VectorXd{{0.5, 1.0, -1.0}});
  const int n = 200;
  const double ts = 0.01;
  const Eigen::VectorXd t = time_grid(ts, n);
  const Eigen::VectorXd y = (1.0 + 2.0 * (-2.0 * t.array()).exp()).matrix();  // y0 = 3
  const IdData d(Eigen::VectorXd::Ones(n), y, ts);
  EXPECT_LT((simulate(m, d, {InitialCondition::Measured, {}}).y.col(0) - y).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_LT((simulate(m, d, {InitialCondition::Estimated, Eigen::VectorXd{{3.0}}}).y.col(0) - y).cwiseAbs().maxCoeff(),
            1e-7);
  EXPECT_NEAR(simulate(m, d).y(0, 0), 0.0, 1e-12);
  EXPECT_NE(message_of([&] { simulate(m, d, {InitialCondition::Estimated, {}}); }).find("diagnostics x0"),
            std::string::npos);
}

// A diverging model is reported with where and why, not thrown; wrong input counts and FSF initial states are
// refused naming the values.
TEST(Simulate, DivergenceIsReportedAndMismatchesAreRefused) {
  const TransferFunction unstable(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, -5.0}});
  const int n = 20000;
  const IdData d(Eigen::VectorXd::Ones(n), Eigen::VectorXd::Zero(n), 0.1);  // e^{5 t} overflows at t ~ 142 s
  const Simulation s = simulate(unstable, d);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.problem.find("not finite from sample"), std::string::npos) << s.problem;
  EXPECT_NE(s.problem.find("unstable poles: 5+0j"), std::string::npos) << s.problem;
  EXPECT_NE(message_of([&] { simulate(MisoModel{{kSecondSim, kFirstDelayed}}, d); }).find("has 2 input(s) but the record has 1"),
            std::string::npos);
  const FsfModel fsf(0.1, 20, 3, Eigen::VectorXd{{1.0, 0.2, -0.1}});
  EXPECT_TRUE(simulate(fsf, d.slice(0, 100)).ok());
  EXPECT_NE(message_of([&] { simulate(fsf, d, {InitialCondition::Estimated, {}}); }).find("only be rest"),
            std::string::npos);
  EXPECT_THROW(initial_condition_from_string("zero"), InvalidArgument);
  EXPECT_EQ(initial_condition_from_string("measured"), InitialCondition::Measured);
}

// Responses of any model, against closed forms: a two-input state space is its two transfer
// functions (step to 1e-12 of the model's own; frequency response to 1e-12 of C (jwI - A)^-1 B); MISO columns are
// the channels' (the delay included: zero before 0.13 s); NARX y(k) = 0.6 y(k-1) + u(k-1) steps to
// (1 - 0.6^k)/0.4 exactly (to 1e-12); NDE 0.5 Dy + y = u to 1 - e^{-2t} (1e-7, the integrator's tolerance);
// nonlinear models have no impulse or frequency response and a windowed FSF model no response at all.
TEST(Simulate, ResponsesOfEveryModelType) {
  const Eigen::VectorXd t = time_grid(0.1, 60);
  Eigen::MatrixXd A(2, 2), B(2, 2), C(1, 2), D = Eigen::MatrixXd::Zero(1, 2);
  A << 0, 1, -4, -1.2;
  B << 0, 1, 1, 0.5;
  C << 3, 1;
  const StateSpace ss(A, B, C, D);
  const Eigen::MatrixXd s = model_step_response(ss, t);
  ASSERT_EQ(s.cols(), 2);
  for (int i = 0; i < 2; ++i)
    EXPECT_LT((s.col(i) - step_response(ss.to_transfer_function(0, i), t)).cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::VectorXd w{{0.1, 2.0, 30.0}};
  const Eigen::MatrixXcd g = model_frequency_response(ss, w);
  for (int k = 0; k < 3; ++k) {
    const Eigen::MatrixXcd jw = std::complex<double>(0, w(k)) * Eigen::MatrixXcd::Identity(2, 2) - A.cast<std::complex<double>>();
    const Eigen::MatrixXcd direct = C.cast<std::complex<double>>() * jw.inverse() * B.cast<std::complex<double>>();
    for (int i = 0; i < 2; ++i) EXPECT_LT(std::abs(g(k, i) - direct(0, i)), 1e-12 * std::abs(direct(0, i)));
  }
  MisoModel miso;
  miso.channels = {kSecondSim, kFirstDelayed};
  const Eigen::MatrixXd ms = model_step_response(miso, t), mi = model_impulse_response(miso, t);
  EXPECT_EQ(ms.col(0), step_response(kSecondSim, t));
  EXPECT_EQ(mi.col(1), impulse_response(kFirstDelayed, t));
  EXPECT_EQ(ms(1, 1), 0.0);  // t = 0.1 s < the delay 0.13 s
  EXPECT_EQ(model_frequency_response(miso, w).col(1), kFirstDelayed.frequency_response(w));

  const NarxModel narx({NarxTerm::parse("y(k-1)"), NarxTerm::parse("u(k-1)")}, Eigen::VectorXd{{0.6, 1.0}}, 0.1);
  const Eigen::MatrixXd ns = model_step_response(narx, t);
  for (int k = 0; k < t.size(); ++k) EXPECT_NEAR(ns(k, 0), (1 - std::pow(0.6, k)) / 0.4, 1e-12) << k;
  const NdeModel nde({NdeTerm::parse("Dy"), NdeTerm::parse("y"), NdeTerm::parse("u")}, Eigen::VectorXd{{0.5, 1.0, -1.0}});
  const Eigen::MatrixXd ds = model_step_response(nde, t);
  for (int k = 0; k < t.size(); ++k) EXPECT_NEAR(ds(k, 0), 1 - std::exp(-2 * t(k)), 1e-7) << k;
  EXPECT_NE(message_of([&] { model_impulse_response(narx, t); }).find("a narx model has no impulse response"),
            std::string::npos);
  EXPECT_NE(message_of([&] { model_frequency_response(nde, w); }).find("GFRFs"), std::string::npos);
  const FsfModel windowed(0.1, 40, 3, Eigen::VectorXd{{1.0, 0.2, -0.1}}, {}, 0.5);
  EXPECT_NE(message_of([&] { model_step_response(windowed, t); }).find("G(s + a)"), std::string::npos);
  EXPECT_NE(message_of([&] { model_step_response(kSecondSim, Eigen::VectorXd{{0.0, 0.2, 0.1}}); }).find("increase"),
            std::string::npos);
}
