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

#include "ctid/data/iddata.hpp"
#include "ctid/data/input_design.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/simulate/lsim.hpp"
#include "test_paths.hpp"

namespace ctid::test {

/// 4/(s^2 + 0.8 s + 4) driven by a PRBS (register 9, clock 3), 2000 samples at 20 ms, 20 dB output noise (seed 3):
/// an ordinary record on which the iterative estimators take several iterations.
inline IdData second_order_record() {
  const TransferFunction g(Eigen::VectorXd{{4.0}}, Eigen::VectorXd{{1.0, 0.8, 4.0}});
  const Eigen::VectorXd u = prbs(2000, {.register_length = 9, .clock_period = 3});
  return IdData(u, add_noise_snr(lsim(g, u, time_grid(0.02, 2000)), 20.0, 3), 0.02);
}

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

/// The folder is emptied the first time a process asks for it: a process id can be reused by a later test run on
/// the same machine (CI runs the Release and the sanitizer builds one after the other), and a file left by that
/// earlier run must not be mistaken for one this run wrote, nor make a command refuse to overwrite it.
inline std::string temp_path(const std::string& name) {
  static const std::filesystem::path dir = [] {
    const auto d = std::filesystem::temp_directory_path() / ("ctid_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(d);
    return d;
  }();
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
