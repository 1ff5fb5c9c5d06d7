// ctid — Cramer-Rao lower bound of transfer-function parameters for output-error
// identification with white Gaussian output noise of variance sigma2:
//   CRLB = sigma2 (S^T S)^{-1},  S = d yhat / d theta at the true model (N x p),
// for the experiment's input, sample times and intersample behaviour (Ljung 1999, ch. 9).
#pragma once

#include <Eigen/Dense>

#include "ctid/data/iddata.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// Covariance bound for [a1..an, b0..b(nb-1)] (and the delay last when with_delay).
/// Throws InvalidArgument for sigma2 <= 0, non-SISO data or an unidentifiable set-up
/// (singular information matrix).
Eigen::MatrixXd crlb(const TransferFunction& truth, int nb, const IdData& experiment, double sigma2,
                     bool with_delay = false);

}  // namespace ctid
