// ctid — physical (grey-box) linear models: a transfer-function expression in s whose
// symbols are named physical parameters, e.g. "k1/(s^2 - k2)", "K/s^2",
// "(R*C*s + 1)/(L*C*s^2 + R*C*s + 1)". Gawthrop & Wang (2005) §3 (partially known model).
//
// Grammar: expr := term {(+|-) term};  term := factor {(*|/) factor};
//          factor := unary [^ non-negative integer];  unary := [+|-] unary | primary;
//          primary := number | name | "(" expr ")".  The name `s` is the Laplace variable.
// The expression is expanded once into N(s; Theta)/D(s; Theta) with coefficients carried
// as values plus exact gradients with respect to Theta (forward automatic differentiation),
// so transfer_function() and its parameter derivatives are exact. State-space forms (entries
// that are expressions, or a C++ callable with its derivatives) give the sensitivities through
// the sensitivity equations d/dt dx/dTheta_k = A dx/dTheta_k + dA/dTheta_k x + dB/dTheta_k u,
// realised as one linear system per parameter (SISO: input 0 to output 0).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ctid/model/state_space.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// A state-space model and its derivatives with respect to each parameter (same sizes).
struct StateSpaceWithGradient {
  StateSpace model;
  std::vector<StateSpace> derivatives;  ///< d(A, B, C, D)/dTheta_k, one per parameter
};

class PhysicalModel {
 public:
  /// Parse `expression`. Every symbol other than `s` must be in `parameters` (the order of
  /// Theta). Throws InvalidArgument with the column (1-based) of a syntax error or an unknown
  /// symbol, for an exponent above 64, for an expression whose expansion reaches polynomials of
  /// degree above 100 in s, and for one that is not a proper rational function of s.
  PhysicalModel(const std::string& expression, std::vector<std::string> parameters);
  /// A state-space structure whose entries are expressions of the parameters (no s), given
  /// row by row, e.g. A = {{"0", "1"}, {"-k/m", "-d/m"}}, B = {{"0"}, {"1/m"}}, C = {{"1", "0"}},
  /// D = {{"0"}}. Throws InvalidArgument (with the entry and column) for bad entries or sizes.
  static PhysicalModel from_state_space(const std::vector<std::vector<std::string>>& A,
                                        const std::vector<std::vector<std::string>>& B,
                                        const std::vector<std::vector<std::string>>& C,
                                        const std::vector<std::vector<std::string>>& D, std::vector<std::string> parameters);
  /// A C++ callable Theta -> state space together with its exact parameter derivatives.
  static PhysicalModel from_callable(std::function<StateSpaceWithGradient(const Eigen::VectorXd&)> model,
                                     std::vector<std::string> parameters, std::string description = "callable");
  /// Names of the symbols used in an expression (other than s), in order of appearance;
  /// throws InvalidArgument on a syntax error.
  static std::vector<std::string> symbols(const std::string& expression);

  const std::string& expression() const { return expr_; }
  const std::vector<std::string>& parameter_names() const { return names_; }
  int n_parameters() const { return static_cast<int>(names_.size()); }

  /// G(s; Theta). Throws InvalidArgument when Theta has the wrong size, is not finite, or
  /// makes the denominator vanish.
  TransferFunction transfer_function(const Eigen::VectorXd& theta) const;
  /// G(s + a; Theta) (the exponentially shifted model of Gawthrop & Wang's unstable case:
  /// A -> A - aI for state-space forms).
  TransferFunction shifted(const Eigen::VectorXd& theta, double a) const;
  /// dG/dTheta_k(s + a) = (N_k D - N D_k)/D^2, one transfer function per parameter.
  std::vector<TransferFunction> sensitivities(const Eigen::VectorXd& theta, double a = 0.0) const;
  /// A state-space realisation of G(s + a; Theta) with its exact parameter derivatives: the state-space forms as
  /// given (A - aI), the transfer-function form in controllable canonical form (first row -a_1 .. -a_n of the
  /// monic denominator, B = e_1, C = b_i - b_0 a_i, D = b_0). What initial-state estimation differentiates: the
  /// free response C e^{At} x0 and its derivatives through the sensitivity equations.
  StateSpaceWithGradient realisation(const Eigen::VectorXd& theta, double a = 0.0) const;

 private:
  PhysicalModel() = default;
  struct Compiled;
  std::string expr_;
  std::vector<std::string> names_;
  std::shared_ptr<const Compiled> c_;
};

}  // namespace ctid
