// The grey-box model language (model/expression.hpp): values against the same formulas written in C++
// (to 1e-15 relative), derivatives against those formulas' analytic derivatives and central differences, and the
// parse errors a user sees.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/model/expression.hpp"
#include "test_util.hpp"

using namespace ctid;

namespace {
const std::vector<std::string> kVars = {"x1", "x2", "u", "k1", "k2", "t"};

// Central difference of e with respect to variable i (step h relative to the value).
double central(const Expression& e, std::vector<double> x, int i) {
  const double h = 1e-6 * std::max(1.0, std::abs(x[static_cast<std::size_t>(i)]));
  x[static_cast<std::size_t>(i)] += h;
  const double up = e(x.data());
  x[static_cast<std::size_t>(i)] -= 2 * h;
  return (up - e(x.data())) / (2 * h);
}
}  // namespace

TEST(Expression, ValuesFollowPrecedenceAndTheFunctions) {
  const std::vector<double> x = {0.7, -1.3, 2.0, 0.05, 3.0, 1.5};  // x1 x2 u k1 k2 t
  auto value = [&](const std::string& s) { return Expression(s, kVars)(x.data()); };
  EXPECT_DOUBLE_EQ(value("1 + 2 * 3"), 7.0);
  EXPECT_DOUBLE_EQ(value("(1 + 2) * 3"), 9.0);
  EXPECT_DOUBLE_EQ(value("2 ^ 3 ^ 2"), 512.0);  // right-associative
  EXPECT_DOUBLE_EQ(value("-x1^2"), -0.49);       // ^ before unary minus
  EXPECT_DOUBLE_EQ(value("8 / 4 / 2"), 1.0);     // left-associative
  EXPECT_DOUBLE_EQ(value("2 - 3 - 4"), -5.0);
  EXPECT_DOUBLE_EQ(value("1e-3 * 2.5E2"), 0.25);
  EXPECT_DOUBLE_EQ(value("-k1*sqrt(max(x1, 0)) + k2*u"), -0.05 * std::sqrt(0.7) + 6.0);
  EXPECT_DOUBLE_EQ(value("sat(k2*u, -5, 5)"), 5.0);
  EXPECT_DOUBLE_EQ(value("sat(x2, -1, 1)"), -1.0);
  EXPECT_DOUBLE_EQ(value("sat(x1, -1, 1)"), 0.7);
  EXPECT_DOUBLE_EQ(value("sign(x2) + sign(0) + abs(x2)"), -1.0 + 0.0 + 1.3);
  EXPECT_DOUBLE_EQ(value("min(x1, x2) + max(x1, x2)"), -1.3 + 0.7);
  EXPECT_DOUBLE_EQ(value("pow(u, 0.5)"), std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(value("exp(log(u)) + tanh(x1) + atan(x2) + sin(t) * cos(t)"),
                   2.0 + std::tanh(0.7) + std::atan(-1.3) + std::sin(1.5) * std::cos(1.5));
  EXPECT_EQ(Expression("k1*x1 + 2", kVars).uses(), (std::vector<bool>{true, false, false, true, false, false}));
}

TEST(Expression, GradientsAreExact) {
  // The cascaded-tank and friction right-hand sides of docs/methods/greybox.md and every function, at a point away from the kinks:
  // the forward-mode gradient equals central differences to 1e-7 relative (their truncation error), and for
  // -k1*sqrt(x1) + k2*u the analytic gradient to 1e-15.
  const std::vector<double> x = {0.7, -1.3, 2.0, 0.05, 3.0, 1.5};
  const std::vector<std::string> texts = {
      "-k1*sqrt(max(x1, 0)) + k2*u", "k1*sqrt(max(x1, 0)) - k2*sqrt(max(x2 + 2, 0))", "-k1*x2 - k2*sign(x2) + u",
      "sat(k2*u - x1, -5, 5) / (1 + x1^2)", "exp(-k1*t) * sin(k2*t + x1)", "pow(u, k1) * atan(x2) - tanh(x1*x2)",
      "abs(x2)^1.5 + log(u + x1) - cos(x1)/k2", "min(x1, 3*x2 + 5) * max(u, k2)", "x1^k2"};
  for (const auto& s : texts) {
    const Expression e(s, kVars);
    std::vector<double> g(kVars.size());
    const double v = e.gradient(x.data(), g.data());
    EXPECT_EQ(v, e(x.data())) << s;
    for (int i = 0; i < static_cast<int>(kVars.size()); ++i) {
      const double fd = central(e, x, i);
      EXPECT_NEAR(g[static_cast<std::size_t>(i)], fd, 1e-7 * std::max(1.0, std::abs(fd))) << s << " d/d" << kVars[i];
      if (!e.uses()[static_cast<std::size_t>(i)]) EXPECT_EQ(g[static_cast<std::size_t>(i)], 0.0) << s;
    }
  }
  const Expression tank("-k1*sqrt(max(x1, 0)) + k2*u", kVars);
  std::vector<double> g(kVars.size());
  tank.gradient(x.data(), g.data());
  EXPECT_NEAR(g[0], -0.05 * 0.5 / std::sqrt(0.7), 1e-15);
  EXPECT_EQ(g[2], 3.0);
  EXPECT_NEAR(g[3], -std::sqrt(0.7), 1e-15);
  EXPECT_EQ(g[4], 2.0);
  // At the kinks: the documented one-sided choices (sign' = 0, sat passes dx inside, the bound outside).
  const std::vector<double> y = {-0.2, 0.0, 2.0, 0.05, 3.0, 0.0};
  Expression("sign(x2)*k2 + sat(x1, -1, 1) + max(x1, 0)", kVars).gradient(y.data(), g.data());
  EXPECT_EQ(g[1], 0.0);
  EXPECT_EQ(g[0], 1.0);  // sat passes dx1; max(x1, 0) takes 0 for x1 < 0
  EXPECT_EQ(g[4], 0.0);  // sign(0) * k2 = 0
  // Ties take the second argument: the guarded square root of an empty tank has a finite (zero) derivative.
  const std::vector<double> empty = {0.0, 1.0, 2.0, 0.05, 3.0, 0.0};
  EXPECT_EQ(Expression("k1*sqrt(max(x1, 0))", kVars).gradient(empty.data(), g.data()), 0.0);
  EXPECT_EQ(g[0], 0.0);
  EXPECT_EQ(g[3], 0.0);
  Expression("sat(x1, 0, 1) + min(x2, 1)", kVars).gradient(empty.data(), g.data());
  EXPECT_EQ(g[0], 0.0);  // at the lower bound: the bound's derivative
  EXPECT_EQ(g[1], 0.0);  // min(1, 1): the constant
  // An orifice law with a fitted exponent, at an empty tank: value 0, every derivative 0 (no 0 * inf, no 0 * log 0).
  EXPECT_EQ(Expression("k1*pow(max(x1, 0), k2)", kVars).gradient(empty.data(), g.data()), 0.0);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(g[static_cast<std::size_t>(i)], 0.0) << i;
}

TEST(Expression, ErrorsNameTheColumnAndTheClosestName) {
  EXPECT_EQ(test::error_of([] { Expression("k1*x3 + u", kVars); }),
            "expression \"k1*x3 + u\": unknown name 'x3'; did you mean 'x1'? (names: x1, x2, u, k1, k2, t) at column 4");
  EXPECT_EQ(test::error_of([] { Expression("sqr(x1)", kVars); }),
            "expression \"sqr(x1)\": unknown function 'sqr'; did you mean 'sqrt'? at column 1");
  EXPECT_EQ(test::error_of([] { Expression("sat(x1, 0)", kVars); }),
            "expression \"sat(x1, 0)\": sat() takes 3 arguments (got 2) at column 1");
  EXPECT_EQ(test::error_of([] { Expression("(x1 + 1", kVars); }), "expression \"(x1 + 1\": expected ')' at column 8");
  EXPECT_EQ(test::error_of([] { Expression("x1 +", kVars); }), "expression \"x1 +\": unexpected end of expression at column 5");
  EXPECT_EQ(test::error_of([] { Expression("x1 x2", kVars); }), "expression \"x1 x2\": unexpected 'x' at column 4");
  EXPECT_EQ(test::error_of([] { Expression("2 * # x1", kVars); }), "expression \"2 * # x1\": unexpected '#' at column 5");
  EXPECT_THROW(Expression("", kVars), InvalidArgument);
  std::string deep;
  for (int i = 0; i < 70; ++i) deep += "(1 + ";
  deep += "1";
  for (int i = 0; i < 70; ++i) deep += ")";
  EXPECT_NE(test::error_of([&] { Expression(deep, kVars); }).find("nested more than 64 levels deep"), std::string::npos);
  EXPECT_THROW(Expression()(nullptr), InvalidArgument);
}
