// ctid — excitation signals for identification experiments, and measurement noise.
// Every random signal takes an explicit seed: the same arguments give the same samples.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Dense>

namespace ctid {

struct PrbsOptions {
  int register_length = 10;   ///< n in [2, 32]; period 2^n - 1 bits
  int clock_period = 1;       ///< samples each bit is held (>= 1)
  double low = -1.0, high = 1.0;  ///< the two levels
  std::uint32_t initial_state = 1;  ///< non-zero register seed (only the low n bits are used)
};
/// Maximum-length pseudo-random binary sequence of n_samples samples from a Fibonacci
/// LFSR with a primitive feedback polynomial; one period is (2^n - 1) * clock_period
/// samples. Throws InvalidArgument for n outside [2, 32], clock_period < 1,
/// n_samples < 1 or an initial state that is zero in the low n bits.
Eigen::VectorXd prbs(int n_samples, const PrbsOptions& options = {});

/// Random binary signal: independent ±amplitude values (equal probability), each held
/// for `clock_period` samples.
Eigen::VectorXd random_binary(int n_samples, std::uint64_t seed, int clock_period = 1, double amplitude = 1.0);

/// Sum of sinusoids sampled at t: sum_i a_i sin(w_i t + phi_i). `phases` may be empty
/// (Schroeder phases phi_i = -pi i (i-1)/K are used, which keep the crest factor low).
Eigen::VectorXd multisine(const Eigen::VectorXd& t, const std::vector<double>& frequencies_rad_s,
                          const std::vector<double>& amplitudes, std::vector<double> phases = {});

/// Piecewise-constant signal at times t: value levels[i] from step_times[i] on
/// (0 before step_times[0]). step_times must be increasing; sizes equal.
Eigen::VectorXd steps(const Eigen::VectorXd& t, const std::vector<double>& step_times, const std::vector<double>& levels);

/// White Gaussian noise of the given standard deviation.
Eigen::VectorXd white_noise(int n_samples, double stddev, std::uint64_t seed);

/// x + e, with e white Gaussian and var(e) = var(x) / 10^(snr_db/10), where var is the
/// variance about the mean of x. Throws InvalidArgument for a constant x.
Eigen::VectorXd add_noise_snr(const Eigen::VectorXd& x, double snr_db, std::uint64_t seed);

}  // namespace ctid
