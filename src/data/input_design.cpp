#include "ctid/data/input_design.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
// Feedback taps (1-based bit positions) of primitive polynomials, n = 2..32
// (the standard maximal-length LFSR table).
const std::vector<std::vector<int>> kTaps = {
    {},           {},           {2, 1},        {3, 2},       {4, 3},        {5, 3},       {6, 5},
    {7, 6},       {8, 6, 5, 4}, {9, 5},        {10, 7},      {11, 9},       {12, 6, 4, 1}, {13, 4, 3, 1},
    {14, 5, 3, 1}, {15, 14},    {16, 15, 13, 4}, {17, 14},   {18, 11},      {19, 6, 2, 1}, {20, 17},
    {21, 19},     {22, 21},     {23, 18},      {24, 23, 22, 17}, {25, 22},  {26, 6, 2, 1}, {27, 5, 2, 1},
    {28, 25},     {29, 27},     {30, 6, 4, 1}, {31, 28},     {32, 22, 2, 1}};
}  // namespace

Eigen::VectorXd prbs(int n_samples, const PrbsOptions& o) {
  CTID_REQUIRE(o.register_length >= 2 && o.register_length <= 32,
               "prbs: register_length must be in [2, 32] (got {})", o.register_length);
  CTID_REQUIRE(o.clock_period >= 1, "prbs: clock_period must be >= 1 sample (got {})", o.clock_period);
  CTID_REQUIRE(n_samples >= 1, "prbs: n_samples must be >= 1 (got {})", n_samples);
  const int n = o.register_length;
  const std::uint64_t mask = (n == 32) ? 0xFFFFFFFFull : ((1ull << n) - 1);
  std::uint64_t state = o.initial_state & mask;
  CTID_REQUIRE(state != 0, "prbs: initial_state must be non-zero in its low {} bits (got {})", n, o.initial_state);
  const auto& taps = kTaps[n];
  Eigen::VectorXd out(n_samples);
  int k = 0;
  while (k < n_samples) {
    const int bit = static_cast<int>(state & 1u);
    // Fibonacci LFSR on bits numbered 1..n from the output end.
    std::uint64_t fb = 0;
    for (int t : taps) fb ^= (state >> (n - t)) & 1u;
    state = (state >> 1) | (fb << (n - 1));
    for (int c = 0; c < o.clock_period && k < n_samples; ++c, ++k) out(k) = bit ? o.high : o.low;
  }
  return out;
}

Eigen::VectorXd random_binary(int n_samples, std::uint64_t seed, int clock_period, double amplitude) {
  CTID_REQUIRE(n_samples >= 1, "random_binary: n_samples must be >= 1 (got {})", n_samples);
  CTID_REQUIRE(clock_period >= 1, "random_binary: clock_period must be >= 1 (got {})", clock_period);
  std::mt19937_64 rng(seed);
  Eigen::VectorXd out(n_samples);
  double v = 0;
  for (int k = 0; k < n_samples; ++k) {
    if (k % clock_period == 0) v = (rng() >> 63) ? amplitude : -amplitude;
    out(k) = v;
  }
  return out;
}

Eigen::VectorXd multisine(const Eigen::VectorXd& t, const std::vector<double>& w, const std::vector<double>& a,
                          std::vector<double> phases) {
  CTID_REQUIRE(!w.empty(), "multisine: at least one frequency is needed");
  CTID_REQUIRE(a.size() == w.size(), "multisine: {} frequencies but {} amplitudes", w.size(), a.size());
  const std::size_t K = w.size();
  if (phases.empty()) {
    phases.resize(K);
    for (std::size_t i = 0; i < K; ++i) phases[i] = -std::numbers::pi * double(i) * double(i + 1) / double(K);
  }
  CTID_REQUIRE(phases.size() == K, "multisine: {} frequencies but {} phases", K, phases.size());
  Eigen::VectorXd out = Eigen::VectorXd::Zero(t.size());
  for (std::size_t i = 0; i < K; ++i) out.array() += a[i] * (w[i] * t.array() + phases[i]).sin();
  return out;
}

Eigen::VectorXd steps(const Eigen::VectorXd& t, const std::vector<double>& times, const std::vector<double>& levels) {
  CTID_REQUIRE(times.size() == levels.size(), "steps: {} step times but {} levels", times.size(), levels.size());
  for (std::size_t i = 1; i < times.size(); ++i)
    CTID_REQUIRE(times[i] > times[i - 1], "steps: step times must increase (t[{}] = {} after {})", i, times[i], times[i - 1]);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(t.size());
  for (Eigen::Index k = 0; k < t.size(); ++k)
    for (std::size_t i = 0; i < times.size(); ++i)
      if (t(k) >= times[i]) out(k) = levels[i];
  return out;
}

Eigen::VectorXd white_noise(int n_samples, double stddev, std::uint64_t seed) {
  CTID_REQUIRE(n_samples >= 0, "white_noise: n_samples must be >= 0 (got {})", n_samples);
  CTID_REQUIRE(stddev >= 0 && std::isfinite(stddev), "white_noise: stddev must be finite and >= 0 (got {})", stddev);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  Eigen::VectorXd e(n_samples);
  for (int k = 0; k < n_samples; ++k) e(k) = stddev * nd(rng);
  return e;
}

Eigen::VectorXd add_noise_snr(const Eigen::VectorXd& x, double snr_db, std::uint64_t seed) {
  CTID_REQUIRE(std::isfinite(snr_db), "add_noise_snr: SNR must be finite (got {} dB)", snr_db);
  CTID_REQUIRE(x.size() >= 2, "add_noise_snr: need at least 2 samples (got {})", x.size());
  const double var = (x.array() - x.mean()).square().mean();
  CTID_REQUIRE(var > 0, "add_noise_snr: the signal is constant (variance 0), SNR is undefined");
  const double sd = std::sqrt(var / std::pow(10.0, snr_db / 10.0));
  return x + white_noise(static_cast<int>(x.size()), sd, seed);
}

}  // namespace ctid
