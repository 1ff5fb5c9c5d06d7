// ctid — simplified refined instrumental variable method for continuous-time models (SRIVC).
//
// Young, P.C. & Jakeman, A.J. (1980), "Refined instrumental variable methods of recursive
// time-series analysis, Part III: extensions", Int. J. Control 31(4); Garnier, H. & Wang, L.
// (eds) (2008), "Identification of Continuous-time Models from Sampled Data", Springer,
// ch. 4 (SRIVC algorithm, eqs 4.40-4.50 there). Model y = e^{-sT} B(s)/A(s) u + e, e white.
//
// Iteration j: prefilter every signal with 1/A_j(s); regress s^n y_f on
// [-s^{n-1} y_f .. -y_f, s^m u_f .. u_f] with instruments built from the auxiliary-model
// output x = B_j/A_j u filtered the same way; A_{j+1}, B_{j+1} from the IV equations.
// Filtering is exact for ZOH/FOH inputs at any (also irregular) sample times; the output
// is interpolated linearly, and since (A/A_j) y_FOH = y_FOH at A_j = A the true parameters
// are an exact fixed point for noise-free data. Covariance: sigma^2 (sum zeta zeta^T)^{-1}
// with sigma^2 the output-error variance (the optimal-IV / CRLB form for white noise).
#pragma once

#include <optional>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/orders.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/model/miso.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

struct SrivcOptions {
  int max_iterations = 50;       ///< IV iterations (>= 1)
  double tolerance = 1e-7;       ///< stop when max_i |theta_i change| / max(|theta_i|, 1e-8) is below
  /// Starting model (its order must match); empty: LSSVF with an automatic filter.
  std::optional<TransferFunction> initial;
  /// Input delay in seconds added to nk * Ts (>= 0); the estimate uses delay + nk Ts.
  double delay = 0.0;
  /// Estimate a (non-integer) input delay: a grid search over [delay_min, delay_max], then
  /// alternate SRIVC with a one-dimensional refinement of the output-error cost.
  bool estimate_delay = false;
  double delay_min = 0.0;        ///< s, >= 0
  double delay_max = -1.0;       ///< s; < 0: 10 % of the record
  int delay_grid = 0;            ///< grid points in [0, kMaxDelayGrid]; 0: one per sample period (at most 200)
  static constexpr int kMaxDelayGrid = 10000;
  /// Seconds at the start of each record left out of the IV equations and of the fit: a record that does not
  /// start at rest (or several experiments, each with its own initial state) has a transient the filters, started
  /// at rest, do not model.
  double transient_time = 0.0;
  void validate() const;
};
/// The settings of SrivcOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<SrivcOptions>& option_table<SrivcOptions>();

/// SISO SRIVC. orders.nb may be nf + 1 (biproper). Throws InvalidArgument for data that
/// are not SISO or too short, InvalidOptions for bad options. Like srivc_miso and
/// srivc_closed_loop it estimates in normalised time and amplitude units and maps the result
/// back, so the estimate does not depend on the units of the record (docs/guide.md).
Result<TransferFunction> srivc(const IdData& data, const TfOrders& orders, const SrivcOptions& options = {});

/// SRIVC on several experiments of one system: one parameter set; each record is filtered and
/// simulated from rest (its own initial conditions and transient), and the instrumental-variable normal equations
/// are summed over the records (Young's SRIVC with the sums of (Garnier & Wang 2008, ch. 4) taken over
/// experiments). The records may differ in length, input and sampling (nk needs one sampling period); units must
/// agree. fit: the simulation fit over all records; covariance sigma^2 (sum zeta zeta^T)^{-1} with sigma^2 from
/// the pooled output error; diagnostics.scalars "experiments". Warnings about the poles use the first record's
/// bandwidth. Throws as srivc, naming the record.
Result<TransferFunction> srivc(const std::vector<IdData>& data, const TfOrders& orders, const SrivcOptions& options = {});

struct SrivcMisoOptions {
  int max_iterations = 100;   ///< sweeps over all channels (>= 1)
  double tolerance = 1e-7;    ///< as SrivcOptions::tolerance, on all parameters
  /// true: y = (sum_i B_i u_i)/A with one A (all nf equal); false: y = sum_i B_i/A_i u_i,
  /// estimated by backfitting (Garnier, Gilson, Young & Huselstein 2007, IFAC SYSID).
  bool common_denominator = false;
  /// Per-input delays in seconds added to nk Ts (empty: zero); each >= 0.
  std::vector<double> delays;
  void validate() const;
};
/// The settings of SrivcMisoOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<SrivcMisoOptions>& option_table<SrivcMisoOptions>();

struct ClosedLoopOptions {
  /// The known controller C(s) (proper, no delay).
  TransferFunction controller;
  /// true: u = r - C y (reference added at the plant input); false: u = C (r - y) (setpoint).
  bool reference_at_plant_input = true;
  Intersample reference_intersample = Intersample::Zoh;
  int max_iterations = 50;
  double tolerance = 1e-7;
  /// Seconds at the start of each record left out of the IV equations and of the fit: a loop that is not at rest
  /// when the record starts (e.g. the second piece of a long run) has a transient the instruments, built from the
  /// reference through the loop at rest, do not model.
  double transient_time = 0.0;
  void validate() const;
};
/// The settings of ClosedLoopOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<ClosedLoopOptions>& option_table<ClosedLoopOptions>();

/// Closed-loop SRIVC (CLSRIVC; Gilson, Garnier, Young & Van den Hof 2008, "Instrumental
/// variable methods for closed-loop continuous-time model identification", in Garnier & Wang
/// (eds) 2008, ch. 5): the plant G = B/A is estimated from the measured plant input u and
/// output y with instruments built from the reference r through the noise-free closed loop
/// with the known controller, which keeps the estimate consistent although u is correlated
/// with the noise. Strictly proper plant, no delay.
Result<TransferFunction> srivc_closed_loop(const IdData& data, const Eigen::VectorXd& reference, const TfOrders& orders,
                                           const ClosedLoopOptions& options);
/// Closed-loop SRIVC on several experiments of one loop (the same controller; each record with its own reference,
/// references[e] with data[e].size() samples): one parameter set, the instrumental-variable sums of each step over
/// the records (each filtered from rest), the fit and the sandwich covariance pooled over the records.
/// Throws InvalidArgument when the counts or lengths differ, a record is not single-input single-output or holds
/// NaN/Inf.
Result<TransferFunction> srivc_closed_loop(const std::vector<IdData>& data, const std::vector<Eigen::VectorXd>& references,
                                           const TfOrders& orders, const ClosedLoopOptions& options);

/// MISO SRIVC, one TfOrders per input. Parameter names: common denominator
/// "a1".."a<n>", then "u<i>.b<j>"; separate denominators "u<i>.a<k>", "u<i>.b<j>".
/// Throws InvalidArgument / InvalidOptions when the orders do not match the inputs (count,
/// different nf with a common denominator) or the data are too short.
Result<MisoModel> srivc_miso(const IdData& data, const std::vector<TfOrders>& orders, const SrivcMisoOptions& options = {});
/// Several experiments of one multi-input system (the same inputs in each record): one parameter set, the IV
/// equations of each step summed over the records (each filtered from rest), the fit pooled over the records.
Result<MisoModel> srivc_miso(const std::vector<IdData>& data, const std::vector<TfOrders>& orders,
                             const SrivcMisoOptions& options = {});

}  // namespace ctid
