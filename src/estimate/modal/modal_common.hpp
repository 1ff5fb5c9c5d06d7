// ctid internal — helpers shared by the El-Shafey (1987) modal-function files (modal.cpp: parametric,
// modal_poles.cpp: poles from free responses, modal_responses.cpp: nonparametric responses).
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <string>

#include "ctid/core/check.hpp"
#include "internal/least_squares.hpp"

namespace ctid::modal_detail {

// A whole number of sampling periods, or InvalidArgument naming `what`.
inline int samples_of(double seconds, double Ts, const std::string& what) {
  const double r = seconds / Ts;
  CTID_REQUIRE(std::isfinite(r) && std::abs(r) <= 1e9 && std::abs(r - std::round(r)) <= 1e-9 * std::max(1.0, std::abs(r)),
               "modal: {} = {} s is not a whole multiple of the sampling period {} s ({} periods)", what, seconds, Ts, r);
  return static_cast<int>(std::lround(r));
}

// D f = Omega f with Omega = [[0, Omega'], [-Omega', 0]], Omega' = diag(w, 2w, .., m w) (ES 3.25, missing
// in the OCR), and f(0) = f(T_o) = [0 .. 0, 1 .. 1].
struct FourierFunctions {
  int m;
  double w;
  void operator()(double tau, Eigen::VectorXd& f) const {
    for (int h = 1; h <= m; ++h) {
      f(h - 1) = std::sin(h * w * tau);
      f(m + h - 1) = std::cos(h * w * tau);
    }
  }
  Eigen::MatrixXd omega() const {
    Eigen::MatrixXd Om = Eigen::MatrixXd::Zero(2 * m, 2 * m);
    for (int h = 1; h <= m; ++h) {
      Om(h - 1, m + h - 1) = h * w;
      Om(m + h - 1, h - 1) = -h * w;
    }
    return Om;
  }
  Eigen::VectorXd at_zero() const {
    Eigen::VectorXd f0 = Eigen::VectorXd::Zero(2 * m);
    f0.tail(m).setOnes();
    return f0;
  }
};

inline internal::LinearSolution least_squares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  internal::StreamingLeastSquares ls(static_cast<int>(A.cols()));
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const Eigen::RowVectorXd row = A.row(i);
    ls.add(row.data(), b(i));
  }
  return ls.solve();
}

}  // namespace ctid::modal_detail
