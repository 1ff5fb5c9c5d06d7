// ctid internal — what the state-space estimators (subspace, ssest) share: the channel scales they run in and the
// fits they report (every output on its own, and all outputs together with each scaled by its standard deviation).
#pragma once

#include <span>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"

namespace ctid::ss_detail {

/// Standard deviation of each input (outputs = false) or output over all the records together (1 where constant).
Eigen::VectorXd channel_scales(std::span<const IdData> records, bool outputs);

struct Fits {
  FitReport all;                ///< every output about its own mean, divided by its scale sy, stacked
  Eigen::VectorXd per_output;   ///< fit_percent of each output over all the records
};
/// Fits of the simulated outputs yhat (one N x ny matrix per record) against the records' outputs.
Fits fits_of(std::span<const IdData> records, std::span<const Eigen::MatrixXd> yhat, const Eigen::VectorXd& sy,
             int n_parameters);

}  // namespace ctid::ss_detail
