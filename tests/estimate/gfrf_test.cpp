// GFRFs of NARX models (Billings & Li 1999 eqs 11-14; BL 11-14) against closed forms, the published
// model (34) and the exact discretisation of a continuous-time system.
#include <algorithm>
#include <cmath>
#include <complex>

#include <gtest/gtest.h>

#include "estimate/billings_li_models.hpp"
#include "ctid/core/error.hpp"
#include "ctid/io/json.hpp"
#include "ctid/estimate/nonlinear/gfrf.hpp"
#include "ctid/simulate/lsim.hpp"

using namespace ctid;

namespace {
NarxModel model(const std::vector<std::string>& terms, const std::vector<double>& c, double Ts = 1.0) {
  std::vector<NarxTerm> t;
  for (const auto& s : terms) t.push_back(NarxTerm::parse(s));
  return NarxModel(t, Eigen::Map<const Eigen::VectorXd>(c.data(), static_cast<Eigen::Index>(c.size())), Ts);
}

}  // namespace

TEST(NarxGfrf, ClosedFormsOfFirstSecondAndThirdOrder) {
  // y(k) = a y(k-1) + b u(k-1) + c y(k-1)^2 + d y(k-1)u(k-2) + e u(k-1)u(k-2) + f y(k-1)^3.
  const double a = 0.6, b = 0.5, c = 0.2, d = -0.3, e = 0.1, f = 0.05;
  const NarxModel m = model({"y(k-1)", "u(k-1)", "y(k-1)*y(k-1)", "y(k-1)*u(k-2)", "u(k-1)*u(k-2)", "y(k-1)*y(k-1)*y(k-1)"},
                            {a, b, c, d, e, f});
  const Complex z1 = std::polar(1.1, 0.3), z2 = std::polar(0.9, -1.2), z3 = std::polar(1.3, 2.0);
  auto H1 = [&](Complex z) { return b / z / (1.0 - a / z); };
  EXPECT_LT(std::abs(narx_gfrf(m, {z1}) - H1(z1)), 1e-14);
  // Asymmetric H_2: the y^2 term gives c H1 H1 (z1 z2)^-1, y(k-1)u(k-2) gives d z2^-2 H1(z1) z1^-1, u u gives e z1^-1 z2^-2.
  const Complex den2 = 1.0 - a / (z1 * z2);
  const Complex h2 = (c * H1(z1) * H1(z2) / (z1 * z2) + d * std::pow(z2, -2) * H1(z1) / z1 + e / z1 * std::pow(z2, -2)) / den2;
  EXPECT_LT(std::abs(narx_gfrf_asymmetric(m, {z1, z2}) - h2), 1e-13);
  const Complex h2r = (c * H1(z1) * H1(z2) / (z1 * z2) + d * std::pow(z1, -2) * H1(z2) / z2 + e / z2 * std::pow(z1, -2)) / den2;
  EXPECT_LT(std::abs(narx_gfrf(m, {z1, z2}) - 0.5 * (h2 + h2r)), 1e-13);
  // Cubic term alone (the quadratic ones also feed H_3; check the pure cubic model).
  const NarxModel cubic = model({"y(k-1)", "u(k-1)", "y(k-1)*y(k-1)*y(k-1)"}, {a, b, f});
  const Complex h3 = f * H1(z1) * H1(z2) * H1(z3) / (z1 * z2 * z3) / (1.0 - a / (z1 * z2 * z3));
  EXPECT_LT(std::abs(narx_gfrf(cubic, {z1, z2, z3}) - h3), 1e-13);
  EXPECT_THROW(narx_gfrf(m, {}), InvalidArgument);
}

TEST(NarxGfrf, PublishedModel34) {
  // Billings & Li 1999, eqs 33-34 and Tables 1-3: with (34) as printed H_1(1) = 0.961 and H_1 at s = j100 (z = e^{j100T}) is
  // -0.023 - 5.06j (true system: -5j); H_2^sym(0, 0) = -0.0945 (true -0.1).
  const NarxModel m = bl34();
  EXPECT_NEAR(narx_gfrf(m, {1.0}).real(), 0.961, 5e-4);
  const Complex h = narx_gfrf_ct(m, {Complex(0, 100)}, false);
  EXPECT_NEAR(h.real(), -0.023, 0.001);
  EXPECT_NEAR(h.imag(), -5.06, 0.005);
  EXPECT_NEAR(narx_gfrf(m, {1.0, 1.0}).real(), -0.0945, 5e-4);
}

TEST(NarxGfrf, ExactDiscretisationMapsToTheContinuousKernelWithTheHoldFactor) {
  // G(s) = 1/(1e-4 s^2 + 2e-3 s + 1) (the linear part of BL (33)) discretised exactly with a held input at
  // T = 2.5 ms. H_d(e^{sT}) = sum_m G(s + j m w_s) Z(s + j m w_s): dividing by Z(s) leaves only the aliased
  // terms. Measured relative errors with Z: 2e-7 at 10 rad/s, 4e-5 at 100, 4e-4 at 200, 1.1e-2 at 500 (both
  // axes); without Z: 1.2 %, 12 %, 25 %, 60 %. Checked: <= 1e-4 up to 100 rad/s (the system's bandwidth), and
  // the median over 10..500 rad/s on both axes below 2e-3 with Z and above 0.15 without.
  const double T = 0.0025;
  const TransferFunction G(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1e-4, 2e-3, 1.0}});
  const StateSpace ss = G.to_state_space();
  const Discretization D = discretize(ss.A(), ss.B(), T);
  const double a1 = -D.Phi.trace(), a2 = D.Phi.determinant();
  const double h1 = (ss.C() * D.Gamma0)(0, 0), h2 = (ss.C() * D.Phi * D.Gamma0)(0, 0);
  const NarxModel m = model({"y(k-1)", "y(k-2)", "u(k-1)", "u(k-2)"}, {-a1, -a2, h1, h2 + a1 * h1}, T);
  std::vector<double> with, without;
  for (int i = 1; i <= 50; ++i)
    for (const Complex s : {Complex(10.0 * i, 0), Complex(0, 10.0 * i)}) {
      const Complex g = G(s);
      with.push_back(std::abs(narx_gfrf_ct(m, {s}) - g) / std::abs(g));
      without.push_back(std::abs(narx_gfrf_ct(m, {s}, false) - g) / std::abs(g));
      if (i <= 10) EXPECT_LT(with.back(), 1e-4) << s;
    }
  std::nth_element(with.begin(), with.begin() + 50, with.end());
  std::nth_element(without.begin(), without.begin() + 50, without.end());
  EXPECT_LT(with[50], 2e-3);
  EXPECT_GT(without[50], 0.15);
}
