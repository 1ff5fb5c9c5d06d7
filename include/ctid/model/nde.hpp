// ctid — polynomial nonlinear differential-equation (NDE) models of Billings & Li (1999), eqs 1-6, in
// the implicit form of BL 4-6:
//     sum_m c_m prod_{f in term m} D^{l_f} x_f(t) = 0,   x_f = y or u,
// e.g. BL (33): y + 0.002 Dy + 0.0001 D^2y - u + 0.1 y^2 - 0.006 y*Dy = 0. The linear part is
// A(D) y - B(D) u with A(s) = sum c(D^l y) s^l, B(s) = -sum c(D^l u) s^l; the tables' convention
// normalises the coefficient of y to +1 (normalized()).
#pragma once

#include <complex>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/status.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/poly/polynomial.hpp"

namespace ctid {

struct NdeFactor {
  bool input = false;  ///< false: y, true: u
  int derivative = 0;  ///< l in D^l
  bool operator==(const NdeFactor&) const = default;
  auto operator<=>(const NdeFactor&) const = default;
};

/// A product of derivatives of y and u (factors kept sorted: y before u, lower derivatives first).
struct NdeTerm {
  std::vector<NdeFactor> factors;
  int degree() const { return static_cast<int>(factors.size()); }
  /// "y", "Dy", "D^2y", "u", "Du", "y^2", "y*Dy", "Dy*u".
  std::string name() const;
  /// Inverse of name() (also accepts "y*y", "D1y", "D^1y"); throws InvalidArgument naming the position.
  static NdeTerm parse(const std::string& text);
  bool operator==(const NdeTerm&) const = default;
};

/// Outcome of an NDE simulation.
struct NdeSimulation {
  Eigen::VectorXd y;                        ///< output at the sample times (NaN after an escape)
  Termination termination = Termination::Completed;  ///< NumericalFailure when the solution escapes
  std::string message;
  bool ok() const { return termination == Termination::Completed; }
};

class NdeModel {
 public:
  NdeModel() = default;
  /// Throws InvalidArgument for size mismatches, non-finite coefficients or repeated terms.
  NdeModel(std::vector<NdeTerm> terms, Eigen::VectorXd coefficients);

  const std::vector<NdeTerm>& terms() const { return terms_; }
  const Eigen::VectorXd& coefficients() const { return c_; }
  /// Coefficient of a term by name (0 when absent).
  double coefficient(const std::string& name) const;
  /// Scaled so that the coefficient of y is +1. Throws InvalidArgument when y is absent.
  NdeModel normalized() const;
  /// A(s) and B(s) of the linear part (descending powers).
  Polynomial a() const;
  Polynomial b() const;
  /// H_1(s) = B(s)/A(s).
  std::complex<double> h1(std::complex<double> s) const;
  /// Symmetric H_2(s_1, s_2) by harmonic probing of the quadratic terms (BL 4-6):
  /// 2 A(s_1+s_2) H_2 = - sum over y-y, y-u and u-u products of their probing expressions.
  std::complex<double> h2(std::complex<double> s1, std::complex<double> s2) const;
  /// Symmetric H_3(s_1, s_2, s_3) by harmonic probing with three exponentials: the coefficient of
  /// e^{(s_1+s_2+s_3)t} gives 6 A(s_1+s_2+s_3) H_3 = - sum over quadratic terms of their first x second
  /// order products (second-order components (s_j+s_k)^l 2 H_2(s_j, s_k) of y) - sum over cubic terms of
  /// the six orderings of first-order products. Terms of degree > 3 do not enter.
  std::complex<double> h3(std::complex<double> s1, std::complex<double> s2, std::complex<double> s3) const;
  /// "y + 0.002 Dy + 0.0001 D^2y - u + 0.1 y^2 - 0.006 y*Dy = 0".
  std::string to_string(int precision = 4) const;

  /// Simulate from the initial state x0 = [y, Dy, .., D^{L-1}y] (empty: rest) driven by u at the times t
  /// (increasing), held (Zoh) or linear (Foh) between samples, by adaptive Dormand-Prince 5(4) with
  /// relative tolerance rtol. The highest derivative of y must appear only in one linear term, and the
  /// input only undifferentiated (held inputs have no derivatives). An escaping solution (|x| > 1e12 or
  /// a step size collapse) ends with termination NumericalFailure, a message and NaN outputs from there.
  /// Throws InvalidArgument for a model that cannot be put in explicit form or size mismatches.
  NdeSimulation simulate(const Eigen::VectorXd& u, const Eigen::VectorXd& t, Intersample intersample = Intersample::Zoh,
                         const Eigen::VectorXd& x0 = {}, double rtol = 1e-9) const;

 private:
  std::vector<NdeTerm> terms_;
  Eigen::VectorXd c_;
};

}  // namespace ctid
