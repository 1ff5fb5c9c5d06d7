// validate/compare: several models scored on one record (ctid compare). Expected numbers come from the noise-free
// truth (a fit of 100 % from the right initial state) and from independent calls of simulate() and fit_percent().
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/compare.hpp"
#include "ctid/validate/metrics.hpp"

using namespace ctid;

namespace {
const TransferFunction kTruth(Eigen::VectorXd{{4.0}}, Eigen::VectorXd{{1.0, 0.8, 4.0}});

// 4/(s^2 + 0.8 s + 4) driven by a PRBS, noise-free, samples 500..1999 of a run from rest: the record starts in motion.
IdData moving_record() {
  const Eigen::VectorXd u = prbs(2000, {.register_length = 9, .clock_period = 3});
  const IdData all(u, lsim(kTruth, u, time_grid(0.02, 2000)), 0.02);
  return all.slice(500, 2000);
}
}  // namespace

TEST(Compare, ScoresEachModelFromTheStateThatFitsTheRecord) {
  const IdData d = moving_record();
  const TransferFunction first(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 1.0}});  // DC gain 1, no resonance
  const auto cs = compare_models(d, {{"truth", kTruth}, {"first order", first}});
  ASSERT_EQ(cs.size(), 2u);
  // The truth from the estimated initial state reproduces the noise-free record (to the simulation's accuracy).
  EXPECT_EQ(cs[0].initial, InitialCondition::Estimated);
  EXPECT_GT(cs[0].fits[0].fit_percent, 99.99);
  EXPECT_TRUE(cs[0].whiteness[0].lags.size() == 26 && cs[0].independence[0].size() == 1u);
  // The first-order model: the fit an independent simulate() + fit_percent() gives, and a lower one.
  SimulateOptions so;
  so.initial = InitialCondition::Estimated;
  const double f1 = fit_percent(d.y().col(0), simulate(AnyModel(first), d, so).y.col(0));
  EXPECT_NEAR(cs[1].fits[0].fit_percent, f1, 1e-9);
  EXPECT_LT(cs[1].mean_fit(), cs[0].mean_fit() - 10);
  EXPECT_FALSE(cs[1].whiteness[0].passed());  // it misses the resonance
  // From rest (given for every model) the truth no longer fits the first samples: a lower fit.
  const auto rest = compare_models(d, {{"truth", kTruth}}, InitialCondition::Rest);
  EXPECT_EQ(rest[0].initial, InitialCondition::Rest);
  EXPECT_LT(rest[0].fits[0].fit_percent, 99.0);
}

TEST(Compare, ADivergingModelIsRecordedAndBadInputIsNamed) {
  const IdData d = moving_record();
  const TransferFunction unstable(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, -20.0}});
  const auto cs = compare_models(d, {{"truth", kTruth}, {"unstable", unstable}});
  EXPECT_TRUE(cs[0].simulation.ok());
  EXPECT_FALSE(cs[1].simulation.ok());
  EXPECT_NE(cs[1].simulation.problem.find("not finite"), std::string::npos) << cs[1].simulation.problem;
  EXPECT_EQ(cs[1].fits[0].fit_percent, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(cs[1].whiteness[0].lags.size(), 0);  // no residual test of a non-finite residual
  const MisoModel two{{kTruth, kTruth}};
  try {
    compare_models(d, {{"truth", kTruth}, {"two inputs", two}});
    FAIL() << "a model of two inputs on a one-input record";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("model two inputs (miso) has 2 input(s) and 1 output(s); the record has 1 and 1"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(compare_models(d, {}), InvalidArgument);
}
