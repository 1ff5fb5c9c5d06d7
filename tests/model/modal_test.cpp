// Modal parameters from known models (El-Shafey 1987; ES 2.13-2.30; the
// exact, model-based oracles of docs/methods/el-shafey.md: Tables 2.1, 3.10, 3.15; "algebraic consistency": Tables 4.5, 4.6).
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>
#include <numbers>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/model/modal.hpp"

using namespace ctid;

namespace {
constexpr double kPi = std::numbers::pi;
// S3 (ES Ex. 3.1 ff.): (13 s + 52)/(s^3 + 4 s^2 + 30 s + 52); S4 (Ex. 3.10 ff.).
const TransferFunction kS3(Eigen::VectorXd{{13.0, 52.0}}, Eigen::VectorXd{{1.0, 4.0, 30.0, 52.0}});
const TransferFunction kS4(Eigen::VectorXd{{400.0, 400.0}}, Eigen::VectorXd{{1.0, 6.0, 115.25, 221.0, 338.0}});

// Every entry within rel * |published| (the tables print 4 significant digits: rel = 5e-4).
void expect_table(const Eigen::MatrixXd& got, const Eigen::MatrixXd& pub, double rel) {
  ASSERT_EQ(got.rows(), pub.rows());
  ASSERT_EQ(got.cols(), pub.cols());
  for (Eigen::Index i = 0; i < pub.rows(); ++i)
    for (Eigen::Index j = 0; j < pub.cols(); ++j)
      EXPECT_NEAR(got(i, j), pub(i, j), rel * std::abs(pub(i, j))) << "row " << i << " column " << j;
}
}  // namespace

TEST(ModalParameters, Table21) {
  // ES Table 2.1: A* = diag(-1+5j, -1-5j, -2), c* = 1 (= S3's poles), T_i = 40, 80, 120 Ts, Ts = pi/420.
  const double Ts = kPi / 420;
  const auto m = modal_parameters(kS3, Eigen::Vector3d(40 * Ts, 80 * Ts, 120 * Ts), 3);
  Eigen::MatrixXd pub(4, 3);  // rows p_0 .. p_3
  pub << -0.6605, 0.6106, -0.3022,  //
      2.999, -0.2564, -0.4330,      //
      5.715, -14.76, 5.721,         //
      -78.48, 34.97, 5.819;
  expect_table(m.P, pub, 5e-4);
  EXPECT_GT(m.condition, 1.0);
}

TEST(ModalParameters, Table310) {
  // ES Table 3.10: S3, T_i = 40, 80, 120 Ts with Ts = pi/576 (Ex. 3.9).
  const double Ts = kPi / 576;
  const auto m = modal_parameters(kS3, Eigen::Vector3d(40 * Ts, 80 * Ts, 120 * Ts), 3);
  Eigen::MatrixXd pub(4, 3);
  pub << -1.389, 1.126, -0.4178,  //
      0.7304, 2.975, -1.688,      //
      22.63, -26.31, 6.471,       //
      -40.22, -42.58, 46.49;
  expect_table(m.P, pub, 5e-4);
}

TEST(ModalParameters, Table315WithTheTypoCorrected) {
  // ES Table 3.15: S4, T_i = 20, 40, 110, 160 Ts, Ts = pi/420; the printed -1.048 is a typo for -1.042
  // (both estimates in Tables 3.13/3.14 say -1.042), 5.326 a rounding slip for 5.3235 (docs/methods/el-shafey.md).
  const double Ts = kPi / 420;
  const auto m = modal_parameters(kS4, Eigen::Vector4d(20 * Ts, 40 * Ts, 110 * Ts, 160 * Ts), 4);
  Eigen::MatrixXd pub(5, 4);
  pub << -1.042, -0.02200, 0.2179, -0.05768,  //
      2.988, -2.806, 1.262, -0.1059,          //
      27.59, -16.35, -8.255, 5.3235,          //
      -411.8, 434.3, -81.05, 8.543,           //
      -1017, -94.38, 1085, -621.9;
  expect_table(m.P, pub, 5e-4);
}

TEST(ModalParameters, ScalarFormAnnihilatesEveryMode) {
  // ES-C1: for distinct poles s_k, 1 + sum_i p_0i e^{-s_k T_i} = 0; and s_k^j + sum_i p_ji e^{-s_k T_i} = 0.
  // Non-uniform and negative shifts are allowed.
  const Eigen::Vector3d T(-0.3, 0.17, 0.5);
  const auto m = modal_parameters(kS3, T, 4);
  const Eigen::VectorXcd s = kS3.poles();
  for (int j = 0; j <= 4; ++j)
    for (Eigen::Index k = 0; k < s.size(); ++k) {
      std::complex<double> v = std::pow(s(k), j);
      for (int i = 0; i < 3; ++i) v += m.P(j, i) * std::exp(-s(k) * T(i));
      EXPECT_LT(std::abs(v), 1e-10 * (1 + std::pow(std::abs(s(k)), j))) << "j " << j << " pole " << k;
    }
}

TEST(ModalParameters, InvariantUnderCoordinateChanges) {
  const Eigen::Vector3d T(0.1, 0.2, 0.35);
  const auto a = modal_parameters(kS3, T, 3);
  const auto b = modal_parameters(StateSpace::controllable_canonical(kS3), T, 3);
  EXPECT_LT((a.P - b.P).cwiseAbs().maxCoeff(), 1e-9 * a.P.cwiseAbs().maxCoeff());
}

TEST(PhaseVariableForm, MarkovParametersOfS6) {
  // El-Shafey 1987, ch. 2: (6.5 s + 52)/(s^3 + 4 s^2 + 30 s + 52) has b~ = (0, 6.5, 26).
  const TransferFunction s6(Eigen::VectorXd{{6.5, 52.0}}, Eigen::VectorXd{{1.0, 4.0, 30.0, 52.0}});
  const StateSpace pv = phase_variable_form(s6);
  EXPECT_NEAR(pv.B()(0, 0), 0.0, 1e-14);
  EXPECT_NEAR(pv.B()(1, 0), 6.5, 1e-13);
  EXPECT_NEAR(pv.B()(2, 0), 26.0, 1e-13);
  const TransferFunction back = pv.to_transfer_function();
  EXPECT_LT((back.num().coefficients() - s6.num().coefficients()).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_THROW(phase_variable_form(TransferFunction(Eigen::VectorXd{{1.0, 0.0}}, Eigen::VectorXd{{1.0, 2.0}})),
               InvalidArgument);
}

TEST(ModalModel, TheoremsFourOneAndFourTwoRecoverTheModelFromExactModalQuantities) {
  // With the exact p_0..p_n and the exact q_j of a sinusoid-sum input, Theorem 4.1 gives a and
  // Theorem 4.2 gives b (ES-C8). q_j from K_j(w) = H(jw)((jw)^j + sum_i p_ji e^{-jw T_i}) in the
  // basis [sin wt, cos wt]: y_j = Im(K e^{jwt}) for u = sin wt.
  const Eigen::Vector3d T(0.3, 0.6, 0.9);
  const auto m = modal_parameters(kS3, T, 3);
  const InputGenerator g = InputGenerator::sinusoid(4.0, 1.0) + InputGenerator::sinusoid(2.0, 0.0, 1.0);
  Eigen::MatrixXd Q(4, 4);
  for (int j = 0; j <= 3; ++j) {
    for (int f = 0; f < 2; ++f) {
      const double w = f == 0 ? 4.0 : 2.0;
      const std::complex<double> jw(0, w);
      std::complex<double> K = std::pow(jw, j);
      for (int i = 0; i < 3; ++i) K += m.P(j, i) * std::exp(-jw * T(i));
      K *= kS3(jw);
      // y_j for u = sin wt: Im(K e^{jwt}) = Re K sin + Im K cos;  for u = cos wt: Re(K e^{jwt}) = -Im K sin + Re K cos.
      if (f == 0) Q.block(j, 0, 1, 2) << K.real(), K.imag();
      else Q.block(j, 2, 1, 2) << -K.imag(), K.real();
    }
  }
  const ModalModel model(T, m.P, Q);
  const TransferFunction tf = model.transfer_function(g);
  EXPECT_LT((tf.den().coefficients() - kS3.den().coefficients()).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_NEAR(tf.num().coefficient_of_power(1), 13.0, 1e-8);
  EXPECT_NEAR(tf.num().coefficient_of_power(0), 52.0, 1e-8);
  EXPECT_NEAR(tf.num().coefficient_of_power(2), 0.0, 1e-8);
  EXPECT_THROW(model.transfer_function(InputGenerator::sinusoid(4.0, 1.0)), InvalidArgument);  // order 2 < n
}

TEST(ModalModel, Tables45And46FollowFromThePublishedEstimates) {
  // Algebraic consistency (~1 %): Theorem 4.1 applied to the published 4-digit p^ of
  // Tables 3.6 (Fourier) / 3.7 (Walsh) gives Table 4.5's a^; Tables 3.13 / 3.14 give Table 4.6's.
  const double Ts = kPi / 420;
  auto a_of = [](const Eigen::VectorXd& T, const Eigen::MatrixXd& P) {
    const Polynomial d = ModalModel(T, P, Eigen::MatrixXd()).characteristic_polynomial();
    Eigen::VectorXd a(T.size());
    for (int j = 0; j < T.size(); ++j) a(j) = d.coefficient_of_power(j);
    return a;
  };
  const Eigen::Vector3d T3(40 * Ts, 80 * Ts, 120 * Ts);
  Eigen::MatrixXd fourier(4, 3), walsh(4, 3);
  fourier << -0.6617, 0.6111, -0.3029, 2.974, -0.2529, -0.4526, 5.757, -14.81, 5.737, -78.15, 34.91, 6.237;
  walsh << -0.6605, 0.6113, -0.3022, 3.002, -0.2543, -0.4325, 5.715, -14.77, 5.718, -78.50, 34.90, 5.870;
  expect_table(a_of(T3, fourier).transpose(), Eigen::RowVector3d(50.27, 29.86, 3.923), 0.01);
  expect_table(a_of(T3, walsh).transpose(), Eigen::RowVector3d(52.29, 30.03, 4.010), 0.01);

  const Eigen::Vector4d T4(20 * Ts, 40 * Ts, 110 * Ts, 160 * Ts);
  Eigen::MatrixXd f4(5, 4), w4(5, 4);
  f4 << -1.042, -0.02220, 0.2179, -0.05770, 2.992, -2.784, 1.236, -0.09301, 26.58, -15.45, -8.259, 5.245, -406.3, 426.8,
      -78.17, 7.556, -938.4, -153.7, 1074, -610.0;
  w4 << -1.042, -0.02200, 0.2179, -0.05769, 2.990, -2.808, 1.262, -0.1059, 27.60, -16.35, -8.266, 5.330, -412.6, 435.0,
      -81.11, 8.519, -1016, -98.21, 1088, -623.1;
  expect_table(a_of(T4, f4).transpose(), Eigen::RowVector4d(337.9, 221.1, 115.3, 5.995), 0.01);
  expect_table(a_of(T4, w4).transpose(), Eigen::RowVector4d(338.3, 221.2, 115.4, 6.006), 0.01);
}

TEST(ModalModel, Tables45To49PolesAreTheRootsOfTheirCoefficients) {
  // The poles printed beside a^ in Tables 4.5, 4.6, 4.8 and 4.9 are the roots of the printed a^ (to the printed digits, 1e-3
  // relative + 2e-3 absolute for the last digit of a 4-digit root); Table 4.6's Walsh row prints "-1.000 + 1.500j"
  // twice (docs/methods/el-shafey.md: a misprint of the conjugate pair, compared here as the pair).
  auto expect_roots = [](const Polynomial& d, const std::vector<std::complex<double>>& pub) {
    Eigen::VectorXcd r = d.roots();
    ASSERT_EQ(r.size(), static_cast<Eigen::Index>(pub.size()));
    for (const auto& p : pub) {
      double best = 1e300;
      for (Eigen::Index i = 0; i < r.size(); ++i) best = std::min(best, std::abs(r(i) - p));
      EXPECT_LT(best, 1e-3 * std::abs(p) + 2e-3) << p;
    }
  };
  using C = std::complex<double>;
  expect_roots(Polynomial{1.0, 3.923, 29.86, 50.27}, {C(-1.932, 0), C(-0.9953, 5.003), C(-0.9953, -5.003)});
  expect_roots(Polynomial{1.0, 4.010, 30.03, 52.29}, {C(-2.011, 0), C(-0.9995, 5.001), C(-0.9995, -5.001)});
  expect_roots(Polynomial{1.0, 5.995, 115.3, 221.1, 337.9},
               {C(-1.000, 1.499), C(-1.000, -1.499), C(-1.997, 10.00), C(-1.997, -10.00)});
  expect_roots(Polynomial{1.0, 6.006, 115.4, 221.2, 338.3},
               {C(-1.000, 1.500), C(-1.000, -1.500), C(-2.003, 10.00), C(-2.003, -10.00)});
  // Table 4.8 (Theorem 4.3 on the S4 free response): a^ = (338.8, 221.6, 115.6, 6.014), poles -2.007 +- 10.01j,
  // -1.000 +- 1.500j.
  expect_roots(Polynomial{1.0, 6.014, 115.6, 221.6, 338.8},
               {C(-2.007, 10.01), C(-2.007, -10.01), C(-1.000, 1.500), C(-1.000, -1.500)});
  // Table 4.9 (augmented by sin 4t): the printed eigenvalues 0.003146 +- 3.995j, -1.003 +- 5.000j, -1.993 are those
  // of the printed P_a = s^5 + 3.992 s^4 + 45.93 s^3 + 115.5 s^2 + 478.4 s + 827.1 (roots of the 4-digit
  // coefficients: 0.0014 +- 3.9954j, -1.0005 +- 4.9987j, -1.9937). The deflation's printed 16 a_1 = 474.4 (so
  // a_1 = 29.65) is the misprint, not 478.4: with 474.4 the pair near -1 +- 5j moves to -0.986 +- 5.026j.
  const std::vector<C> table49 = {C(0.003146, 3.995), C(0.003146, -3.995), C(-1.003, 5.000), C(-1.003, -5.000),
                                  C(-1.993, 0)};
  expect_roots(Polynomial{1.0, 3.992, 45.93, 115.5, 478.4, 827.1}, table49);
  const Eigen::VectorXcd misprint = Polynomial{1.0, 3.992, 45.93, 115.5, 474.4, 827.1}.roots();
  double nearest = 1e300;
  for (Eigen::Index i = 0; i < misprint.size(); ++i) nearest = std::min(nearest, std::abs(misprint(i) - C(-1.003, 5.0)));
  EXPECT_GT(nearest, 0.02);  // (the printed P_a gives a_1 = 478.4 / 16 = 29.90; the printed a^ has 29.65 = 474.4 / 16)
}

TEST(ModalModel, Table47WalshRowFollowsFromTables311And312) {
  // ES Table 4.7 (Ex. 4.5): b^ by Theorem 4.2 from the prefiltered pairs of Ex. 3.9 (S3, Ts = pi/576, T_i = 40, 80,
  // 120 Ts; L_1 leaves u_1 = -sin 3t + cos 3t, L_2 leaves u_2 = 2 cos 6t), published q^ (4 digits) in, b^ out.
  // The thesis does not say the basis of its q^. It is found here from the model, not from b^: the published q^
  // equal M q_true with x' = M x = -[cos w(t - t0), sin w(t - t0)] and t0 = 24 Ts for both frequencies (the model's
  // q_true mapped this way match the published Fourier q^ to 0.10 and 0.19 % and the Walsh q^ to 1.05 and 0.71 % of
  // each table's largest entry, the estimates' own error; a phase t0 one sample off moves b1 by 0.3). With that
  // basis and a^ by Theorem 4.1 from the same tables' p^ (stacked over the two pairs, as modal_theorems_tf does),
  // the Walsh row (51.81, 12.66, -0.06689) is reproduced within the
  // spread that the printed inputs' rounding allows (half a unit in the 4th digit of every p^ and q^, 20 000 draws:
  // b0 51.68..51.89, b1 12.656..12.672, b2 -0.0685..-0.0647; ours 51.783, 12.663, -0.06661).
  // The Fourier row (51.91, 12.91, -0.03879) does not follow from Tables 3.8/3.9 in any basis we found: the same
  // route gives (52.78, 13.16, -0.0211) (rounding spread 52.67..52.87 in b0), with Table 4.5's Fourier a^
  // (50.81, 13.04, 0.0012), and no basis phase t0 gives both printed b1 and b2; b0 does not depend on t0 at all.
  // An earlier reading took the a^ of Table 4.7 as Table 4.5's; with that a^ the Walsh row is off by 0.3 % in b0
  // (51.98), outside the rounding spread, so the thesis evidently used the pairs' own p^.
  const double Ts = kPi / 576, t0 = 24 * Ts;
  const Eigen::Vector3d T(40 * Ts, 80 * Ts, 120 * Ts);
  const Eigen::MatrixXd P_true = modal_parameters(kS3, T, 3).P;
  struct Pair {
    double w;
    Eigen::Vector2d c;  // u = c^T [sin wt, cos wt]
  };
  const Pair pairs[2] = {{3.0, Eigen::Vector2d(-1.0, 1.0)}, {6.0, Eigen::Vector2d(0.0, 2.0)}};
  // The published basis x' = M x: rows -cos w(t - t0) and -sin w(t - t0) of x = [sin wt, cos wt].
  auto M_of = [&](double w) {
    Eigen::Matrix2d M;
    M << -std::sin(w * t0), -std::cos(w * t0), -std::cos(w * t0), std::sin(w * t0);
    return M;
  };
  // The published q^ as rows q_0..q_3 per pair; p^ rows p_0..p_3 (Tables 3.8, 3.9 Fourier; 3.11, 3.12 Walsh, the
  // latter's printed "+4.179" read as -0.4179, docs/methods/el-shafey.md).
  Eigen::MatrixXd qF[2] = {Eigen::MatrixXd(4, 2), Eigen::MatrixXd(4, 2)}, qW[2] = {qF[0], qF[1]};
  Eigen::MatrixXd pF[2] = {Eigen::MatrixXd(4, 3), Eigen::MatrixXd(4, 3)}, pW[2] = {pF[0], pF[1]};
  qF[0] << -0.3362, 0.4154, -1.629, 2.898, 4.215, 6.785, 72.36, -46.58;
  qF[1] << -0.9154, -0.08869, -5.276, 1.354, 3.682, 23.80, 227.9, 53.18;
  qW[0] << -0.3434, 0.4151, -1.683, 2.893, 4.137, 6.802, 73.20, -46.54;
  qW[1] << -0.9128, -0.0873, -5.325, 1.364, 2.981, 23.71, 226.1, 52.83;
  pF[0] << -1.390, 1.188, -0.4190, 0.7137, 2.994, -1.701, 22.71, -26.40, 6.527, -39.97, -42.91, 46.71;
  pF[1] << -1.387, 1.124, -0.4168, 0.7382, 2.968, -1.684, 22.52, -26.22, 6.424, -40.38, -42.24, 46.34;
  pW[0] << -1.388, 1.126, -0.4179, 0.7306, 2.975, -1.688, 22.63, -26.32, 6.474, -40.24, -42.56, 46.49;
  pW[1] << -1.388, 1.126, -0.4179, 0.7314, 2.973, -1.687, 22.62, -26.30, 6.467, -40.23, -42.54, 46.47;

  std::vector<ModalExperiment> fourier, walsh;
  for (int k = 0; k < 2; ++k) {
    const double w = pairs[k].w;
    const Eigen::Matrix2d M = M_of(w);
    Eigen::Matrix2d A;
    A << 0.0, w, -w, 0.0;
    const InputGenerator published_basis(M * A * M.transpose(), M * pairs[k].c, M * Eigen::Vector2d(0.0, 1.0));
    // The basis check: q_true (from the model) in the published basis against the published q^.
    Eigen::MatrixXd q_true(4, 2);
    for (int j = 0; j <= 3; ++j) {
      const std::complex<double> jw(0, w);
      std::complex<double> K = std::pow(jw, j);
      for (int i = 0; i < 3; ++i) K += P_true(j, i) * std::exp(-jw * T(i));
      K *= kS3(jw) * std::complex<double>(pairs[k].c(0), pairs[k].c(1));  // y_j = Im(K e^{jwt}) for u = sin wt
      q_true.row(j) = (M * Eigen::Vector2d(K.real(), K.imag())).transpose();
    }
    EXPECT_LT((q_true - qF[k]).cwiseAbs().maxCoeff() / qF[k].cwiseAbs().maxCoeff(), 2.5e-3) << "pair " << k;
    EXPECT_LT((q_true - qW[k]).cwiseAbs().maxCoeff() / qW[k].cwiseAbs().maxCoeff(), 1.5e-2) << "pair " << k;
    fourier.push_back({ModalModel(T, pF[k], qF[k]), published_basis});
    walsh.push_back({ModalModel(T, pW[k], qW[k]), published_basis});
  }
  const TransferFunction tw = modal_theorems_tf(walsh);
  EXPECT_NEAR(tw.num().coefficient_of_power(0), 51.81, 0.08);     // rounding spread 51.68 .. 51.89
  EXPECT_NEAR(tw.num().coefficient_of_power(1), 12.66, 0.008);    // 12.656 .. 12.672
  EXPECT_NEAR(tw.num().coefficient_of_power(2), -0.06689, 0.002);  // -0.0685 .. -0.0647
  // The same route on the Fourier tables does not give the printed Fourier row (51.91, 12.91, -0.03879): asserted
  // against the print, b0 lies 1.5-2.0 % above it and b1 1.5-2.5 % above (the rounding spread of the inputs moves
  // b0 by 0.1 %); b2 is -0.0211 against the printed -0.03879. The values 52.78, 13.16, -0.0211 of the comment above
  // are regression values, not printed.
  const TransferFunction tf = modal_theorems_tf(fourier);
  const double b0 = tf.num().coefficient_of_power(0), b1 = tf.num().coefficient_of_power(1);
  EXPECT_GT(b0 / 51.91 - 1, 0.015);
  EXPECT_LT(b0 / 51.91 - 1, 0.020);
  EXPECT_GT(b1 / 12.91 - 1, 0.015);
  EXPECT_LT(b1 / 12.91 - 1, 0.025);
  EXPECT_NEAR(tf.num().coefficient_of_power(2), -0.0211, 0.002);  // regression value, not printed (-0.03879)
}

TEST(ModalParameters, BadInputs) {
  EXPECT_THROW(modal_parameters(kS3, Eigen::Vector2d(0.1, 0.2), 1), InvalidArgument);          // 2 shifts, order 3
  EXPECT_THROW(modal_parameters(kS3, Eigen::Vector3d(0.1, 0.1, 0.2), 1), InvalidArgument);     // repeated shift
  EXPECT_THROW(modal_parameters(kS3, Eigen::Vector3d(0.0, 0.1, 0.2), 1), InvalidArgument);     // zero shift
  // Shifts 2 pi / 5 apart cannot separate the poles -1 +- 5j: psi singular.
  const double P = 2 * kPi / 5;
  EXPECT_THROW(modal_parameters(TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 2.0, 26.0}}),
                                Eigen::Vector2d(P, 2 * P), 1),
               InvalidArgument);
  EXPECT_THROW(InputGenerator::sinusoid(0.0, 1.0), InvalidArgument);
}

TEST(InputGenerator, BasisOnUniformGridsEqualsTheClosedForm) {
  // Uniform grids step by e^{A h} with exact re-anchoring every 1024 samples; compare with the closed form.
  const InputGenerator g = InputGenerator::sinusoid(3.0, 1.0, 0.5, -0.1) + InputGenerator::constant(2.0);
  const int N = 5000;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(N, 0.0, (N - 1) * 0.01);
  const Eigen::MatrixXd X = g.basis(t);
  for (int i = 0; i < N; i += 7) {
    EXPECT_NEAR(X(i, 0), std::exp(-0.1 * t(i)) * std::sin(3 * t(i)), 1e-12);
    EXPECT_NEAR(X(i, 1), std::exp(-0.1 * t(i)) * std::cos(3 * t(i)), 1e-12);
    EXPECT_NEAR(X(i, 2), 1.0, 1e-12);
  }
  EXPECT_NEAR(g(t)(100), X(100, 0) + 0.5 * X(100, 1) + 2.0, 1e-14);
  EXPECT_EQ(g.characteristic_polynomial().degree(), 3);
}

TEST(ModalParameters, ShiftHelperMinimisesTheConditionOfPsi) {
  // S3 sampled at pi/420 with shifts up to 3 x 120 Ts: the chosen spacing's cond(psi) is the minimum of the
  // scanned curve and no larger than that of the thesis' choice 40 Ts (cond 132.7, printed by the example).
  const double Ts = kPi / 420;
  const ShiftChoice c = choose_modal_shifts(kS3, Ts, 360 * Ts);
  EXPECT_EQ(c.spacings.size(), 120);
  EXPECT_DOUBLE_EQ(c.condition, c.conditions.minCoeff());
  EXPECT_LE(c.condition, modal_parameters(kS3, Eigen::Vector3d(40 * Ts, 80 * Ts, 120 * Ts), 0).condition + 1e-9);
  EXPECT_GT(c.conditions(0), 100 * c.condition);  // one-sample spacing: psi nearly singular
  EXPECT_THROW(choose_modal_shifts(kS3, Ts, 2 * Ts), InvalidArgument);
  EXPECT_THROW(choose_modal_shifts(kS3, Ts, std::numeric_limits<double>::infinity()), InvalidArgument);  // no int overflow
  EXPECT_THROW(choose_modal_shifts(kS3, Ts, 1e9), InvalidArgument);
}
