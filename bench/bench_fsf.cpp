// Gawthrop-Wang stage 1: FSF compression of N = 1e6 samples, T/Delta = 1000, n = 21.
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
// Unstable circuit stand-in (Gawthrop & Wang 2005, §5) with M samples at 10 ms: two-stage route
// (FSF compression + LM on the compressed step response) versus output error on the raw record.
ctid::IdData circuit(int M) {
  const double Ts = 0.01;
  const ctid::StateSpace ss = ctid::TransferFunction(Eigen::VectorXd{{1.0}}, Eigen::VectorXd{{1.0, 0.0, -1.0}}).to_state_space();
  const ctid::Discretization D = ctid::discretize(ss.A(), ss.B(), Ts);
  const Eigen::VectorXd e = ctid::white_noise(M, 0.05, 1);
  Eigen::VectorXd u(M), y(M), x = Eigen::VectorXd::Zero(2);
  double d = 0, yprev = 0;
  for (int i = 0; i < M; ++i) {
    const double w = (i / 150) % 3 == 0 ? 0.5 : -0.5;
    y(i) = (ss.C() * x)(0) + e(i);
    d = (0.1 * d + (y(i) - yprev)) / (0.1 + Ts);
    yprev = y(i);
    u(i) = 3.0 * (w - y(i) - d);
    x = D.Phi * x + D.Gamma0 * u(i);
  }
  return ctid::IdData(u, y, Ts);
}

void BM_TwoStagePhysical(benchmark::State& state) {
  const ctid::IdData d = circuit(static_cast<int>(state.range(0)));
  const ctid::PhysicalModel m("k1/(s^2 - k2)", {"k1", "k2"});
  double stage1 = 0, stage2 = 0;
  for (auto _ : state) {
    const auto c = ctid::fsf(d, {.T = 8.0, .n = 21, .a = 2.0});
    const auto r = ctid::fit_physical_step(m, {{"k1", 2.0}, {"k2", 0.0}}, c.model);
    stage1 += c.summary.seconds;
    stage2 += r.summary.seconds;
    benchmark::DoNotOptimize(r.parameters.values.data());
  }
  state.counters["stage1_s"] = stage1 / state.iterations();
  state.counters["stage2_s"] = stage2 / state.iterations();
}
BENCHMARK(BM_TwoStagePhysical)->Arg(1000000)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_RawOutputErrorPhysical(benchmark::State& state) {
  const ctid::IdData d = circuit(static_cast<int>(state.range(0)));
  const ctid::PhysicalModel m("k1/(s^2 - k2)", {"k1", "k2"});
  for (auto _ : state) {
    const auto r = ctid::fit_physical_raw(m, {{"k1", 2.0}, {"k2", 0.0}}, d, 2.0);
    benchmark::DoNotOptimize(r.parameters.values.data());
    state.counters["lm_iterations"] = r.summary.iterations;
  }
}
BENCHMARK(BM_RawOutputErrorPhysical)->Arg(1000000)->Unit(benchmark::kMillisecond)->Iterations(2);
}  // namespace

BENCHMARK_MAIN();
