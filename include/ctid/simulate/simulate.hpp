// ctid — simulate any model (model/any_model.hpp) on a record with an explicit initial condition.
// The one simulation the CLI (simulate, validate, report), the HTML report and Python use.
//
// Linear models are simulated exactly (simulate/lsim.hpp) with the record's times and intersample
// behaviour; FSF models by their discrete convolution (uniform records at their Delta; only a model fitted
// without exponential window, shift 0, describes the system itself); NARX models at
// their sampling period (uniform records at it); NDE models by the adaptive integrator at the record's
// times.
//
// Initial conditions:
//  - Rest: zero state, zero input and output before the first sample (NARX: zero output history).
//  - Measured: the record's first outputs are the model's history (NARX: y(0..max_lag-1); NDE:
//    y(0) measured, its derivatives zero). Linear models have no output history: InvalidArgument.
//  - Estimated: the state that fits the record best. `x0` when given (e.g. the initial state an NDE
//    output-error fit estimated, its diagnostics "x0"); otherwise, for linear continuous-time models, the
//    least-squares initial state (the output is affine in it: y = y_rest + O x0); NARX models: the
//    measured history (their state is their past outputs); grey-box models: the state that best explains the
//    first initial_samples samples (greybox_initial_state); FSF and NDE models without `x0`: InvalidArgument.
//  Grey-box models: Rest is the zero state; Measured their declared initial state, the states marked "estimate"
//    that an output reads alone taken from its first sample.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/any_model.hpp"

namespace ctid {

enum class InitialCondition { Rest, Measured, Estimated };

/// "rest", "measured", "estimated".
const char* to_string(InitialCondition initial);
/// Inverse of to_string; throws InvalidArgument naming the valid names.
InitialCondition initial_condition_from_string(const std::string& name);

struct SimulateOptions {
  InitialCondition initial = InitialCondition::Rest;
  /// Initial state for Estimated (empty: estimate it where the model allows). Linear models: the state of
  /// their realisation (MISO: the channels' states stacked); NDE: [y, Dy, .., D^{L-1} y].
  Eigen::VectorXd x0;
  /// Estimated without x0, grey-box models: the initial state is estimated from the record's first
  /// initial_samples samples only (0: all) — the nonlinear-benchmark protocol for a test record.
  int initial_samples = 0;
};

/// A simulation: the outputs (N x ny) at the record's sample times, the initial state used (empty for
/// rest or where the model has none), and whether it stayed finite.
struct Simulation {
  Eigen::MatrixXd y;
  Eigen::VectorXd x0;
  /// "" when every output is finite; otherwise where it stopped being finite and why
  /// ("the simulated output is not finite from sample k (t = .. s): the model diverges on these
  /// inputs; unstable poles: ..." or the integrator's message).
  std::string problem;
  bool ok() const { return problem.empty(); }
};

/// The initial condition an estimator's own fit (Result::fit) was computed with: NARX models the measured
/// history (FROLS, NARMAX), a result whose diagnostics hold a fitted "x0" (NDE output error) estimated, every
/// other rest. Reports of a fit use it so that their plotted fit is the one the estimator reported.
InitialCondition fit_initial_condition(const AnyModel& model, const Diagnostics& diagnostics);

/// The initial condition for comparing a model with a record it was not fitted on (a held-out part of a record does
/// not start at rest): Estimated — the state that fits the record best, as MATLAB's compare — for linear and grey-box
/// models, Measured (the record's own history) for NARX and NDE models, Rest for FSF models (simulated from rest only).
InitialCondition validation_initial_condition(const AnyModel& model);

/// What a simulation of a fitted result is for. It decides the initial condition when none is asked for, and
/// whether the initial state the fit estimated (diagnostics x0, that of its first record) is used: the one rule of
/// `ctid fit --validate`, `ctid simulate`, `ctid validate`, `ctid report`, the HTML report and Python's simulate().
enum class SimulationPurpose {
  OwnFit,       ///< the record the result was fitted to: the fit's own initial condition (fit_initial_condition), its x0
  OtherRecord,  ///< a further record of the same joint fit: as the fit starts a record, without the first one's x0
  Validation,   ///< a held-out record: the state that fits it best (validation_initial_condition)
  FreeRun,      ///< a record the result is simulated on: rest; a grey-box model from its fit's initial state
};

/// The options of a simulation of `result` for `purpose`; `initial`, when given, wins over the purpose's default.
/// Estimated takes the fitted x0 (diagnostics x0) on the result's own record, and for a nonlinear model (NDE, grey
/// box) in a free run; otherwise the state is estimated on the record simulated (a linear model's by least squares,
/// a grey-box model's by greybox_initial_state), never taken from another record. initial_samples > 0 (grey-box
/// models, Estimated): the state from the record's first initial_samples samples instead of the fitted x0.
SimulateOptions simulate_options(const Result<AnyModel>& result, SimulationPurpose purpose,
                                 std::optional<InitialCondition> initial = std::nullopt, int initial_samples = 0);
/// The result's model simulated on `data` for `purpose`: simulate(result.model, data, simulate_options(...)).
Simulation simulate(const Result<AnyModel>& result, const IdData& data, SimulationPurpose purpose,
                    std::optional<InitialCondition> initial = std::nullopt, int initial_samples = 0);

/// Simulate `model` driven by the inputs of `data` (its outputs are read only for the Measured and
/// Estimated initial conditions). Throws InvalidArgument when the data do not match the model (input
/// count, sampling period, no outputs where the initial condition needs them, an x0 of the wrong size).
Simulation simulate(const AnyModel& model, const IdData& data, const SimulateOptions& options = {});

/// The initial state that best explains the first `samples` samples of `data` (0: all) from the model's
/// initial-state guess, estimating the states marked "estimate" (every state when none is marked), by Levenberg-Marquardt on
/// the sensitivities; also started with the unmeasured estimated states at 0 (together and one at a time), the lowest
/// cost wins. Used by simulate with InitialCondition::Estimated (the nonlinear-benchmark protocol: the test record's
/// first samples initialise the state, nothing else of it enters the model). Throws InvalidArgument for sizes.
Eigen::VectorXd greybox_initial_state(const GreyboxModel& model, const IdData& data, int samples = 0, double rtol = 1e-8);

/// Responses of any model, one column per input (MISO: the response to that input alone;
/// single-input models: one column). Times t in seconds, increasing, >= 0; frequencies w in rad/s.
///
/// Response from rest to the step `amplitude` * 1(t). Linear models: exact (transfer functions with their delay);
/// FSF: its own estimate (FsfModel::step_response). NARX and NDE models: the simulated response — for a
/// nonlinear model it depends on the amplitude; NARX needs t on its sampling grid from 0. Throws InvalidArgument
/// for a windowed FSF model (shift a > 0: G(s + a), not the system), a non-finite amplitude, or times the model
/// cannot be simulated at.
Eigen::MatrixXd model_step_response(const AnyModel& model, const Eigen::VectorXd& t, double amplitude = 1.0);
/// Impulse response g(t) of a linear model (a direct term, a Dirac, is left out). Throws InvalidArgument for
/// NARX/NDE models (no impulse response; see model_step_response) and windowed FSF models.
Eigen::MatrixXd model_impulse_response(const AnyModel& model, const Eigen::VectorXd& t);
/// Frequency response G(jw) of a linear model (with its delay). Throws InvalidArgument for NARX/NDE models (their
/// frequency-domain description is the GFRFs: estimate/nonlinear/gfrf.hpp) and windowed FSF models.
Eigen::MatrixXcd model_frequency_response(const AnyModel& model, const Eigen::VectorXd& w);

}  // namespace ctid
