// FROLS on SysIdentPy's benchmark problem: polynomial degree 2, input and output lags 1..16
// (561 candidates with the constant), 20 terms, N = 1e3 .. 1e6; and the same with AIC over the 20 model
// sizes read off the one greedy pass.
// Run: build/bench/bench_frols --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <sys/resource.h>

#include <benchmark/benchmark.h>

#include "ctid/ctid.hpp"
#include "narx_record.hpp"

namespace {

void run(benchmark::State& state, ctid::InformationCriterion c) {
  const int N = static_cast<int>(state.range(0));
  const ctid::IdData d = bench::narx_record(N);
  const auto cand = ctid::narx_candidates(2, 16, 16);
  for (auto _ : state) {
    auto r = ctid::frols(d, cand, {.max_terms = 20, .criterion = c});
    benchmark::DoNotOptimize(r.parameters.values.data());
  }
  state.SetItemsProcessed(state.iterations() * N);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  state.counters["peak_rss_MB"] = ru.ru_maxrss / 1024.0;
}

void BM_Frols20Terms(benchmark::State& state) { run(state, ctid::InformationCriterion::None); }
void BM_FrolsAic(benchmark::State& state) { run(state, ctid::InformationCriterion::Aic); }
BENCHMARK(BM_Frols20Terms)->Arg(1000)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrolsAic)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();
