// Kernel Invariance Algorithm stage times (issue 6) on the published NARX model (34) of Billings & Li:
// H_1 at 500 points, H_2 on a 70 x 70 grid, the linear stage (500 points, GLS order 10) and the quadratic
// stage (70 point pairs, GLS order 3).
// Run: build/bench/bench_kia --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "ctid/ctid.hpp"

namespace {
ctid::NarxModel bl34() {
  const std::vector<std::string> n = {
      "y(k-1)",  "y(k-8)",  "y(k-2)",          "u(k-2)",  "u(k-3)",  "u(k-5)",          "y(k-3)",  "u(k-4)",
      "y(k-3)*y(k-8)", "y(k-9)", "u(k-7)", "u(k-1)",  "y(k-12)", "u(k-6)", "y(k-7)*y(k-9)", "y(k-1)*y(k-2)",
      "u(k-8)",  "u(k-9)",  "y(k-13)",         "u(k-10)", "y(k-10)*y(k-11)", "u(k-11)", "y(k-11)", "y(k-5)",
      "y(k-10)", "y(k-7)*y(k-15)", "y(k-9)*y(k-14)", "u(k-12)", "y(k-16)", "y(k-2)*y(k-8)"};
  const std::vector<double> c = {0.22099,  -0.28266, 0.00073,  0.11415,  0.13593, 0.16375, 0.09909,  0.13737,
                                 0.02375,  0.08582,  0.13896,  0.04719,  -0.34567, 0.11822, -0.0840,  0.13378,
                                 0.09797,  0.08407,  -0.06159, 0.07489,  -0.09918, 0.03417, -0.09156, 0.1092,
                                 0.08644,  0.10144,  -0.10199, 0.01344,  -0.02788, -0.09730};
  std::vector<ctid::NarxTerm> t;
  for (const auto& s : n) t.push_back(ctid::NarxTerm::parse(s));
  return ctid::NarxModel(t, Eigen::Map<const Eigen::VectorXd>(c.data(), static_cast<Eigen::Index>(c.size())), 0.0025);
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
