#include "ctid/poly/rational.hpp"

#include "ctid/core/check.hpp"

namespace ctid {

Rational::Rational(Polynomial num, Polynomial den) {
  CTID_REQUIRE(!den.is_zero(), "Rational: the denominator is the zero polynomial");
  const double lead = den.leading();
  num_ = num * (1.0 / lead);
  den_ = den.monic();
}

Rational Rational::operator/(const Rational& o) const {
  CTID_REQUIRE(!o.num_.is_zero(), "Rational: division by the zero function");
  return {num_ * o.den_, den_ * o.num_};
}

}  // namespace ctid
