// ctid — SISO continuous-time transfer function
//   G(s) = e^{-s T_d} N(s) / D(s),  N, D in descending powers of s, D monic.
#pragma once

#include <string>

#include <Eigen/Dense>

#include "ctid/poly/polynomial.hpp"

namespace ctid {

class StateSpace;

class TransferFunction {
 public:
  TransferFunction() : num_{0.0}, den_{1.0} {}
  /// Throws InvalidArgument for a zero or improper (deg N > deg D) denominator, or a
  /// negative / non-finite delay. The denominator is normalised to be monic.
  TransferFunction(Polynomial num, Polynomial den, double io_delay = 0.0);
  TransferFunction(const Eigen::VectorXd& num, const Eigen::VectorXd& den, double io_delay = 0.0)
      : TransferFunction(Polynomial(num), Polynomial(den), io_delay) {}

  const Polynomial& num() const { return num_; }
  const Polynomial& den() const { return den_; }
  double io_delay() const { return delay_; }
  void set_io_delay(double seconds);
  int order() const { return den_.degree(); }

  Eigen::VectorXcd poles() const { return den_.roots(); }
  Eigen::VectorXcd zeros() const { return num_.roots(); }
  /// G(0); +/-Inf for a pole at the origin.
  double dc_gain() const;
  /// True when every pole has a negative real part.
  bool is_stable() const;
  /// G(j w) for each w (rad/s), including the delay.
  Eigen::VectorXcd frequency_response(const Eigen::VectorXd& w) const;
  std::complex<double> operator()(std::complex<double> s) const;
  /// Controllable canonical realisation (delay not included).
  StateSpace to_state_space() const;
  /// Human-readable "N(s) / D(s)" with the delay, one line.
  std::string to_string(int precision = 6) const;

 private:
  Polynomial num_, den_;
  double delay_ = 0.0;
};

/// Why a user-given transfer function cannot be simulated meaningfully, or "" when it can: a pole more than
/// 1e10 times faster than every other (non-zero) pole is parasitic, the trace of a leading denominator
/// coefficient that is zero up to rounding (den [1e-20, 1, 2] is 1/(s + 2) with a pole at -1e20); its
/// discretisation is meaningless. Model-file readers and the Python constructor refuse such models.
std::string parasitic_pole_problem(const TransferFunction& g);

}  // namespace ctid
