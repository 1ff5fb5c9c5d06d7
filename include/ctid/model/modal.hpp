// ctid — modal functions and modal parameters of El-Shafey (1987), "Linear
// Continuous-time System Identification and State Observer Design by Modal Analysis" (PhD thesis), chapter 2 (equations "ES n"); docs/methods/el-shafey.md,
// ES-C1 (modal parameters from a known model, ES 2.13-2.30, with the corrected sign e^{-s_k T_i}),
// ES-C2 (modal functions, ES 2.26-2.45), the phase-variable form (ES 2.11-2.12), input generators
// (ES 2.35-2.36) and Theorems 4.1 and 4.2 (ES 4.15-4.31).
//
// Conventions. The system is SISO, strictly proper, of order n: D^n y + sum a_j D^j y = sum b_j D^j u.
// Modal time shifts 0 < T_1 < ... < T_n in seconds (non-uniform allowed; negative shifts are allowed
// where stated). The output-derivative modal function of order j is
//     y_j(t) = D^j y(t) + sum_i p_{j,i} y(t - T_i),
// which contains only the input's modes: with a generated input, y_j(t) = q_j^T x_c(t).
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "ctid/model/state_space.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/poly/polynomial.hpp"

namespace ctid {

/// Input generator (ES 2.35-2.36): the input is the free response u(t) = c^T x_c(t) of the known
/// autonomous system D x_c = A x_c, x_c(t) = e^{A t} x0 (t in seconds from the record start).
/// The basis x_c(t) is what the q vectors of a ModalModel refer to.
class InputGenerator {
 public:
  InputGenerator() = default;
  /// Throws InvalidArgument for inconsistent sizes or non-finite entries.
  InputGenerator(Eigen::MatrixXd A, Eigen::VectorXd c, Eigen::VectorXd x0);
  /// u = level (one mode at s = 0; basis x_c = 1).
  static InputGenerator constant(double level = 1.0);
  /// u = amplitude e^{sigma t} (basis x_c = e^{sigma t}).
  static InputGenerator exponential(double sigma, double amplitude = 1.0);
  /// u = e^{sigma t} (a_sin sin wt + a_cos cos wt), w > 0; basis x_c = e^{sigma t} [sin wt, cos wt],
  /// A = [[sigma, w], [-w, sigma]].
  static InputGenerator sinusoid(double w, double a_sin, double a_cos = 0.0, double sigma = 0.0);
  /// Sum of two generators: block-diagonal A, bases concatenated.
  InputGenerator operator+(const InputGenerator& other) const;

  const Eigen::MatrixXd& A() const { return A_; }
  const Eigen::VectorXd& c() const { return c_; }
  const Eigen::VectorXd& x0() const { return x0_; }
  int order() const { return static_cast<int>(A_.rows()); }
  /// The input's modes: eigenvalues of A.
  Eigen::VectorXcd modes() const;
  /// det(sI - A), monic, descending powers.
  Polynomial characteristic_polynomial() const;
  /// Rows x_c(t_i)^T = (e^{A t_i} x0)^T, exact.
  Eigen::MatrixXd basis(const Eigen::VectorXd& t) const;
  /// u(t_i) = c^T x_c(t_i).
  Eigen::VectorXd operator()(const Eigen::VectorXd& t) const;

 private:
  Eigen::MatrixXd A_;
  Eigen::VectorXd c_, x0_;
};

/// Modal parameters of a known model (ES-C1) with the conditioning of the problem.
struct ModalParameters {
  Eigen::MatrixXd P;        ///< (max_order + 1) x n; row j is p_j^T = -c^T A^j psi^{-1}
  Eigen::MatrixXd psi;      ///< n x n, row i is c^T e^{-A T_i}
  double condition = 0.0;  ///< 2-norm condition number of psi (large: shifts badly placed)
};

/// psi, P for a SISO state-space model and n = nx shifts (seconds; distinct; any sign).
/// Invariant under state coordinate changes. Throws InvalidArgument for a MIMO model, a wrong
/// number of shifts, repeated or zero shifts, max_order < 0, or a singular psi (unobservable
/// model, or shifts at which two modes coincide: e.g. T_2 - T_1 a multiple of 2 pi / (mode spacing)).
ModalParameters modal_parameters(const StateSpace& sys, const Eigen::VectorXd& shifts, int max_order);
/// Same for a strictly proper transfer function (through its phase-variable form).
ModalParameters modal_parameters(const TransferFunction& tf, const Eigen::VectorXd& shifts, int max_order);

/// Result of choose_modal_shifts: the chosen uniform shifts and the conditioning curve.
struct ShiftChoice {
  Eigen::VectorXd shifts;      ///< T_i = i * spacing, i = 1..n
  double condition = 0.0;      ///< cond(psi) at the chosen spacing
  Eigen::VectorXd spacings;    ///< every candidate spacing (seconds)
  Eigen::VectorXd conditions;  ///< cond(psi) at each candidate (inf where psi is singular)
};

/// Helper for choosing modal time shifts (ES tunables: "affects conditioning of psi"): uniform shifts
/// T_i = i * spacing with spacing a multiple of Ts up to max_shift / n, picking the spacing that
/// minimises cond(psi) for a prior model (a first estimate, e.g. from srivc or prony). Short spacings
/// make psi nearly singular (the shifted outputs are nearly equal); spacings near 2 pi / (mode
/// frequency differences) alias modes. Throws InvalidArgument for Ts <= 0 or max_shift < n Ts.
ShiftChoice choose_modal_shifts(const TransferFunction& prior, double Ts, double max_shift);

/// Phase-variable (observable canonical) form of ES 2.11: A companion with ones on the
/// super-diagonal and last row [-a_0 ... -a_{n-1}], c = e_1, b = the Markov parameters b~
/// (b~_k = k-th coefficient of H(s) = sum b~_k s^{-k}); the state is x~_1 = y,
/// x~_{j+1} = D^j y - sum_{i<=j} b~_i D^{j-i} u. Throws InvalidArgument unless strictly proper.
StateSpace phase_variable_form(const TransferFunction& tf);

/// Modal parameters and modal-function coefficients estimated from data (estimate/modal/modal.hpp) or
/// computed from a model: row j of P is p_j^T (n shift weights), row j of Q is q_j^T (coefficients
/// of y_j(t) = q_j^T x_c(t) in the input basis; may have zero columns when no input modes are used).
class ModalModel {
 public:
  ModalModel() = default;
  /// Throws InvalidArgument for inconsistent sizes.
  ModalModel(Eigen::VectorXd shifts, Eigen::MatrixXd P, Eigen::MatrixXd Q);

  const Eigen::VectorXd& shifts() const { return shifts_; }
  const Eigen::MatrixXd& P() const { return P_; }
  const Eigen::MatrixXd& Q() const { return Q_; }
  /// System order n (number of shifts).
  int order() const { return static_cast<int>(shifts_.size()); }
  /// Highest derivative order j available.
  int max_order() const { return static_cast<int>(P_.rows()) - 1; }

  /// Theorem 4.1 (ES 4.15-4.17): p_n + sum_j a_j p_j = 0, so a = -P^{-T} p_n with P = [p_0; ..; p_{n-1}].
  /// Returns s^n + a_{n-1} s^{n-1} + ... + a_0. Throws InvalidArgument if max_order() < n.
  Polynomial characteristic_polynomial() const;
  /// Theorems 4.1 and 4.2 (ES 4.15-4.31): b from q_n + sum_j a_j q_j = R_b b,
  /// R_b = [c, A^T c, ..., A^{(n-1)T} c] of the input generator (needs generator order >= n, same
  /// basis as Q). Throws InvalidArgument otherwise. Several experiments: see modal_theorems_tf.
  TransferFunction transfer_function(const InputGenerator& input) const;

 private:
  Eigen::VectorXd shifts_;
  Eigen::MatrixXd P_, Q_;
};

/// One experiment's modal quantities with the generator of the input they were estimated on (for
/// prefiltered pairs: the filtered input, see modal_filter(InputGenerator, ...)).
struct ModalExperiment {
  ModalModel model;
  InputGenerator input;
};

/// Theorems 4.1 and 4.2 stacked over experiments (ES-C8, e.g. prefiltered pairs of ES-C6): a from all
/// p_n + sum_j a_j p_j = 0 by least squares, b from all q_n + sum_j a_j q_j = R_b b. Needs max_order >= n
/// in every experiment and at least n input modes in total. Throws InvalidArgument otherwise.
TransferFunction modal_theorems_tf(const std::vector<ModalExperiment>& experiments);

/// Output-modal-function route (ES-C7, ES 4.1-4.14): from p_0 and q_0 of each experiment,
/// nu^T = c^T (I + sum_i p_0i e^{-A T_i}) and q_0^T (A^n + sum a_j A^j) = sum b_j nu^T A^j, stacked:
/// theta = [a; b] = -(R^T R)^{-1} R^T (A^n)^T q_0. Needs at least 2n input modes in total.
/// Throws InvalidArgument otherwise.
TransferFunction modal_output_function_tf(const std::vector<ModalExperiment>& experiments);

}  // namespace ctid
