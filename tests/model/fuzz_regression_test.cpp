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
