// ctid — continuous-time transfer function from frequency-response data.
//
// 1. Sanathanan & Koerner (1963), IEEE Trans. Autom. Control 8(1): iterate the linear
//    least-squares problem min sum |B(jw) - G A(jw)|^2 / |A_prev(jw)|^2 (the weighting by
//    the previous denominator removes Levy's emphasis on high frequencies).
// 2. Output-error refinement: Levenberg-Marquardt on sum |G_k - B/A(jw_k) e^{-jw T}|^2 with
//    analytic derivatives (dG/da_i = -G (jw)^{n-i}/A, dG/db_j = (jw)^{nb-1-j}/A, dG/dT = -jw G).
// Frequencies are scaled by their geometric mean during the computation. Covariance
// sigma^2 (J^T J)^{-1} for complex noise of variance sigma^2 per real and imaginary part.
#pragma once

#include "ctid/core/types.hpp"
#include "ctid/data/frequency_data.hpp"
#include "ctid/estimate/orders.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/estimate/options.hpp"

namespace ctid {

struct FrequencyFitOptions {
  int sk_iterations = 30;        ///< Sanathanan-Koerner iterations (>= 1)
  bool refine = true;            ///< output-error refinement after SK
  int max_iterations = 500;      ///< LM iterations of the refinement (a well-posed fit converges long before)
  double tolerance = 1e-12;
  bool estimate_delay = false;   ///< add an input delay T (s) to the refinement ("delay")
  double delay = 0.0;            ///< fixed or initial delay (s)
  /// Keep the refinement among stable models (steps to an unstable denominator are
  /// rejected). Frequency data alone do not constrain stability; without this, noisy data
  /// can pull a pole far into the right half plane where it mimics a constant.
  bool require_stable = true;
  void validate() const;
};
/// The settings of FrequencyFitOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<FrequencyFitOptions>& option_table<FrequencyFitOptions>();

/// Fit G(s) = e^{-sT} B(s)/A(s) with orders.nb numerator and orders.nf denominator
/// coefficients (orders.nk must be 0). Throws InvalidArgument when there are fewer real
/// equations (2 x frequencies) than parameters.
Result<TransferFunction> tf_from_frequency(const FrequencyData& data, const TfOrders& orders,
                                           const FrequencyFitOptions& options = {});

}  // namespace ctid
