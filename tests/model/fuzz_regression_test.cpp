// Inputs found by the libFuzzer targets (tests/fuzz; corpus files regression-*): each used to end the process
// (an uncaught std::out_of_range from a number too large for int/double) and must now be a clear InvalidArgument.
#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/model/narx.hpp"
#include "ctid/model/nde.hpp"
#include "ctid/model/physical_model.hpp"

using namespace ctid;

namespace {
std::string message_of(void (*f)()) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(FuzzRegression, HugeNumbersInTermsAndExpressionsAreRejected) {
  EXPECT_NE(message_of([] { (void)NarxTerm::parse("y(k-1999999999999999999999)*u(k-2)"); }).find("lag larger than 1000000"),
            std::string::npos);
  EXPECT_NE(message_of([] { (void)NarxTerm::parse("u(k-2000000)"); }).find("lag larger than 1000000"), std::string::npos);
  EXPECT_EQ(NarxTerm::parse("u(k-1000000)").max_lag(), 1000000);
  EXPECT_NE(message_of([] { (void)NdeTerm::parse("D^99999999999999y"); }).find("number larger than 99"), std::string::npos);
  EXPECT_NE(message_of([] { (void)PhysicalModel("k/s^" + std::string(400, '9'), {"k"}); }).find("exponent larger than 64"),
            std::string::npos);
}

TEST(FuzzRegression, NestedPowersAreRefusedBeforeTheyAreExpanded) {
  // tests/fuzz/corpus/expression/regression-nested-power.txt: (s^55 + ...)^55 was expanded to degree 3025 with a
  // gradient per coefficient (> 10 s, a fuzz timeout). Degrees above 100 are now refused when parsing; here 55 x 55.
  EXPECT_EQ(message_of([] { (void)PhysicalModel("k1/(s*k1/(s^55+k-+k2)^55+k-+k2)", {"k", "k1", "k2"}); }),
            "expression \"k1/(s*k1/(s^55+k-+k2)^55+k-+k2)\": expanding it gives polynomials in s of degree 3025 (at most "
            "100 supported)");
  // The bound counts what the expansion multiplies: 1/(s+1)^50 + 1/(s+2)^50 is degree 100 and is accepted.
  const PhysicalModel ok("1/(s+a)^50 + 1/(s+b)^50", {"a", "b"});
  EXPECT_EQ(ok.transfer_function(Eigen::Vector2d(1, 2)).den().degree(), 100);
  EXPECT_THROW(PhysicalModel("1/(s+a)^50 + 1/(s+b)^51", {"a", "b"}), InvalidArgument);
  EXPECT_THROW(PhysicalModel::from_state_space({{"(s+a)^60*(s+a)^60"}}, {{"1"}}, {{"1"}}, {{"0"}}, {"a"}), InvalidArgument);
}
