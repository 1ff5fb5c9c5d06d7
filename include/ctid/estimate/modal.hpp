// ctid — El-Shafey (1987), "Identification of linear continuous-time systems using modal functions":
// estimation of modal parameters and what is derived from them. SEEDS-SPEC Part ES:
//   ES-C3  discrete samples, least squares and instrumental variables (ES 3.1-3.10, 3.19-3.20)
//   ES-C4  Fourier modulating functions with the c_{j-1} recursion (ES 3.11-3.30; Omega of ES 3.25)
//   ES-C5  Walsh (block-pulse) functions with the edge recursion (ES 3.18, 3.31-3.37)
//   ES-C8  a and b by Theorems 4.1 and 4.2 (ES 4.15-4.31)
//   ES-C9  poles from a free-response data matrix, Newton's identities (ES 4.37-4.63, index fix of
//          ES 4.50), augmentation and deflation for generated inputs; Prony's method as the baseline.
//
// Data are uniformly sampled (Ts); the record starts at rest unless the validity windows exclude its
// start; samples before the record count as zero. Times are seconds from the first sample.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/model/modal.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/signal/modal_filter.hpp"

namespace ctid {

/// A time interval [start, start + length] (seconds from the first sample) in which the modal-function
/// relation holds: the input is one free response of its generator since at least T_n before start.
struct ModalWindow {
  double start = 0.0;
  double length = 0.0;
};

/// Validity windows of a piecewise-constant input (ES-C11 "constant-input windows"): from `settle`
/// seconds (>= T_n) after each level switch (t = 0 counts as a switch) to the sample before the next
/// switch; windows shorter than min_length are dropped. Throws InvalidArgument for a multi-input record.
std::vector<ModalWindow> piecewise_constant_windows(const IdData& data, double settle, double min_length = 0.0);

enum class ModalBasis {
  Discrete,  ///< the equations at sample instants (ES-C3); only j = 0
  Fourier,   ///< Fourier modulating functions on each window (ES-C4)
  Walsh      ///< Walsh / block-pulse functions on each window (ES-C5)
};

struct ModalOptions {
  Eigen::VectorXd shifts;            ///< T_1 < ... < T_n (seconds, > 0, multiples of Ts); n = system order
  ModalBasis basis = ModalBasis::Fourier;
  int max_order = 0;                 ///< estimate p_j, q_j for j = 0..max_order (> 0 needs Fourier or Walsh)
  std::vector<ModalWindow> windows;  ///< empty: one window from T_n to the end of the record
  /// Fourier: 2m functions (even, >= 2) on the concatenation of the windows (local time runs on from one
  /// window to the next; j > 0 needs a single window). Walsh: N = 2^k functions (blocks) on each window.
  int functions = 6;
  Quadrature quadrature = Quadrature::Simpson;  ///< Fourier/Walsh integrals; Trapezoid reproduces the thesis
  int stride = 1;                    ///< Discrete: every stride-th sample of each window is an equation
  double iv_shift = 0.0;             ///< Discrete: > 0 uses instruments y(t - T_i + iv_shift) (ES 3.19-3.20)
  /// Throws InvalidOptions naming the field (shifts not increasing or not > 0, functions, stride, ...).
  void validate() const;
};

/// Modal parameters p_j and modal-function coefficients q_j (j = 0..max_order) from one record.
/// input_basis: N x n_c samples of the input generator basis x_c(t) (InputGenerator::basis at the
/// sample times, or u itself for a piecewise-constant input treated window by window; 0 columns for a
/// free response). Parameters are named p<j>_<i> and q<j>_<k>; their covariance is that of each
/// regression given the previous order's estimates. fit.mse is the mean squared j = 0 equation error.
/// Throws InvalidArgument for shifts or windows off the sample grid, windows outside the record,
/// too few equations, a Walsh block shorter than one sample.
Result<ModalModel> modal_estimate(const IdData& data, const Eigen::MatrixXd& input_basis, const ModalOptions& options);
/// Same with the basis of a known input generator evaluated at the sample times.
Result<ModalModel> modal_estimate(const IdData& data, const InputGenerator& input, const ModalOptions& options);

/// Transfer function by Theorems 4.1 and 4.2 (ES-C8): p_0..p_n and q_0..q_n estimated with
/// options.max_order = n (set automatically), then a = -P^{-T} p_n and b from the q's. The input must
/// have at least n modes. fit compares the model's exact response to the generated input (from rest)
/// with the measured output.
Result<TransferFunction> modal_transfer_function(const IdData& data, const InputGenerator& input,
                                                 ModalOptions options);

/// Characteristic polynomial det(sI - M) by Newton's identities with T_k = trace(M^k) (ES 4.50 with
/// the index fix of SEEDS-SPEC ES-C9): a_{n-1} = -T_1, a_{n-k} = -(a_{n-k+1} T_1 + ... + a_{n-1} T_{k-1} + T_k)/k.
Polynomial newton_characteristic_polynomial(const Eigen::MatrixXd& M);

struct FreeResponseOptions {
  Eigen::VectorXd shifts;   ///< T_1..T_n' (seconds, distinct, multiples of Ts); n' = order (+ generator order)
  double start = 0.0;       ///< t_o1 (seconds); t_o1 - T_i must lie in the record
  double interval = 0.0;    ///< t_fk - t_ok (seconds, > 0, multiple of Ts)
  double spacing = 0.0;     ///< t_o(k+1) - t_ok (seconds, > 0, multiple of Ts)
  int pairs = 0;            ///< N >= n' instant pairs
  Quadrature quadrature = Quadrature::Simpson;
  /// Characteristic polynomial of a known input generator (forced response, ES 4.56-4.62): the
  /// estimate of order n' is deflated by it. Default 1: a free response.
  Polynomial generator{1.0};
  void validate() const;
};

/// Poles estimated from data; the polynomial coefficients are descending and monic.
struct PoleEstimate {
  Eigen::VectorXcd poles;        ///< of the system (after deflation), s-plane
  Polynomial characteristic;     ///< of the system (after deflation)
  Eigen::VectorXcd all_poles;    ///< before deflation (Theorem 4.3: system and generator)
  Polynomial augmented;          ///< before deflation
  Eigen::MatrixXd lambda;        ///< Theorem 4.3's Lambda = psi A psi^{-1} (data-matrix method); empty for Prony
  double condition = 0.0;        ///< Z Z^T (data matrix) or R^T R (Prony), 2-norm
  std::vector<std::string> warnings;
};

/// Theorem 4.3 (ES-C9): Y_N = [y(t_fk - T_i) - y(t_ok - T_i)], Z_N = [int_{t_ok}^{t_fk} y(t - T_i) dt],
/// Lambda = Y Z^T (Z Z^T)^{-1}, poles = eig(Lambda), polynomial by Newton's identities, then deflation
/// of the generator polynomial by least squares on the coefficients. y: the free (or generated-input)
/// response sampled at Ts. Throws InvalidArgument for instants outside the record or off the grid,
/// pairs < n', or a generator polynomial of degree >= n'.
PoleEstimate free_response_poles(const Eigen::VectorXd& y, double Ts, const FreeResponseOptions& options);

struct PronyOptions {
  int order = 0;     ///< number of exponentials
  int spacing = 1;   ///< sample spacing T = spacing * Ts of the Prony samples
  int equations = 0; ///< N >= order
  int start = 0;     ///< first sample index used
};

/// Prony's method (ES Ex. 4.8, reconstructed): y(m) + sum_k p_k y(m - k) = 0 on samples spaced T,
/// least squares, poles s = ln(z)/T of z^order + p_1 z^{order-1} + ... . Reports cond(R^T R) and a
/// warning that imaginary parts are only known modulo 2 pi / T (aliasing band (-pi/T, pi/T]).
PoleEstimate prony(const Eigen::VectorXd& y, double Ts, const PronyOptions& options);

}  // namespace ctid
