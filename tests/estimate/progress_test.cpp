// Progress callback and cancellation (core/progress.hpp): every iterative estimator reports its iterations and
// stops with Termination::Interrupted, returning its best iterate, when the callback says so.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ctid/core/progress.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/estimate/nonlinear/frols.hpp"
#include "ctid/estimate/transfer_function/oe.hpp"
#include "ctid/estimate/transfer_function/srivc.hpp"
#include "ctid/simulate/lsim.hpp"
#include "test_util.hpp"

using namespace ctid;

namespace {
// Second-order plant 1/(s^2 + 0.8 s + 4), PRBS input, 20 dB output noise: several SRIVC and LM iterations.
IdData plant() { return test::second_order_record(); }

// Stops at the given iteration of the given stage, recording the calls.
struct Stopper {
  std::string stage;
  int at;
  std::vector<int> seen;
  ProgressCallback callback() {
    return [this](const ProgressEvent& e) {
      if (stage != e.stage) return true;
      seen.push_back(e.iteration);
      return e.iteration < at;
    };
  }
};
}  // namespace

TEST(Progress, SrivcStopsWhenAsked) {
  const IdData d = plant();
  const auto full = srivc(d, {.nb = 1, .nf = 2});
  ASSERT_EQ(full.summary.termination, Termination::Converged);
  ASSERT_GE(full.summary.iterations, 3);
  Stopper s{"srivc", 2, {}};
  Result<TransferFunction> r;
  {
    ProgressScope scope(s.callback());
    r = srivc(d, {.nb = 1, .nf = 2});
  }
  EXPECT_EQ(r.summary.termination, Termination::Interrupted);
  EXPECT_EQ(r.summary.iterations, 1);  // the iterate before the refused second one
  EXPECT_TRUE(r.parameters.values.allFinite());
  EXPECT_FALSE(r.usable());
  EXPECT_EQ(s.seen, (std::vector<int>{1, 2}));
  // The scope has ended: the same call converges again.
  EXPECT_EQ(srivc(d, {.nb = 1, .nf = 2}).summary.termination, Termination::Converged);
}

TEST(Progress, LevenbergMarquardtStopsWhenAsked) {
  const IdData d = plant();
  Stopper s{"levenberg_marquardt", 2, {}};
  ProgressScope scope(s.callback());
  const auto r = oe(d, {.nb = 1, .nf = 2}, {.initial = TransferFunction(Eigen::VectorXd{{3.0}}, Eigen::VectorXd{{1.0, 1.5, 3.0}})});
  EXPECT_EQ(r.summary.termination, Termination::Interrupted);
  EXPECT_EQ(r.summary.iterations, 1);
  EXPECT_NE(r.summary.message.find("interrupted"), std::string::npos);
}

TEST(Progress, FrolsStopsAfterTheTermsSelectedSoFar) {
  const IdData d = plant();
  Stopper s{"frols", 3, {}};
  ProgressScope scope(s.callback());
  const auto r = frols(d, narx_candidates(2, 3, 3), {.max_terms = 10});
  EXPECT_EQ(r.summary.termination, Termination::Interrupted);
  EXPECT_EQ(r.parameters.size(), 3);
  EXPECT_EQ(s.seen, (std::vector<int>{1, 2, 3}));
}

TEST(Progress, ScopesNest) {
  int outer = 0, inner = 0;
  ProgressScope a([&](const ProgressEvent&) { return ++outer, true; });
  {
    ProgressScope b([&](const ProgressEvent&) { return ++inner, true; });
    EXPECT_TRUE(report_progress("x", 1, 0.0));
  }
  EXPECT_TRUE(report_progress("x", 1, 0.0));
  EXPECT_EQ(inner, 1);
  EXPECT_EQ(outer, 1);
}
