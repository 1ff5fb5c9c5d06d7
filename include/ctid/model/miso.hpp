// ctid — multiple-input single-output continuous-time model y = sum_i G_i(s) u_i, each
// G_i a transfer function with its own input delay (a common denominator is the special
// case of equal denominators).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ctid/model/transfer_function.hpp"

namespace ctid {

struct MisoModel {
  std::vector<TransferFunction> channels;  ///< one per input
  int nu() const { return static_cast<int>(channels.size()); }
  bool is_stable() const {
    for (const auto& c : channels)
      if (!c.is_stable()) return false;
    return true;
  }
  /// "u1: G1(s) + u2: G2(s)" on one line.
  std::string to_string(int precision = 6) const {
    std::string s;
    for (std::size_t i = 0; i < channels.size(); ++i)
      s += (i ? "  +  " : "") + std::string("u") + std::to_string(i + 1) + ": " + channels[i].to_string(precision);
    return s;
  }
};

}  // namespace ctid
