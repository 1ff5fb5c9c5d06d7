// ctid — stage 1 of Gawthrop & Wang (2005): least-squares compression of sampled data into a
// frequency-sampling-filter model (GW eqs 6-8), with the exponential window a and residual
// weighting b for unstable plants (GW 1-21).
//
// Regressors phi_i = sum_{l<N} f_l u_{i-l} (zero input before the record) are computed by
// exact FIR summation from prefix/suffix partial sums of N-sample chunks (O(n) per sample) —
// never by the marginally stable recursive form. With a window
// a and weight b the rows are formed as in GW 14-21, never with e^{bt} and e^{-at}
// separately:  e^{b t_i} y_{a,i} = e^{(b-a) t_i} y_i,
//              e^{b t_i} phi_{a,i} = e^{(b-a) t_i} sum_{l<N} (f_l e^{a l Delta}) u_{i-l}.
// The fitted model is then that of the shifted system G(s + a).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/fsf.hpp"
#include "ctid/estimate/options.hpp"

namespace ctid {

struct FsfOptions {
  /// Window T (s): the settling time of the (shifted) system, rounded to a whole number N of sampling periods.
  /// 0: automatic — the time after which a pre-estimate's impulse response (of G(s + a)) stays below 1e-3 of its
  /// peak, at most half the record.
  double T = 0.0;
  /// Number of filters, odd, <= N. 0: automatic — the filter frequencies 2 pi k / T (k <= (n-1)/2) reach the
  /// frequency where the pre-estimate's |G(a + jw)| has fallen to 3 % of its largest value (n <= 101 and <= 1/10
  /// of the record's samples).
  int n = 0;
  /// Exponential window e^{-at} (1/s), >= 0; must exceed every unstable pole's real part. 0 for a plant declared
  /// unstable or a pre-estimate with a pole at Re >= 0: automatic, 1.5 times the largest such real part (at least
  /// 20 / record duration) — the smallest a with a margin for the pre-estimate's error (GW: "use the minimum
  /// appropriate a"; on the unstable-circuit stand-in a = 1.5 gives a 2 to 6 times smaller spread than a = 2).
  double a = 0.0;
  double b = 0.0;     ///< residual weighting e^{bt} (1/s), 0 <= b <= a; b > 0 is risky (see the method page)
  Eigen::VectorXd weights;  ///< optional per-sample residual weights (>= 0, length N_data); empty: 1
  bool unstable = false;    ///< the plant is declared unstable: a window a > 0 is used (chosen when a = 0)
  void validate() const;
};
/// The settings of FsfOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<FsfOptions>& option_table<FsfOptions>();

/// Fit an FSF model to one input and one output (uniform Ts). T, n and a left automatic (0) are chosen from a
/// pre-estimate (srivc_auto without delay; LSSVF, equation error, for a plant declared unstable: it serves
/// closed-loop records) as documented in FsfOptions; each choice, and a T rounded to whole sampling periods, is a line of diagnostics.choices. Throws
/// InvalidArgument / InvalidOptions for: even n, n > N, T longer than the record, b > a, negative weights, non-SISO
/// or irregular data. A warning is reported when b > 0 and the record is longer than T (docs/methods/gawthrop-wang.md: the window's pitfall).
/// Parameters: "theta0", "re_theta1", "im_theta1", ...; fit: one-step output of the discrete
/// FSF model against the windowed output.
Result<FsfModel> fsf(const IdData& data, const FsfOptions& options);

/// The settings fsf() runs with on `data`: T (a whole number of sampling periods), n and a completed as
/// documented in FsfOptions; `choices` (if given) receives one line per setting chosen or rounded. Throws
/// InvalidArgument when a setting is automatic and no pre-estimate can be made.
FsfOptions fsf_settings(const IdData& data, const FsfOptions& options, std::vector<std::string>* choices = nullptr);

/// Stage 1 from spectra (GW 24-29); T and n must be given (there is no record to pre-estimate): U and Y are the one-sided DFTs (bins
/// 0..L/2, L even) of input and output records of M samples at Ts, zero-padded to L >= M + N so
/// that linear and circular convolution coincide. The window a is applied as inverse FFT ->
/// e^{-at} -> FFT (the paper's recommendation); b must be 0 (the authors define no frequency-
/// domain weighting). Solves Y(w_i) = sum_k theta_k Hbar_k(e^{j w_i Ts}) U(w_i) over all bins
/// (real and imaginary parts, interior bins counted twice for the two-sided sum). Throws
/// InvalidArgument for inconsistent sizes or L < N.
Result<FsfModel> fsf_from_spectra(const Eigen::VectorXcd& U, const Eigen::VectorXcd& Y, int L, double Ts,
                                  const FsfOptions& options);
/// One-sided DFT (bins 0..L/2) of x zero-padded to length L (L even, L >= x.size()).
Eigen::VectorXcd one_sided_dft(const Eigen::VectorXd& x, int L);

/// Helper for T: the time after which the impulse response of g (shifted by a: g(s + a))
/// stays below `tolerance` times its peak (searched up to `t_max`).
double fsf_settling_time(const class TransferFunction& g, double a = 0.0, double tolerance = 1e-3, double t_max = 1e4);

}  // namespace ctid
