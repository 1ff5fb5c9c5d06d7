// static_gain — the toy estimator of docs/architecture.md ("Worked example: adding an estimator"): y = K u by
// least squares on one record of one input and one output, with a ridge term.
#pragma once

#include "ctid/ctid.hpp"

namespace toy {
struct StaticGainOptions {
  double ridge = 0.0;  ///< added to u'u (>= 0): shrinks K towards 0
};
}  // namespace toy

template <>
const ctid::OptionTable<toy::StaticGainOptions>& ctid::option_table<toy::StaticGainOptions>();

namespace toy {
/// The gain K of y = K u (a transfer function of order 0), its standard deviation from the residual variance, and
/// the fit. Throws ctid::InvalidArgument for a record that is not single-input single-output.
ctid::Result<ctid::TransferFunction> static_gain(const ctid::IdData& d, const StaticGainOptions& o = {});
}  // namespace toy
