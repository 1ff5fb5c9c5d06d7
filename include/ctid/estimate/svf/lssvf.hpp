// ctid — Johansson's state-variable-filter least squares (LSSVF) and its instrumental-
// variable variant (IVSVF) for continuous-time transfer functions.
//
// Johansson, R. (1986), "Identification of continuous time dynamic systems", Lund
// TFRT-7318: transformed regression y = theta_tau^T phi_tau (RJ 11-17), exact transform
// (RJ 18-23), direct estimation of the physical coefficients with known ones fixed
// (RJ 24-25), LS criterion with Riemann or trapezoidal weights (RJ 44, 59-61),
// exponential weighting e^{2 alpha t} (RJ 52-55), B(-1/tau) != 0 identifiability
// condition (RJ 26-41); the frequency-domain criterion (RJ 45) on frequency-response data and
// the information matrix of an input spectrum (RJ 47-50).
//
// Model: G(s) = e^{-s nk Ts} (b_0 s^{nb-1} + .. + b_{nb-1}) / (s^nf + a_1 s^{nf-1} + .. + a_nf).
// Parameter names: "a1".."a<nf>", "b0".."b<nb-1>" (b0 multiplies the highest power).
// The estimates are consistent for noise-free data; with output noise LSSVF is biased
// (equation error) — IVSVF removes most of it with auxiliary-model instruments.
// Standard deviations assume white equation error; they are indicative for LSSVF.
#pragma once

#include <map>
#include <optional>
#include <string>

#include "ctid/core/types.hpp"
#include "ctid/data/frequency_data.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/orders.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// How samples are weighted in the LS criterion J = int e^2 dt (RJ 44, 59-61).
enum class SvfWeights {
  Riemann,      ///< weight h_k (the interval before sample k)
  Trapezoidal,  ///< weight (h_k + h_{k+1})/2, half weights at both ends
};

struct LssvfOptions {
  /// Filter time constant tau (s) of z = 1/(1 + p tau); 0 = choose automatically by
  /// the best simulation fit over a log-spaced grid from 2 Ts to duration/20.
  double tau = 0.0;
  SvfWeights weights = SvfWeights::Riemann;
  /// Exponential weighting rate alpha >= 0 (1/s): criterion weight e^{2 alpha t}.
  double alpha = 0.0;
  /// Seconds at the start excluded from the criterion (filter/system transients).
  double transient_time = 0.0;
  /// Known coefficients held fixed, by parameter name (e.g. {"a2", 1.0}).
  FixedValues fixed;
  /// Optional extra data filter F(s) applied to both sides (stable, proper, no delay).
  std::optional<TransferFunction> data_filter;
  /// Number of tau candidates for the automatic choice, in [2, kMaxTauGrid].
  int tau_grid_size = 12;
  static constexpr int kMaxTauGrid = 1000;
  /// Throws InvalidOptions naming the field.
  void validate() const;
};
/// The settings of LssvfOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<LssvfOptions>& option_table<LssvfOptions>();

struct IvsvfOptions {
  LssvfOptions svf;            ///< filter, weights and fixed coefficients (as for LSSVF)
  int max_iterations = 20;     ///< instrument/estimate refinements after the LS start
  double tolerance = 1e-7;     ///< stop when the relative parameter change is below
  void validate() const;
};
/// The settings of IvsvfOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<IvsvfOptions>& option_table<IvsvfOptions>();

/// LSSVF on one input and one output. Throws InvalidArgument for data with other
/// channel counts, irregular data with nk > 0, or too few samples for the free
/// parameters; InvalidOptions for bad orders/options (incl. an unknown fixed name).
Result<TransferFunction> lssvf(const IdData& data, const TfOrders& orders, const LssvfOptions& options = {});

/// IVSVF: LSSVF start, then instruments from the auxiliary model B^/A^ driven by u,
/// iterated to convergence (Young's IV idea applied to Johansson's regression).
Result<TransferFunction> ivsvf(const IdData& data, const TfOrders& orders, const IvsvfOptions& options = {});

/// Several experiments of one system: the normal equations (LSSVF) or IV equations (IVSVF)
/// summed over the records, each filtered from rest (transient_time leaves out the start of each); tau chosen on
/// the pooled simulation fit; fit over all records; diagnostics.scalars "experiments". Throws as the one-record
/// functions, naming the record.
Result<TransferFunction> lssvf(const std::vector<IdData>& data, const TfOrders& orders, const LssvfOptions& options = {});
Result<TransferFunction> ivsvf(const std::vector<IdData>& data, const TfOrders& orders, const IvsvfOptions& options = {});

/// Frequency-domain LSSVF (RJ 45): theta fitted to frequency-response data G_k = G(i w_k) by least squares on the
/// filtered equation error G_k - theta^T Gamma~_k, Gamma~_k = [z G_k, .., z^n G_k, z, .., z^n], z = 1/(1 + i w_k tau)
/// (real and imaginary parts), in the physical coefficients with fixed ones as in the time domain. Each frequency
/// weighs 1 / variance of G_k when the data carry variances (e.g. frf_from_periodic), else 1 — the input spectrum of a
/// multisine of equal amplitudes, for which the criterion equals the time-domain one (RJ 44) over whole periods in
/// steady state (Parseval) — times |F(i w_k)|^2 with a data_filter F. tau = 0 chooses tau on a log grid from
/// 0.1 / w_max to 10 / w_min by the weighted fit of the model's response to the data. Standard deviations assume a
/// white equation error (indicative, as in the time domain). The fit is on the complex response (as
/// tf_from_frequency). Throws InvalidArgument for several channels or fewer real equations than free parameters;
/// InvalidOptions for nk > 0 or the time-domain settings alpha, transient_time and trapezoidal weights.
Result<TransferFunction> lssvf(const FrequencyData& data, const TfOrders& orders, const LssvfOptions& options = {});

/// The regressor's response to the input (RJ 49-50): phi_tau = Gamma_tau(s) U(s) with
/// Gamma_tau(i w) = [z G0, .., z^n G0, z, .., z^n], z = 1 / (1 + i w tau), n = g0's order (theta_tau coordinates,
/// nb = nf = n). A delay of g0 is included. Throws InvalidArgument for tau <= 0, w < 0 or a static g0.
Eigen::VectorXcd svf_gamma(const TransferFunction& g0, double tau, double w);

/// The information matrix of theta_tau per second of data (RJ 47, 50) for a stationary input of known line spectrum:
/// u = sum_k A_k cos(w_k t + phase_k) in steady state gives mean(phi_tau phi_tau^T) = sum_k power_k Re[Gamma(i w_k)
/// Gamma(i w_k)^H], power_k the line's mean square (A_k^2 / 2; a constant c at w = 0 has power c^2). A continuous
/// spectrum enters as lines on a fine grid (power_k = its one-sided density times the grid step). Experiment design:
/// theta_tau is identifiable from this input exactly when the matrix has full rank 2n (every sinusoid adds rank 2, a
/// constant rank 1); the weakest direction and the condition number say how well. For least squares with a white
/// equation error of intensity lambda (y^2 s), cov(theta_tau) is about lambda / T times the inverse over T seconds.
struct SvfInformation {
  Eigen::MatrixXd matrix;       ///< 2n x 2n, per second of data
  Eigen::VectorXd eigenvalues;  ///< ascending
  Eigen::MatrixXd directions;   ///< unit eigenvectors as columns, in the eigenvalues' order
  int rank = 0;                 ///< eigenvalues above 1e-10 times the largest
  double condition = 0.0;       ///< largest / smallest eigenvalue (infinite when rank < 2n)
  bool identifiable() const { return rank == matrix.rows(); }
};
/// Throws InvalidArgument for an unstable g0 (no stationary response), tau <= 0, w and power of different lengths or
/// empty, a negative or repeated frequency (w must increase), or a negative power.
SvfInformation svf_information(const TransferFunction& g0, double tau, const Eigen::VectorXd& w,
                               const Eigen::VectorXd& power);

/// Parameter names for the given orders: a1..a<nf>, b0..b<nb-1>.
std::vector<std::string> tf_parameter_names(const TfOrders& orders);

}  // namespace ctid
