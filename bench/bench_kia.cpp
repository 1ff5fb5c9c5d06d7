// Kernel Invariance Algorithm stage times on the published NARX model (34) of Billings & Li:
// H_1 at 500 points, H_2 on a 70 x 70 grid, the linear stage (500 points, GLS order 10) and the quadratic
// stage (70 point pairs, GLS order 3); the output-error refinement (nde_oe) of the reconstructed equation of
// Billings & Li (33) on 1000 samples of its 20 dB record.
// Run: build/bench/bench_kia --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <random>

#include "ctid/ctid.hpp"

namespace {
ctid::NarxModel bl34() {  // Billings & Li (1999) model (34) as printed
  return ctid::read_narx_json(std::string(CTID_EXAMPLES_DATA_DIR) + "/bl34_narx.json");
}

void BM_GfrfH1_500(benchmark::State& state) {
  const auto m = bl34();
  const auto s = ctid::kia_points({});
  for (auto _ : state)
    for (const auto& p : s) benchmark::DoNotOptimize(ctid::narx_gfrf_ct(m, {p}));
}
BENCHMARK(BM_GfrfH1_500)->Unit(benchmark::kMillisecond);

void BM_GfrfH2_70x70(benchmark::State& state) {
  const auto m = bl34();
  const auto s = ctid::kia_points({.region = ctid::KiaRegion::ImaginaryAxis, .count = 70, .max = 220, .grid = true});
  for (auto _ : state)
    for (const auto& a : s)
      for (const auto& b : s) benchmark::DoNotOptimize(ctid::narx_gfrf_ct(m, {a, b}));
}
BENCHMARK(BM_GfrfH2_70x70)->Unit(benchmark::kMillisecond);

void BM_KiaLinear(benchmark::State& state) {
  const auto m = bl34();
  double iters = 0;
  for (auto _ : state) {
    auto r = ctid::kia_linear(m, {.zoh = false});
    iters = r.diagnostics.get(ctid::diagnostic::gls_iterations);
  }
  state.counters["gls_iterations"] = iters;
}
BENCHMARK(BM_KiaLinear)->Unit(benchmark::kMillisecond);

void BM_KiaQuadratic(benchmark::State& state) {
  const auto m = bl34();
  const auto lin = ctid::kia_linear(m, {.zoh = false});
  double iters = 0;
  for (auto _ : state) {
    auto r = ctid::kia_quadratic(
        m, lin.model, {.candidates = {ctid::NdeTerm::parse("y^2"), ctid::NdeTerm::parse("y*Dy")}, .zoh = false});
    iters = r.diagnostics.get(ctid::diagnostic::gls_iterations);
  }
  state.counters["gls_iterations"] = iters;
}
BENCHMARK(BM_KiaQuadratic)->Unit(benchmark::kMillisecond);
void BM_NdeOe_1000(benchmark::State& state) {
  using namespace ctid;
  std::vector<NdeTerm> t;
  for (const char* s : {"y", "Dy", "D^2y", "u", "y^2", "y*Dy"}) t.push_back(NdeTerm::parse(s));
  const NdeModel truth(t, (Eigen::VectorXd(6) << 1, 0.002, 1e-4, -1, 0.1, -0.006).finished());
  std::mt19937 rng(1);
  std::bernoulli_distribution coin(0.5);
  Eigen::VectorXd u(1000);
  for (auto& v : u) v = coin(rng) ? 1.0 : -1.0;
  const IdData d(u, add_noise_snr(truth.simulate(u, time_grid(0.0025, 1000), Intersample::Zoh, {}, 1e-11).y, 20.0, 101),
                 0.0025);
  Eigen::VectorXd c = truth.coefficients();
  c.tail(5) *= 1.1;  // a KIA-like start, every coefficient 10 % off
  const NdeModel start(t, c);
  double iters = 0;
  for (auto _ : state) iters = nde_oe(d, start).summary.iterations;
  state.counters["lm_iterations"] = iters;
}
BENCHMARK(BM_NdeOe_1000)->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();
