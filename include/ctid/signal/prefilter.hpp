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

/// Sensitivities of the simulated output of G = e^{-sT} B/A (SISO, from rest) to the
/// parameters [a1..an, b0..b(nb-1)] (and T when with_delay), N x (nf + nb [+1]):
///   dy/da_i = -s^{n-i} B/A^2 u(t-T),  dy/db_j = s^{nb-1-j}/A u(t-T),  dy/dT = -s B/A u(t-T).
/// Exact for the data's intersample behaviour. with_delay needs a strictly proper G.
Eigen::MatrixXd output_sensitivities(const TransferFunction& G, int nb, const IdData& data, bool with_delay);

}  // namespace ctid
