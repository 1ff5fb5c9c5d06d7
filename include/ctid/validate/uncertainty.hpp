// ctid — what every view of an estimated transfer function needs besides the model: which parameter is which
// coefficient, the frequency grid and time horizon of its responses, and the band of its frequency response
// from the parameter covariance. One implementation for the HTML report (io/report) and Python (ctid.plot).
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/model/any_model.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// The transfer-function coefficient a parameter is: poly 'a' (denominator, index k of a monic denominator in
/// descending powers, k >= 1) or 'b' (numerator, index k), or poly 0 for a parameter that is not a coefficient
/// (e.g. "delay").
struct TfCoefficient {
  char poly = 0;
  int index = -1;
};

/// For each parameter named a<k> or b<k> whose value equals that coefficient of g, where it sits in g; other
/// names (e.g. "delay") get poly 0. Returns an empty vector when g's denominator is not monic or a name a<k>/b<k>
/// does not match g (another parameterisation, e.g. physical parameters).
std::vector<TfCoefficient> tf_coefficients(const TransferFunction& g, const ParameterSet& p);

/// g with the coefficients named by map (from tf_coefficients) set to the values v (one per parameter).
TransferFunction with_coefficients(const TransferFunction& g, const std::vector<TfCoefficient>& map, const Eigen::VectorXd& v);

/// n log-spaced angular frequencies (rad/s) from two decades below the smallest to two decades above the largest
/// nonzero pole magnitude (1 rad/s when there is none), ending at w_max when w_max > 0 (e.g. the Nyquist
/// frequency of the data). Throws InvalidArgument for n < 2.
Eigen::VectorXd frequency_grid(const Eigen::VectorXcd& poles, double w_max = 0.0, int n = 300);
/// The default frequency grid (rad/s) of a model's frequency response: frequency_grid of its poles up to w_max for
/// linear models (transfer function, MISO, state space); an FSF model's own band, n log-spaced points from half its
/// first filter frequency 2 pi / T to 0.95 of its Nyquist frequency pi / Delta. The report, `ctid fit --responses`
/// and Python's plots use it. Throws InvalidArgument for a nonlinear model (its frequency description is the GFRFs).
Eigen::VectorXd model_frequency_grid(const AnyModel& model, double w_max = 0.0, int n = 300);

/// Time horizon (s) of step and impulse plots: 8 times the slowest stable time constant of the models plus their
/// largest delay; `fallback` when none has a stable pole.
double response_horizon(const std::vector<TransferFunction>& models, double fallback);
/// The same from a set of poles (no delay): 8 / (the smallest -Re p over the stable poles), else `fallback`.
double poles_response_horizon(const Eigen::VectorXcd& poles, double fallback);

/// Pointwise band of |G(jw)|: lower and upper are empty when it cannot be computed.
struct MagnitudeBand {
  Eigen::VectorXd lower, upper;
  bool empty() const { return lower.size() == 0; }
};

/// The central `level` band of |G(jw)| at w over `draws` transfer functions whose estimated coefficients are drawn
/// from N(values, covariance) of r (fixed parameters and non-coefficients held; a seeded generator, so the band is
/// reproducible). Empty when r has no finite covariance of its parameters' size or none of its parameters is a
/// coefficient of its model (e.g. physical parameters). Throws InvalidArgument for level outside (0, 1) or draws < 10.
MagnitudeBand magnitude_band(const Result<TransferFunction>& r, const Eigen::VectorXd& w, double level = 0.95,
                             int draws = 200, unsigned seed = 1);
/// `draws` transfer functions whose estimated coefficients are drawn from N(values, covariance) of r (fixed parameters
/// and non-coefficients held; a seeded generator, so the draws are reproducible): the models behind the bands below and
/// the report's pole-zero cloud. Empty when r has no finite covariance of its parameters' size or none of its
/// parameters is a coefficient of its model. Throws InvalidArgument for draws < 10.
std::vector<TransferFunction> drawn_models(const Result<TransferFunction>& r, int draws = 200, unsigned seed = 1);
/// The same band for any real response of the model — `response(g)`, one value per point (e.g. the step response at
/// given times, or the unwrapped phase): pointwise central `level` band over the drawn transfer functions.
MagnitudeBand response_band(const Result<TransferFunction>& r,
                            const std::function<Eigen::VectorXd(const TransferFunction&)>& response, double level = 0.95,
                            int draws = 200, unsigned seed = 1);

// State-space results (ssest): what a parameter is, and the uncertainty of poles and frequency responses.

/// The change of (A, B, C, D) per unit change of one parameter of a state-space result.
struct StateSpaceDirection {
  Eigen::MatrixXd dA, dB, dC, dD;
  Eigen::MatrixXd dK;  ///< nx x ny for a model with an innovation gain, else nx x 0
};
/// One direction per parameter of p, read from its name: A<i>_<j>, B<i>_<j>, C<i>_<j>, D<i>_<j>, K<i>_<j> (that entry, 1-based),
/// pole<a> (A(a,a)), sigma<a> (A(a,a) and A(a+1,a+1)), omega<a> (A(a,a+1) and, negated, A(a+1,a)) — the names of
/// ssest's and subspace's parameters. Throws InvalidArgument for another name or an index outside m.
std::vector<StateSpaceDirection> state_space_directions(const StateSpace& m, const ParameterSet& p);

/// Standard deviations of each mode's natural frequency (rad/s) and damping ratio, in the order of
/// r.model.modes(), from the parameter covariance by first-order propagation (the derivative of a simple eigenvalue:
/// d lambda_i = (V^-1 dA V)_ii). NaN where there is no finite covariance.
struct ModeUncertainty {
  double wn_std = 0.0, zeta_std = 0.0;
};
std::vector<ModeUncertainty> mode_uncertainty(const Result<StateSpace>& r);

/// Standard deviations of |G(jw)| and arg G(jw) (rad) from input `in` to output `out` at each w (rad/s), by
/// first-order propagation of the parameter covariance (dG = dC R B + C R dA R B + C R dB + dD, R = (jwI - A)^-1).
/// NaN where there is no finite covariance. Throws InvalidArgument for out/in outside the model.
struct ResponseStd {
  Eigen::VectorXd magnitude, phase;
};
ResponseStd frequency_response_std(const Result<StateSpace>& r, const Eigen::VectorXd& w, int out = 0, int in = 0);

}  // namespace ctid
