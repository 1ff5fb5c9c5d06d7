// ctid — frequency-sampling-filter (FSF) model of Gawthrop & Wang (2005), "Data compression
// for estimation of the physical parameters of stable and unstable linear systems",
// Automatica 41(8), eqs (1)-(13) (reconstructed pole e^{j2 pi k/N}).
//
//   Gbar(z) = sum_{k=-m..m} theta_k Hbar_k(z),  Hbar_k(z) = (1/N)(1 - z^{-N})/(1 - e^{j2 pi k/N} z^{-1}),
//   N = T/Delta, n = 2m + 1 (odd), theta_{-k} = conj(theta_k) for real data.
// theta_k = Gbar(e^{j2 pi k/N}) are samples of the discrete frequency response at w = k Omega,
// Omega = 2 pi/T. Stored as the real vector [theta_0, Re theta_1, Im theta_1, .., Re theta_m, Im theta_m].
// Continuous-time interpretation (fast sampling, g_i ~ Delta g(i Delta)):
//   impulse g(t) = sum_k theta_k e^{jk Omega t}/T on [0, T), 0 after;
//   step y_s(t) = theta_0 t/T + sum_{k=1}^m 2 Re[theta_k (e^{jk Omega t} - 1)/(jk Omega T)], y_s(t >= T) = y_s(T) = theta_0.
// When the model was fitted to exponentially windowed data (shift a), these are the responses
// of the shifted system G(s + a).
#pragma once

#include <complex>

#include <Eigen/Dense>

namespace ctid {

class FsfModel {
 public:
  FsfModel() = default;
  /// delta > 0 (s), N >= 1 samples per window, n odd with 1 <= n <= N, theta of length n
  /// (real parameterisation), covariance n x n or empty, shift a >= 0 the window it was
  /// fitted with. Throws InvalidArgument.
  FsfModel(double delta, int N, int n, Eigen::VectorXd theta, Eigen::MatrixXd covariance = {}, double shift = 0.0);

  double delta() const { return delta_; }
  int N() const { return N_; }
  int n() const { return n_; }
  int m() const { return (n_ - 1) / 2; }
  double T() const { return delta_ * N_; }
  double omega() const;   ///< 2 pi / T
  double shift() const { return shift_; }
  const Eigen::VectorXd& theta() const { return theta_; }
  const Eigen::MatrixXd& covariance() const { return cov_; }
  /// Complex theta_k for k in [-m, m].
  std::complex<double> theta_k(int k) const;

  /// Filter k evaluated at z = e^{j w Delta} (the removable 0/0 at w = k Omega gives 1).
  std::complex<double> filter_response(int k, double w) const;
  /// Gbar(e^{j w Delta}) at each w (rad/s, below the Nyquist frequency pi/Delta).
  Eigen::VectorXcd frequency_response(const Eigen::VectorXd& w) const;
  Eigen::VectorXd step_response(const Eigen::VectorXd& t) const;
  Eigen::VectorXd impulse_response(const Eigen::VectorXd& t) const;
  /// Standard deviation of the step response at t from the parameter covariance (the step
  /// response is linear in theta); empty covariance -> NaN.
  Eigen::VectorXd step_response_std(const Eigen::VectorXd& t) const;
  /// Standard deviation of the impulse response at t (linear in theta); NaN without covariance.
  Eigen::VectorXd impulse_response_std(const Eigen::VectorXd& t) const;
  /// Standard deviations of the real and imaginary parts of Gbar(e^{j w Delta}) at each w,
  /// returned as std_re + j std_im (both are linear in theta); NaN without covariance.
  Eigen::VectorXcd frequency_response_std(const Eigen::VectorXd& w) const;
  /// Row vector b(t) with impulse_response(t) = b(t) . theta.
  Eigen::RowVectorXd impulse_basis(double t) const;
  /// The discrete model's impulse response g_i = sum_k theta_k e^{j2 pi k i/N}/N, i = 0..N-1.
  Eigen::VectorXd discrete_impulse_response() const;
  /// Output of the discrete model for input u (from rest): y_i = sum_{l<N} g_l u_{i-l}.
  Eigen::VectorXd simulate(const Eigen::VectorXd& u) const;

  /// Row vector r(t) with step_response(t) = r(t) . theta.
  Eigen::RowVectorXd step_basis(double t) const;

 private:
  double delta_ = 1.0, shift_ = 0.0;
  int N_ = 1, n_ = 1;
  Eigen::VectorXd theta_;
  Eigen::MatrixXd cov_;
};

}  // namespace ctid
