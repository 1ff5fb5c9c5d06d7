// validate/uncertainty: coefficient maps, plotting ranges and the Monte Carlo band of |G(jw)| (shared by the HTML
// report and ctid.plot). The band is checked against the delta method, which is exact to first order for small
// parameter uncertainty.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/validate/uncertainty.hpp"

using namespace ctid;

namespace {
// G = b0 / (s + a1), a1 = 2, b0 = 4, standard deviations 1 % (0.02, 0.04), uncorrelated.
Result<TransferFunction> first_order() {
  Result<TransferFunction> r;
  r.model = TransferFunction(Eigen::VectorXd{{4.0}}, Eigen::VectorXd{{1.0, 2.0}});
  r.parameters.names = {"a1", "b0"};
  r.parameters.values = Eigen::Vector2d(2.0, 4.0);
  r.parameters.fixed = {false, false};
  r.parameters.covariance = Eigen::Vector2d(0.02 * 0.02, 0.04 * 0.04).asDiagonal();
  r.parameters.std = Eigen::Vector2d(0.02, 0.04);
  return r;
}
}  // namespace

TEST(Uncertainty, MagnitudeBandMatchesTheDeltaMethod) {
  const auto r = first_order();
  const Eigen::Vector3d w(0.5, 2.0, 10.0);
  const MagnitudeBand b = magnitude_band(r, w, 0.95, 4000, 3);
  ASSERT_FALSE(b.empty());
  for (int i = 0; i < 3; ++i) {
    const double q = w(i) * w(i) + 4.0, mag = 4.0 / std::sqrt(q);
    // d|G|/db0 = 1/sqrt(q), d|G|/da1 = -b0 a1 / q^1.5.
    const double sd = std::hypot(0.04 / std::sqrt(q), 4.0 * 2.0 * 0.02 / std::pow(q, 1.5));
    EXPECT_LT(b.lower(i), mag);
    EXPECT_GT(b.upper(i), mag);
    // Half-width 1.96 sd within 6 % (4000 draws: the 2.5 % and 97.5 % quantiles scatter by about 3 %).
    EXPECT_NEAR(0.5 * (b.upper(i) - b.lower(i)), 1.96 * sd, 0.06 * 1.96 * sd) << "w = " << w(i);
  }
  // Reproducible: the same seed gives the same band; the default is the report's (200 draws, seed 1).
  EXPECT_EQ(magnitude_band(r, w).lower, magnitude_band(r, w).lower);
}

TEST(Uncertainty, DrawnModelsSpreadAsTheCovarianceSays) {
  // The pole of each drawn b0 / (s + a1) is -a1 of the draw: over 2000 draws its mean is -2 within 4 standard errors
  // (0.02 / sqrt(2000) each) and its spread is std(a1) = 0.02 within 6 % (the sample std of 2000 normal draws
  // scatters by 1.6 %). The same seed gives the same draws (the report is reproducible).
  const auto r = first_order();
  const std::vector<TransferFunction> g = drawn_models(r, 2000, 5);
  ASSERT_EQ(g.size(), 2000u);
  double s = 0, s2 = 0;
  for (const TransferFunction& m : g) {
    ASSERT_EQ(m.poles().size(), 1);
    const double p = m.poles()(0).real();
    s += p;
    s2 += p * p;
  }
  const double mean = s / 2000, sd = std::sqrt(s2 / 2000 - mean * mean);
  EXPECT_NEAR(mean, -2.0, 4 * 0.02 / std::sqrt(2000.0));
  EXPECT_NEAR(sd, 0.02, 0.06 * 0.02);
  EXPECT_EQ(drawn_models(r, 50, 5)[7].den(), g[7].den());
  auto no_cov = r;
  no_cov.parameters.covariance.resize(0, 0);
  EXPECT_TRUE(drawn_models(no_cov).empty());
  EXPECT_THROW(drawn_models(r, 5), InvalidArgument);
}

TEST(Uncertainty, StepResponseBandMatchesTheDeltaMethod) {
  // response_band of the step response y(t) = (b0/a1)(1 - e^{-a1 t}) of G = 4/(s + 2): dy/db0 = (1 - e^{-a1 t})/a1,
  // dy/da1 = -(b0/a1^2)(1 - e^{-a1 t}) + (b0/a1) t e^{-a1 t}; half-width 1.96 sd within 6 % (4000 draws).
  const auto r = first_order();
  const Eigen::Vector3d t(0.2, 1.0, 5.0);
  const MagnitudeBand b = response_band(
      r, [&](const TransferFunction& g) { return Eigen::VectorXd((g.dc_gain() * (1 - (-g.poles()(0).real() * -t.array()).exp())).matrix()); },
      0.95, 4000, 3);
  ASSERT_FALSE(b.empty());
  for (int i = 0; i < 3; ++i) {
    const double a = 2.0, b0 = 4.0, e = std::exp(-a * t(i));
    const double y = b0 / a * (1 - e);
    const double sd = std::hypot(0.04 * (1 - e) / a, 0.02 * (-b0 / (a * a) * (1 - e) + b0 / a * t(i) * e));
    EXPECT_LT(b.lower(i), y);
    EXPECT_GT(b.upper(i), y);
    EXPECT_NEAR(0.5 * (b.upper(i) - b.lower(i)), 1.96 * sd, 0.06 * 1.96 * sd) << "t = " << t(i);
  }
  EXPECT_THROW(response_band(r, [](const TransferFunction&) { return Eigen::VectorXd(); }, 1.5), InvalidArgument);
}

TEST(Uncertainty, BandIsEmptyWithoutAUsableCovarianceAndBadArgumentsAreNamed) {
  const Eigen::Vector2d w(1.0, 10.0);
  auto r = first_order();
  r.parameters.covariance = Eigen::Matrix3d::Identity();  // wrong size
  EXPECT_TRUE(magnitude_band(r, w).empty());
  r = first_order();
  r.parameters.covariance(0, 0) = NAN;
  EXPECT_TRUE(magnitude_band(r, w).empty());
  r = first_order();
  r.parameters.names = {"k", "tau"};  // physical parameters: no coefficient of the model (before: a zero-width band)
  for (const TfCoefficient& c : tf_coefficients(r.model, r.parameters)) EXPECT_EQ(c.poly, 0);
  EXPECT_TRUE(magnitude_band(r, w).empty());
  r.parameters.names = {"a1", "b0"};
  r.parameters.values(0) = 2.5;  // named a1 but not the model's a1 = 2: another parameterisation
  EXPECT_TRUE(tf_coefficients(r.model, r.parameters).empty());
  r = first_order();
  r.parameters.covariance(0, 0) = 0;  // a1 fixed: the band is that of b0 alone, |G| b0-proportional
  const MagnitudeBand b = magnitude_band(r, w, 0.95, 2000);
  EXPECT_NEAR((b.upper(0) - b.lower(0)) / (b.upper(1) - b.lower(1)), std::sqrt(104.0 / 5.0), 1e-9);
  EXPECT_THROW(magnitude_band(first_order(), w, 1.5), InvalidArgument);
  EXPECT_THROW(magnitude_band(first_order(), w, 0.95, 3), InvalidArgument);
  // with_coefficients puts values where tf_coefficients says.
  const auto map = tf_coefficients(first_order().model, first_order().parameters);
  ASSERT_EQ(map.size(), 2u);
  EXPECT_EQ(with_coefficients(first_order().model, map, Eigen::Vector2d(3.0, 5.0)).to_string(),
            TransferFunction(Eigen::VectorXd{{5.0}}, Eigen::VectorXd{{1.0, 3.0}}).to_string());
}

TEST(Uncertainty, GridAndHorizon) {
  const Eigen::VectorXd w = frequency_grid(Eigen::Vector2cd(-1.0, -100.0));
  ASSERT_EQ(w.size(), 300);
  EXPECT_NEAR(w(0), 1e-2, 1e-14);
  EXPECT_NEAR(w(299), 1e4, 1e-8);
  EXPECT_NEAR(frequency_grid(Eigen::Vector2cd(-1.0, -100.0), 50.0)(299), 50.0, 1e-10);  // capped at Nyquist
  const Eigen::VectorXd none = frequency_grid(Eigen::VectorXcd(), 0.0, 5);
  EXPECT_NEAR(none(0), 1e-2, 1e-15);
  EXPECT_NEAR(none(4), 1e2, 1e-12);
  EXPECT_THROW(frequency_grid(Eigen::VectorXcd(), 0.0, 1), InvalidArgument);
  // The default grid of a model: a linear model's is frequency_grid of its poles; an FSF model's its own band, from
  // half its first filter frequency 2 pi / T to 0.95 of its Nyquist frequency pi / Delta (T = N Delta = 8 s here).
  const TransferFunction g(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 101.0, 100.0}});
  EXPECT_EQ(model_frequency_grid(g, 50.0), frequency_grid(g.poles(), 50.0));
  const FsfModel f(0.01, 800, 21, Eigen::VectorXd::Zero(21));
  const Eigen::VectorXd wf = model_frequency_grid(f);
  ASSERT_EQ(wf.size(), 300);
  EXPECT_NEAR(wf(0), std::numbers::pi / 8.0, 1e-12);
  EXPECT_NEAR(wf(299), 0.95 * std::numbers::pi / 0.01, 1e-9);
  EXPECT_NEAR(wf(1) / wf(0), wf(299) / wf(298), 1e-12);  // log-spaced
  EXPECT_THROW(model_frequency_grid(NarxModel()), InvalidArgument);
  // 8 / 0.5 + 0.3 s; an unstable model alone gives the fallback.
  const TransferFunction slow(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 0.5}}, 0.3);
  const TransferFunction fast(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 10.0}});
  EXPECT_NEAR(response_horizon({slow, fast}, 1.0), 16.3, 1e-12);
  EXPECT_EQ(response_horizon({TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, -1.0}})}, 7.0), 7.0);
}
