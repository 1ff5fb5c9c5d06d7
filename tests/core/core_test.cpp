#include <gtest/gtest.h>

#include "ctid/core/check.hpp"
#include "ctid/core/types.hpp"

using namespace ctid;

TEST(Core, FormatReplacesPlaceholdersInOrder) {
  EXPECT_EQ(detail::format("u has {}, y has {}", 1000, 999), "u has 1000, y has 999");
  EXPECT_EQ(detail::format("no placeholders"), "no placeholders");
  EXPECT_EQ(detail::format("{} extra", 1, 2), "1 extra");
}

TEST(Core, RequireThrowsTheRightTier) {
  EXPECT_THROW(CTID_REQUIRE(false, "x {}", 1), InvalidArgument);
  EXPECT_THROW(CTID_REQUIRE_OPTION(false, "x"), InvalidOptions);
  try {
    CTID_REQUIRE_OPTION(1 > 2, "field tau must be > 0 (got {})", -0.5);
  } catch (const std::invalid_argument& e) {  // catchable as a std exception
    EXPECT_STREQ(e.what(), "field tau must be > 0 (got -0.5)");
  }
}

TEST(Core, TerminationNamesRoundTrip) {
  for (Termination t : {Termination::Completed, Termination::Converged, Termination::MaxIterations,
                        Termination::RankDeficient, Termination::Unstable, Termination::NumericalFailure,
                        Termination::Interrupted})
    EXPECT_EQ(termination_from_string(to_string(t)), t);
  EXPECT_THROW(termination_from_string("bogus"), InvalidArgument);
}

TEST(Core, ResultUsable) {
  Result<int> r;
  r.parameters.values = Eigen::VectorXd::Ones(2);
  EXPECT_TRUE(r.usable()) << r.why_not_usable();
  r.parameters.values(1) = NAN;
  EXPECT_FALSE(r.usable());
  r.parameters.values(1) = 1;
  r.summary.termination = Termination::MaxIterations;
  EXPECT_FALSE(r.usable());
  r.parameters.names = {"a1", "b0"};
  EXPECT_EQ(r.parameters.index("b0"), 1);
  EXPECT_THROW(r.parameters.index("c"), InvalidArgument);
}

// The usability rules of core/types.hpp, one case each; the expected words are those of the reasons.
TEST(Core, UsabilityRulesNameTheCause) {
  auto base = [] {
    Result<int> r;
    r.parameters.names = {"a1", "b0"};
    r.parameters.values = Eigen::Vector2d(2.0, 3.0);
    r.parameters.covariance = Eigen::Matrix2d{{0.01, 0.002}, {0.002, 0.04}};
    r.parameters.fixed = {false, false};
    r.fit.n_samples = 1000;
    r.fit.n_parameters = 2;
    r.fit.nrmse = 0.2;
    r.fit.fit_percent = 80;
    return r;
  };
  EXPECT_TRUE(base().usable()) << base().why_not_usable();
  auto r = base();
  r.summary.termination = Termination::MaxIterations;
  r.summary.message = "no convergence in 50 iterations";
  EXPECT_EQ(r.why_not_usable(), "no convergence in 50 iterations");
  r = base();
  r.fit.fit_percent = -19;
  r.fit.nrmse = 1.19;
  EXPECT_NE(r.why_not_usable().find("worse than the output's mean"), std::string::npos);
  r.fit.fit_percent = -INFINITY;
  EXPECT_NE(r.why_not_usable().find("diverges"), std::string::npos);
  r = base();
  r.parameters.covariance(1, 1) = 0;
  r.parameters.covariance(0, 1) = r.parameters.covariance(1, 0) = 0;
  EXPECT_NE(r.why_not_usable().find("standard deviation of b0 is 0"), std::string::npos) << r.why_not_usable();
  r.parameters.fixed[1] = true;  // a fixed parameter has no variance: fine
  EXPECT_TRUE(r.usable()) << r.why_not_usable();
  r = base();
  r.parameters.covariance(0, 1) = r.parameters.covariance(1, 0) = 0.05;  // correlation 2.5: not PSD
  EXPECT_NE(r.why_not_usable().find("not positive semi-definite"), std::string::npos);
  r = base();
  r.parameters.covariance(0, 0) = NAN;
  EXPECT_NE(r.why_not_usable().find("not finite"), std::string::npos);
  r = base();
  r.parameters.covariance = Eigen::Matrix3d::Identity();
  EXPECT_NE(r.why_not_usable().find("3 x 3 for 2 parameters"), std::string::npos);
  // F test: 4 parameters, N = 1000. R^2 = 0.004 (what 4 parameters fitted to noise explain: d/N) gives
  // F = 1.0 below the 95 % point 2.37 of F(4, inf); R^2 = 0.02 gives F = 5.1 above it.
  r = base();
  r.fit.n_parameters = 4;
  r.fit.nrmse = std::sqrt(1 - 0.004);
  r.fit.fit_percent = 100 * (1 - r.fit.nrmse);
  EXPECT_NE(r.why_not_usable().find("no more of the output than 4 parameters fitted to noise"), std::string::npos);
  r.fit.nrmse = std::sqrt(1 - 0.02);
  r.fit.fit_percent = 100 * (1 - r.fit.nrmse);
  EXPECT_TRUE(r.usable()) << r.why_not_usable();
  // Collinear estimates (correlation 1 - 1e-15: smallest eigenvalue of the correlation matrix below 1e-13 of the
  // largest) name the parameters; a real but high correlation (1 - 1e-9) is fine.
  r = base();
  r.parameters.covariance = Eigen::Matrix2d{{1.0, 1.0 - 1e-15}, {1.0 - 1e-15, 1.0}} * 0.01;
  EXPECT_NE(r.why_not_usable().find("do not determine a1, b0 separately: their estimates are collinear"), std::string::npos)
      << r.why_not_usable();
  r.parameters.covariance = Eigen::Matrix2d{{1.0, 1.0 - 1e-9}, {1.0 - 1e-9, 1.0}} * 0.01;
  EXPECT_TRUE(r.usable()) << r.why_not_usable();
  // Noise-free exact fit: zero covariance is the truth, not a singular information matrix.
  r = base();
  r.fit.nrmse = 1e-9;
  r.fit.fit_percent = 100;
  r.parameters.covariance.setZero();
  EXPECT_TRUE(r.usable()) << r.why_not_usable();
}

// ParameterSet::set_covariance, the one covariance finishing of every estimator: the covariance of the estimated
// parameters is scattered into their slots, fixed parameters get zero rows (std 0), an unknown covariance is NaN
// for the estimated ones only (so usable() names the singular information matrix).
TEST(Core, SetCovarianceScattersTheEstimatedParameters) {
  ParameterSet p;
  p.names = {"a1", "a2", "b0"};
  p.values = Eigen::Vector3d(1.0, 2.0, 3.0);
  p.fixed = {false, true, false};
  Eigen::Matrix2d c;
  c << 4.0, 1.0, 1.0, 9.0;
  p.set_covariance(c, {0, 2});
  EXPECT_EQ(p.covariance(0, 0), 4.0);
  EXPECT_EQ(p.covariance(0, 2), 1.0);
  EXPECT_EQ(p.covariance(2, 2), 9.0);
  EXPECT_EQ(p.covariance(1, 1), 0.0);
  EXPECT_EQ(p.std(0), 2.0);
  EXPECT_EQ(p.std(1), 0.0);
  EXPECT_EQ(p.std(2), 3.0);
  p.set_covariance(Eigen::MatrixXd(), {0, 2});
  EXPECT_TRUE(std::isnan(p.std(0)) && std::isnan(p.std(2)));
  EXPECT_EQ(p.std(1), 0.0);
  Result<int> r;
  r.parameters = p;
  r.summary.termination = Termination::Converged;
  EXPECT_NE(r.why_not_usable().find("singular"), std::string::npos) << r.why_not_usable();
  p.set_covariance(Eigen::Matrix3d::Identity());  // no slots: all parameters in order
  EXPECT_EQ(p.std(1), 1.0);
}
