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
  EXPECT_TRUE(r.usable());
  r.parameters.values(1) = NAN;
  EXPECT_FALSE(r.usable());
  r.parameters.values(1) = 1;
  r.summary.termination = Termination::MaxIterations;
  EXPECT_FALSE(r.usable());
  r.parameters.names = {"a1", "b0"};
  EXPECT_EQ(r.parameters.index("b0"), 1);
  EXPECT_THROW(r.parameters.index("c"), InvalidArgument);
}
