// ctid — frequency-response data: G(j w_k) at angular frequencies w_k (rad/s), from a
// measured response or from input/output spectra (G = Y / U).
#pragma once

#include <Eigen/Dense>

namespace ctid {

class FrequencyData {
 public:
  FrequencyData() = default;
  /// w strictly increasing and > 0 (rad/s), G finite, same length >= 1. Throws
  /// InvalidArgument naming the first offending index and values.
  FrequencyData(Eigen::VectorXd w, Eigen::VectorXcd G);
  /// From input and output spectra at w: G = Y / U (U must be non-zero).
  static FrequencyData from_spectra(const Eigen::VectorXd& w, const Eigen::VectorXcd& U, const Eigen::VectorXcd& Y);
  int size() const { return static_cast<int>(w_.size()); }
  const Eigen::VectorXd& w() const { return w_; }
  const Eigen::VectorXcd& response() const { return g_; }

 private:
  Eigen::VectorXd w_;
  Eigen::VectorXcd g_;
};

}  // namespace ctid
