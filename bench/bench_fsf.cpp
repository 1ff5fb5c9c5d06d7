// Gawthrop-Wang stage 1 (issue 4): FSF compression of N = 1e6 samples, T/Delta = 1000, n = 21.
// Run: build/bench/bench_fsf --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <sys/resource.h>

#include <benchmark/benchmark.h>

#include "ctid/ctid.hpp"

namespace {
void BM_FsfCompression(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const double Ts = 0.001;
  const ctid::TransferFunction g(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 4.0, 3.0}});
  const Eigen::VectorXd u = ctid::prbs(N, {.register_length = 20, .clock_period = 50});
  const ctid::IdData d(u, ctid::add_noise_snr(ctid::lsim(g, u, ctid::time_grid(Ts, N)), 20.0, 1), Ts);
  for (auto _ : state) {
    auto r = ctid::fsf(d, {.T = 1000 * Ts, .n = 21});
    benchmark::DoNotOptimize(r.parameters.values.data());
  }
  state.SetItemsProcessed(state.iterations() * N);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  state.counters["peak_rss_MB"] = ru.ru_maxrss / 1024.0;
}
BENCHMARK(BM_FsfCompression)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->Iterations(3);
}  // namespace

BENCHMARK_MAIN();
