// ctid — real polynomials in descending powers (MATLAB's convention):
// c = [c0, c1, ..., cn] means c0 s^n + c1 s^(n-1) + ... + cn.
#pragma once

#include <complex>
#include <initializer_list>
#include <string>

#include <Eigen/Dense>

namespace ctid {

class Polynomial {
 public:
  /// The zero polynomial.
  Polynomial() : c_(Eigen::VectorXd::Zero(1)) {}
  /// Coefficients in descending powers; leading zeros are removed. Throws
  /// InvalidArgument for a non-finite coefficient. An empty vector is the zero polynomial.
  explicit Polynomial(Eigen::VectorXd descending);
  Polynomial(std::initializer_list<double> descending);

  /// Monic polynomial with the given roots; complex roots must come in conjugate
  /// pairs (to 1e-9 relative), else InvalidArgument.
  static Polynomial from_roots(const Eigen::VectorXcd& roots);
  static Polynomial constant(double c) { return Polynomial{c}; }

  /// Degree (0 for a constant, also for the zero polynomial).
  int degree() const { return static_cast<int>(c_.size()) - 1; }
  bool is_zero() const { return c_.size() == 1 && c_(0) == 0.0; }
  const Eigen::VectorXd& coefficients() const { return c_; }
  double leading() const { return c_(0); }
  /// Coefficient of s^power (0 for powers above the degree).
  double coefficient_of_power(int power) const;

  double operator()(double s) const;
  std::complex<double> operator()(std::complex<double> s) const;

  /// Roots (eigenvalues of the companion matrix); empty for a constant.
  Eigen::VectorXcd roots() const;
  Polynomial derivative() const;
  /// Divide by the leading coefficient. Throws InvalidArgument for the zero polynomial.
  Polynomial monic() const;

  Polynomial operator+(const Polynomial& o) const;
  Polynomial operator-(const Polynomial& o) const;
  Polynomial operator*(const Polynomial& o) const;
  Polynomial operator*(double k) const;
  Polynomial operator-() const { return *this * -1.0; }
  bool operator==(const Polynomial& o) const { return c_ == o.c_; }

  /// e.g. "s^2 + 3 s + 2" with the given variable name.
  std::string to_string(const std::string& var = "s", int precision = 6) const;

 private:
  Eigen::VectorXd c_;
};

}  // namespace ctid
