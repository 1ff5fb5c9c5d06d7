// ctid internal — helpers shared by the transfer-function estimators (SRIVC, OE, order
// selection): parameter vectors [a1..an, b0..b(nb-1)] <-> TransferFunction, output error.
#pragma once

#include <Eigen/Dense>

#include "ctid/data/iddata.hpp"
#include "ctid/estimate/orders.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid::tf_detail {

TransferFunction make_tf(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double delay);
/// [a1..an, b0..b(nb-1)] of g for the given orders (missing coefficients are zero).
Eigen::VectorXd params_of(const TransferFunction& g, const TfOrders& o);
TransferFunction tf_of(const Eigen::VectorXd& p, const TfOrders& o, double delay);
/// Mean squared output error of g simulated on d (+Inf if the simulation diverges).
double output_error_mse(const TransferFunction& g, const IdData& d);
/// Mirror unstable poles into the left half plane (prefilters and auxiliary models must be stable).
TransferFunction stabilized(const TransferFunction& tf);

}  // namespace ctid::tf_detail
