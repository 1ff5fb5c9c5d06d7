// Kernel Invariance Algorithm stage times (issue 6) on the published NARX model (34) of Billings & Li:
// H_1 at 500 points, H_2 on a 70 x 70 grid, the linear stage (500 points, GLS order 10) and the quadratic
// stage (70 point pairs, GLS order 3).
// Run: build/bench/bench_kia --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "ctid/ctid.hpp"

namespace {
ctid::NarxModel bl34() {  // Billings & Li (1999) model (34) as printed (SEEDS-SPEC BL.3)
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
    iters = r.diagnostics.scalars["gls_iterations"];
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
    iters = r.diagnostics.scalars["gls_iterations"];
  }
  state.counters["gls_iterations"] = iters;
}
BENCHMARK(BM_KiaQuadratic)->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();
