// ctid — nonlinear continuous-time grey-box models: the physics of a machine written as state
// equations with named parameters,
//     dx/dt = f(x, u, theta, t),   y = h(x, u, theta, t),   x(t_0) = x0(theta) or estimated,
// every right-hand side an Expression (model/expression.hpp: + - * / ^, exp log sqrt abs sign tanh sin cos atan
// min max pow sat, the time t). The model file (JSON, `"type": "greybox"`; io/json.hpp) holds exactly a
// GreyboxSpec. Simulation integrates the states by adaptive Dormand-Prince 5(4) (internal/ode.hpp) with the
// inputs held or linear between samples; sensitivities() integrates the forward sensitivity equations
//     dS/dt = (df/dx) S + df/dtheta,   S(t_0) = dx0/dtheta,   dy/dtheta = (dh/dx) S + dh/dtheta
// (Ljung 1999 §7; Hairer, Norsett & Wanner I.14) on the same steps, with the Jacobians of f and h exact (forward-mode
// differentiation of the compiled expressions). sign(s) of a function s of the states and parameters is a switching
// surface s = 0: the integrator locates where s changes sign, holds sign(s) at +-1 on each side, follows the
// Filippov sliding field on the surface where both sides' fields point at it (friction at rest), and the
// sensitivities jump at each crossing and start of a sliding mode (Filippov 1988; Hiskens & Pai 2000; the method is
// in model/greybox.cpp). At the kinks of abs/min/max/sat (f continuous) and of sign() of an input or t the
// sensitivities follow the one-sided derivative the integrator's stage sees (Expression's documented choices); no
// jump is needed where f is continuous and the switching function does not depend on theta.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/status.hpp"
#include "ctid/data/iddata.hpp"

namespace ctid {

/// A named physical parameter: its value (the start of a fit, the estimate after it), optional bounds, or held.
struct GreyboxParameter {
  std::string name;
  double value = 0.0;
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  bool fixed = false;  ///< held at `value`, never estimated
  bool operator==(const GreyboxParameter&) const = default;
};

/// The initial value of one state: an expression of the parameters (a number is one), or estimated — one free
/// initial state per experiment. An estimated state's `expression` is its starting value (empty: the first
/// sample of an output that is this state alone, else 0); after a fit it is the first experiment's estimate.
struct GreyboxInitial {
  std::string expression = "0";
  bool estimate = false;
  bool operator==(const GreyboxInitial&) const = default;
};

/// Everything a grey-box model file declares, in declaration order. Names are identifiers ([A-Za-z_][A-Za-z0-9_]*),
/// distinct across inputs, states and parameters, and none is `t` or a function name.
struct GreyboxSpec {
  std::vector<std::string> inputs;   ///< data column names (unless mapped by the caller), in the model's order
  std::vector<std::string> states;
  std::vector<std::pair<std::string, std::string>> outputs;  ///< output name and its expression
  std::vector<GreyboxParameter> parameters;
  std::vector<std::string> equations;     ///< dx_i/dt, one per state (same order)
  std::vector<GreyboxInitial> initial;    ///< one per state
  bool operator==(const GreyboxSpec&) const = default;
};

/// How a grey-box model is integrated: Explicit — adaptive Dormand-Prince 5(4) (non-stiff, cheapest per step); Bdf —
/// CVODES's variable-order BDF with Newton on the exact Jacobian (stiff models: time constants far apart); Auto —
/// Dormand-Prince, and BDF where it needs more than 200 steps per sample on average (the sign of stiffness).
enum class GreyboxIntegrator { Auto, Explicit, Bdf };

/// States and outputs of a simulation.
struct GreyboxSimulation {
  Eigen::MatrixXd y;  ///< N x ny outputs at the sample times (NaN from an escape on)
  Eigen::MatrixXd x;  ///< N x nx states
  Termination termination = Termination::Completed;  ///< NumericalFailure when the solution escapes
  std::string message;
  GreyboxIntegrator integrator = GreyboxIntegrator::Explicit;  ///< the one that ran (Auto: Explicit or Bdf)
  bool ok() const { return termination == Termination::Completed; }
};

/// A simulation with its derivatives with respect to a chosen set of quantities q (free parameters and free initial
/// states): dy[j] is N x q, the derivatives of output j.
struct GreyboxSensitivities {
  Eigen::MatrixXd y;
  std::vector<Eigen::MatrixXd> dy;
  Eigen::VectorXd x_end;   ///< the state at the last time (what multiple shooting ties to the next segment)
  Eigen::MatrixXd dx_end;  ///< its derivatives, nx x q
  bool ok = true;
  std::string message;
  GreyboxIntegrator integrator = GreyboxIntegrator::Explicit;  ///< the one that ran (Auto: Explicit or Bdf)
};

class GreyboxModel {
 public:
  GreyboxModel() = default;
  /// Compiles every expression. Throws InvalidArgument naming the problem: a missing or repeated name, a name that
  /// is not an identifier or is reserved (t, a function), an equation count that is not the state count, an
  /// expression that does not parse (its text, column and the closest name), an initial-state expression that
  /// reads a state or input, a parameter whose value lies outside its bounds or whose lower bound is not below the
  /// upper, no outputs.
  explicit GreyboxModel(GreyboxSpec spec);

  const GreyboxSpec& spec() const { return spec_; }
  int nx() const { return static_cast<int>(spec_.states.size()); }
  int nu() const { return static_cast<int>(spec_.inputs.size()); }
  int ny() const { return static_cast<int>(spec_.outputs.size()); }
  int np() const { return static_cast<int>(spec_.parameters.size()); }
  std::vector<std::string> parameter_names() const;
  Eigen::VectorXd parameter_values() const;
  std::vector<std::string> output_names() const;
  /// Index of a parameter or state by name; throws InvalidArgument naming the closest one.
  int parameter_index(const std::string& name) const;
  int state_index(const std::string& name) const;
  /// The same model with other parameter values (np entries, finite); bounds are not enforced here.
  GreyboxModel with_parameters(const Eigen::VectorXd& values) const;
  /// The same model with these initial values (nx entries) written into the estimated states' expressions.
  GreyboxModel with_estimated_initial(const Eigen::VectorXd& x0) const;
  /// Whether any state's initial value is estimated.
  bool estimates_initial_state() const;
  /// The initial state at the current parameters: every expression evaluated (an estimated state with an empty
  /// expression: NaN — its start comes from data).
  Eigen::VectorXd initial_state() const;
  /// initial_state() with each estimated state that has no value taken from `data`: the first sample of an output
  /// whose expression is that state alone, else 0 (the start of an initial-state estimate).
  Eigen::VectorXd initial_state_guess(const IdData& data) const;
  /// The output whose expression is state i alone ("y": "x2"), or -1.
  int output_of_state(int i) const;
  /// d x0 / d theta (nx x np) of the initial-state expressions (0 for estimated states).
  Eigen::MatrixXd initial_state_jacobian() const;
  /// The equations and outputs, one per line ("dx1/dt = ...", "y = ...").
  std::string to_string() const;

  /// Simulates from x0 (nx entries; empty: initial_state(), where estimated states without a value start at 0)
  /// driven by the inputs u (N x nu) at the increasing times t (seconds; the expressions' t), the inputs held,
  /// linear or band-limited (windowed-sinc interpolation, uniform times only) between samples, with relative tolerance rtol (absolute tolerance rtol times 1e-3) by `integrator`. An escaping
  /// solution (|x| > 1e12, non-finite, step-size collapse) ends with NumericalFailure, a message naming the time,
  /// and NaN from there. Throws InvalidArgument for size mismatches, non-increasing times or a non-finite x0 entry.
  GreyboxSimulation simulate(const Eigen::MatrixXd& u, const Eigen::VectorXd& t, Intersample intersample = Intersample::Zoh,
                             const Eigen::VectorXd& x0 = {}, double rtol = 1e-8,
                             GreyboxIntegrator integrator = GreyboxIntegrator::Auto) const;
  /// The simulation from x0 together with the output derivatives with respect to the parameters `free` (indices)
  /// and then the initial states `free_x0` (indices of states whose x0 is varied), and the final state with its
  /// derivatives. Initial-state expressions of parameters contribute dx0/dtheta unless `x0_from_parameters` is
  /// false (a multiple-shooting segment, whose start is free). Same errors as simulate().
  GreyboxSensitivities sensitivities(const Eigen::MatrixXd& u, const Eigen::VectorXd& t, Intersample intersample,
                                     const Eigen::VectorXd& x0, const std::vector<int>& free,
                                     const std::vector<int>& free_x0, double rtol = 1e-8,
                                     bool x0_from_parameters = true,
                                     GreyboxIntegrator integrator = GreyboxIntegrator::Auto) const;
  bool operator==(const GreyboxModel& o) const { return spec_ == o.spec_; }

 private:
  struct Compiled;
  GreyboxSpec spec_;
  std::shared_ptr<const Compiled> c_;
};

/// How a grey-box simulation reads the inputs of `data` between samples (one way for all inputs): held when every
/// input is Zoh, band-limited (windowed-sinc interpolation; uniformly sampled records only) when every input is
/// BandLimited, linear otherwise.
Intersample greybox_intersample(const IdData& data);


}  // namespace ctid
