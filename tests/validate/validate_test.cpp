#include <cmath>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/validate/metrics.hpp"
#include "ctid/validate/residuals.hpp"

using namespace ctid;

TEST(Metrics, DefinitionsByHand) {
  const Eigen::VectorXd y{{1.0, 2.0, 3.0, 4.0}}, yh{{1.0, 2.0, 3.0, 3.0}};
  // ||e|| = 1, ||y - mean|| = sqrt(5): fit = 100 (1 - 1/sqrt 5).
  EXPECT_NEAR(fit_percent(y, yh), 100 * (1 - 1 / std::sqrt(5.0)), 1e-12);
  EXPECT_NEAR(mse(y, yh), 0.25, 1e-15);
  const FitReport r = fit_report(y, yh, 1);
  EXPECT_NEAR(r.fpe, 0.25 * (1 + 0.25) / (1 - 0.25), 1e-15);
  EXPECT_NEAR(r.aic, 4 * std::log(0.25) + 2, 1e-12);
  EXPECT_NEAR(r.aicc, r.aic + 2.0 * 1 * 2 / (4 - 1 - 1), 1e-12);
  EXPECT_NEAR(r.bic, 4 * std::log(0.25) + std::log(4.0), 1e-12);
  EXPECT_TRUE(std::isinf(fpe(1.0, 3, 3)));
  EXPECT_THROW(fit_percent(Eigen::VectorXd::Ones(3), Eigen::VectorXd::Ones(3)), InvalidArgument);
  EXPECT_THROW(mse(y, Eigen::VectorXd::Ones(3)), InvalidArgument);
}

TEST(Metrics, FitPercentTextStaysShortForADivergingModel) {
  // Two decimals as before; a diverging simulation's fit (about -1e138 %) was printed with 140 digits.
  EXPECT_EQ(fit_percent_text(87.254), "87.25");
  EXPECT_EQ(fit_percent_text(-9999.994), "-9999.99");
  EXPECT_EQ(fit_percent_text(-1.2345e138), "-1.23e+138");
  EXPECT_EQ(fit_percent_text(12345.0), "1.23e+04");
  EXPECT_EQ(fit_percent_text(-INFINITY), "-inf");
  EXPECT_EQ(fit_percent_text(NAN), "nan");
  EXPECT_EQ(fit_percent_text(-NAN), "nan");
}

TEST(Residuals, WhiteNoisePassesColouredFails) {
  const int N = 5000;
  const Eigen::VectorXd e = white_noise(N, 1.0, 5);
  const CorrelationTest a = residual_autocorrelation(e, 20);
  EXPECT_NEAR(a.values(0), 1.0, 1e-15);
  EXPECT_NEAR(a.bound, 2.5758 / std::sqrt(5000.0), 1e-4);
  EXPECT_LE(a.n_outside, 2);  // 20 lags at 1 % each: P(> 2 outside) ~ 0.1 %
  Eigen::VectorXd c = e;
  for (int k = 1; k < N; ++k) c(k) = 0.8 * c(k - 1) + e(k);  // AR(1): r(1) ~ 0.8
  const CorrelationTest b = residual_autocorrelation(c, 20);
  EXPECT_NEAR(b.values(1), 0.8, 0.03);
  EXPECT_FALSE(b.passed());
  // Residuals that contain the input at lag 3 fail the cross-correlation test at k = 3.
  const Eigen::VectorXd u = white_noise(N, 1.0, 6);
  Eigen::VectorXd r = e;
  for (int k = 3; k < N; ++k) r(k) += 0.5 * u(k - 3);
  const CorrelationTest x = input_residual_crosscorrelation(u, r, 10);
  EXPECT_EQ(x.lags(13), 3);
  EXPECT_NEAR(x.values(13), 0.5 / std::sqrt(1.25), 0.03);
  EXPECT_FALSE(x.passed());
  EXPECT_THROW(residual_autocorrelation(e, 0), InvalidArgument);
  // Residuals of a diverging simulation (squares overflow): an error, not correlations of 0/Inf that "pass".
  Eigen::VectorXd big = e;
  big.tail(10).setConstant(1e300);
  EXPECT_THROW(residual_autocorrelation(big, 10), InvalidArgument);
  EXPECT_THROW(input_residual_crosscorrelation(u, big, 10), InvalidArgument);
}
