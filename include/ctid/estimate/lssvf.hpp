// ctid — Johansson's state-variable-filter least squares (LSSVF) and its instrumental-
// variable variant (IVSVF) for continuous-time transfer functions.
//
// Johansson, R. (1986), "Identification of continuous time dynamic systems", Lund
// TFRT-7318: transformed regression y = theta_tau^T phi_tau (RJ 11-17), exact transform
// (RJ 18-23), direct estimation of the physical coefficients with known ones fixed
// (RJ 24-25), LS criterion with Riemann or trapezoidal weights (RJ 44, 59-61),
// exponential weighting e^{2 alpha t} (RJ 52-55), B(-1/tau) != 0 identifiability
// condition (RJ 26-41). SEEDS-SPEC Part RJ.
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

/// Several experiments of one system (issue 14, item 2): the normal equations (LSSVF) or IV equations (IVSVF)
/// summed over the records, each filtered from rest (transient_time leaves out the start of each); tau chosen on
/// the pooled simulation fit; fit over all records; diagnostics.scalars "experiments". Throws as the one-record
/// functions, naming the record.
Result<TransferFunction> lssvf(const std::vector<IdData>& data, const TfOrders& orders, const LssvfOptions& options = {});
Result<TransferFunction> ivsvf(const std::vector<IdData>& data, const TfOrders& orders, const IvsvfOptions& options = {});

/// Parameter names for the given orders: a1..a<nf>, b0..b<nb-1>.
std::vector<std::string> tf_parameter_names(const TfOrders& orders);

}  // namespace ctid
