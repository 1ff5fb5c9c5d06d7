// ctid — stage 1 of Gawthrop & Wang (2005): least-squares compression of sampled data into a
// frequency-sampling-filter model (GW eqs 6-8), with the exponential window a and residual
// weighting b for unstable plants (GW 14-21; SEEDS-SPEC GW-A1, GW-A2).
//
// Regressors phi_i = sum_{l<N} f_l u_{i-l} (zero input before the record) are computed by
// exact FIR summation from prefix/suffix partial sums of N-sample chunks (O(n) per sample) —
// never by the marginally stable recursive form. With a window
// a and weight b the rows are formed as in SEEDS-SPEC GW-A2, never with e^{bt} and e^{-at}
// separately:  e^{b t_i} y_{a,i} = e^{(b-a) t_i} y_i,
//              e^{b t_i} phi_{a,i} = e^{(b-a) t_i} sum_{l<N} (f_l e^{a l Delta}) u_{i-l}.
// The fitted model is then that of the shifted system G(s + a).
#pragma once

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/fsf.hpp"
#include "ctid/estimate/options.hpp"

namespace ctid {

struct FsfOptions {
  double T = 0.0;     ///< settling time (s) of the (shifted) system; N = T/Ts must be a whole number
  int n = 21;         ///< number of filters, odd, <= N
  double a = 0.0;     ///< exponential window e^{-at} (1/s), >= 0; choose a > max Re(poles) for unstable plants
  double b = 0.0;     ///< residual weighting e^{bt} (1/s), 0 <= b <= a; b > 0 is risky (see the method page)
  Eigen::VectorXd weights;  ///< optional per-sample residual weights (>= 0, length N_data); empty: 1
  bool unstable = false;    ///< the plant is declared unstable: validate() then requires a > 0
  void validate() const;
};
/// The settings of FsfOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<FsfOptions>& option_table<FsfOptions>();

/// Fit an FSF model to one input and one output (uniform Ts). Throws InvalidArgument /
/// InvalidOptions for: even n, n > N, T not a whole multiple of Ts (to 1e-9) or longer than
/// the record, b > a, negative weights, non-SISO or irregular data. A warning is reported
/// when b > 0 and the record is longer than T (SEEDS-SPEC GW-A2 pitfall).
/// Parameters: "theta0", "re_theta1", "im_theta1", ...; fit: one-step output of the discrete
/// FSF model against the windowed output.
Result<FsfModel> fsf(const IdData& data, const FsfOptions& options);

/// Stage 1 from spectra (GW 24-29, SEEDS-SPEC GW-A4): U and Y are the one-sided DFTs (bins
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
