// ctid — Johansson's state-variable filter bank and the exact parameter transform.
//
// Johansson, R. (1986), "Identification of continuous time dynamic systems",
// Lund TFRT-7318, eqs (7)-(23); RJ 7-17, RJ 18-23 (reconstructed M_tau, G_tau).
//
// The operator z = 1/(1 + p tau) (p = d/dt) is realised as a chain of n first-order
// filters tau dx_k/dt = x_{k-1} - x_k, x_0 = the signal, so x_k = [z^k s](t). Between
// samples the chain moves exactly for a held (ZOH) or linear (FOH) signal, with the
// closed form (x = h/tau, P(k, x) the regularised lower incomplete gamma function):
//   Phi_ik = e^{-x} x^{i-k} / (i-k)!  (i >= k),  Gamma0_k = P(k, x),
//   Gamma1_k = e^{-x} sum_{j>=k} x^j/j! (j+1-k)/(j+1)    (the FOH slope term).
// An optional extra data filter F(s) (RJ 42-43, stable and proper) is placed in front
// of the chain; then the bank is one linear system discretised by matrix exponential.
// The filters start at rest; the regression y = theta_tau^T phi_tau is exact when the
// process also starts at rest.
//
// Parameter transform (RJ 18-23, reconstructed in RJ 18-23):
//   theta = [-a_1 .. -a_n, b_1 .. b_n],  A(p) = p^n + a_1 p^{n-1} + .. + a_n,
//   B(p) = b_1 p^{n-1} + .. + b_n,  theta_tau = [-alpha_1 .. -alpha_n, beta_1 .. beta_n],
//   theta_tau = F_tau theta + G_tau,  F_tau = diag(M_tau, M_tau),
//   (M_tau)_ij = (-1)^{i-j} C(n-j, i-j) tau^j (i >= j),  G_tau = [g, 0], g_i = (-1)^{i+1} C(n, i),
//   inverse (M_tau^{-1})_ki = tau^{-k} C(n-i, k-i).
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "ctid/data/iddata.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// M_tau (n x n, lower triangular). Throws InvalidArgument for n < 1 or tau <= 0.
Eigen::MatrixXd svf_m_tau(int n, double tau);
/// Closed-form inverse of M_tau.
Eigen::MatrixXd svf_m_tau_inverse(int n, double tau);
/// g (length n): the first half of G_tau (the second half is zero).
Eigen::VectorXd svf_g_tau(int n);
/// theta_tau from the physical coefficients a = [a_1..a_n], b = [b_1..b_n] (RJ 18-22).
Eigen::VectorXd theta_tau_from_ab(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double tau);
/// Exact inverse: physical a, b from theta_tau (length 2n).
void ab_from_theta_tau(const Eigen::VectorXd& theta_tau, double tau, Eigen::VectorXd& a, Eigen::VectorXd& b);

/// Exact step of the plain chain over an interval h (closed form, see file comment):
/// x_k <- sum_{m<=k} e[k-m] x_m + g0[k] s(t) + g1[k] (s(t+h) - s(t)), k = 0..n-1.
struct SvfChainCoefficients {
  std::vector<double> e, g0, g1;
  /// Resize to n and compute for interval h and time constant tau (no allocation
  /// after the first call with this n).
  void compute(int n, double h, double tau);
};

/// Filter bank producing [z s, z^2 s, .., z^n s] for several sampled signals at once.
/// Without an extra filter, step() allocates nothing (closed-form coefficients are
/// recomputed in place when the interval changes); with one, a new interval length
/// costs a matrix exponential.
class SvfFilterBank {
 public:
  /// n >= 1 filters per signal, tau > 0 (s), one intersample behaviour per signal
  /// (BandLimited is treated as Foh). extra_filter: optional stable proper F(s)
  /// applied to each signal before the chain. Throws InvalidArgument.
  SvfFilterBank(int n, double tau, std::vector<Intersample> intersample,
                const std::optional<TransferFunction>& extra_filter = std::nullopt);

  int order() const { return n_; }
  double tau() const { return tau_; }
  int n_signals() const { return static_cast<int>(is_.size()); }
  /// All filter states to zero (rest).
  void reset();
  /// Advance every signal over an interval of length h > 0 from the samples `prev`
  /// to the samples `next` (arrays of n_signals() values).
  void step(double h, const double* prev, const double* next);
  /// [z^k s_i] for k = 1..n (pointer to n values) of signal i at the current time.
  const double* chain(int i) const { return &chain_out_[static_cast<std::size_t>(i) * n_]; }
  /// The (extra-)filtered signal F s_i at the current time; with no extra filter this
  /// is the last sample given for signal i.
  double filtered(int i) const { return filt_out_[i]; }
  /// Set the current sample values (used before the first step to define filtered()).
  void set_current(const double* values);

 private:
  void update_coefficients(double h);
  int n_;
  double tau_;
  std::vector<Intersample> is_;
  double h_ = -1.0;
  SvfChainCoefficients coef_;
  // generic bank (extra filter): states [x_F; x_chain] per signal
  bool generic_ = false;
  Eigen::MatrixXd Ab_, Bb_, Cf_;  // bank dynamics; Cf_ = output row of F (size nF)
  double Df_ = 0.0;
  int nf_ = 0;
  Eigen::MatrixXd Phi_;
  Eigen::VectorXd G0_, G1_;
  Eigen::MatrixXd xs_;            // (nF + n) x n_signals
  Eigen::VectorXd tmp_;
  std::vector<double> chain_out_, filt_out_;
};

/// A two-signal bank [y (FOH), u] fed one sample at a time, for on-line estimators:
/// keeps the previous sample and tells when a regression instant is reached (every
/// sample, or at most every `regression_interval` seconds). push() allocates nothing.
class SvfStream {
 public:
  /// who: the estimator's name for error messages. Throws InvalidArgument.
  SvfStream(int n, double tau, Intersample input, double regression_interval, const char* who);
  /// Feed one sample; returns true at a regression instant (never for the first sample,
  /// where the filters are still at rest). Throws InvalidArgument for a non-finite value
  /// or a time that does not increase.
  bool push(double t, double u, double y);
  /// Seconds between the last two regression instants.
  double regression_step() const { return reg_step_; }
  /// [z^k y] (signal 0) and [z^k u] (signal 1); filtered(0) is the current y.
  const SvfFilterBank& bank() const { return bank_; }
  double time() const { return t_; }
  void reset();

 private:
  SvfFilterBank bank_;
  double interval_;
  const char* who_;
  double t_ = 0, t_reg_ = 0, reg_step_ = 0, u_prev_ = 0, y_prev_ = 0;
  bool started_ = false;
};

/// Filter a whole experiment: returns [z y, .., z^n y] (N x n) for output `output`,
/// or for input `input` when output < 0; output intersample is Foh. Convenience for
/// analysis and tests (the estimators stream instead of storing).
Eigen::MatrixXd svf_filter(const IdData& data, int n, double tau, int input, int output,
                           const std::optional<TransferFunction>& extra_filter = std::nullopt);

}  // namespace ctid
