// ctid — filtered time derivatives [s^k G v](t), k = 0..k_max, computed exactly for a
// held (ZOH) or linear (FOH) signal v by simulating one realisation of G(s) with the
// extra outputs C A^k (plus the direct term where s^k G is biproper). Used by the
// refined instrumental-variable and output-error estimators (prefilter 1/A, auxiliary
// model B/A^2, parameter sensitivities).
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "ctid/data/iddata.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// N x (k_max + 1) matrix whose column k is s^k G(s) applied to v delayed by `delay`
/// seconds (zero before the record), from rest, at the times t. Requires
/// k_max <= deg(den) - deg(num) (s^k G proper). Throws InvalidArgument otherwise.
Eigen::MatrixXd filtered_derivatives(const TransferFunction& G, int k_max, const Eigen::Ref<const Eigen::VectorXd>& v,
                                     const Eigen::VectorXd& t, Intersample intersample, double delay = 0.0);

/// The same into `out`, resized only when its shape differs: a buffer reused over the iterations of a fit is written
/// in place (no allocation, no page faults); v is read in place.
void filtered_derivatives_into(const TransferFunction& G, int k_max, const Eigen::Ref<const Eigen::VectorXd>& v,
                               const Eigen::VectorXd& t, Intersample intersample, double delay, Eigen::MatrixXd& out);

/// The recursion filtered_derivatives runs, at a uniform interval h without delay, for estimators that use each row
/// of derivatives as it is made and drop it (no N x (k_max + 1) matrix, so a pass reads the signal and nothing else):
/// from x_0 = 0, row k = C x_k + D v_k and x_{k+1} = Phi x_k + G0 v_k + G1 (v_{k+1} - v_k) (G1 = 0 for ZOH) — exact,
/// the same recursion as lsim. Conditions as filtered_derivatives.
struct DerivativeRecursion {
  Eigen::MatrixXd Phi, C;    ///< n x n; (k_max + 1) x n
  Eigen::VectorXd G0, G1, D;  ///< n; n; k_max + 1
};
DerivativeRecursion derivative_recursion(const TransferFunction& G, int k_max, double h, Intersample intersample);

/// Sensitivities of the simulated output of G = e^{-sT} B/A (SISO, from rest) to the
/// parameters [a1..an, b0..b(nb-1)] (and T when with_delay), N x (nf + nb [+1]):
///   dy/da_i = -s^{n-i} B/A^2 u(t-T),  dy/db_j = s^{nb-1-j}/A u(t-T),  dy/dT = -s B/A u(t-T).
/// Exact for the data's intersample behaviour. with_delay needs a strictly proper G.
Eigen::MatrixXd output_sensitivities(const TransferFunction& G, int nb, const IdData& data, bool with_delay);

/// Buffers output_sensitivities_into reuses from call to call: one per record of a fit (its times are read from the
/// record at the first call and kept).
struct SensitivityWorkspace {
  Eigen::VectorXd t;           ///< the record's sample times
  Eigen::MatrixXd xa, ub, yd;  ///< filtered derivatives of its input
};
/// output_sensitivities into S (resized only when its shape differs), with the buffers of ws.
void output_sensitivities_into(const TransferFunction& G, int nb, const IdData& data, bool with_delay,
                               SensitivityWorkspace& ws, Eigen::MatrixXd& S);

}  // namespace ctid
