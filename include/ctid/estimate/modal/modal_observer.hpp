// ctid — El-Shafey (1987) chapter 6: the minimum-time (dead-beat) state observer for piecewise-
// constant inputs (ES 6.1-6.36, ES 6.1-6.36 with the RECONSTRUCTED signs: r_m(s) = int_0^{s-mT} h~
// and x~ = -P y + Qbar(s) u), and the estimate of the Markov parameters b~ (ES 6.37-6.43, ES-C14;
// ES 6.39's b~_j read as b~_n).
//
// The input is constant on [kT, (k+1)T); the shifts are T_i = i T. The state is the phase-variable
// state of phase_variable_form(): x~_1 = y, x~_{j+1} = D^j y - sum_{i<=j} b~_i D^{j-i} u. At t = kT + s
// (0 <= s < T, k >= n) the observer gives it exactly from n past output samples and n + 1 input levels:
//     x~(kT + s) = -P [y((k-1)T + s) .. y((k-n)T + s)]^T + Qbar(s) [u(k) .. u(k-n)]^T.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "ctid/data/iddata.hpp"
#include "ctid/estimate/modal/modal.hpp"
#include "ctid/model/modal.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

class DeadbeatObserver {
 public:
  DeadbeatObserver() = default;
  /// Design from a known strictly proper model for level period T and sampling period Ts (T a whole
  /// multiple of Ts): Qbar(s) at the offsets s = r Ts, r = 0 .. T/Ts - 1. Throws InvalidArgument.
  static DeadbeatObserver from_model(const TransferFunction& tf, double T, double Ts);
  /// Design from data (ES 6.26-6.29): p_0 .. p_{n-1} for the shifts i T (model.P() rows) and a step
  /// response estimate on the grid t = j Ts covering [0, (n+1) T) (modal_step_response): qbar_0(s) =
  /// Delta L g(s), [q~_00; r(s)] = (Delta^T Gamma_0)^{-1} qbar_0(s). Throws InvalidArgument.
  static DeadbeatObserver from_step_response(const ModalModel& model, const TimeResponse& step, double T);

  int order() const { return static_cast<int>(P_.rows()); }
  double period() const { return T_; }
  /// Samples per level period (offsets s = r Ts).
  int offsets() const { return static_cast<int>(Qbar_.size()); }
  /// n x n, rows p_0 .. p_{n-1} (state modal parameters for T_i = i T).
  const Eigen::MatrixXd& P() const { return P_; }
  /// n x (n+1) at offset r (s = r Ts).
  const Eigen::MatrixXd& Qbar(int r) const;
  /// r(s) = [r_1(s) .. r_n(s)] at offset r (s = r Ts).
  const Eigen::VectorXd& r(int offset) const;
  /// q~_j0 = p_j^T r(0), j = 0 .. n-1 (ES 6.15, 6.26).
  const Eigen::VectorXd& q_tilde0() const { return qt0_; }
  /// Discrete dead-beat observer (s = 0): x~(k) = -P y(k-1 .. k-n) + Q u(k-1 .. k-n), Q = Qbar(0) without
  /// its first (zero) column.
  Eigen::MatrixXd Q_discrete() const { return Qbar(0).rightCols(order()); }

  /// Phase-variable state at every sample of a record whose input is constant on each level period
  /// (rows; NaN for the first n periods, where the observer has too little history). Throws
  /// InvalidArgument when the record's sampling period differs from the design's or the input changes
  /// inside a level period.
  Eigen::MatrixXd reconstruct(const IdData& data) const;

  /// ES-C14: b~_j = q_j0 - q~_j0 (j = 1 .. n-1), b~_n = q_n0 + sum_j a_j q~_j0, with a from Theorem 4.1 and
  /// q_j0 = g_c sum_i p_ji the constant that p_j leaves of the step response. g_c is the step response's constant
  /// part, the DC gain H(0) = q~_00 / (1 + sum_i p_0i) (the thesis' g(inf) for a stable system; the same formula
  /// holds for an unstable one, whose step response has no limit). p_n: the n-th order modal parameters for the
  /// same shifts. Returns b~_1 .. b~_n. Throws InvalidArgument for a wrong size of p_n, or when the system has a
  /// pole at s = 0 (1 + sum_i p_0i = 0: the step response of an integrating plant has no constant part).
  Eigen::VectorXd markov_parameters(const Eigen::RowVectorXd& p_n) const;

 private:
  double T_ = 0, Ts_ = 0;
  Eigen::MatrixXd P_;
  Eigen::VectorXd qt0_;
  std::vector<Eigen::MatrixXd> Qbar_;
  std::vector<Eigen::VectorXd> r_;
  void assemble(const std::vector<Eigen::VectorXd>& r);  // q~_j0 and Qbar from r(s) and P
};

}  // namespace ctid
