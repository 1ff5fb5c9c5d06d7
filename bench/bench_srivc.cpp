// SRIVC / tfest / frequency-domain fit times and SRIVC scaling in N with peak memory.
// Run: build/bench/bench_srivc --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <sys/resource.h>

#include <benchmark/benchmark.h>

#include "ctid/ctid.hpp"

namespace {
const ctid::TransferFunction kRao(Eigen::VectorXd{{-6400.0, 1600.0}}, Eigen::VectorXd{{1.0, 5.0, 408.0, 416.0, 1600.0}});

ctid::IdData rao(int N) {
  const Eigen::VectorXd u = ctid::prbs(N, {.register_length = 16, .clock_period = 7});
  return ctid::IdData(u, ctid::add_noise_snr(ctid::lsim(kRao, u, ctid::time_grid(0.01, N)), 10.0, 1), 0.01);
}

double peak_rss_mb() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss / 1024.0;
}

void BM_SrivcRaoGarnier(benchmark::State& state) {
  // Set-up 1: PRBS register 10 held 7 samples, N = 7161, 10 dB.
  const int N = 7161;
  const Eigen::VectorXd u = ctid::prbs(N, {.register_length = 10, .clock_period = 7});
  const ctid::IdData d(u, ctid::add_noise_snr(ctid::lsim(kRao, u, ctid::time_grid(0.01, N)), 10.0, 1), 0.01);
  for (auto _ : state) {
    auto r = ctid::srivc(d, {2, 4, 0});
    benchmark::DoNotOptimize(r.parameters.values.data());
  }
}
BENCHMARK(BM_SrivcRaoGarnier)->Unit(benchmark::kMillisecond);

void BM_SrivcScaling(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const ctid::IdData d = rao(N);
  for (auto _ : state) {
    auto r = ctid::srivc(d, {2, 4, 0});
    benchmark::DoNotOptimize(r.parameters.values.data());
  }
  state.SetItemsProcessed(state.iterations() * N);
  state.counters["peak_rss_MB"] = peak_rss_mb();
}
BENCHMARK(BM_SrivcScaling)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_TfestRaoGarnier(benchmark::State& state) {
  const int N = 7161;
  const Eigen::VectorXd u = ctid::prbs(N, {.register_length = 10, .clock_period = 7});
  const ctid::IdData d(u, ctid::add_noise_snr(ctid::lsim(kRao, u, ctid::time_grid(0.01, N)), 10.0, 1), 0.01);
  for (auto _ : state) {
    auto r = ctid::tfest(d, {2, 4, 0});
    benchmark::DoNotOptimize(r.parameters.values.data());
  }
}
BENCHMARK(BM_TfestRaoGarnier)->Unit(benchmark::kMillisecond);

void BM_FrequencyFit(benchmark::State& state) {
  Eigen::VectorXd w(250);
  for (int k = 0; k < 250; ++k) w(k) = 0.1 * std::pow(1000.0, k / 249.0);
  Eigen::VectorXcd G = kRao.frequency_response(w);
  const Eigen::VectorXd e = ctid::white_noise(500, 1.5, 3);
  for (int k = 0; k < 250; ++k) G(k) += std::complex<double>(e(2 * k), e(2 * k + 1));
  const ctid::FrequencyData fd(w, G);
  for (auto _ : state) {
    auto r = ctid::tf_from_frequency(fd, {2, 4, 0});
    benchmark::DoNotOptimize(r.parameters.values.data());
  }
}
BENCHMARK(BM_FrequencyFit)->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();
