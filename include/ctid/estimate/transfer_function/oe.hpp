// ctid — continuous-time output-error (prediction-error for white output noise) estimation
// of a transfer function, and `tfest` = SRIVC start + output-error refinement.
//
// Minimises sum_k (y(t_k) - yhat(t_k; theta))^2 with yhat the exact simulation of
// e^{-sT} B(s)/A(s) u from rest, by Levenberg-Marquardt with exact sensitivities
// (dy/da_i = -s^{n-i} B/A^2 u, dy/db_j = s^{nb-1-j}/A u, dy/dT = -s B/A u; see
// signal/prefilter.hpp), simple bounds and fixed parameters. Ljung (1999), System
// Identification, ch. 7 and 10 (the continuous-time OE form of MATLAB's tfest refinement).
// Covariance: the prediction-error sandwich S^+ Q S^+T that allows for coloured output noise (Ljung 1999 §9.3; Q from
// an AR model of the residuals, diagnostics residual_ar_order), sigma^2 (S^T S)^{-1} when they are white (S the
// sensitivity matrix of the free parameters; that figure stays in diagnostics white_noise_std). With estimate_initial_state
// each record's free response E_e(s)/A(s) is estimated with the model (the initial-condition polynomial of
// Ljung 1999 §4.3 / the "estimate initial condition" of MATLAB's tfest), its coefficients eliminated from the
// covariance by the Schur complement.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/orders.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/estimate/transfer_function/srivc.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

struct OeOptions {
  int max_iterations = 500;  ///< Levenberg-Marquardt iterations (a well-posed fit converges long before)
  double tolerance = 1e-12;      ///< relative cost decrease / parameter change that stops the search
  /// Starting model; empty: LSSVF with an automatic filter (oe) or SRIVC (tfest).
  std::optional<TransferFunction> initial;
  /// Parameters held at a value, by name ("a1", "b0", "delay").
  FixedValues fixed;
  /// Bounds by name: {lower, upper}; absent = unbounded (the delay is always >= 0).
  ParameterBounds bounds;
  bool estimate_delay = false;   ///< add the input delay T (s) as a parameter "delay"
  double delay = 0.0;            ///< initial / fixed delay (s), added to nk Ts
  SrivcOptions srivc;            ///< options of the SRIVC start (tfest); its delay search is used when estimate_delay
  /// Seconds at the start of each record left out of the output-error cost (and of the SRIVC start): a record
  /// simulated from rest that did not start at rest.
  double transient_time = 0.0;
  /// Estimate each record's initial condition instead of starting it from rest: its free response, the impulse
  /// response of E(s)/A(s) with nf free coefficients per record (exact sensitivities; the model's covariance is
  /// that with the initial conditions eliminated). diagnostics x0 (per record) holds the equivalent state of the
  /// model's realisation (TransferFunction::to_state_space), from which simulate and validate start. Excludes
  /// transient_time (the two are alternatives for a record that does not start at rest).
  bool estimate_initial_state = false;
  void validate() const;
};
/// The settings of OeOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<OeOptions>& option_table<OeOptions>();

/// Output-error estimate of a SISO transfer function. Throws InvalidArgument /
/// InvalidOptions for bad data or options (incl. unknown parameter names).
Result<TransferFunction> oe(const IdData& data, const TfOrders& orders, const OeOptions& options = {});
/// SRIVC (with delay search when estimate_delay) followed by output-error refinement.
Result<TransferFunction> tfest(const IdData& data, const TfOrders& orders, const OeOptions& options = {});

/// Several experiments of one system: one parameter set minimising the output error summed
/// over the records, each simulated from rest (after transient_time); sensitivities stacked; the records may
/// differ in length, input and sampling (nk needs one sampling period). tfest starts from the joint SRIVC
/// estimate. diagnostics.scalars "experiments". Throws as oe/tfest, naming the record.
Result<TransferFunction> oe(const std::vector<IdData>& data, const TfOrders& orders, const OeOptions& options = {});
Result<TransferFunction> tfest(const std::vector<IdData>& data, const TfOrders& orders, const OeOptions& options = {});

}  // namespace ctid
