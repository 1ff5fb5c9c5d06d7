// ctid internal — helpers shared by the transfer-function estimators (SRIVC, OE, order
// selection): parameter vectors [a1..an, b0..b(nb-1)] <-> TransferFunction, output error.
#pragma once

#include <Eigen/Dense>
#include <utility>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/orders.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/validate/uncertainty.hpp"
#include "data/record_refs.hpp"

namespace ctid::tf_detail {

TransferFunction make_tf(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double delay);
/// [a1..an, b0..b(nb-1)] of g for the given orders (missing coefficients are zero).
Eigen::VectorXd params_of(const TransferFunction& g, const TfOrders& o);
TransferFunction tf_of(const Eigen::VectorXd& p, const TfOrders& o, double delay);
/// Mean squared output error of g simulated on d (+Inf if the simulation diverges).
double output_error_mse(const TransferFunction& g, const IdData& d);
/// The first sample at or after `transient` seconds from the record's start (the rows a transient_time leaves out).
Eigen::Index first_after(const IdData& d, double transient);
/// The measured and simulated (from rest) outputs of every record after its first `transient` seconds, each
/// concatenated in record order (several experiments of one system).
std::pair<Eigen::VectorXd, Eigen::VectorXd> pooled_outputs(const TransferFunction& g, const internal::RecordRefs& ds,
                                                           double transient);
/// Mirror unstable poles into the left half plane (prefilters and auxiliary models must be stable).
TransferFunction stabilized(const TransferFunction& tf);

/// "p1, p2, ..." (6 significant digits, complex poles as re+imj).
std::string poles_text(const TransferFunction& g);
/// The Nyquist frequency of d in rad/s (pi over the mean sample interval).
double nyquist(const IdData& d);
/// Whether a pole of g is faster than 10 times the data's Nyquist frequency (the data cannot resolve it: a lower
/// order describes them as well) — a structure that ranks after the usable ones in select_order and srivc_auto.
bool pole_beyond_bandwidth(const TransferFunction& g, const IdData& d);
/// A warning for each pole of r.model faster than 10 times the data's Nyquist frequency: the data cannot
/// resolve it (a lower order likely describes them as well). Returns whether there was one.
bool warn_poles_beyond_bandwidth(Result<TransferFunction>& r, const IdData& d);
/// The fit of a model to frequency-response data on the complex response: 100 (1 - ||G - Gm|| / ||G - mean G||).
FitReport frequency_fit(const TransferFunction& g, const Eigen::VectorXd& w, const Eigen::VectorXcd& G, int n_parameters);

/// A rough model of d for the automatic settings of other methods (the FSF window, modal shifts), fitted to the
/// record with its means removed: SRIVC of order nf (nb = nf; nf = 0: srivc_auto without the delay search) when
/// that fit is usable and stable; otherwise LSSVF with the automatic tau (equation error: it also serves unstable
/// plants and closed-loop records) of order nf, or for nf = 0 the least BIC over nf = 1..3 among the usable stable
/// fits (nf = 2 when there is none). equation_error: LSSVF only, of order nf or 2 (a plant known to be unstable:
/// its records come from a closed loop, where SRIVC would describe the loop, and a simulation criterion cannot
/// rank unstable fits). Throws InvalidArgument when no fit is possible
/// (constant input, too short a record).
Result<TransferFunction> pre_estimate(const IdData& d, int nf = 0, bool equation_error = false);

/// Time and amplitude normalisation of a SISO transfer-function estimation (results must not depend
/// on the units of time, input and output). With t' = t / c, u' = u / su, y' = y / sy, the model
/// G(s) = B(s)/A(s) (A monic of degree n, B with nb coefficients b_j of s^(nb-1-j)) becomes
/// G'(s') = (su/sy) G(s'/c): a_k' = a_k c^k, b_j' = b_j c^(n-nb+1+j) su/sy, delay' = delay / c.
/// c = 1/w_c with w_c = rms(dy/dt) / rms(y - mean y) (a characteristic frequency of the output, so the
/// normalised coefficients are of order one); su, sy are the RMS values of u and y.
struct TfNormalisation {
  double c = 1.0, su = 1.0, sy = 1.0;
  /// Of one record, or pooled over several records of one system (one set of units for all).
  static TfNormalisation of(const internal::RecordRefs& ds);
  /// The normalised record (times / c, u / su, y / sy; names and intersample kept).
  IdData data(const IdData& d) const;
  /// The same with input i divided by input_scales(i) instead of su (MISO: each input by its own RMS).
  IdData data(const IdData& d, const Eigen::RowVectorXd& input_scales) const;
  /// normalised value = original value * factor(name) for a parameter a<k>, b<j> or "delay" (1 otherwise).
  double factor(const std::string& name, const TfOrders& o) const;
  TransferFunction to_normalised(const TransferFunction& g, const TfOrders& o) const;
  /// The inverse of to_normalised: a model of the normalised problem in the user's units.
  TransferFunction from_normalised(const TransferFunction& g, const TfOrders& o) const;
  /// Maps a result of the normalised problem back to the user's units: model, parameters, covariance, fit
  /// measures, delay and noise diagnostics.
  void restore(Result<TransferFunction>& r, const TfOrders& o) const;
  /// The parts of restore() that do not depend on the model type: parameter values, standard deviations and
  /// covariance divided by the factors f (normalised = original * f), fit measures and the diagnostics
  /// "delay", "noise_variance", "delay_grid", "delay_grid_mse"; sets the diagnostic "time_scale" = c.
  void restore_common(ParameterSet& p, const Eigen::VectorXd& f, FitReport& fit, Diagnostics& dg) const;
};
/// The checks every SISO transfer-function result gets in the user's units: pole-zero cancellation,
/// poles beyond the data's bandwidth, and a warning for a model that is not asymptotically stable.
void finish_tf_result(Result<TransferFunction>& r, const IdData& d);

/// Near-unidentifiability check of a successful transfer-function estimate with parameters named a1..an,
/// b0..b(nb-1) and a covariance: a pole p and a zero z whose difference is within the 99 % confidence region
/// of its own uncertainty (linearised: dp/da_k = -p^{n-k}/A'(p), dz/db_j = -z^{m-j}/B'(z)) cancel, i.e. the
/// order is higher than the data support. Then the termination becomes Unidentifiable with a message naming
/// the pair. Results of other parameterisations are left alone.
template <class R>
void check_cancellation(R& r);

}  // namespace ctid::tf_detail
