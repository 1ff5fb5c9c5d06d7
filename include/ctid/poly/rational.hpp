// ctid — rational functions N(s)/D(s) of real polynomials (descending powers).
#pragma once

#include <complex>

#include "ctid/poly/polynomial.hpp"

namespace ctid {

class Rational {
 public:
  Rational() : num_(Polynomial{0.0}), den_(Polynomial{1.0}) {}
  /// Throws InvalidArgument for a zero denominator. The denominator is made monic
  /// (numerator scaled accordingly).
  Rational(Polynomial num, Polynomial den);

  const Polynomial& num() const { return num_; }
  const Polynomial& den() const { return den_; }
  std::complex<double> operator()(std::complex<double> s) const { return num_(s) / den_(s); }
  double operator()(double s) const { return num_(s) / den_(s); }
  bool is_proper() const { return num_.degree() <= den_.degree(); }
  bool is_strictly_proper() const { return num_.degree() < den_.degree() || num_.is_zero(); }

  Rational operator+(const Rational& o) const { return {num_ * o.den_ + o.num_ * den_, den_ * o.den_}; }
  Rational operator-(const Rational& o) const { return {num_ * o.den_ - o.num_ * den_, den_ * o.den_}; }
  Rational operator*(const Rational& o) const { return {num_ * o.num_, den_ * o.den_}; }
  Rational operator/(const Rational& o) const;

 private:
  Polynomial num_, den_;
};

}  // namespace ctid
