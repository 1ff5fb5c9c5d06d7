#include <algorithm>
#include <complex>

#include <gtest/gtest.h>

#include "ctid/core/error.hpp"
#include "ctid/poly/polynomial.hpp"
#include "ctid/poly/rational.hpp"

using namespace ctid;

TEST(Polynomial, EvaluateArithmeticDerivative) {
  const Polynomial p{1.0, -3.0, 2.0};  // s^2 - 3 s + 2 = (s-1)(s-2)
  EXPECT_EQ(p.degree(), 2);
  EXPECT_DOUBLE_EQ(p(3.0), 2.0);
  EXPECT_EQ(p(std::complex<double>(0, 1)), std::complex<double>(1.0, -3.0));
  EXPECT_EQ(p * (Polynomial{1.0, 1.0}), (Polynomial{1.0, -2.0, -1.0, 2.0}));
  EXPECT_EQ(p + (Polynomial{3.0, 0.0}), (Polynomial{1.0, 0.0, 2.0}));
  EXPECT_EQ(p - p, Polynomial{0.0});
  EXPECT_EQ(p.derivative(), (Polynomial{2.0, -3.0}));
  EXPECT_EQ((Polynomial{0.0, 0.0, 5.0}).degree(), 0);  // leading zeros trimmed
  EXPECT_EQ(p.coefficient_of_power(1), -3.0);
  EXPECT_EQ(p.to_string(), "s^2 - 3 s + 2");
  EXPECT_THROW(Polynomial({1.0, NAN}), InvalidArgument);
}

TEST(Polynomial, RootsAndFromRoots) {
  const Polynomial p = Polynomial{1.0, 0.1, 1.0} * Polynomial{1.0, 0.4, 25.0} * Polynomial{1.0, 0.0};
  Eigen::VectorXcd r = p.roots();
  EXPECT_EQ(r.size(), 5);
  const Polynomial q = Polynomial::from_roots(r);
  EXPECT_LT((q.coefficients() - p.coefficients()).cwiseAbs().maxCoeff(), 1e-12);
  int zeros = 0;
  for (auto z : r) zeros += std::abs(z) == 0.0;
  EXPECT_EQ(zeros, 1);  // exact root at the origin
  EXPECT_THROW(Polynomial::from_roots(Eigen::VectorXcd{{std::complex<double>(1, 1)}}), InvalidArgument);
  EXPECT_EQ(Polynomial{3.0}.roots().size(), 0);
}

TEST(Rational, MonicDenominatorAndOperations) {
  const Rational g(Polynomial{2.0}, Polynomial{2.0, 4.0});  // 1/(s+2)
  EXPECT_EQ(g.den(), (Polynomial{1.0, 2.0}));
  EXPECT_EQ(g.num(), Polynomial{1.0});
  const Rational h = g * g + g;
  EXPECT_NEAR(h(1.0), 1.0 / 9 + 1.0 / 3, 1e-15);
  EXPECT_NEAR((g / g)(0.7), 1.0, 1e-15);
  EXPECT_TRUE(g.is_strictly_proper());
  EXPECT_THROW(Rational(Polynomial{1.0}, Polynomial{0.0}), InvalidArgument);
}
