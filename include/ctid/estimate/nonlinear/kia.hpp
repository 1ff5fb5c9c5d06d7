// ctid — the Kernel Invariance Algorithm of Billings & Li (1999): continuous-time NDE coefficients from
// the GFRFs of an identified NARX model, order by order, by linear least squares on kernel values at
// chosen s-points, with generalised least squares (GLS) whitening and ERR term selection.
//   linear stage     BL 15-25 (BL 15-25): H_1(s) A(s) = B(s), A(s) = 1 + sum alpha_l s^l
//   quadratic stage  BL 26-27 (BL-D5): 2 A(s_1+s_2) H_2(s_1,s_2) = - sum gamma (probing expression)
//   ERR selection    BL 28-32 (BL-D6): forward orthogonal selection on the stacked real system; the
//                    over-parameterise -> converge -> prune -> re-estimate workflow; ERR-chosen filter order.
// Kernel invariance: H_n^{NDE}(s_1..s_n) = H_n^{NARX}(e^{s_1 T}..e^{s_n T}), divided by prod Z(s_i) for data
// sampled with a held input (narx_gfrf_ct). Points on the real and imaginary axes (the reading of the
// paper that reproduces its tables; Billings & Li 1999, eqs 33-34 and Tables 1-3).
#pragma once

#include <complex>
#include <limits>
#include <optional>
#include <vector>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/nonlinear/nde_oe.hpp"
#include "ctid/model/narx.hpp"
#include "ctid/model/nde.hpp"
#include "ctid/estimate/options.hpp"

namespace ctid {

enum class KiaRegion {
  Axes,           ///< half of the points on the positive real axis, half on the positive imaginary axis
  RealAxis,
  ImaginaryAxis,
  Complex         ///< s = t_1 + j t_2 with t_1, t_2 in (0, max]
};

struct KiaPointOptions {
  KiaRegion region = KiaRegion::Axes;
  int count = 500;        ///< points (linear stage) or point pairs (quadratic stage)
  double max = 0.0;       ///< rad/s, at most the Nyquist frequency pi/T of the NARX model; 0: automatic, the
                          ///< paper's range in units of its sampling rate (500 and 220 rad/s at T = 2.5 ms):
                          ///< 1.25/T for the linear stage, 0.55/T for the quadratic and cubic stages
  bool grid = false;      ///< evenly spaced instead of uniformly random
  unsigned seed = 1;
};
template <>
const OptionTable<KiaPointOptions>& option_table<KiaPointOptions>();

/// The s-points of a region; for pairs call twice with different seeds (as kia_quadratic does).
/// Throws InvalidArgument for count < 1 or max <= 0 (the estimators resolve max = 0 from T first).
std::vector<std::complex<double>> kia_points(const KiaPointOptions& options);

struct KiaLinearOptions {
  int y_order = 2;             ///< candidates D^1 y .. D^{y_order} y (y itself has coefficient 1)
  int u_order = 0;             ///< candidates u .. D^{u_order} u
  KiaPointOptions points;      ///< default: 500 points on both axes in (0, 1.25/T] rad/s (the paper's 500 rad/s)
  int gls_order = 10;          ///< filter order G; 0: plain least squares; -1: the smallest G <= 12 whose
                               ///< converged fit explains >= 99.99 % (sum of ERR; the paper: order 10, 99.992 %)
  int max_iterations = 100;
  double tolerance = 1e-8;     ///< relative change of the coefficients between GLS iterations
  double err_threshold = 0.0;  ///< % : > 0 prunes terms with a smaller ERR after convergence, then re-estimates
  bool zoh = true;             ///< divide the NARX kernel by the hold factor Z(s) (data sampled with a held input)
  /// ERR denominator: false (default) sum z^2 over the stacked real system, so the ERRs of a complete model sum to
  /// 100 % (the gls_order = -1 rule relies on that); true: the paper's centred sum z^2 - (sum z)^2 / N (BL 32),
  /// every ERR scaled by the same factor (the ranking is the same; the sum can pass 100 %). Used for pruning and
  /// reported in "err" / "err_sum"; the automatic GLS order always uses the uncentred sum.
  bool err_centred = false;
  void validate() const;
};
template <>
const OptionTable<KiaLinearOptions>& option_table<KiaLinearOptions>();

/// Linear stage: returns the linear NDE y + sum alpha_l D^l y - sum beta_l D^l u = 0 (normalised).
/// parameters: the implicit-form coefficients of the retained candidate terms (names "Dy", "D^2y", "u", ...);
/// diagnostics.vectors "err" (ERR % of each parameter at convergence, forward selection), "first_iteration"
/// (plain least squares); scalars "gls_iterations", "gls_order", "err_sum". Throws InvalidArgument for a
/// NARX model without linear input terms or a point range beyond the Nyquist frequency.
Result<NdeModel> kia_linear(const NarxModel& narx, const KiaLinearOptions& options = {});

struct KiaQuadraticOptions {
  std::vector<NdeTerm> candidates;  ///< degree-2 terms, e.g. y^2, y*Dy, Dy^2, y*u
  KiaPointOptions points{.count = 70};  ///< point pairs in (0, 0.55/T] (the paper: 35 real + 35 imaginary in (0, 220))
  int gls_order = 3;                ///< filter F(s_1 + s_2) order; 0: plain least squares
  int max_iterations = 100;
  double tolerance = 1e-8;
  double err_threshold = 0.0;       ///< % : prune below it after convergence, then re-estimate
  bool zoh = true;
  bool err_centred = false;         ///< as KiaLinearOptions::err_centred
  void validate() const;
};
template <>
const OptionTable<KiaQuadraticOptions>& option_table<KiaQuadraticOptions>();

/// Quadratic stage with the linear part fixed: returns linear + retained quadratic terms (normalised), with
/// parameters, "err" and "first_iteration" for the quadratic coefficients. Throws InvalidArgument for
/// candidates that are not of degree 2, an empty candidate list or a point range beyond the Nyquist frequency.
Result<NdeModel> kia_quadratic(const NarxModel& narx, const NdeModel& linear, const KiaQuadraticOptions& options);

struct KiaCubicOptions {
  std::vector<NdeTerm> candidates;  ///< degree-3 terms, e.g. y^3, y^2*Dy
  KiaPointOptions points{.count = 70};  ///< point triples (s_1, s_2, s_3), each from its own seed; range as quadratic
  int gls_order = 3;                ///< filter F(s_1 + s_2 + s_3) order; 0: plain least squares
  int max_iterations = 100;
  double tolerance = 1e-8;
  double err_threshold = 0.0;
  bool zoh = true;
  bool err_centred = false;  ///< as KiaLinearOptions::err_centred
  void validate() const;
};
template <>
const OptionTable<KiaCubicOptions>& option_table<KiaCubicOptions>();

/// Cubic stage (BL-D5 "higher orders proceed likewise"): with the linear and quadratic terms of `model`
/// fixed, 6 A(s_1+s_2+s_3) H_3 + Q = sum_cubic gamma C is linear in the cubic coefficients gamma (Q: the
/// quadratic terms' contribution through H_1 and H_2, C: minus the six orderings of first-order products;
/// NdeModel::h3). Returns model + the retained cubic terms (normalised).
Result<NdeModel> kia_cubic(const NarxModel& narx, const NdeModel& model, const KiaCubicOptions& options);

/// The default candidates of a stage: every product of `degree` factors (unordered, repetition allowed) of y,
/// D y .. D^{y_order - 1} y, u .. D^{u_order} u, in the order y-factors first, lower derivatives first.
std::vector<NdeTerm> kia_product_candidates(int degree, int y_order, int u_order);

/// The whole workflow from a record and the NARX model identified from it (what `ctid fit --method kia` and
/// Python's ctid.kia run): the linear stage, the quadratic and cubic stages when they have candidates, stacked
/// into one equation; its simulation on the record; the check that it reproduces its NARX model; and the
/// output-error refinement (nde_oe, consistent under output noise), which replaces the equation when usable.
struct KiaOptions {
  KiaLinearOptions linear;
  /// Candidates left empty: when the NARX model has terms of degree 2 (3), all products of two (three) of y,
  /// D y .. D^{y_order - 1} y, u .. D^{u_order} u (linear stage's orders; the highest derivative of y appears once,
  /// linearly, so that the equation can be solved for it), pruned after convergence at err_threshold, or
  /// at 0.01 % when that is 0 (Billings & Li's over-parameterise -> converge -> prune -> re-estimate; their example's
  /// threshold). No stage when the NARX model has no terms of that degree.
  KiaQuadraticOptions quadratic;
  KiaCubicOptions cubic;          ///< as quadratic, for degree 3
  bool refine = true;             ///< refine the reconstructed equation by output error on the record
  NdeOeOptions refinement;
  void validate() const;
};
template <>
const OptionTable<KiaOptions>& option_table<KiaOptions>();

struct KiaRun {
  /// The reconstructed equation: every stage's coefficients (no standard deviations), diagnostics.vectors "err"
  /// (ERR % of each), fit = its simulated output on the record. Not usable when the simulation fails, or when its
  /// fit is below half of the NARX model's free-run fit on the same record: then it does not reproduce its NARX
  /// model (candidate terms that cannot express the kernels, or sampling too slow for kernel invariance).
  Result<NdeModel> reconstructed;
  /// The NARX model's free-run fit (%) on the record after its first max_lag samples; -Inf when it escapes.
  double narx_fit_percent = -std::numeric_limits<double>::infinity();
  std::optional<Result<NdeModel>> refined;  ///< the output-error refinement (options.refine), usable or not
  /// The answer: the refinement when it is usable, the reconstructed equation otherwise.
  const Result<NdeModel>& result() const { return refined && refined->usable() ? *refined : reconstructed; }
};

/// Throws InvalidArgument for a record that is not SISO, a NARX model identified at another sampling period,
/// and the stages' errors (kia_linear, kia_quadratic, kia_cubic).
KiaRun kia(const IdData& data, const NarxModel& narx, const KiaOptions& options = {});
/// Several records (experiments of one system; the NARX model identified from all of them, e.g. narx(records)):
/// the equation's fit and the NARX model's free-run fit are pooled over the records, and the refinement fits one
/// equation to all of them, each record with its own initial state (nde_oe on the records; diagnostics
/// "experiments"). Throws as the one-record form, naming the record.
KiaRun kia(const std::vector<IdData>& data, const NarxModel& narx, const KiaOptions& options = {});

}  // namespace ctid
