// El-Shafey (1987) ch. 6: minimum-time observer (ES 6.1-6.36, Table 6.1 "ours" matrices, 1e-5)
// and the estimate of b~ (ES-C14, Table 6.2).
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/estimate/modal/modal_observer.hpp"
#include "ctid/simulate/lsim.hpp"

using namespace ctid;

namespace {
// S6 (ES Ex. 6.1): (6.5 s + 52)/(s^3 + 4 s^2 + 30 s + 52); Ts = 0.01 s, T = 20 Ts = 0.2 s.
const TransferFunction kS6(Eigen::VectorXd{{6.5, 52.0}}, Eigen::VectorXd{{1.0, 4.0, 30.0, 52.0}});
constexpr double kTs = 0.01, kT = 0.2;

// Input +1, +2, -1, -2 each 80 Ts from rest (Ex. 6.1), with the exact phase-variable state.
struct Record {
  IdData data;
  Eigen::MatrixXd x;
};
Record s6_record() {
  const int N = 320;
  const double levels[4] = {1, 2, -1, -2};
  const StateSpace pv = phase_variable_form(kS6);
  const Discretization D = discretize(pv.A(), pv.B(), kTs);
  Eigen::VectorXd u(N), y(N);
  Eigen::MatrixXd X(N, 3);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(3);
  for (int i = 0; i < N; ++i) {
    u(i) = levels[i / 80];
    X.row(i) = x.transpose();
    y(i) = x(0);
    x = D.Phi * x + D.Gamma0 * u(i);
  }
  return {IdData(u, y, kTs), X};
}

void expect_matrix(const Eigen::MatrixXd& got, const Eigen::MatrixXd& table, double tol) {
  ASSERT_EQ(got.rows(), table.rows());
  ASSERT_EQ(got.cols(), table.cols());
  for (Eigen::Index i = 0; i < table.rows(); ++i)
    for (Eigen::Index j = 0; j < table.cols(); ++j)
      EXPECT_NEAR(got(i, j), table(i, j), tol * std::max(1.0, std::abs(table(i, j)))) << "(" << i << ", " << j << ")";
}
}  // namespace

TEST(DeadbeatObserver, Table61MatricesFromTheModel) {
  const DeadbeatObserver o = DeadbeatObserver::from_model(kS6, kT, kTs);
  Eigen::MatrixXd P(3, 3), Q0(3, 4), Qh(3, 4);
  P << -1.55504, 1.26337, -0.44933, -0.31530, 4.33453, -2.16146, 26.19080, -28.35996, 6.03719;
  Q0 << 0, 0.145541, 0.147545, -0.0340911, 0, 1.44424, 0.577527, -0.163993, 0, -0.243785, -2.84624, 0.458048;
  Qh << 0.0356038, 0.225684, 0.00980518, -0.0120981, 0.731075, 1.18465, 0.000242427, -0.0581969, 1.14690, -3.50313,
      -0.438290, 0.162550;
  expect_matrix(o.P(), P, 1e-5);
  expect_matrix(o.Qbar(0), Q0, 1e-5);
  expect_matrix(o.Qbar(10), Qh, 1e-5);  // s = T/2
  expect_matrix(o.r(0), Eigen::Vector3d(0.07587, -0.03917, -0.94912), 1e-5);
  expect_matrix(o.r(10), Eigen::Vector3d(0.02693, 0.08081, -0.36315), 1e-5);
  EXPECT_NEAR(o.q_tilde0()(0), 0.25899, 1e-5);
  EXPECT_EQ(o.Q_discrete().cols(), 3);
}

TEST(DeadbeatObserver, ReconstructsThePhaseVariableStateInNIntervals) {
  // Noise-free: from the n-th level period on, the state at every sample to 1e-9.
  const Record rec = s6_record();
  const Eigen::MatrixXd X = DeadbeatObserver::from_model(kS6, kT, kTs).reconstruct(rec.data);
  EXPECT_TRUE(std::isnan(X(59, 0)));  // the first n = 3 periods have no estimate
  double err = 0;
  for (int i = 60; i < rec.data.size(); ++i) err = std::max(err, (X.row(i) - rec.x.row(i)).cwiseAbs().maxCoeff());
  EXPECT_LT(err, 1e-9);
}

TEST(DeadbeatObserver, DataRouteEqualsTheModelRouteAndGivesTheMarkovParameters) {
  // ES 6.26-6.29: from the step response estimated by ES-C11 and p_0..p_2 (here estimated from the constant-
  // input windows for p_0 and from g for p_1, p_2 with Fourier functions, positive shifts i T) the observer
  // equals the model-based one; ES-C14 then gives b~ = (0, 6.5, 26) (Table 6.2 true; published estimate
  // (0.0074, 6.453, 26.24)).
  const Record rec = s6_record();
  const Eigen::Vector3d shifts(kT, 2 * kT, 3 * kT);
  ModalOptions o{.shifts = shifts, .basis = ModalBasis::Discrete};
  o.windows = piecewise_constant_windows(rec.data, 3 * kT);
  const auto m0 = modal_estimate(rec.data, rec.data.u(), o);
  const TimeResponse g = modal_step_response(rec.data, m0.model, kT, 20.0);  // extrapolated to g(inf) within 1e-8
  // p_1 .. p_3 from the step response: u = 1 (constant mode), Fourier on one window after 3T.
  const IdData step(Eigen::VectorXd::Ones(g.t.size()), g.value, kTs);
  ModalOptions f{.shifts = shifts, .max_order = 3, .functions = 8};
  f.windows = {{0.6, 3.2}};
  const auto mj = modal_estimate(step, step.u(), f);
  const DeadbeatObserver model = DeadbeatObserver::from_model(kS6, kT, kTs);
  const DeadbeatObserver data = DeadbeatObserver::from_step_response(mj.model, g, kT);
  EXPECT_LT((data.P() - model.P()).cwiseAbs().maxCoeff(), 1e-6 * model.P().cwiseAbs().maxCoeff());
  // Qbar entries are O(1): the Fourier estimates of p_1, p_2 (Simpson at Ts = 0.01) carry ~1e-6 relative error.
  for (int r : {0, 7, 10, 19}) EXPECT_LT((data.Qbar(r) - model.Qbar(r)).cwiseAbs().maxCoeff(), 1e-5) << "offset " << r;
  // ES-C14 with exact modal quantities, then with the data route.
  const Eigen::RowVectorXd p3 = modal_parameters(kS6, shifts, 3).P.row(3);
  const Eigen::VectorXd bt = model.markov_parameters(p3);
  EXPECT_NEAR(bt(0), 0.0, 1e-9);
  EXPECT_NEAR(bt(1), 6.5, 1e-9);
  EXPECT_NEAR(bt(2), 26.0, 1e-8);
  const Eigen::VectorXd bd = data.markov_parameters(mj.model.P().row(3));
  EXPECT_LT((bd - Eigen::Vector3d(0.0, 6.5, 26.0)).cwiseAbs().maxCoeff(), 1e-4);
  // Table 6.2's printed estimate (0.007399, 6.453, 26.24) is not reproduced: ours is the truth, from which the print
  // lies 0.7 % (b~_1) and 0.9 % (b~_2) away — the size of the thesis' estimation error, which it does not itemise.
  EXPECT_NEAR(bd(1) / 6.453 - 1, 0.0073, 5e-4);
  EXPECT_NEAR(bd(2) / 26.24 - 1, -0.0091, 5e-4);
}

TEST(DeadbeatObserver, MarkovParametersOfAnUnstableSystemAndAnIntegratorRefused) {
  // ES-C14 reads the step response's constant part; the thesis takes it as g(inf), which an unstable system does
  // not have. Its DC gain H(0) = q~_00 / (1 + sum p_0i) is that constant part for any system without a pole at 0.
  // (6.5 s + 52)/((s - 1)(s^2 + 2 s + 26)) = (6.5 s + 52)/(s^3 + s^2 + 24 s - 26): b~ = (b_2, b_1 - a_2 b~_1,
  // b_0 - a_2 b~_2 - a_1 b~_1) = (0, 6.5, 52 - 6.5) = (0, 6.5, 45.5), by the model route and from data (the
  // step response of ES-C11 on the +1, +2, -1, -2 record, which grows as e^t).
  const TransferFunction unstable(Eigen::VectorXd{{6.5, 52.0}}, Eigen::VectorXd{{1.0, 1.0, 24.0, -26.0}});
  const Eigen::Vector3d shifts(kT, 2 * kT, 3 * kT);
  const DeadbeatObserver model = DeadbeatObserver::from_model(unstable, kT, kTs);
  const Eigen::VectorXd bt = model.markov_parameters(modal_parameters(unstable, shifts, 3).P.row(3));
  EXPECT_LT((bt - Eigen::Vector3d(0.0, 6.5, 45.5)).cwiseAbs().maxCoeff(), 1e-8);

  const int N = 320;
  const double levels[4] = {1, 2, -1, -2};
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = levels[i / 80];
  const IdData d(u, lsim(unstable, u, time_grid(kTs, N)), kTs);
  ModalOptions o{.shifts = shifts, .basis = ModalBasis::Discrete};
  o.windows = piecewise_constant_windows(d, 3 * kT);
  const auto m0 = modal_estimate(d, d.u(), o);
  const TimeResponse g = modal_step_response(d, m0.model, kT, 4.0);
  EXPECT_LT((g.value - step_response(unstable, g.t)).cwiseAbs().maxCoeff(), 1e-6 * g.value.cwiseAbs().maxCoeff());
  const IdData step(Eigen::VectorXd::Ones(g.t.size()), g.value, kTs);
  ModalOptions f{.shifts = shifts, .max_order = 3, .functions = 8};
  f.windows = {{0.6, 3.2}};
  const auto mj = modal_estimate(step, step.u(), f);
  const DeadbeatObserver data = DeadbeatObserver::from_step_response(mj.model, g, kT);
  const Eigen::VectorXd bd = data.markov_parameters(mj.model.P().row(3));
  // Measured 1.3e-3 (b~_3, 2.8e-5 relative): the Fourier p_1..p_3 of a step response growing as e^t.
  EXPECT_LT((bd - Eigen::Vector3d(0.0, 6.5, 45.5)).cwiseAbs().maxCoeff(), 2e-3);

  // A pole at s = 0: refused, naming it.
  const TransferFunction integrator(Eigen::VectorXd{{6.5, 52.0}}, Eigen::VectorXd{{1.0, 4.0, 30.0, 0.0}});
  const DeadbeatObserver io = DeadbeatObserver::from_model(integrator, kT, kTs);
  try {
    io.markov_parameters(modal_parameters(integrator, shifts, 3).P.row(3));
    ADD_FAILURE() << "an integrating plant was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("pole at s = 0"), std::string::npos) << e.what();
  }
  EXPECT_THROW(model.markov_parameters(Eigen::RowVector2d(1.0, 2.0)), InvalidArgument);  // p_n of the wrong size
}

TEST(DeadbeatObserver, BadInputs) {
  EXPECT_THROW(DeadbeatObserver::from_model(kS6, 0.205, kTs), InvalidArgument);  // T not a multiple of Ts
  const Record rec = s6_record();
  const DeadbeatObserver o = DeadbeatObserver::from_model(kS6, kT, 0.02);
  EXPECT_THROW(o.reconstruct(rec.data), InvalidArgument);  // designed for another Ts
  EXPECT_THROW(o.Qbar(10), InvalidArgument);             // 10 offsets only
}
