// Polynomial NDE models (Billings & Li 1999, eqs 1-6): names, the linear kernel, harmonic
// probing H_2 against a two-tone simulation, and simulation accuracy and escape detection.
#include <cmath>
#include <complex>
#include <numbers>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/model/nde.hpp"
#include "ctid/simulate/lsim.hpp"

using namespace ctid;

namespace {
NdeModel bl33() {  // y + 0.002 Dy + 0.0001 D^2y - u + 0.1 y^2 - 0.006 y*Dy = 0
  std::vector<NdeTerm> t;
  for (const char* s : {"y", "Dy", "D^2y", "u", "y^2", "y*Dy"}) t.push_back(NdeTerm::parse(s));
  return NdeModel(t, (Eigen::VectorXd(6) << 1, 0.002, 1e-4, -1, 0.1, -0.006).finished());
}
}  // namespace

TEST(NdeModel, TermsAndTheEquation) {
  for (const char* s : {"y", "Dy", "D^2y", "u", "Du", "y^2", "y*Dy", "Dy*u", "D^3y*u^2"}) EXPECT_EQ(NdeTerm::parse(s).name(), s);
  EXPECT_EQ(NdeTerm::parse("y*y").name(), "y^2");
  EXPECT_EQ(NdeTerm::parse("u*Dy").name(), "Dy*u");
  EXPECT_THROW(NdeTerm::parse("x"), InvalidArgument);
  EXPECT_THROW(NdeTerm::parse("y*"), InvalidArgument);
  const NdeModel m = bl33();
  EXPECT_EQ(m.to_string(4), "y + 0.002 Dy + 0.0001 D^2y - u + 0.1 y^2 - 0.006 y*Dy = 0");
  EXPECT_NEAR(m.h1(0.0).real(), 1.0, 1e-15);
  EXPECT_NEAR(m.h2(0.0, 0.0).real(), -0.1, 1e-15);  // BL 4-6 check: -gamma_20(0,0) H_1(0)^2
  EXPECT_NEAR(NdeModel(m.terms(), 2 * m.coefficients()).normalized().coefficient("y*Dy"), -0.006, 1e-15);
}

TEST(NdeModel, HarmonicProbingH2AgreesWithATwoToneSimulation) {
  // u = A (cos w1 t + cos w2 t), w1 = 2 pi 4, w2 = 2 pi 7 rad/s, A = 0.01: the steady-state component at
  // w1 + w2 is A^2 |H_2(j w1, j w2)| cos((w1 + w2) t + arg H_2) plus O(A^4). Linear input interpolation at
  // 5 kHz; DFT over the last second.
  const NdeModel m = bl33();
  const double A = 0.01, w1 = 2 * std::numbers::pi * 4, w2 = 2 * std::numbers::pi * 7, Ts = 2e-4;
  const int N = 15001;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(N, 0.0, (N - 1) * Ts);
  const Eigen::VectorXd u = A * ((w1 * t).array().cos() + (w2 * t).array().cos());
  const NdeSimulation r = m.simulate(u, t, Intersample::Foh);
  ASSERT_TRUE(r.ok()) << r.message;
  std::complex<double> c = 0.0;
  const int K = 5000;
  for (int i = N - K; i < N; ++i) c += r.y(i) * std::exp(std::complex<double>(0, -(w1 + w2) * t(i)));
  c *= 2.0 / K;  // complex amplitude of the cos((w1 + w2) t + phi) component
  const std::complex<double> h2 = m.h2({0, w1}, {0, w2});
  EXPECT_LT(std::abs(c - A * A * h2), 2e-3 * std::abs(A * A * h2));
}

TEST(NdeModel, LinearSimulationIsExactAndEscapesAreReported) {
  // The linear part of BL (33) against the exact matrix-exponential simulation (held input).
  const std::vector<NdeTerm> lin = {NdeTerm::parse("y"), NdeTerm::parse("Dy"), NdeTerm::parse("D^2y"), NdeTerm::parse("u")};
  const NdeModel m(lin, (Eigen::VectorXd(4) << 1, 0.002, 1e-4, -1).finished());
  const Eigen::VectorXd t = time_grid(0.0025, 400);
  Eigen::VectorXd u(400);
  for (int i = 0; i < 400; ++i) u(i) = (i / 20) % 2 ? 1.0 : -1.0;
  const NdeSimulation r = m.simulate(u, t);
  ASSERT_TRUE(r.ok());
  const Eigen::VectorXd exact = lsim(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1e-4, 2e-3, 1.0}}), u, t);
  EXPECT_LT((r.y - exact).cwiseAbs().maxCoeff(), 1e-7);
  // Dy - y^2 - u = 0 escapes in finite time for u = 1: a termination status and NaN, not infinities.
  const NdeModel bad({NdeTerm::parse("Dy"), NdeTerm::parse("y^2"), NdeTerm::parse("u")}, Eigen::Vector3d(1, -1, -1));
  const NdeSimulation b = bad.simulate(Eigen::VectorXd::Ones(400), time_grid(0.01, 400));
  EXPECT_EQ(b.termination, Termination::NumericalFailure);
  EXPECT_NE(b.message.find("escapes"), std::string::npos);
  EXPECT_TRUE(std::isnan(b.y(399)));
  // Not explicit: D^2y inside a product.
  const NdeModel implicit({NdeTerm::parse("y"), NdeTerm::parse("y*D^2y"), NdeTerm::parse("u")}, Eigen::Vector3d(1, 1, -1));
  EXPECT_THROW(implicit.simulate(u, t), InvalidArgument);
}

TEST(NdeModel, HarmonicProbingH3AgreesWithAThreeToneSimulation) {
  // BL (33) plus 0.05 y^3: H_3 gets the cubic term and the quadratic terms' products with H_2. Tones at 4, 6 and
  // 7 Hz (amplitude A = 0.005): the only third-order combination at 17 Hz is 4 + 6 + 7, whose cosine amplitude is
  // (3/2) A^3 H_3; lower orders have no 17 Hz component, higher ones are O(A^4). 5 kHz, linear interpolation.
  std::vector<NdeTerm> t;
  for (const char* s : {"y", "Dy", "D^2y", "u", "y^2", "y*Dy", "y^3"}) t.push_back(NdeTerm::parse(s));
  const NdeModel m(t, (Eigen::VectorXd(7) << 1, 0.002, 1e-4, -1, 0.1, -0.006, 0.05).finished());
  EXPECT_NEAR((NdeModel({NdeTerm::parse("y"), NdeTerm::parse("u"), NdeTerm::parse("y^3")}, Eigen::Vector3d(1, -1, 0.2))
                   .h3(1.0, 2.0, 3.0)).real(), -0.2, 1e-15);  // y = u - 0.2 y^3: H_3 = -0.2
  const double A = 0.005, pi2 = 2 * std::numbers::pi, Ts = 2e-4;
  const double w[3] = {pi2 * 4, pi2 * 6, pi2 * 7};
  const int N = 15001;
  const Eigen::VectorXd tt = Eigen::VectorXd::LinSpaced(N, 0.0, (N - 1) * Ts);
  const Eigen::VectorXd u = A * ((w[0] * tt).array().cos() + (w[1] * tt).array().cos() + (w[2] * tt).array().cos());
  const NdeSimulation r = m.simulate(u, tt, Intersample::Foh, {}, 1e-11);
  ASSERT_TRUE(r.ok()) << r.message;
  const double ws = w[0] + w[1] + w[2];
  std::complex<double> c = 0.0;
  const int K = 5000;
  for (int i = N - K; i < N; ++i) c += r.y(i) * std::exp(std::complex<double>(0, -ws * tt(i)));
  c *= 2.0 / K;
  const std::complex<double> h3 = m.h3({0, w[0]}, {0, w[1]}, {0, w[2]});
  EXPECT_LT(std::abs(c - 1.5 * A * A * A * h3), 0.01 * std::abs(1.5 * A * A * A * h3));
}
