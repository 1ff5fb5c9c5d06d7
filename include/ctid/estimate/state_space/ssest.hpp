// ctid — multi-input multi-output continuous-time state space by output error: `ssest` =
// the subspace start (estimate/state_space/subspace.hpp) refined by prediction-error minimisation for white output noise.
//
// Cost: V = 1/2 sum_records sum_k sum_j w_j (y_j(t_k) - yhat_j(t_k))^2, yhat the exact simulation of
// dx/dt = A x + B u, y = C x + D u from each record's initial state x0_e (ZOH/FOH inputs, any sample times), with
// w_j = 1/sigma_j^2 the inverse noise variance of output j, re-estimated from the residuals of the converged model
// and the search repeated once when one moved by more than 10 % — the Gaussian maximum-likelihood estimate for
// independent white output noise of unknown variances (Ljung 1999, "System Identification", §7.4 and §9.4:
// asymptotic covariance (J^T W J)^-1 for white noise; the sandwich with each output's AR model of the residuals when
// they are coloured, §9.3, diagnostics residual_ar_order and white_noise_std). With estimate_k, yhat is instead the one-step prediction of the innovation
// form dx/dt = A x + B u + K e, y = C x + D u + e (Ljung 1999, §4.3 eq. 4.84; predict() in simulate/lsim.hpp).
//
// Parametrisation: every entry of (A, B, C, D, x0_e) (the "full parametrisation" of McKelvey, Helmersson &
// Ribarits 2004, "Data driven local coordinates for multivariable linear systems and their application to system
// identification", Automatica 40(9), 1629-1635), searched in data-driven local coordinates: only in the directions
// orthogonal to the tangent space of the change-of-basis manifold {(T^-1 A T, T^-1 B, C T, D, T^-1 x0)} at the
// current model (their eq. 9-12), re-centred every 5 Levenberg-Marquardt iterations (the damping carried over);
// inputs and outputs scaled to unit variance, and the states whitened along the model's trajectory at each
// re-centring, so the search stays well conditioned. enforce_stability rejects steps that make a stable model
// unstable. Exact sensitivities: the derivative of
// the output in a direction (dA, dB, dC, dD, dx0) is the output of the linear system
//   [x; dx]' = [[A, 0], [dA, A]] [x; dx] + [B; dB] u,   dy = [dC, C] [x; dx] + dD u,   dx(0) = dx0,
// discretised exactly like the model itself (Van Loan's block exponential), so it is exact for ZOH/FOH inputs on
// any sample grid. The residuals stream through; only J^T W J and J^T W r are kept (memory O(N) for the data
// themselves, O(parameters^2) for the search).
//
// Structure: D = 0 (estimate_d false); k known integrators (poles held at 0: A's first k columns zero); entries of
// A, B, C, D held at values given by name in `fixed` (A, B, C entries only with a starting model, whose coordinates
// they refer to). Result: without held A/B/C entries the model is returned in real modal form — A block diagonal,
// a real pole p at state a ("pole<a>") or a pair sigma +- j omega as the block [[sigma, omega], [-omega, sigma]] at
// states a, a+1 ("sigma<a>", "omega<a>"), modes in order of increasing natural frequency, each mode's scale fixed
// by one entry of C (the largest of its column(s): 1, and 0 beside it for a pair) — a parametrisation in which
// every parameter is determined by the data, with its covariance. With held A/B/C entries the model is returned in
// the starting model's coordinates.
#pragma once

#include <optional>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/estimate/state_space/subspace.hpp"
#include "ctid/model/state_space.hpp"

namespace ctid {

struct SsestOptions {
  /// State dimension; 0 = the subspace start's choice (where its singular values drop most).
  int nx = 0;
  /// With nx_max > nx: every order nx..nx_max is fitted and the least BIC kept (diagnostics nx_grid, nx_grid_bic).
  int nx_max = 0;
  /// Levenberg-Marquardt iterations, summed over the rounds. Real records with unmodelled dynamics can need a few
  /// hundred (the industrial dryer at nx = 5: 328); reaching the limit makes the result not usable.
  int max_iterations = 500;
  /// A round of the search ends when a step lowers the cost 1/2 sum_j sum_k e_j^2/sigma_j^2 (the squared errors in noise
  /// standard deviations) by less than this: a move worth a small fraction of one standard deviation.
  double tolerance = 1e-3;
  bool estimate_d = true;       ///< false: D = 0 (a strictly proper model)
  /// The prediction-error variant: also estimate an innovation gain K (nx x ny) of the innovation form
  /// dx/dt = A x + B u + K e, y = C x + D u + e (e held between samples; predict() in simulate/lsim.hpp) and
  /// minimise the one-step prediction errors — coloured output noise whose model shares the plant's poles. The search
  /// starts from K = 0 (the output-error predictor). Time-domain records only.
  bool estimate_k = false;
  bool estimate_initial_state = true;  ///< false: each record starts at rest
  /// Keep a stable start stable: a step that moves a pole (other than a held integrator) to Re >= 0 is rejected. An
  /// unstable start is searched without it. false: an unstable plant (with start.stabilize false).
  bool enforce_stability = true;
  /// Frequency data with variances: weight each entry by its inverse variance (ML when measurement noise is the only
  /// error). false: each output's error variance is estimated from the residuals instead — when systematic errors
  /// dominate (chi2_per_dof >> 1, e.g. the nonlinear distortion of a single multisine realisation), the variances
  /// would put the weight on the bins where the noise is lowest rather than where the model is right.
  bool use_variance = true;
  /// Known pure integrators: k poles held at 0 (the first k states integrate; A's first k columns are zero).
  int integrators = 0;
  /// Entries held at a value by name: "D1_2" (row 1, column 2), and with a starting model "A1_1", "B2_1", "C1_3".
  FixedValues fixed;
  /// Multi-start (records, from the subspace start): the subspace start, then starts - 1 starts with each of its poles
  /// moved by a factor drawn (seeded) log-uniformly within a decade either way (a complex pair keeps its damping);
  /// each searched fully, the usable fit of least MSE kept (diagnostic starts_cost: each start's MSE).
  int starts = 1;
  int seed = 1;  ///< seed of the drawn starts
  /// The subspace start's settings (horizon, route, tau, stabilize: CLI/Python start_horizon ..); its nx, estimate_d and estimate_initial_state are ssest's.
  SubspaceOptions start;
  void validate() const;
};
/// The settings of SsestOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<SsestOptions>& option_table<SsestOptions>();

/// Output-error estimate of a continuous-time state-space model from one record (see the file comment).
/// Result: the model (modal form, or the starting model's coordinates when A/B/C entries are held); parameters
/// with covariance; fit over all outputs (each scaled by its standard deviation); diagnostics output_fit_percent,
/// output_noise_variance, x0, start_fit_percent, mode_wn_std and mode_zeta_std (aligned with model.modes()), cost,
/// singular_values (of the start). Throws InvalidArgument for data without inputs, non-finite values or too few
/// samples; InvalidOptions for bad options or a held entry that is not one of the model's. A search that cannot
/// leave its start, ends at the iteration limit or leaves a parameter undetermined is returned with usable() false
/// and the reason.
Result<StateSpace> ssest(const IdData& data, const SsestOptions& options = {});
/// Several records of one system: one (A, B, C, D), an initial state per record (diagnostics x0, x0_2, ..).
/// The start is the subspace estimate on the longest record.
Result<StateSpace> ssest(const std::vector<IdData>& data, const SsestOptions& options = {});
/// The same from a given starting model (its nx; options.nx must be 0 or equal): held A/B/C entries refer to it.
Result<StateSpace> ssest(const std::vector<IdData>& data, const StateSpace& initial, const SsestOptions& options = {});

/// Frequency-response data (an FRF matrix, e.g. frf_from_periodic) -> continuous-time state space: the
/// frequency-domain subspace start (subspace(FrequencyData)) refined by weighted least squares
/// V = 1/2 sum_k sum_ij 2 |G_ij(jw_k) - Ghat_ij(jw_k)|^2 / var_kij with the data's variances (ML for independent
/// circular complex errors), or with each output's error variance estimated from the residuals when the data carry
/// none; the same local coordinates, modal form and uncertainty as for records (estimate/state_space/ssest_frequency.cpp).
/// Options as above; estimate_initial_state does not apply; integrators and held A/B/C entries are refused (only
/// fixed.D<i>_<j>). Fit and output_fit_percent about 0 (100 (1 - ||G - Ghat|| / ||G||)); diagnostics as above plus
/// chi2_per_dof (the weighted residual sum of squares per degree of freedom: near 1 when the variances given
/// account for the errors; the covariance is multiplied by it when it exceeds 1, with a warning above 2) and
/// frequency_scale (the start's alpha).
Result<StateSpace> ssest(const FrequencyData& data, const SsestOptions& options = {});
/// The same from a given starting model (e.g. the model of a neighbouring excitation level).
Result<StateSpace> ssest(const FrequencyData& data, const StateSpace& initial, const SsestOptions& options = {});

/// The Cramér-Rao bound of ssest's parameters at `truth` for records with these inputs and sample times, each starting
/// at rest, under independent white output noise of the given variances (one per output): a Result in ssest's
/// parametrisation (the modal form of `truth`) whose covariance is (J^T W J)^-1 at the truth (W = the inverse
/// variances; the initial states, when estimate_initial_state, as nuisance parameters), with diagnostics mode_wn_std
/// and mode_zeta_std — the bound a Monte Carlo study compares ssest's spread with. The outputs of `data` are used for
/// the fits only. Throws InvalidArgument for mismatched sizes or non-positive variances.
Result<StateSpace> ssest_crlb(const StateSpace& truth, const std::vector<IdData>& data, const Eigen::VectorXd& noise_variance,
                              const SsestOptions& options = {});

}  // namespace ctid
