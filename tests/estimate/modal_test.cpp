// El-Shafey (1987) modal-function estimators on exactly simulated data: the tables of docs/methods/el-shafey.md
// ("noise-free estimators ... reproduce the true values to ~1e-6 with Simpson/exact
// quadrature"; statistical checks by seeded Monte Carlo).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/estimate/modal/modal.hpp"
#include "ctid/simulate/lsim.hpp"

using namespace ctid;

namespace {
constexpr double kPi = std::numbers::pi;
const TransferFunction kS3(Eigen::VectorXd{{13.0, 52.0}}, Eigen::VectorXd{{1.0, 4.0, 30.0, 52.0}});
const TransferFunction kS4(Eigen::VectorXd{{400.0, 400.0}}, Eigen::VectorXd{{1.0, 6.0, 115.25, 221.0, 338.0}});
const double kTs420 = kPi / 420;
const Eigen::Vector3d kShifts3(40 * kTs420, 80 * kTs420, 120 * kTs420);

// Ex. 3.1 record: S3 from rest, u = +1 from t = 0, -1 from 444 Ts (Ts = pi/420), exact ZOH simulation.
IdData step_record(int N, double noise = 0.0, unsigned seed = 1) {
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = i < 444 ? 1.0 : -1.0;
  Eigen::VectorXd y = lsim(kS3, u, time_grid(kTs420, N));
  if (noise > 0) y += white_noise(N, noise, seed);
  return IdData(u, y, kTs420);
}

// Ex. 3.5 record: S3 from rest driven by u = sin 4t, simulated exactly with the generator.
IdData sine_record(int N) {
  const InputGenerator g = InputGenerator::sinusoid(4.0, 1.0);
  const Eigen::VectorXd t = time_grid(kTs420, N);
  return IdData(g(t), lsim(kS3.to_state_space(), g, t), kTs420);
}

// True q_j for u = sin wt in the basis [sin wt, cos wt]: y_j = Im(K_j e^{jwt}),
// K_j = H(jw)((jw)^j + sum_i p_ji e^{-jw T_i}) (Table 3.6, "q true").
Eigen::Vector2d q_true_sine(const TransferFunction& h, const Eigen::VectorXd& T, const Eigen::RowVectorXd& pj, int j,
                            double w) {
  const std::complex<double> jw(0, w);
  std::complex<double> K = std::pow(jw, j);
  for (Eigen::Index i = 0; i < T.size(); ++i) K += pj(i) * std::exp(-jw * T(i));
  K *= h(jw);
  return {K.real(), K.imag()};
}

double max_rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

// The fraction of v at or below x: where a printed single run falls in our Monte Carlo distribution.
double percentile_of(const std::vector<double>& v, double x) {
  return static_cast<double>(std::count_if(v.begin(), v.end(), [x](double e) { return e <= x; })) / static_cast<double>(v.size());
}

// The monic polynomial (descending coefficients) whose roots are the modes mapped by the trapezoid rule of step h,
// lambda -> (2/h) tanh(lambda h / 2): what Theorem 4.3 returns with trapezoid integrals on a sum of those modes.
Eigen::VectorXd trapezoid_mapped(const Eigen::VectorXcd& modes, double h) {
  Eigen::VectorXcd c = Eigen::VectorXcd::Zero(modes.size() + 1);
  c(0) = 1.0;
  for (Eigen::Index k = 0; k < modes.size(); ++k) {
    const std::complex<double> m = 2.0 / h * std::tanh(modes(k) * h / 2.0);
    for (Eigen::Index i = k + 1; i >= 1; --i) c(i) -= m * c(i - 1);
  }
  return c.real();
}
}  // namespace

TEST(ModalEstimate, Table31DiscreteSamplesReproduceTheTrueValues) {
  // ES Table 3.1: two windows (w1 from T_3 to the switch at 444 Ts, w2 from 444 Ts + T_3), 10 equations each
  // spaced 20 Ts ([STAND-IN] starts 120 Ts and 564 Ts). Model y + sum p_0i y(t - T_i) = q_00 u.
  // Published (-0.6605, 0.6106, -0.3022, 0.6480); true q_00 = (1 + sum p_0i) H(0) = 0.64794.
  const IdData d = step_record(800);
  ModalOptions o{.shifts = kShifts3, .basis = ModalBasis::Discrete, .stride = 20};
  o.windows = {{120 * kTs420, 180 * kTs420}, {564 * kTs420, 180 * kTs420}};
  const auto r = modal_estimate(d, d.u(), o);
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  const Eigen::MatrixXd P = modal_parameters(kS3, kShifts3, 0).P;
  EXPECT_LT(max_rel(r.model.P(), P), 1e-9);
  EXPECT_NEAR(r.model.Q()(0, 0), (1 + P.sum()) * kS3.dc_gain(), 1e-9);
  EXPECT_NEAR(r.model.Q()(0, 0), 0.6480, 2e-4);  // the published q_00 (4 digits)
  // The validity windows of the piecewise-constant input are found automatically.
  const auto w = piecewise_constant_windows(d, kShifts3(2));
  ASSERT_EQ(w.size(), 2u);
  EXPECT_NEAR(w[0].start, 120 * kTs420, 1e-12);
  EXPECT_NEAR(w[0].start + w[0].length, 443 * kTs420, 1e-12);
  EXPECT_NEAR(w[1].start, 564 * kTs420, 1e-12);
}

TEST(ModalEstimate, Table32ContinuousDataFourierAndWalshGiveTheTrueValues) {
  // ES Table 3.2: windows of Table 3.1, 6 Fourier / 8 Walsh functions (320 Ts per window: 40 Ts per Walsh
  // block). For j = 0 any quadrature gives the exact values (a linear combination of exact
  // pointwise equations), so the trapezoid is checked too.
  const IdData d = step_record(900);
  const Eigen::MatrixXd P = modal_parameters(kS3, kShifts3, 0).P;
  for (auto basis : {ModalBasis::Fourier, ModalBasis::Walsh})
    for (auto rule : {Quadrature::Simpson, Quadrature::Trapezoid}) {
      ModalOptions o{.shifts = kShifts3, .basis = basis, .functions = basis == ModalBasis::Fourier ? 6 : 8,
                     .quadrature = rule};
      o.windows = {{120 * kTs420, 320 * kTs420}, {564 * kTs420, 320 * kTs420}};
      const auto r = modal_estimate(d, d.u(), o);
      ASSERT_TRUE(r.usable()) << r.why_not_usable();
      EXPECT_LT(max_rel(r.model.P(), P), 1e-9) << static_cast<int>(basis) << " " << static_cast<int>(rule);
      EXPECT_NEAR(r.model.Q()(0, 0), (1 + P.sum()) * kS3.dc_gain(), 1e-9);
    }
}

TEST(ModalEstimate, Tables36And37FourierAndWalshRecursionsToTheThirdDerivative) {
  // ES Ex. 3.5 / 3.6: u = sin 4t from rest, T_i = 40, 80, 120 Ts; window [120 Ts, 504 Ts] ([STAND-IN] t_o),
  // 6 Fourier functions (omega_o = 2 pi / (384 Ts)) or 8 Walsh functions; j = 0..3.
  const IdData d = sine_record(600);
  const InputGenerator g = InputGenerator::sinusoid(4.0, 1.0);
  const Eigen::MatrixXd P = modal_parameters(kS3, kShifts3, 3).P;
  Eigen::MatrixXd Q(4, 2);
  for (int j = 0; j <= 3; ++j) Q.row(j) = q_true_sine(kS3, kShifts3, P.row(j), j, 4.0).transpose();
  for (auto basis : {ModalBasis::Fourier, ModalBasis::Walsh}) {
    ModalOptions o{.shifts = kShifts3, .basis = basis, .max_order = 3,
                   .functions = basis == ModalBasis::Fourier ? 6 : 8};
    o.windows = {{120 * kTs420, 384 * kTs420}};
    const auto r = modal_estimate(d, g, o);
    ASSERT_TRUE(r.usable()) << r.why_not_usable();
    // Simpson at Ts = pi/420: measured relative errors <= 2.5e-7 (j = 1, 2), the oracle asks ~1e-6.
    for (int j = 0; j <= 3; ++j) {
      EXPECT_LT(max_rel(r.model.P().row(j), P.row(j)), 1e-6) << "basis " << static_cast<int>(basis) << " j " << j;
      EXPECT_LT(max_rel(r.model.Q().row(j), Q.row(j)), 1e-6) << "basis " << static_cast<int>(basis) << " j " << j;
    }
    // The published estimates (Tables 3.6/3.7, another quadrature) agree loosely: j = 0 within 0.5 %.
    EXPECT_NEAR(r.model.P()(0, 0), -0.6617, 0.005);
  }
}

TEST(ModalEstimate, TrapezoidIntegralsReproduceTheThesisClassError) {
  // ES 3.18, 3.31-3.37: on Example 3.5 data, trapezoid Walsh block integrals give
  // p_1 = (2.9993, -0.2566, -0.4331), Simpson gives the exact (2.9990, -0.2564, -0.4330); Table 3.6 "ours,
  // trapezoid" (Fourier): p_1 = (3.001, -0.2569, -0.4315). Both reproduced to the printed digits.
  const IdData d = sine_record(600);
  {
    ModalOptions o{.shifts = kShifts3, .max_order = 1, .quadrature = Quadrature::Trapezoid};
    o.windows = {{120 * kTs420, 384 * kTs420}};
    const auto r = modal_estimate(d, InputGenerator::sinusoid(4.0, 1.0), o);
    EXPECT_NEAR(r.model.P()(1, 0), 3.001, 5e-4);
    EXPECT_NEAR(r.model.P()(1, 1), -0.2569, 1e-4);
    EXPECT_NEAR(r.model.P()(1, 2), -0.4315, 1e-4);
  }
  ModalOptions o{.shifts = kShifts3, .basis = ModalBasis::Walsh, .max_order = 1, .functions = 8,
                 .quadrature = Quadrature::Trapezoid};
  o.windows = {{120 * kTs420, 384 * kTs420}};
  const auto r = modal_estimate(d, InputGenerator::sinusoid(4.0, 1.0), o);
  EXPECT_NEAR(r.model.P()(1, 0), 2.9993, 1e-4);
  EXPECT_NEAR(r.model.P()(1, 1), -0.2566, 1e-4);
  EXPECT_NEAR(r.model.P()(1, 2), -0.4331, 1e-4);
}

TEST(ModalEstimate, TheoremsFourOneAndFourTwoGiveTheTransferFunction) {
  // ES-C8 on a two-sinusoid input (n_c = 4 >= n = 3): a and b of S3 from noise-free data.
  const InputGenerator g = InputGenerator::sinusoid(4.0, 1.0) + InputGenerator::sinusoid(1.5, 0.0, 0.7);
  const Eigen::VectorXd t = time_grid(kTs420, 1500);
  const IdData d(g(t), lsim(kS3.to_state_space(), g, t), kTs420);
  ModalOptions o{.shifts = kShifts3, .functions = 10};
  o.windows = {{120 * kTs420, 1344 * kTs420}};
  const auto r = modal_transfer_function(d, g, o);
  ASSERT_TRUE(r.usable()) << r.why_not_usable();
  EXPECT_LT((r.model.den().coefficients() - kS3.den().coefficients()).cwiseAbs().maxCoeff(), 1e-4 * 52);
  EXPECT_NEAR(r.model.num().coefficient_of_power(1), 13.0, 1e-4 * 52);
  EXPECT_NEAR(r.model.num().coefficient_of_power(0), 52.0, 1e-4 * 52);
  EXPECT_GT(r.fit.fit_percent, 99.9);
  EXPECT_EQ(r.parameters.names, tf_parameter_names({3, 3, 0}));  // a1..a3, b0..b2 (b0 of s^2: 0 here)
  EXPECT_NEAR(r.parameters.value("b2"), 52.0, 1e-4 * 52);
}

TEST(FreeResponsePoles, Table48DataMatrixOnTheS4FreeResponse) {
  // ES Ex. 4.6: y(0) = 0.2, Dy(0) = 10, D^2y = D^3y = 0, Ts = pi/420, N = 15 pairs, shifts 40, 80, 100, 120 Ts,
  // t_fk - t_ok = 20 Ts, spacing 20 Ts; the first instant t_o1 is not stated (120 Ts here, the earliest possible).
  const Eigen::VectorXd t = time_grid(kTs420, 1200);
  const Eigen::VectorXd y =
      lsim(phase_variable_form(kS4), InputGenerator::constant(0.0), t, Eigen::Vector4d(0.2, 10.0, 0.0, 0.0));
  FreeResponseOptions o{.shifts = Eigen::Vector4d(40, 80, 100, 120) * kTs420, .start = 120 * kTs420,
                        .interval = 20 * kTs420, .spacing = 20 * kTs420, .pairs = 15};
  const PoleEstimate s = free_response_poles(y, kTs420, o);
  EXPECT_LT(max_rel(s.characteristic.coefficients(), kS4.den().coefficients()), 1e-6);  // Simpson: the truth
  // Newton's identities equal the characteristic polynomial of Lambda computed from its eigenvalues.
  const Eigen::VectorXd ev = s.characteristic.coefficients();
  EXPECT_LT(max_rel(ev, StateSpace(s.lambda, Eigen::MatrixXd::Zero(4, 1), Eigen::MatrixXd::Zero(1, 4),
                                   Eigen::MatrixXd::Zero(1, 1)).to_transfer_function().den().coefficients()),
            1e-10);
  // The trapezoid rule, derived: a pair's difference of e^{lambda t} over its trapezoid integral maps each mode to
  // (2/h) tanh(lambda h / 2) — the same for every window, as every pair of a free response holds the same modes.
  // So the estimate is the polynomial of the mapped true poles, whatever t_o1.
  o.quadrature = Quadrature::Trapezoid;
  const Eigen::VectorXd mapped = trapezoid_mapped(kS4.poles(), kTs420);
  Eigen::VectorXd c;
  // (Measured 2e-12 at 120 and 400 Ts; at 800 Ts, where the response has decayed to 3e-3, rounding: 4.8e-8.)
  for (int start : {120, 400, 800}) {
    o.start = start * kTs420;
    c = free_response_poles(y, kTs420, o).characteristic.coefficients();
    EXPECT_LT(max_rel(c, mapped), start < 800 ? 1e-9 : 1e-7) << "t_o1 = " << start << " Ts";
  }
  // The printed a^ (Table 4.8) is not reproduced: it lies 0.14-0.21 % from our trapezoid estimate in every
  // coefficient (above it, as the trapezoid lies above the truth), and no window changes a free response's estimate.
  // The trapezoid at a step of 1.6 Ts (not a step the thesis names) comes within 1.7 half-units of the print's last
  // digit in every coefficient, and prints its poles -2.007 +- 10.01j, -1.000 +- 1.500j (el-shafey.md).
  const Eigen::Vector4d printed(6.014, 115.6, 221.6, 338.8);
  const Eigen::Array4d gap = (printed - c.tail(4)).array() / printed.array();
  EXPECT_GT(gap.minCoeff(), 1.0e-3);
  EXPECT_LT(gap.maxCoeff(), 2.5e-3);
}

TEST(FreeResponsePoles, Table49AugmentedWithTheGeneratorAndDeflated) {
  // ES Ex. 4.7: S3 forced by sin 4t from rest, order 5, shifts 40, 80, 110, 140, 170 Ts, N = 20 pairs spaced
  // 20 Ts, interval 20 Ts; t_o1 not stated (170 Ts here, the earliest). True P_a = s^5 + 4s^4 + 46s^3 + 116s^2 +
  // 480s + 832 = (s^3 + 4s^2 + 30s + 52)(s^2 + 16); deflation returns a = (52, 30, 4).
  const IdData d = sine_record(1200);
  FreeResponseOptions o{.shifts = Eigen::VectorXd{{40, 80, 110, 140, 170}} * kTs420, .start = 170 * kTs420,
                        .interval = 20 * kTs420, .spacing = 20 * kTs420, .pairs = 20,
                        .generator = InputGenerator::sinusoid(4.0, 1.0).characteristic_polynomial()};
  const PoleEstimate s = free_response_poles(d.y().col(0), kTs420, o);
  const Eigen::VectorXd truth{{1, 4, 46, 116, 480, 832}};
  EXPECT_LT(max_rel(s.augmented.coefficients(), truth), 1e-6);
  EXPECT_LT(max_rel(s.characteristic.coefficients(), kS3.den().coefficients()), 1e-6);
  EXPECT_EQ(s.all_poles.size(), 5);
  EXPECT_EQ(s.poles.size(), 3);
  // The forced response is a free response of the augmented system: the trapezoid maps its five modes (the
  // system's and the generator's +-4j) to (2/h) tanh(lambda h / 2), for every start while the transient lasts.
  o.quadrature = Quadrature::Trapezoid;
  Eigen::VectorXcd modes(5);
  modes << kS3.poles(), std::complex<double>(0, 4), std::complex<double>(0, -4);
  const Eigen::VectorXd mapped = trapezoid_mapped(modes, kTs420);
  Eigen::VectorXd c;
  // (Measured up to 2.7e-8, at 450 Ts: the system's modes decay and the rounding of the data matrix grows.)
  for (int start : {170, 300, 450}) {
    o.start = start * kTs420;
    c = free_response_poles(d.y().col(0), kTs420, o).augmented.coefficients();
    EXPECT_LT(max_rel(c, mapped), 1e-7) << "t_o1 = " << start << " Ts";
  }
  // The printed P_a = (3.992, 45.93, 115.5, 478.4, 827.1) is not reproduced: it lies below the truth in every
  // coefficient, while the trapezoid (at steps of 1 to 3 Ts) and Simpson lie on or above it; it is 0.17-0.63 % from our
  // trapezoid estimate (a_0: 827.1 against 832.30) (el-shafey.md).
  const Eigen::VectorXd printed{{3.992, 45.93, 115.5, 478.4, 827.1}};
  for (int j = 1; j <= 5; ++j) EXPECT_GT(c(j), truth(j)) << "coefficient " << j;
  const Eigen::ArrayXd gap = (c.tail(5) - printed).array() / printed.array();
  EXPECT_GT(gap.minCoeff(), 1.5e-3);
  EXPECT_LT(gap.maxCoeff(), 7e-3);
}

TEST(Prony, Table410AliasesWhereTheDataMatrixMethodDoesNot) {
  // ES Ex. 4.8: y = e^{-t} sin 3t + cos 100t, Ts = T_l/666, T_l = 2 pi/3; order 4, N = 10 equations.
  // Computed independently (double precision, start t = 0): T = 33 Ts -> -1 +- 3j and +-21.09j (100 rad/s aliases),
  // cond(R^T R) 21.5; T = 4 Ts -> exact, cond 2.25e4.
  const double Ts = 2 * kPi / 3 / 666;
  const Eigen::VectorXd t = time_grid(Ts, 2000);
  const Eigen::VectorXd y = (-t).array().exp() * (3 * t).array().sin() + (100 * t).array().cos();
  auto sorted_imag = [](const Eigen::VectorXcd& p) {
    std::vector<double> v;
    for (auto z : p) v.push_back(z.imag());
    std::sort(v.begin(), v.end());
    return v;
  };
  const PoleEstimate slow = prony(y, Ts, {.order = 4, .spacing = 33, .equations = 10});
  const auto im33 = sorted_imag(slow.poles);
  EXPECT_NEAR(im33[0], -21.09, 0.01);
  EXPECT_NEAR(im33[3], 21.09, 0.01);
  EXPECT_NEAR(slow.condition, 21.5, 0.5);
  EXPECT_FALSE(slow.warnings.empty());
  const PoleEstimate fast = prony(y, Ts, {.order = 4, .spacing = 4, .equations = 10});
  const auto im4 = sorted_imag(fast.poles);
  EXPECT_NEAR(im4[0], -100.0, 1e-5);
  EXPECT_NEAR(im4[1], -3.0, 1e-5);
  EXPECT_NEAR(fast.condition, 2.25e4, 0.01e4);
  // Table 4.11 set-up: Theorem 4.3 with T_i = i 33 Ts, 10 pairs spaced 33 Ts, interval 33 Ts, start 132 Ts
  // recovers every exponent without aliasing (Simpson at 20 samples per period of cos 100t: 1e-3 relative).
  const PoleEstimate dm = free_response_poles(
      y, Ts, {.shifts = Eigen::Vector4d(33, 66, 99, 132) * Ts, .start = 132 * Ts, .interval = 33 * Ts,
              .spacing = 33 * Ts, .pairs = 10});
  const auto imd = sorted_imag(dm.poles);
  EXPECT_NEAR(imd[0], -100.0, 0.1);
  EXPECT_NEAR(imd[3], 100.0, 0.1);
  EXPECT_NEAR(imd[1], -3.0, 1e-3);
  for (auto z : dm.poles)
    if (std::abs(z.imag()) < 10) EXPECT_NEAR(z.real(), -1.0, 1e-3);
}

TEST(ModalEstimate, BadInputs) {
  const IdData d = step_record(800);
  ModalOptions o{.shifts = kShifts3, .basis = ModalBasis::Discrete};
  o.shifts = Eigen::Vector3d(40, 30, 120) * kTs420;
  EXPECT_THROW(modal_estimate(d, d.u(), o), InvalidOptions);  // not increasing
  o.shifts = Eigen::Vector3d(40.5, 80, 120) * kTs420;
  EXPECT_THROW(modal_estimate(d, d.u(), o), InvalidArgument);  // not a multiple of Ts
  o.shifts = kShifts3;
  o.windows = {{120 * kTs420, 2 * kTs420}};
  EXPECT_THROW(modal_estimate(d, d.u(), o), InvalidArgument);  // 3 equations for 4 unknowns
  o.windows = {{700 * kTs420, 200 * kTs420}};
  EXPECT_THROW(modal_estimate(d, d.u(), o), InvalidArgument);  // beyond the record
  o = {.shifts = kShifts3, .basis = ModalBasis::Walsh, .functions = 6};
  EXPECT_THROW(modal_estimate(d, d.u(), o), InvalidOptions);  // not a power of two
  o = {.shifts = kShifts3, .basis = ModalBasis::Discrete, .max_order = 1};
  EXPECT_THROW(modal_estimate(d, d.u(), o), InvalidOptions);  // derivatives need Fourier/Walsh
  o = {.shifts = kShifts3, .basis = ModalBasis::Walsh, .functions = 8};
  o.windows = {{120 * kTs420, 100 * kTs420}};
  EXPECT_THROW(modal_estimate(d, d.u(), o), InvalidArgument);  // 100 Ts not divisible into 8 blocks
  EXPECT_THROW(free_response_poles(d.y().col(0), kTs420, {.shifts = kShifts3, .start = 10 * kTs420, .interval = kTs420,
                                                           .spacing = kTs420, .pairs = 3}),
               InvalidArgument);  // t_o1 - T_3 before the record
}

TEST(ModalEstimate, Tables33To35NoisyOutputBiasesLeastSquaresAndIvOrIntegralsRemoveIt) {
  // ES Ex. 3.3-3.4: the Table 3.1 set-up with N(0, 0.1^2) output noise, 200 seeded runs. The thesis prints one
  // run each (p^_01: Table 3.3, LS on samples, -0.5832; Table 3.4, Fourier -0.6370, Walsh -0.6317; Table 3.5, IV,
  // is empty in the source). Our medians: LS -0.265 (a regression value of 2 000 runs, not printed), strongly
  // biased towards zero; IV (tau_iv = 25 Ts), Fourier and Walsh within 0.05 of the true p_01 = -0.6605.
  const int N = 900;
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = i < 444 ? 1.0 : -1.0;
  const Eigen::VectorXd y0 = lsim(kS3, u, time_grid(kTs420, N));
  const int runs = 200;
  std::vector<double> ls, iv, fourier, walsh;
  for (int run = 0; run < runs; ++run) {
    const IdData d(u, y0 + white_noise(N, 0.1, 1000 + run), kTs420);
    ModalOptions o{.shifts = kShifts3, .basis = ModalBasis::Discrete, .stride = 20};
    o.windows = {{120 * kTs420, 180 * kTs420}, {564 * kTs420, 180 * kTs420}};
    ls.push_back(modal_estimate(d, d.u(), o).model.P()(0, 0));
    o.iv_shift = 25 * kTs420;
    iv.push_back(modal_estimate(d, d.u(), o).model.P()(0, 0));
    ModalOptions c{.shifts = kShifts3, .functions = 6};
    c.windows = {{120 * kTs420, 320 * kTs420}, {564 * kTs420, 320 * kTs420}};
    fourier.push_back(modal_estimate(d, d.u(), c).model.P()(0, 0));
    c.basis = ModalBasis::Walsh;
    c.functions = 8;
    walsh.push_back(modal_estimate(d, d.u(), c).model.P()(0, 0));
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  const double truth = -0.6605;
  EXPECT_NEAR(median(ls), -0.265, 0.03);  // regression value (2 000 runs of this set-up), not printed
  EXPECT_GT(median(ls) - truth, 0.3);     // LS biased towards zero, as the printed single run (-0.5832) is
  EXPECT_NEAR(median(iv), truth, 0.05);
  EXPECT_NEAR(median(fourier), truth, 0.05);
  EXPECT_NEAR(median(walsh), truth, 0.05);
  // Where the printed single runs fall in our 200 (the fraction of our runs at or below the print; each bound is
  // about 4 binomial standard errors of a 200-run fraction): Table 3.3's LS -0.5832 at 0.12 — inside our LS
  // spread, which is wide (10-90 %: -0.598 .. -0.011) — Table 3.4's Fourier -0.6370 at 0.79 and Walsh -0.6317 at
  // 0.53.
  EXPECT_GT(percentile_of(ls, -0.5832), 0.03);
  EXPECT_LT(percentile_of(ls, -0.5832), 0.21);
  EXPECT_GT(percentile_of(fourier, -0.6370), 0.67);
  EXPECT_LT(percentile_of(fourier, -0.6370), 0.91);
  EXPECT_GT(percentile_of(walsh, -0.6317), 0.41);
  EXPECT_LT(percentile_of(walsh, -0.6317), 0.64);
}

namespace {
// True q_j in the basis [sin wt, cos wt] for the input a sin wt + b cos wt: y_j = Im((a + jb) K_j e^{jwt}).
Eigen::Vector2d q_true(const TransferFunction& h, const Eigen::VectorXd& T, const Eigen::RowVectorXd& pj, int j,
                       double w, const Eigen::Vector2d& ab) {
  const Eigen::Vector2d k = q_true_sine(h, T, pj, j, w);
  const std::complex<double> M = std::complex<double>(ab(0), ab(1)) * std::complex<double>(k(0), k(1));
  return {M.real(), M.imag()};
}
}  // namespace

TEST(ModalEstimate, Tables38To312PrefilteredPairsOfATwoFrequencyInput) {
  // ES Ex. 3.9: S3, u = cos 6t - sin 3t from rest, T_o = 2 pi/3, Ts = T_o/384 = pi/576, T_i = 40, 80, 120 Ts.
  // L_1 (shifts T_o/8, T_o/4, l = [0, 1]) leaves -sin 3t + cos 3t; L_2 (T_o/4, T_o/2, l = [0, 1]) leaves 2 cos 6t.
  // Window [320 Ts, 704 Ts] (after the filter's and the system's shifts); 6 Fourier / 8 Walsh functions, j = 0..3.
  // p parts = Table 3.10 (true) to 1e-6; q only via invariants: |q_j| equals |q true| (the published
  // q^ are in another sinusoid basis, |q^ published| = |q true|, e.g. 0.5344 for q^1_0).
  const double Ts = kPi / 576, To = 384 * Ts;
  const Eigen::Vector3d T(40 * Ts, 80 * Ts, 120 * Ts);
  const InputGenerator g3 = InputGenerator::sinusoid(3.0, -1.0), g6 = InputGenerator::sinusoid(6.0, 0.0, 1.0);
  const Eigen::VectorXd t = time_grid(Ts, 800);
  const IdData d((g3 + g6)(t), lsim(kS3.to_state_space(), g3 + g6, t), Ts);
  const Eigen::MatrixXd P = modal_parameters(kS3, T, 3).P;
  struct Pair {
    Eigen::Vector2d shifts;
    InputGenerator keep;
    double w;
  };
  const Pair pairs[2] = {{Eigen::Vector2d(To / 8, To / 4), g3, 3.0}, {Eigen::Vector2d(To / 4, To / 2), g6, 6.0}};
  const double published_abs_q0[2] = {std::hypot(-0.3362, 0.4154), std::hypot(-0.9154, -0.08869)};  // Tables 3.8, 3.9
  std::vector<ModalExperiment> fourier_pairs;
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector2d l(0.0, 1.0);
    const IdData f = modal_filter(d, pairs[k].shifts, l);
    const InputGenerator left = modal_filter(pairs[k].keep, pairs[k].shifts, l);
    for (auto basis : {ModalBasis::Fourier, ModalBasis::Walsh}) {
      ModalOptions o{.shifts = T, .basis = basis, .max_order = 3, .functions = basis == ModalBasis::Fourier ? 6 : 8};
      o.windows = {{320 * Ts, 384 * Ts}};
      const auto r = modal_estimate(f, left, o);
      ASSERT_TRUE(r.usable()) << r.why_not_usable();
      EXPECT_LT(max_rel(r.model.P(), P), 1e-6) << "pair " << k << " basis " << static_cast<int>(basis);
      for (int j = 0; j <= 3; ++j) {
        const Eigen::Vector2d q = q_true(kS3, T, P.row(j), j, pairs[k].w, left.c());
        EXPECT_NEAR(r.model.Q().row(j).norm(), q.norm(), 1e-6 * q.norm()) << "pair " << k << " j " << j;
      }
      EXPECT_NEAR(r.model.Q().row(0).norm(), published_abs_q0[k], 5e-4 * published_abs_q0[k]);
      if (basis == ModalBasis::Fourier) fourier_pairs.push_back({r.model, left});
    }
  }
  // Table 4.7's route on these estimates: Theorems 4.1 and 4.2 stacked over the two pairs (4 input modes,
  // dim b = 3) give b = (52, 13, 0) (the printed b^ from the printed p^ and q^: tests/model/modal_test.cpp).
  const TransferFunction tf = modal_theorems_tf(fourier_pairs);
  EXPECT_LT((tf.den().coefficients() - kS3.den().coefficients()).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_NEAR(tf.num().coefficient_of_power(0), 52.0, 1e-4);
  EXPECT_NEAR(tf.num().coefficient_of_power(1), 13.0, 1e-4);
  EXPECT_NEAR(tf.num().coefficient_of_power(2), 0.0, 1e-4);
}

TEST(ModalEstimate, Tables41And42PrefiltersAndTheOutputModalFunctionRoute) {
  // ES Ex. 4.1: S3, u = cos 6t - sin 4t - sin 2t from rest, Ts = pi/420, T_i = 40, 80, 120 Ts; 15 discrete
  // equations per filtered pair spaced 10 Ts. L_1: shifts (105, 210) Ts, l = [0, 1] (leaves frequency 4);
  // L_2: [STAND-IN] shifts 40, 80, 120, 160 Ts annihilating 6 and 4 (leaves 2); L_3: shifts 50, 100, 150, 200 Ts
  // annihilating 4 and 2, l = (-1.6156, 2.2191, -1.6156, 1.0000) [RECONSTRUCTED] (leaves 6).
  // Table 4.1: p^_0 = true for all three pairs. Table 4.2 (ES-C7): a = (52, 30, 4), b = (52, 13, 0) exactly.
  const InputGenerator g6 = InputGenerator::sinusoid(6.0, 0.0, 1.0), g4 = InputGenerator::sinusoid(4.0, -1.0),
                       g2 = InputGenerator::sinusoid(2.0, -1.0);
  const InputGenerator u = g6 + g4 + g2;
  const Eigen::VectorXd t = time_grid(kTs420, 600);
  const IdData d(u(t), lsim(kS3.to_state_space(), u, t), kTs420);
  const Eigen::Vector4d s2 = Eigen::Vector4d(40, 80, 120, 160) * kTs420, s3 = Eigen::Vector4d(50, 100, 150, 200) * kTs420;
  const Eigen::VectorXd l3 = annihilator(g4 + g2, s3);
  EXPECT_LT((l3 - Eigen::Vector4d(-1.6156, 2.2191, -1.6156, 1.0)).cwiseAbs().maxCoeff(), 1e-4);
  struct Filter {
    Eigen::VectorXd shifts, l;
    InputGenerator keep;
  };
  const std::vector<Filter> filters = {{Eigen::Vector2d(105, 210) * kTs420, Eigen::Vector2d(0, 1), g4},
                                       {s2, annihilator(g6 + g4, s2), g2},
                                       {s3, l3, g6}};
  const Eigen::MatrixXd P = modal_parameters(kS3, kShifts3, 0).P;
  // Table 4.1's printed p^_0, one column per filter: within 0.5 % of the truth, which our estimates are.
  const double p0_print[3][3] = {{-0.6586, 0.6087, -0.3016}, {-0.6597, 0.6120, -0.3034}, {-0.6572, 0.6092, -0.3030}};
  std::vector<ModalExperiment> ex;
  for (std::size_t k = 0; k < filters.size(); ++k) {
    const Filter& f = filters[k];
    ModalOptions o{.shifts = kShifts3, .basis = ModalBasis::Discrete, .stride = 10};
    o.windows = {{340 * kTs420, 140 * kTs420}};
    const InputGenerator left = modal_filter(f.keep, f.shifts, f.l);
    const auto r = modal_estimate(modal_filter(d, f.shifts, f.l), left, o);
    ASSERT_TRUE(r.usable()) << r.why_not_usable();
    EXPECT_LT(max_rel(r.model.P(), P), 1e-8);
    const Eigen::RowVector3d printed(p0_print[k]);
    EXPECT_LT((r.model.P().row(0).array() / printed.array() - 1).abs().maxCoeff(), 5.5e-3) << "Table 4.1 filter " << k + 1;
    // q^_0 of L_3 (the one filter whose shifts and parameters are both known): |q^_0| 2.829 against the printed
    // (-1.374, -2.457), 2.815. L_1's (1.508 against 0.647) is not reproduced: its printed parameters [1 0] disagree
    // with the text's [0 1], and with [1 0] the filter does not annihilate the frequencies it should. L_2's shifts
    // are lost.
    if (k == 2) EXPECT_NEAR(r.model.Q().row(0).norm() / std::hypot(-1.374, -2.457), 1.0049, 1e-3);
    ex.push_back({r.model, left});
  }
  const TransferFunction tf = modal_output_function_tf(ex);
  EXPECT_LT((tf.den().coefficients() - kS3.den().coefficients()).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_NEAR(tf.num().coefficient_of_power(1), 13.0, 1e-6);
  EXPECT_NEAR(tf.num().coefficient_of_power(0), 52.0, 1e-6);
  EXPECT_NEAR(tf.num().coefficient_of_power(2), 0.0, 1e-6);
  // Table 4.2's printed a^ = (52.05, 30.00, 4.001) agrees with ours (the truth) within 1e-3; its b^ = (52.04, 12.80,
  // -0.0476) within 1e-3 in b_0 only: b_1 lies 1.5 % below ours (el-shafey.md).
  const Eigen::Vector3d a_print(52.05, 30.00, 4.001);
  for (int j = 0; j < 3; ++j) EXPECT_LT(std::abs(tf.den().coefficient_of_power(j) / a_print(j) - 1), 1e-3) << "a_" << j;
  EXPECT_LT(std::abs(tf.num().coefficient_of_power(0) / 52.04 - 1), 1e-3);
  EXPECT_NEAR(tf.num().coefficient_of_power(1) / 12.80 - 1, 0.0156, 1e-3);
  EXPECT_THROW(modal_output_function_tf({ex[0], ex[1]}), InvalidArgument);  // 4 modes < 2n = 6
}

TEST(ModalResponses, Tables51And52FrequencyResponseFromASquareWave) {
  // ES Ex. 5.1: S3 driven by a square wave (+1 on (0, pi), -1 on (pi, 2 pi), w_o = 1) from rest, Ts = pi/420;
  // p_0 from the constant-input windows (shifts 40, 80, 120 Ts); correlations are un-normalised integrals over
  // [T_3, T_3 + 2 pi] with basis sin k(t - T_3), cos k(t - T_3) [RECONSTRUCTED set-up, VERIFIED]; u_0 integrated
  // exactly (held input), y_0 by Simpson. Table 5.1 "ours" columns to the printed 4 digits; Table 5.2: H(jk).
  const int N = 1000;
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = (i / 420) % 2 == 0 ? 1.0 : -1.0;
  const IdData d(u, lsim(kS3, u, time_grid(kTs420, N)), kTs420);
  ModalOptions o{.shifts = kShifts3, .basis = ModalBasis::Discrete};
  o.windows = piecewise_constant_windows(d, kShifts3(2));
  const auto m = modal_estimate(d, d.u(), o);
  const HarmonicResponse h = modal_frequency_response(d, m.model, 2 * kPi, {1, 3, 5, 7, 9, 11}, 120 * kTs420);
  Eigen::MatrixXd table(6, 4);  // Table 5.1 recomputed independently: nu_1, nu_2, q_1, q_2
  table << 1.4363, 2.3589, 1.9751, 1.7512,  //
      -0.9006, 0.3565, -0.4773, 0.8428,     //
      0.1392, -0.3715, -0.6021, -0.0997,    //
      0.4130, 0.6290, -0.1093, -0.3872,     //
      -0.6607, 0.7805, 0.1793, -0.1676,     //
      -0.8866, -0.2617, 0.1214, 0.0437;
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(h.nu(k, 0), table(k, 0), 1e-4) << "harmonic " << 2 * k + 1;
    EXPECT_NEAR(h.nu(k, 1), table(k, 1), 1e-4) << "harmonic " << 2 * k + 1;
    EXPECT_NEAR(h.q(k, 0), table(k, 2), 1e-4) << "harmonic " << 2 * k + 1;
    EXPECT_NEAR(h.q(k, 1), table(k, 3), 1e-4) << "harmonic " << 2 * k + 1;
    // Table 5.2: H(jk) against the true frequency response (Simpson on y_0 at 840 samples per period:
    // measured relative error <= 5.9e-7).
    const std::complex<double> truth = kS3(std::complex<double>(0, 2 * k + 1));
    EXPECT_LT(std::abs(h.response.response()(k) - truth), 2e-6 * std::abs(truth)) << "harmonic " << 2 * k + 1;
  }
  // The printed Table 5.1 (every row): ours differ from the print by at most 1.5e-3 (nu_2 at k = 11: -0.2617 against
  // -0.2632; docs/methods/el-shafey.md), the thesis' quadrature of u_0 and y_0 being coarser (its Table 5.2 is accordingly
  // further from the truth than ours); asserted within 2e-3.
  Eigen::MatrixXd printed51(6, 4);
  printed51 << 1.436, 2.359, 1.974, 1.751,  //
      -0.9008, 0.3559, -0.4778, 0.8423,     //
      0.1395, -0.3717, -0.6021, -0.1003,    //
      0.4124, 0.6293, -0.1089, -0.3875,     //
      -0.6618, 0.7798, 0.1795, -0.1675,     //
      -0.8865, -0.2632, 0.1213, 0.04375;
  // Table 5.2, printed: the estimated and the true columns (Re, Im of H(jk), k = 1, 3, .., 11).
  const double printed52_est[6][2] = {{0.9135, -0.2811}, {0.7784, -0.6276}, {-0.2964, -1.509},
                                      {-0.5101, -0.1612}, {-0.2384, -0.02782}, {-0.1392, -0.008015}};
  const double printed52_true[6][2] = {{0.9135, -0.2811}, {0.7785, -0.6277}, {-0.2974, -1.509},
                                       {-0.5099, -0.1610}, {-0.2383, -0.02795}, {-0.1393, -0.008181}};
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(h.nu(k, 0), printed51(k, 0), 2e-3) << "harmonic " << 2 * k + 1;
    EXPECT_NEAR(h.nu(k, 1), printed51(k, 1), 2e-3) << "harmonic " << 2 * k + 1;
    EXPECT_NEAR(h.q(k, 0), printed51(k, 2), 2e-3) << "harmonic " << 2 * k + 1;
    EXPECT_NEAR(h.q(k, 1), printed51(k, 3), 2e-3) << "harmonic " << 2 * k + 1;
    // Table 5.2's estimated column follows from the printed Table 5.1 by ES 5.14 (algebraic consistency of the
    // 4-digit numbers: measured at most 3.7e-4, Im H(5j)).
    const double nu1 = printed51(k, 0), nu2 = printed51(k, 1), q1 = printed51(k, 2), q2 = printed51(k, 3);
    const double det = nu1 * nu1 + nu2 * nu2;
    EXPECT_NEAR((q1 * nu1 + q2 * nu2) / det, printed52_est[k][0], 4e-4) << "harmonic " << 2 * k + 1;
    EXPECT_NEAR((q2 * nu1 - q1 * nu2) / det, printed52_est[k][1], 4e-4) << "harmonic " << 2 * k + 1;
    // Our H(jk) against Table 5.2's printed true column, to its printed digits (measured at most 6.4e-5).
    EXPECT_NEAR(h.response.response()(k).real(), printed52_true[k][0], 1e-4) << "harmonic " << 2 * k + 1;
    EXPECT_NEAR(h.response.response()(k).imag(), printed52_true[k][1], 1e-4) << "harmonic " << 2 * k + 1;
  }
  EXPECT_THROW(modal_frequency_response(d, m.model, 2 * kPi, {2}, 120 * kTs420), InvalidArgument);  // no even harmonics
  EXPECT_THROW(modal_frequency_response(d, m.model, 2 * kPi, {1}, 100 * kTs420), InvalidArgument);  // before T_3
}

TEST(ModalResponses, Tables53And54StepAndImpulseResponsesFromPiecewiseConstantData) {
  // ES Ex. 5.2: S3, input +1, +2, -1, -2 each 80 Ts, Ts = pi/320, from rest; T = 20 Ts, shifts 20, 40, 60 Ts;
  // p_0 from the constant-input windows (computed independently: (-1.5883, 1.2918, -0.4559)); g on [0, 640 Ts] by ES 5.32
  // and 5.37 equals the true step response (spec: 6e-15). Table 5.3's true column (spacing 20 Ts) to 5e-4.
  const double Ts = kPi / 320, T = 20 * Ts;
  const int N = 320;
  Eigen::VectorXd u(N);
  const double levels[4] = {1, 2, -1, -2};
  for (int i = 0; i < N; ++i) u(i) = levels[i / 80];
  const IdData d(u, lsim(kS3, u, time_grid(Ts, N)), Ts);
  const Eigen::Vector3d shifts(T, 2 * T, 3 * T);
  ModalOptions o{.shifts = shifts, .basis = ModalBasis::Discrete};
  o.windows = piecewise_constant_windows(d, 3 * T);
  const auto m = modal_estimate(d, d.u(), o);
  EXPECT_LT((m.model.P().row(0) - Eigen::RowVector3d(-1.5883, 1.2918, -0.4559)).cwiseAbs().maxCoeff(), 1e-4);
  const TimeResponse g = modal_step_response(d, m.model, T, 640 * Ts);
  const Eigen::VectorXd truth = step_response(kS3, g.t);
  EXPECT_LT((g.value - truth).cwiseAbs().maxCoeff(), 1e-9);
  // Every printed row of Table 5.3 (k = 0..31, samples every 20 Ts, not the printed 10): our g to 5e-4 relative
  // (4 printed digits; 1e-6 absolute for k = 0, printed 6.047e-7, true 0). Two rows are misprints (docs/methods/el-shafey.md):
  // k = 2 repeats row 1 (0.2291; compared here with the true 0.7141) and the estimated column's k = 19 prints 0.9804
  // (the true column and our g: 0.9894).
  const double table53[32] = {6.047e-7, 0.2291, 0.7141 /* printed 0.2291 */, 1.086, 1.154, 1.004, 0.8457, 0.8207,
                              0.9160, 1.028, 1.071, 1.039, 0.9821, 0.9542, 0.9680, 1.000, 1.021, 1.018, 1.002,
                              0.9894 /* printed 0.9804 */, 0.9887, 0.9967, 1.005, 1.006, 1.003, 0.9981, 0.9965, 0.9980,
                              1.001, 1.002, 1.001, 0.9999};
  for (int k = 0; k < 32; ++k)
    EXPECT_NEAR(g.value(20 * k), table53[k], std::max(5e-4 * std::abs(table53[k]), 1e-6)) << "k = " << k;

  // ES Ex. 5.3 / Table 5.4: impulse response from this step response with negative shifts (-40, -80, -120) Ts
  // (the shifts that reproduce the published p_1 [RECONSTRUCTED]), 6 Fourier functions with period 192 Ts.
  // True p_1 = (-1.6728, 8.1618, 11.2474), q_10 = 17.736; h to 8e-7 (computed independently).
  const Eigen::Vector3d neg(-40 * Ts, -80 * Ts, -120 * Ts);
  const ImpulseFromStep imp = modal_impulse_from_step(g, neg, 192 * Ts);
  EXPECT_LT((imp.p1 - Eigen::Vector3d(-1.6728, 8.1618, 11.2474)).cwiseAbs().maxCoeff(), 5e-4 * 11.25);
  EXPECT_NEAR(imp.q10, 17.736, 5e-4 * 17.736);
  const Eigen::VectorXd h_true = impulse_response(kS3, imp.impulse.t);
  EXPECT_LT((imp.impulse.value - h_true).cwiseAbs().maxCoeff(), 1e-5);
  // Every printed row of Table 5.4 (k = 0..25, every 20 Ts): our h against the printed true column to its 4 digits
  // (5e-4 relative, at least 1e-6 absolute). The printed estimates differ from the printed true column by up to
  // 3.0e-3 (k = 1, 2: 2.135, 2.464 against 2.132, 2.461; 6.5e-4 at k = 20, 0.02612 against 0.02547), the thesis' own
  // quadrature error; ours from the truth by at most 8e-7. Asserted: ours within 3.5e-3 of every printed estimate.
  const double table54_true[26] = {-1e-15,   2.132,    2.461,    1.155,     -0.3724,   -0.9616,  -0.5195,
                                   0.2472,   0.6253,   0.4369,   -1.019e-3, -0.2809,   -0.2457,  -0.02778,
                                   0.1452,   0.1544,   0.04508,  -0.06168,  -0.08580,  -0.03604, 0.02547,
                                   0.04788,  0.02672,  -0.007797, -0.02507, -0.01757};
  const double table54_est[26] = {3.080e-4, 2.135,    2.464,    1.156,     -0.3732,   -0.9625,  -0.5194,
                                  0.2483,   0.6266,   0.4378,   -6.800e-4, -0.2808,   -0.2454,  -0.02713,
                                  0.1460,   0.1551,   0.04564,  -0.06123,  -0.08530,  -0.03548, 0.02612,
                                  0.04851,  0.02734,  -0.007232, -0.02450, -0.01698};
  for (int k = 0; k < 26; ++k) {
    EXPECT_NEAR(imp.impulse.value(20 * k), table54_true[k], std::max(5e-4 * std::abs(table54_true[k]), 1e-6))
        << "k = " << k;
    EXPECT_NEAR(imp.impulse.value(20 * k), table54_est[k], 3.5e-3) << "k = " << k;
  }
  // Bad input: positive shifts, shifts that are not i T, input changing inside a level period.
  EXPECT_THROW(modal_impulse_from_step(g, -neg, 192 * Ts), InvalidArgument);
  EXPECT_THROW(modal_step_response(d, m.model, 10 * Ts, 640 * Ts), InvalidArgument);
  EXPECT_THROW(modal_step_response(d, m.model, 20 * Ts, 1e300), InvalidArgument);  // no int overflow
}

TEST(ModalFit, PiecewiseConstantInputsGiveTheTransferFunctionByBothRoutes) {
  // The Ex. 5.2 record (levels +1, +2, -1, -2 each 80 Ts, Ts = pi/320) extended to 4 cycles: (a) Walsh functions
  // on the constant-input windows with p_0..p_3 and Theorem 4.1, (b) the Discrete route with uniform shifts
  // i T (poles from p_0). Both with the numerator by least squares given A(s): S3 to 1e-6 on noise-free data.
  const double Ts = kPi / 320;
  const int N = 1280;
  Eigen::VectorXd u(N);
  const double levels[4] = {1, 2, -1, -2};
  for (int i = 0; i < N; ++i) u(i) = levels[(i / 80) % 4];
  const IdData d(u, lsim(kS3, u, time_grid(Ts, N)), Ts);
  const Eigen::Vector3d shifts(16 * Ts, 32 * Ts, 48 * Ts);
  for (auto basis : {ModalBasis::Walsh, ModalBasis::Discrete}) {
    const auto r = modal_fit(d, 2, {.shifts = shifts, .basis = basis, .functions = 8});
    ASSERT_TRUE(r.usable()) << r.why_not_usable();
    EXPECT_LT(max_rel(r.model.den().coefficients(), kS3.den().coefficients()), 1e-6) << static_cast<int>(basis);
    EXPECT_NEAR(r.model.num().coefficient_of_power(1), 13.0, 1e-5);
    EXPECT_NEAR(r.model.num().coefficient_of_power(0), 52.0, 1e-5);
    EXPECT_GT(r.fit.fit_percent, 99.999);
    // One naming of transfer-function coefficients across methods: a1..a3 of s^2..s^0, b0 of the
    // numerator's highest power — SRIVC's names for the same coefficients of S3 = (13 s + 52)/(s^3 + ...).
    EXPECT_EQ(r.parameters.names, tf_parameter_names({2, 3, 0}));
    EXPECT_NEAR(r.parameters.value("a1"), kS3.den().coefficient_of_power(2), 1e-6 * 52);
    EXPECT_NEAR(r.parameters.value("a3"), kS3.den().coefficient_of_power(0), 1e-6 * 52);
    EXPECT_NEAR(r.parameters.value("b0"), 13.0, 1e-5);
    EXPECT_NEAR(r.parameters.value("b1"), 52.0, 1e-5);
  }
  // The shifts left to modal_fit (order 3 only): uniform shifts with T_3 <= half the 80-sample levels, from
  // the conditioning scan of an SRIVC pre-estimate (chosen: 10 samples apart); noise-free the same S3 to 1e-6 (measured
  // 5e-8), the choice stated.
  {
    const auto r = modal_fit(d, 2, {.order = 3});
    ASSERT_TRUE(r.usable()) << r.why_not_usable();
    EXPECT_LT(max_rel(r.model.den().coefficients(), kS3.den().coefficients()), 1e-6);
    ASSERT_EQ(r.diagnostics.choices.size(), 1u);
    EXPECT_NE(r.diagnostics.choices[0].find("half the median level duration"), std::string::npos) << r.diagnostics.choices[0];
    EXPECT_THROW(modal_fit(d, 2, {}), InvalidOptions);  // neither shifts nor order
    EXPECT_THROW(modal_fit(d, 2, {.shifts = shifts, .order = 2}), InvalidOptions);
  }
  EXPECT_THROW(modal_fit(d, 4, {.shifts = shifts}), InvalidArgument);  // nb > n
  EXPECT_THROW(modal_fit(d, 2, {.shifts = Eigen::Vector3d(16, 32, 56) * Ts, .basis = ModalBasis::Discrete}),
               InvalidArgument);  // non-uniform shifts on the Discrete route
}

TEST(ModalEstimate, Tables313And314SquareWaveAnnihilatedToAFreeResponse) {
  // ES Ex. 3.10: S4 driven by a square wave of period T_o = pi (amplitude +-1) from the initial state y(0) = 0.2,
  // Dy = D^2y = D^3y = 0 (phase variables), Ts = pi/420, T_i = 20, 40, 110, 160 Ts. L y = y(t) + y(t - T_o/2)
  // removes every odd harmonic, so L y is a free response (no input basis). 8 Fourier / 8 Walsh functions on one
  // period from [STAND-IN] 370 Ts = T_o/2 + T_4; p_0..p_4 (Simpson) equal the true Table 3.15 values to 5e-6
  // (measured <= 2.4e-6: the 10 rad/s modes at 42 samples per period).
  const int N = 900;
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = (i / 210) % 2 == 0 ? 1.0 : -1.0;
  const StateSpace pv = phase_variable_form(kS4);
  const Discretization D = discretize(pv.A(), pv.B(), kTs420);
  Eigen::VectorXd y(N), x = Eigen::Vector4d(0.2, 0.0, 0.0, 0.0);
  for (int i = 0; i < N; ++i) {
    y(i) = x(0);
    x = D.Phi * x + D.Gamma0 * u(i);
  }
  const IdData f = modal_filter(IdData(u, y, kTs420), Eigen::VectorXd::Constant(1, 210 * kTs420), Eigen::VectorXd::Ones(1));
  const Eigen::Vector4d T = Eigen::Vector4d(20, 40, 110, 160) * kTs420;
  const Eigen::MatrixXd P = modal_parameters(kS4, T, 4).P;
  for (auto basis : {ModalBasis::Fourier, ModalBasis::Walsh}) {
    ModalOptions o{.shifts = T, .basis = basis, .max_order = 4, .functions = 8};
    o.windows = {{370 * kTs420, (basis == ModalBasis::Walsh ? 416 : 420) * kTs420}};  // Walsh: 52 samples per block
    const auto r = modal_estimate(f, Eigen::MatrixXd(N, 0), o);
    ASSERT_TRUE(r.usable()) << r.why_not_usable();
    for (int j = 0; j <= 4; ++j)
      EXPECT_LT(max_rel(r.model.P().row(j), P.row(j)), 5e-6) << "basis " << static_cast<int>(basis) << " j " << j;
  }
  // The printed estimates against ours, row by row (deviations relative to the true row's norm). Table 3.14 (Walsh)
  // is the thesis' trapezoid quadrature: our trapezoid Walsh estimate on the same window lies within 3.0e-4 of every
  // printed row (4-digit rounding; entry by entry within 0.3 %, the largest p_4's second entry, printed -98.21
  // against our -97.94), and 2.9e-3 from the truth, as the print is.
  const double walsh_print[5][4] = {{-1.042, -0.02200, 0.2179, -0.05769},
                                    {2.990, -2.808, 1.262, -0.1059},
                                    {27.60, -16.35, -8.266, 5.330},
                                    {-412.6, 435.0, -81.11, 8.519},
                                    {-1016, -98.21, 1088, -623.1}};
  ModalOptions o{.shifts = T, .basis = ModalBasis::Walsh, .max_order = 4, .functions = 8};
  o.quadrature = Quadrature::Trapezoid;
  o.windows = {{370 * kTs420, 416 * kTs420}};
  const Eigen::MatrixXd trap = modal_estimate(f, Eigen::MatrixXd(N, 0), o).model.P();
  for (int j = 0; j <= 4; ++j) {
    const Eigen::Vector4d walsh(walsh_print[j]);
    EXPECT_LT((walsh - trap.row(j).transpose()).norm(), 4e-4 * P.row(j).norm()) << "Table 3.14 row p_" << j;
    EXPECT_LT((walsh - trap.row(j).transpose()).cwiseAbs().cwiseQuotient(walsh.cwiseAbs()).maxCoeff(), 3e-3)
        << "Table 3.14 row p_" << j;
  }
  // Table 3.13 (Fourier, eight functions, w_o = 2) is not reproduced beyond p_0: its rows p_1..p_4 lie up to 6 % of
  // the row's norm from the truth (p_4's second entry -153.7 against -94.39). Our Simpson Fourier estimate is the
  // truth for every window start (above); the trapezoid's varies with the start, and over every start from 370 to
  // 2180 Ts the closest comes within no less than 48 half-units of a printed last digit (el-shafey.md). p_0 agrees:
  // our Fourier estimate lies within 4.2e-4 of each printed entry (relative), except the second, printed -0.02220
  // where the Walsh table and the truth have -0.02200 (a transposed digit).
  ModalOptions fo{.shifts = T, .basis = ModalBasis::Fourier, .max_order = 4, .functions = 8};
  fo.windows = {{370 * kTs420, 420 * kTs420}};
  const Eigen::RowVectorXd p0 = modal_estimate(f, Eigen::MatrixXd(N, 0), fo).model.P().row(0);
  const Eigen::Vector4d fourier_p0(-1.042, -0.02200, 0.2179, -0.05770);
  for (int i = 0; i < 4; ++i)
    EXPECT_LT(std::abs(p0(i) / fourier_p0(i) - 1), 5e-4) << "Table 3.13 p_0 entry " << i;
}

TEST(ModalEstimate, Tables43And44NoisyPrefilteredRouteLeastSquaresAgainstIv) {
  // ES Ex. 4.2: the Table 4.1 set-up with N(0, 0.01^2) output noise, 400 seeded runs, ES-C7 on the three
  // prefiltered pairs, 15 equations 10 Ts apart from the first instant at which a filtered pair obeys the modal
  // relation (the filter's longest shift + T_3, as Example 3.1's window w1 starts at T_3). Published single runs:
  // LS a = (56.71, 39.45, 4.170), IV (52.53, 30.05, 4.015); an independent Monte Carlo (200 runs):
  // LS median a = (48.5, 29.8, 3.82), IV (tau_iv = 25 Ts) (50.0, 30.1, 3.90) with a larger spread.
  //
  // Why the instants matter: after the prefilter a filtered output is one sinusoid plus the system's decaying free
  // response, and p_0 is identified by that free response alone (a steady sinusoid fits every p_0 with some q_0).
  // A window starting at 340 Ts for every filter (this test's former set-up) begins 60 Ts late for L_2 and gives
  // LS a_0 = 63.5, IV 60.4 — the "16 % IV bias" was the late window, not the estimator.
  const InputGenerator g6 = InputGenerator::sinusoid(6.0, 0.0, 1.0), g4 = InputGenerator::sinusoid(4.0, -1.0),
                       g2 = InputGenerator::sinusoid(2.0, -1.0);
  const InputGenerator u = g6 + g4 + g2;
  const Eigen::VectorXd t = time_grid(kTs420, 600);
  const Eigen::VectorXd y0 = lsim(kS3.to_state_space(), u, t);
  const Eigen::Vector4d s2 = Eigen::Vector4d(40, 80, 120, 160) * kTs420, s3 = Eigen::Vector4d(50, 100, 150, 200) * kTs420;
  struct Filter {
    Eigen::VectorXd shifts, l;
    InputGenerator keep;
  };
  const std::vector<Filter> filters = {{Eigen::Vector2d(105, 210) * kTs420, Eigen::Vector2d(0, 1), g4},
                                       {s2, annihilator(g6 + g4, s2), g2},
                                       {s3, annihilator(g4 + g2, s3), g6}};
  std::vector<double> a[2][3];  // [LS, IV][a_0, a_1, a_2]
  for (int run = 0; run < 400; ++run) {
    const IdData d(u(t), y0 + white_noise(600, 0.01, 500 + run), kTs420);
    for (int iv = 0; iv < 2; ++iv) {
      std::vector<ModalExperiment> ex;
      for (const auto& f : filters) {
        ModalOptions o{.shifts = kShifts3, .basis = ModalBasis::Discrete, .stride = 10, .iv_shift = iv ? 25 * kTs420 : 0.0};
        o.windows = {{f.shifts.maxCoeff() + kShifts3(2), 140 * kTs420}};
        const InputGenerator left = modal_filter(f.keep, f.shifts, f.l);
        ex.push_back({modal_estimate(modal_filter(d, f.shifts, f.l), left, o).model, left});
      }
      const Polynomial den = modal_output_function_tf(ex).den();
      for (int j = 0; j < 3; ++j) a[iv][j].push_back(den.coefficient_of_power(j));
    }
  }
  auto quantile = [](std::vector<double> v, double q) {
    const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size()));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return v[static_cast<std::size_t>(k)];
  };
  auto iqr = [&](const std::vector<double>& v) { return quantile(v, 0.75) - quantile(v, 0.25); };
  // Reference medians from 2 000 runs of the same set-up (seeds 500..2499): LS a = (48.71, 29.90, 3.81), IV
  // (49.24, 30.01, 3.85); IQR of a_0 4.48 (LS) and 8.93 (IV). Tolerances: 4 standard errors of a median of 400
  // runs (1.25 sigma / 20 with sigma = IQR / 1.35): 0.85 (LS a_0), 1.65 (IV a_0), 0.06 / 0.13 (a_1), 0.02 / 0.04 (a_2).
  EXPECT_NEAR(quantile(a[0][0], 0.5), 48.71, 0.85);
  EXPECT_NEAR(quantile(a[0][1], 0.5), 29.90, 0.06);
  EXPECT_NEAR(quantile(a[0][2], 0.5), 3.81, 0.02);
  EXPECT_NEAR(quantile(a[1][0], 0.5), 49.24, 1.65);
  EXPECT_NEAR(quantile(a[1][1], 0.5), 30.01, 0.13);
  EXPECT_NEAR(quantile(a[1][2], 0.5), 3.85, 0.04);
  EXPECT_NEAR(iqr(a[0][0]), 4.48, 1.0);
  EXPECT_NEAR(iqr(a[1][0]), 8.93, 2.0);
  // The thesis' claim, in distribution: the IV estimates lie closer to the truth (52, 30, 4) than LS in each
  // coefficient, at twice the spread. The published LS a_1 = 39.45 lies about 18 LS-IQRs (0.54) above our LS median.
  for (int j = 0; j < 3; ++j) {
    const double truth = kS3.den().coefficient_of_power(j);
    EXPECT_LT(std::abs(quantile(a[1][j], 0.5) - truth), std::abs(quantile(a[0][j], 0.5) - truth)) << "a_" << j;
  }
  EXPECT_GT(iqr(a[1][0]), 1.5 * iqr(a[0][0]));
  // The printed single runs against our 400. Table 4.4 (IV, 52.53, 30.05, 4.015) falls inside: at the fractions
  // 0.71, 0.51 and 0.77 of our runs (bounds about 4 binomial standard errors). Table 4.3 (LS, 56.71, 39.45, 4.170)
  // does not: it lies above the truth in all three coefficients, above 99 % of our runs in each, while our LS
  // estimates lie below the truth in all three (el-shafey.md).
  const double printed_ls[3] = {56.71, 39.45, 4.170}, printed_iv[3] = {52.53, 30.05, 4.015};
  const double iv_fraction[3] = {0.705, 0.5125, 0.7675};
  for (int j = 0; j < 3; ++j) {
    const double truth = kS3.den().coefficient_of_power(j);
    EXPECT_LT(quantile(a[0][j], 0.5), truth) << "a_" << j;  // LS biased downward
    EXPECT_GT(percentile_of(a[0][j], printed_ls[j]), 0.97) << "a_" << j;
    EXPECT_NEAR(percentile_of(a[1][j], printed_iv[j]), iv_fraction[j], 0.1) << "a_" << j;
  }
}

namespace {
// A piecewise-constant record of S3 from rest (Ts = pi/320): `cycles` cycles of the given levels, each held for
// `hold` samples; white noise of standard deviation `noise` on the output.
IdData level_record(const std::vector<double>& levels, int hold, int cycles, double noise = 0.0, unsigned seed = 1) {
  const double Ts = kPi / 320;
  const int N = hold * static_cast<int>(levels.size()) * cycles;
  Eigen::VectorXd u(N);
  for (int i = 0; i < N; ++i) u(i) = levels[(i / hold) % levels.size()];
  Eigen::VectorXd y = lsim(kS3, u, time_grid(Ts, N));
  if (noise > 0) y += white_noise(N, noise, seed);
  return IdData(u, y, Ts);
}
}  // namespace

TEST(ModalFit, SeveralRecordsArePooledIntoOneEstimateMoreAccurateThanEither) {
  // Several experiments: two records of S3 with different level sequences and hold times, each from
  // rest. Noise-free, the joint Walsh and Discrete fits give S3 to 1e-6 (as one record does, ModalFit above) and
  // count the windows of both records.
  const double Ts = kPi / 320;
  const Eigen::Vector3d shifts(16 * Ts, 32 * Ts, 48 * Ts);
  const std::vector<double> levels_a = {1, 2, -1, -2}, levels_b = {-1.5, 0.5, 2.5, -0.5};
  const IdData a = level_record(levels_a, 80, 2), b = level_record(levels_b, 96, 1);
  for (auto basis : {ModalBasis::Walsh, ModalBasis::Discrete}) {
    const auto r = modal_fit(std::vector<IdData>{a, b}, 2, {.shifts = shifts, .basis = basis, .functions = 8});
    ASSERT_TRUE(r.usable()) << r.why_not_usable();
    EXPECT_LT(max_rel(r.model.den().coefficients(), kS3.den().coefficients()), 1e-6) << static_cast<int>(basis);
    EXPECT_NEAR(r.model.num().coefficient_of_power(0), 52.0, 1e-4);
    EXPECT_GT(r.fit.fit_percent, 99.999);
    EXPECT_EQ(r.fit.n_samples, a.size() + b.size());
    EXPECT_EQ(r.diagnostics.get(diagnostic::experiments), 2);
    EXPECT_EQ(r.diagnostics.get(diagnostic::windows), 8 + 4);  // one window per level: 8 in a, 4 in b
  }
  // Refusals: explicit windows are times of one record; a generated input belongs to one record.
  EXPECT_THROW(modal_fit(std::vector<IdData>{a, b}, 2, {.shifts = shifts, .windows = {{0.5, 0.2}}}), InvalidArgument);
  const InputGenerator g = InputGenerator::constant(1.0);
  EXPECT_THROW(modal_fit(std::vector<IdData>{a, b}, 3, {.shifts = shifts}, &g), InvalidArgument);

  // Monte Carlo (200 seeded runs, output noise of standard deviation 0.002, about 0.15 % of the output's RMS): the
  // relative RMS error of the denominator coefficients of the joint Walsh fit is below that of either record alone
  // (measured: a 0.141, b 0.159, joint 0.058; the error scales linearly with the noise, 0.035/0.040/0.014 at 0.0005).
  const int runs = 200;
  double se_a = 0, se_b = 0, se_joint = 0;
  const Eigen::VectorXd den = kS3.den().coefficients();
  auto err2 = [&](const Result<TransferFunction>& r) {
    return (r.model.den().coefficients() - den).cwiseQuotient(den).squaredNorm();
  };
  const ModalOptions o{.shifts = shifts, .basis = ModalBasis::Walsh, .functions = 8};
  for (int k = 0; k < runs; ++k) {
    const IdData na = level_record(levels_a, 80, 2, 0.002, 1000 + k), nb = level_record(levels_b, 96, 1, 0.002, 5000 + k);
    se_a += err2(modal_fit(na, 2, o));
    se_b += err2(modal_fit(nb, 2, o));
    se_joint += err2(modal_fit(std::vector<IdData>{na, nb}, 2, o));
  }
  const double rms_a = std::sqrt(se_a / runs), rms_b = std::sqrt(se_b / runs), rms_joint = std::sqrt(se_joint / runs);
  RecordProperty("rms_a", std::to_string(rms_a));
  RecordProperty("rms_b", std::to_string(rms_b));
  RecordProperty("rms_joint", std::to_string(rms_joint));
  std::printf("modal several records: relative RMS error a %.4g, b %.4g, joint %.4g\n", rms_a, rms_b, rms_joint);
  EXPECT_LT(rms_joint, 0.8 * std::min(rms_a, rms_b));
}

TEST(ComparePoles, ShiftsLeftEmptyAreChosenOnPronysPreEstimate) {
  // No hand-picked settings: shifts T_i = i d with d of least cond(psi) for Prony's pre-estimate.
  // Noise-free, the data-matrix method is exact whatever well-conditioned shifts it gets (an independent computation:
  // ~1e-6 with Simpson); measured 2.5e-7 on the Ex. 4.6 record (the hand-picked shifts of Table 4.8: 2.6e-7).
  const Eigen::VectorXd t = time_grid(kTs420, 600);
  const Eigen::VectorXd y =
      lsim(phase_variable_form(kS4), InputGenerator::constant(0.0), t, Eigen::Vector4d(0.2, 10.0, 0.0, 0.0));
  const PolesComparison c = compare_poles(y, kTs420, 4, PolesOptions{});
  EXPECT_LT(max_rel(c.data_matrix.characteristic.coefficients(), kS4.den().coefficients()), 1e-6);
  ASSERT_EQ(c.choices.size(), 1u);
  EXPECT_NE(c.choices[0].find("Prony's pre-estimate"), std::string::npos) << c.choices[0];
  ASSERT_EQ(c.free_response.shifts.size(), 4);
  for (int i = 1; i < 4; ++i) EXPECT_NEAR(c.free_response.shifts(i), (i + 1) * c.free_response.shifts(0), 1e-12);
  // Ex. 4.8: the best-conditioned Prony spacing aliases cos 100t, yet the shifts it suggests keep the data-matrix
  // method alias-free: 100 rad/s within 0.1, -1 +- 3j within 1e-2 (measured 2.5e-4 relative on the coefficients;
  // hand-picked shifts of Table 4.11: 1e-3 on each exponent).
  const double Ts = 2 * kPi / 3 / 666;
  const Eigen::VectorXd t8 = time_grid(Ts, 2000);
  const Eigen::VectorXd y8 = (-t8).array().exp() * (3 * t8).array().sin() + (100 * t8).array().cos();
  const PolesComparison c8 = compare_poles(y8, Ts, 4, PolesOptions{});
  int fast = 0;
  for (auto z : c8.data_matrix.poles) {
    if (std::abs(z.imag()) > 10) {
      EXPECT_NEAR(std::abs(z.imag()), 100.0, 0.1);
      ++fast;
    } else {
      EXPECT_NEAR(z.real(), -1.0, 1e-2);
      EXPECT_NEAR(std::abs(z.imag()), 3.0, 1e-2);
    }
  }
  EXPECT_EQ(fast, 2);
  // A response forced by sin 4t (Ex. 4.7): 3 + 2 shifts chosen on the augmented pre-estimate, then deflated.
  const IdData d = sine_record(800);
  PolesOptions forced;
  forced.generator = Eigen::VectorXd{{4.0}};
  const PolesComparison cf = compare_poles(d.y().col(0), kTs420, 3, forced);
  EXPECT_EQ(cf.free_response.shifts.size(), 5);
  EXPECT_LT(max_rel(cf.data_matrix.characteristic.coefficients(), kS3.den().coefficients()), 1e-5);
  // A zero response is named, not estimated.
  EXPECT_THROW(compare_poles(Eigen::VectorXd::Zero(400), kTs420, 2, PolesOptions{}), InvalidArgument);
}
