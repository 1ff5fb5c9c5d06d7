// Exact simulation throughput: order 2, 4, 8 at N = 1e4 .. 1e6, ZOH input, uniform Ts.
// Run: build/bench/bench_simulate --benchmark_min_time=0.5
#include <benchmark/benchmark.h>

#include "ctid/ctid.hpp"

namespace {
ctid::TransferFunction model_of_order(int n) {
  // Cascade of lightly damped second-order sections (first order if n is odd).
  ctid::Polynomial den{1.0};
  for (int k = 0; k < n / 2; ++k) den = den * ctid::Polynomial{1.0, 0.2 * (k + 1), double((k + 1) * (k + 1))};
  if (n % 2) den = den * ctid::Polynomial{1.0, 1.0};
  return ctid::TransferFunction(ctid::Polynomial{1.0}, den);
}

void BM_LsimZoh(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int N = static_cast<int>(state.range(1));
  const ctid::StateSpace ss = model_of_order(n).to_state_space();
  const Eigen::MatrixXd u = ctid::prbs(N, {});
  const Eigen::VectorXd t = ctid::time_grid(0.01, N);
  for (auto _ : state) {
    Eigen::MatrixXd y = ctid::lsim(ss, u, t, {ctid::Intersample::Zoh});
    benchmark::DoNotOptimize(y.data());
  }
  state.SetItemsProcessed(state.iterations() * N);
}
BENCHMARK(BM_LsimZoh)->ArgsProduct({{2, 4, 8}, {10000, 100000, 1000000}})->Unit(benchmark::kMillisecond);

void BM_LsimIrregular(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int N = 10000;
  const ctid::StateSpace ss = model_of_order(n).to_state_space();
  const Eigen::MatrixXd u = ctid::prbs(N, {});
  Eigen::VectorXd t = ctid::time_grid(0.01, N);
  for (int k = 1; k < N; ++k) t(k) += 0.004 * std::sin(1.7 * k);  // every interval different
  for (auto _ : state) {
    Eigen::MatrixXd y = ctid::lsim(ss, u, t, {ctid::Intersample::Zoh});
    benchmark::DoNotOptimize(y.data());
  }
  state.SetItemsProcessed(state.iterations() * N);
}
BENCHMARK(BM_LsimIrregular)->Arg(2)->Arg(4)->Arg(8)->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();
