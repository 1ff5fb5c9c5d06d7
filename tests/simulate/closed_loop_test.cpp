// simulate_closed_loop: a continuous plant under a digital RST controller (include/ctid/simulate/closed_loop.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/simulate/closed_loop.hpp"
#include "ctid/simulate/lsim.hpp"

using namespace ctid;

namespace {
// The loops as the Gawthrop & Wang tests wrote them by hand before the helper existed: the plant's ZOH
// discretisation stepped sample by sample and the PID's difference equations (integral by the backward rectangle,
// filtered derivative of the measurement), with an actuator clamp.
IdData hand_loop(const TransferFunction& g, double kp, double ki, double kd, double tf, double Ts,
                 const Eigen::VectorXd& w, const Eigen::VectorXd& e, double limit) {
  const StateSpace ss = g.to_state_space();
  const Discretization D = discretize(ss.A(), ss.B(), Ts);
  const Eigen::Index M = w.size();
  Eigen::VectorXd u(M), y(M), x = Eigen::VectorXd::Zero(ss.A().rows());
  double d = 0, yprev = 0, integral = 0;
  for (Eigen::Index i = 0; i < M; ++i) {
    y(i) = (ss.C() * x)(0) + e(i);
    d = (tf * d + kd * (y(i) - yprev)) / (tf + Ts);
    yprev = y(i);
    integral += Ts * (w(i) - y(i));
    u(i) = std::clamp(kp * (w(i) - y(i)) - d + ki * integral, -limit, limit);
    x = D.Phi * x + D.Gamma0 * u(i);
  }
  return IdData(u, y, Ts);
}
}  // namespace

// The helper's PID in RST form is the hand-written loop: the unstable circuit 1/(s^2 - 1) under PD (Gawthrop & Wang 2005, §5, simulated)
// and the ball and beam 2.5/s^2 under a clamped PID with measurement noise (GW.4), to 1e-9 of the signals' range
// (measured 1.1e-13 and 1.4e-12: the RST recursion sums the same terms in another order).
TEST(ClosedLoop, PidInRstFormIsTheHandWrittenLoop) {
  struct Case {
    TransferFunction g;
    double kp, ki, kd, tf, limit, noise;
  };
  const std::vector<Case> cases = {
      {TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 0.0, -1.0}}), 3.0, 0.0, 3.0, 0.1, 1e300, 0.0},
      {TransferFunction(Eigen::VectorXd{{2.5}}, Eigen::VectorXd{{1.0, 0.0, 0.0}}), 1.0, 0.1, 0.8, 0.05, 1.5, 0.02}};
  const double Ts = 0.01;
  const int M = 6000;
  Eigen::VectorXd w(M);
  for (int i = 0; i < M; ++i) w(i) = std::fmod(i * Ts, 20.0) < 10.0 ? 0.5 : -0.5;
  for (const Case& c : cases) {
    const Eigen::VectorXd e = c.noise > 0 ? white_noise(M, c.noise, 11) : Eigen::VectorXd::Zero(M);
    const IdData hand = hand_loop(c.g, c.kp, c.ki, c.kd, c.tf, Ts, w, e, c.limit);
    RstController ctl = RstController::pid(c.kp, c.ki, c.kd, c.tf, Ts);
    ctl.u_min = -c.limit;
    ctl.u_max = c.limit;
    const IdData loop = simulate_closed_loop(c.g, ctl, w, Ts, c.noise > 0 ? e : Eigen::VectorXd());
    const double scale = hand.y().cwiseAbs().maxCoeff() + hand.u().cwiseAbs().maxCoeff();
    EXPECT_LT((loop.y() - hand.y()).cwiseAbs().maxCoeff(), 1e-9 * scale);
    EXPECT_LT((loop.u() - hand.u()).cwiseAbs().maxCoeff(), 1e-9 * scale);
    EXPECT_EQ(loop.ts(), Ts);
    EXPECT_EQ(loop.input_names().front(), "u");
    if (c.limit < 10) EXPECT_NEAR(loop.u().cwiseAbs().maxCoeff(), 1.5, 1e-12);  // the clamp was reached
  }
}

// Open loop (S = 0, T = 1: u = r) the helper's plant is lsim's: a proper plant with a delay of three samples and a
// second-order plant, to 1e-12 (lsim discretises the same ZOH exactly, with its own code).
TEST(ClosedLoop, OpenLoopPlantIsLsims) {
  const double Ts = 0.02;
  const Eigen::VectorXd r = prbs(500, {.register_length = 7, .clock_period = 3});
  RstController open;
  open.T = Eigen::VectorXd::Ones(1);
  for (const TransferFunction& g : {TransferFunction(Eigen::VectorXd{{1.0, 2.0}}, Eigen::VectorXd{{1.0, 1.0}}, 3 * Ts),
                                    TransferFunction(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}})}) {
    const IdData loop = simulate_closed_loop(g, open, r, Ts);
    const Eigen::VectorXd y = lsim(g, r, time_grid(Ts, 500));
    EXPECT_LT((loop.y().col(0) - y).cwiseAbs().maxCoeff(), 1e-12 * y.cwiseAbs().maxCoeff()) << g.to_string(4);
    EXPECT_EQ((loop.u().col(0) - r).cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(ClosedLoop, RefusalsNameTheProblem) {
  const TransferFunction proper(Eigen::VectorXd{{1.0, 2.0}}, Eigen::VectorXd{{1.0, 1.0}});
  const TransferFunction unstable(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, -1.0}});
  const Eigen::VectorXd r = Eigen::VectorXd::Ones(100);
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const InvalidArgument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message([&] { simulate_closed_loop(proper, RstController::gains(1, 2), r, 0.1); }).find("algebraic loop"),
            std::string::npos);
  EXPECT_NE(message([&] { simulate_closed_loop(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 1.0}}, 0.15),
                                               RstController::gains(1, 1), r, 0.1); })
                .find("not a whole number of samples"),
            std::string::npos);
  // No control of 1/(s - 1) for 1 000 s overflows: refused at the sample where it does, not returned as inf.
  RstController none;
  none.T = Eigen::VectorXd::Ones(1);
  EXPECT_NE(message([&] { simulate_closed_loop(unstable, none, Eigen::VectorXd::Ones(10000), 0.1); }).find("diverged"),
            std::string::npos);
  EXPECT_NE(message([&] { simulate_closed_loop(unstable, none, r, 0.1, Eigen::VectorXd::Zero(5)); }).find("5 noise values"),
            std::string::npos);
  RstController bad;
  bad.P = Eigen::VectorXd::Zero(1);
  EXPECT_NE(message([&] { bad.validate(); }).find("P(0)"), std::string::npos);
  EXPECT_NE(message([] { RstController::pid(1, 0, 1, -0.1, 0.01); }).find("tf must be >= 0"), std::string::npos);
  // A proper plant with S(0) = 0 (the controller reads y one sample late) is no algebraic loop.
  RstController late;
  late.T = Eigen::VectorXd::Ones(1);
  late.S = Eigen::Vector2d(0.0, 0.5);
  EXPECT_EQ(simulate_closed_loop(proper, late, r, 0.1).size(), 100);
}
