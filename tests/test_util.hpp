// Shared helpers for the ctid tests.
#pragma once

#include <complex>
#include <cstdlib>
#include <unistd.h>
#include <exception>
#include <filesystem>
#include <functional>
#include <string>

#include <Eigen/Dense>

#include "ctid/model/transfer_function.hpp"

namespace ctid::test {

/// Step response by residues (distinct poles): y(t) = G(0) + sum_i N(p_i)/(p_i D'(p_i)) e^{p_i (t - Td)}.
/// An independent closed form, not using the matrix exponential.
inline double step_by_residues(const TransferFunction& g, double t) {
  t -= g.io_delay();
  if (t < 0) return 0.0;
  const Eigen::VectorXcd p = g.poles();
  const Polynomial dD = g.den().derivative();
  std::complex<double> y = g.num()(0.0) / g.den()(0.0);
  for (Eigen::Index i = 0; i < p.size(); ++i) y += g.num()(p(i)) / (p(i) * dD(p(i))) * std::exp(p(i) * t);
  return y.real();
}

/// Response to a piecewise-constant input switching at times ts[k] (value v[k] from ts[k] on,
/// 0 before ts[0]): superposition of delayed step responses.
inline double zoh_response(const TransferFunction& g, const Eigen::VectorXd& ts, const Eigen::VectorXd& v, double t) {
  double y = 0, prev = 0;
  for (Eigen::Index k = 0; k < ts.size(); ++k) {
    y += (v(k) - prev) * step_by_residues(g, t - ts(k));
    prev = v(k);
  }
  return y;
}

inline std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("ctid_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

/// The message of the exception f throws ("" when it throws none).
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

inline bool shared_data_available() { return std::filesystem::exists(CTID_SHARED_DATA_DIR); }

}  // namespace ctid::test
