// ctid — multi-input multi-output continuous-time state space by subspace identification.
//
// Continuous-time route (the default): Johansson, Verhaegen & Chou (1999), "Stochastic theory of continuous-time
// state-space identification", IEEE Trans. Signal Processing 47(1), 41-51. With Johansson's operator
// lambda = 1/(1 + p tau) (the state-variable filters of RJ 1986 eqs 7-23, signal/svf.hpp) the system
// dx/dt = A x + B u, y = C x + D u becomes x = lambda (A_l x + B_l u) with A_l = I + tau A, B_l = tau B
// (JVC eqs 6-9): lambda plays the part of the delay of a discrete-time model, so the stacked relation
//   Y_f = O_r xi + H_r U_f,   O_r = [C; C A_l; ..; C A_l^{r-1}],   xi = lambda^{r-1} x,
// holds for the block rows lambda^{r-1-k} y, lambda^{r-1-k} u (k = 0..r-1) at every sample time, on any sample grid
// (the filters run exactly between samples for held or linear signals). The range of O_r is estimated by
// PI-MOESP (Verhaegen 1994, Automatica 30(1)): U_f projected out, the "past" inputs lambda^{r..2r-1} u as
// instruments (past outputs are not used: lambda-filtered noise is correlated across the block rows). C is the
// first block row, A_l follows from shift invariance, A = (A_l - I)/tau.
// Discrete-time route (the comparison): PO-MOESP on the samples (uniform grid only; past inputs and outputs as
// instruments), A = logm(A_d)/Ts (exact d2c of the dynamics, refused when A_d has an eigenvalue on the negative real
// axis or at 0: no real continuous-time A maps onto it).
// Both routes then estimate B, D and the initial state x0 by linear least squares in continuous time: with A, C
// fixed, y(t) = C e^{A t} x0 + sum_i C X_i(t) b_i + D u(t), X_i' = A X_i + I u_i (exact ZOH/FOH between samples),
// solved by the shared streaming least-squares kernel (blocked QR) as the record streams by.
//
// Memory is O(1) in the number of samples: the data enter only through Gram matrices of size
// (2 r nu + r ny)^2 (continuous) or 2 r (nu + ny) squared (discrete) and the QR factor of the (B, D, x0) regression.
#pragma once

#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/frequency_data.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/model/state_space.hpp"

namespace ctid {

/// Which subspace route estimates A and C.
enum class SubspaceRoute {
  Lambda,    ///< continuous time, Johansson's lambda operator (any sample times)
  Discrete,  ///< discrete-time PO-MOESP on the samples, then A = logm(A_d)/Ts (uniform sampling)
};

struct SubspaceOptions {
  /// State dimension; 0 = where the singular values drop most: the largest ratio s_n / s_(n+1), n = 1 .. 12 (as far
  /// as the horizon allows).
  int nx = 0;
  /// Block rows r of the extended observability matrix; 0 = nx + 2 (with nx = 0: 10). Needs (r - 1) ny >= nx.
  int horizon = 0;
  SubspaceRoute route = SubspaceRoute::Lambda;
  /// Time constant tau (s) of lambda = 1/(1 + p tau); 0 = the least BIC of the simulation error (stable models first) over 8
  /// values log-spaced from 2 Ts to duration/50 (Lambda route only).
  double tau = 0.0;
  bool estimate_d = true;               ///< false: D = 0 (a strictly proper model)
  bool estimate_initial_state = true;   ///< false: the record starts at rest (x0 = 0)
  /// Move each pole re + j im of A with re > 0 to -re + j im (same eigenvectors) before B, D and x0 are estimated:
  /// a spurious noise mode of noisy, finely sampled data becomes a fast stable mode instead of a response that
  /// overflows over the record. false: keep A as estimated (an unstable plant).
  bool stabilize = true;
  void validate() const;
};
/// The settings of SubspaceOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<SubspaceOptions>& option_table<SubspaceOptions>();

/// Subspace estimate of a continuous-time state-space model with any number of inputs and outputs.
/// Result: the model; parameters A (row-major "A11", "A12", ..), B, D (when estimated) with no covariance (a
/// subspace estimate has none of its own; output-error refinement gives one); fit over all outputs, each scaled by
/// its own standard deviation; diagnostics singular_values, output_fit_percent, x0, tau (Lambda route; tau_grid
/// and tau_grid_fit_percent when chosen automatically). Throws InvalidArgument for data without inputs, with too
/// few samples for the horizon, non-finite values, or the Discrete route on irregular samples; InvalidOptions for
/// bad options. A model whose A has no real logarithm (Discrete route) or whose fit is not above 0 is returned with
/// usable() false and the reason.
Result<StateSpace> subspace(const IdData& data, const SubspaceOptions& options = {});

/// Frequency-domain subspace estimate from an FRF matrix (McKelvey, Akçay & Ljung 1996, Algorithm 2, after the
/// bilinear map z = (alpha + s)/(alpha - s); estimate/state_space/ssest_frequency.cpp): A and C from the block rows z^i G(z_k)
/// (i < horizon; horizon 0 = max(2 nx, nx + 2), with nx = 0: 20), B and D by least squares on the data (weighted by
/// their variances when given). tau = 1/alpha (s); 0 = alpha the geometric mean of the lowest and highest data
/// frequency. route must be lambda; estimate_initial_state does not apply. Result as above, without x0; its fit
/// compares G and Ghat about 0 (100 (1 - ||G - Ghat|| / ||G||) per output); diagnostics singular_values,
/// output_fit_percent, frequency_scale (alpha, rad/s). Throws InvalidArgument for too few frequencies for the
/// horizon.
Result<StateSpace> subspace(const FrequencyData& data, const SubspaceOptions& options = {});

/// B, D and the initial state of a model with given A and C (the least-squares step above), on one record.
/// Returns the model and writes x0 (nx values) when x0 != nullptr.
StateSpace subspace_bd(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C, const IdData& data, bool estimate_d,
                       bool estimate_initial_state, Eigen::VectorXd* x0 = nullptr);

}  // namespace ctid
