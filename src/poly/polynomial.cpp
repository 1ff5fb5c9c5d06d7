#include "ctid/poly/polynomial.hpp"

#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "ctid/core/check.hpp"

namespace ctid {

Polynomial::Polynomial(Eigen::VectorXd c) {
  for (Eigen::Index i = 0; i < c.size(); ++i)
    CTID_REQUIRE(std::isfinite(c(i)), "Polynomial: coefficient {} is not finite ({})", i, c(i));
  Eigen::Index first = 0;
  while (first < c.size() - 1 && c(first) == 0.0) ++first;
  if (c.size() == 0) c_ = Eigen::VectorXd::Zero(1);
  else c_ = c.segment(first, c.size() - first);
}

Polynomial::Polynomial(std::initializer_list<double> c)
    : Polynomial(Eigen::Map<const Eigen::VectorXd>(c.begin(), static_cast<Eigen::Index>(c.size())).eval()) {}

Polynomial Polynomial::from_roots(const Eigen::VectorXcd& r) {
  Eigen::VectorXcd c = Eigen::VectorXcd::Zero(r.size() + 1);
  c(0) = 1.0;
  for (Eigen::Index k = 0; k < r.size(); ++k) {
    for (Eigen::Index i = k + 1; i >= 1; --i) c(i) -= r(k) * c(i - 1);
  }
  Eigen::VectorXd out(c.size());
  for (Eigen::Index i = 0; i < c.size(); ++i) {
    const double scale = std::max(1.0, std::abs(c(i)));
    CTID_REQUIRE(std::abs(c(i).imag()) <= 1e-9 * scale * std::max<double>(1.0, double(r.size())),
                 "Polynomial::from_roots: the roots are not closed under conjugation (coefficient {} has imaginary part {})",
                 i, c(i).imag());
    out(i) = c(i).real();
  }
  return Polynomial(out);
}

double Polynomial::coefficient_of_power(int power) const {
  if (power < 0 || power > degree()) return 0.0;
  return c_(degree() - power);
}

double Polynomial::operator()(double s) const {
  double v = 0;
  for (Eigen::Index i = 0; i < c_.size(); ++i) v = v * s + c_(i);
  return v;
}

std::complex<double> Polynomial::operator()(std::complex<double> s) const {
  std::complex<double> v = 0;
  for (Eigen::Index i = 0; i < c_.size(); ++i) v = v * s + c_(i);
  return v;
}

Eigen::VectorXcd Polynomial::roots() const {
  const int n = degree();
  if (n < 1) return Eigen::VectorXcd(0);
  // Trailing zero coefficients are roots at 0; deflate them for accuracy.
  int zeros = 0;
  while (zeros < n && c_(n - zeros) == 0.0) ++zeros;
  const int m = n - zeros;
  Eigen::VectorXcd r(n);
  r.setZero();
  if (m > 0) {
    Eigen::MatrixXd comp = Eigen::MatrixXd::Zero(m, m);
    for (int j = 0; j < m; ++j) comp(0, j) = -c_(j + 1) / c_(0);
    for (int i = 1; i < m; ++i) comp(i, i - 1) = 1.0;
    Eigen::EigenSolver<Eigen::MatrixXd> es(comp, false);
    r.head(m) = es.eigenvalues();
  }
  return r;
}

Polynomial Polynomial::derivative() const {
  const int n = degree();
  if (n == 0) return Polynomial{0.0};
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i) d(i) = c_(i) * (n - i);
  return Polynomial(d);
}

Polynomial Polynomial::monic() const {
  CTID_REQUIRE(!is_zero(), "Polynomial::monic: the zero polynomial has no leading coefficient");
  return Polynomial(Eigen::VectorXd(c_ / c_(0)));
}

Polynomial Polynomial::operator+(const Polynomial& o) const {
  const Eigen::Index n = std::max(c_.size(), o.c_.size());
  Eigen::VectorXd r = Eigen::VectorXd::Zero(n);
  r.tail(c_.size()) += c_;
  r.tail(o.c_.size()) += o.c_;
  return Polynomial(r);
}

Polynomial Polynomial::operator-(const Polynomial& o) const { return *this + o * -1.0; }

Polynomial Polynomial::operator*(const Polynomial& o) const {
  Eigen::VectorXd r = Eigen::VectorXd::Zero(c_.size() + o.c_.size() - 1);
  for (Eigen::Index i = 0; i < c_.size(); ++i) r.segment(i, o.c_.size()) += c_(i) * o.c_;
  return Polynomial(r);
}

Polynomial Polynomial::operator*(double k) const { return Polynomial(Eigen::VectorXd(c_ * k)); }

std::string Polynomial::to_string(const std::string& var, int precision) const {
  std::ostringstream os;
  os.precision(precision);
  const int n = degree();
  bool first = true;
  for (int i = 0; i <= n; ++i) {
    const double c = c_(i);
    const int p = n - i;
    if (c == 0.0 && !(n == 0)) continue;
    const double a = std::abs(c);
    if (first) os << (c < 0 ? "-" : "");
    else os << (c < 0 ? " - " : " + ");
    if (a != 1.0 || p == 0) os << a << (p > 0 ? " " : "");
    if (p >= 1) os << var;
    if (p >= 2) os << "^" << p;
    first = false;
  }
  if (first) os << "0";
  return os.str();
}

}  // namespace ctid
