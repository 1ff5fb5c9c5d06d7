// LSSVF fit time: n = 2 and 4 at N = 1e4 .. 1e7 (fixed tau; includes the
// output-error fit report), and the RLS-SVF update cost for n = 2 and 4.
// Run: build/bench/bench_lssvf --benchmark_min_time=0.5
#include <benchmark/benchmark.h>

#include "ctid/ctid.hpp"

namespace {
ctid::IdData make_data(int n, int N) {
  const ctid::TransferFunction g =
      n == 2 ? ctid::TransferFunction(Eigen::VectorXd{{1.0, 3.0}}, Eigen::VectorXd{{1.0, 1.2, 4.0}})
             : ctid::TransferFunction(Eigen::VectorXd{{1.0, 3.0}}, (ctid::Polynomial{1.0, 1.2, 4.0} * ctid::Polynomial{1.0, 3.0, 25.0}).coefficients());
  ctid::PrbsOptions po;
  po.register_length = 16;
  po.clock_period = 10;
  const Eigen::VectorXd u = ctid::prbs(N, po);
  return ctid::IdData(u, ctid::lsim(g, u, ctid::time_grid(0.01, N)), 0.01);
}

void BM_Lssvf(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int N = static_cast<int>(state.range(1));
  const ctid::IdData d = make_data(n, N);
  ctid::LssvfOptions o;
  o.tau = 0.3;
  for (auto _ : state) {
    auto r = ctid::lssvf(d, {2, n, 0}, o);
    benchmark::DoNotOptimize(r.parameters.values.data());
  }
  state.SetItemsProcessed(state.iterations() * N);
}
BENCHMARK(BM_Lssvf)
    ->ArgsProduct({{2, 4}, {10000, 100000, 1000000, 10000000}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

void BM_RlsSvfUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int N = 100000;
  const ctid::IdData d = make_data(n, N);
  ctid::RlsSvfOptions o;
  o.tau = 0.3;
  ctid::RlsSvf rls({n, n, 0}, o);
  int k = 0;
  double t0 = 0;
  for (auto _ : state) {
    rls.update(t0 + d.time(k), d.u()(k, 0), d.y()(k, 0));
    if (++k == N) {
      k = 0;
      t0 += d.time(N - 1) + 0.01;
    }
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RlsSvfUpdate)->Arg(2)->Arg(4);
}  // namespace

BENCHMARK_MAIN();
