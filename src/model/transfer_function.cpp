#include "ctid/model/transfer_function.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "ctid/core/check.hpp"
#include "ctid/model/state_space.hpp"

namespace ctid {

TransferFunction::TransferFunction(Polynomial num, Polynomial den, double io_delay) {
  CTID_REQUIRE(!den.is_zero(), "TransferFunction: the denominator is zero");
  CTID_REQUIRE(num.degree() <= den.degree() || num.is_zero(),
               "TransferFunction: improper model (numerator degree {} > denominator degree {})", num.degree(), den.degree());
  const double lead = den.leading();
  num_ = num * (1.0 / lead);
  den_ = den.monic();
  set_io_delay(io_delay);
}

void TransferFunction::set_io_delay(double seconds) {
  CTID_REQUIRE(std::isfinite(seconds) && seconds >= 0, "TransferFunction: the delay must be finite and >= 0 (got {} s)", seconds);
  delay_ = seconds;
}

double TransferFunction::dc_gain() const {
  const double d = den_(0.0), n = num_(0.0);
  if (d == 0.0) return n == 0.0 ? std::numeric_limits<double>::quiet_NaN() : std::copysign(INFINITY, n);
  return n / d;
}

bool TransferFunction::is_stable() const {
  const Eigen::VectorXcd p = poles();
  for (Eigen::Index i = 0; i < p.size(); ++i)
    if (!(p(i).real() < 0)) return false;
  return true;
}

std::complex<double> TransferFunction::operator()(std::complex<double> s) const {
  return num_(s) / den_(s) * std::exp(-s * delay_);
}

Eigen::VectorXcd TransferFunction::frequency_response(const Eigen::VectorXd& w) const {
  Eigen::VectorXcd g(w.size());
  for (Eigen::Index i = 0; i < w.size(); ++i) g(i) = (*this)(std::complex<double>(0.0, w(i)));
  return g;
}

StateSpace TransferFunction::to_state_space() const { return StateSpace::controllable_canonical(*this); }

std::string TransferFunction::to_string(int precision) const {
  std::ostringstream os;
  os << "(" << num_.to_string("s", precision) << ") / (" << den_.to_string("s", precision) << ")";
  if (delay_ > 0) {
    os.precision(precision);
    os << " * exp(-" << delay_ << " s)";
  }
  return os.str();
}

std::string parasitic_pole_problem(const TransferFunction& g) {
  // With den = s^n + a1 s^(n-1) + ... + an and |a1| huge, one pole is about -a1 and the others are the roots of
  // a1 s^(n-1) + ... + an (computing all roots at once loses the slow ones to rounding).
  if (g.order() < 2) return "";
  const Eigen::VectorXd& a = g.den().coefficients();
  const double fast = std::abs(a(1));
  const Eigen::VectorXd rest = a.tail(a.size() - 1) / a(1);
  if (!rest.allFinite()) return "";
  const Eigen::VectorXcd slow = Polynomial(rest).roots();
  const double next = slow.size() ? slow.cwiseAbs().maxCoeff() : 0.0;
  if (!(next > 0) || !(fast > 1e10 * next)) return "";
  return detail::format("a pole at about {} is more than 1e10 times faster than the others (at most {} in magnitude): a "
                        "leading denominator coefficient is zero up to rounding; drop it (order {})",
                        -a(1), next, g.order() - 1);
}

}  // namespace ctid
