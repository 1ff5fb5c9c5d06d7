// El-Shafey modal functions: modal-parameter estimation (Fourier recursion to j = n, and the
// discrete least squares on constant-input windows) and the free-response data-matrix pole method, at
// N = 1e4 .. 1e6 samples. Must be linear in N.
// Run: build/bench/bench_modal --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <sys/resource.h>

#include <benchmark/benchmark.h>

#include "ctid/ctid.hpp"

namespace {
const ctid::TransferFunction kS3(Eigen::VectorXd{{13.0, 52.0}}, Eigen::VectorXd{{1.0, 4.0, 30.0, 52.0}});
constexpr double kTs = 1e-3;
const Eigen::Vector3d kShifts(0.04, 0.08, 0.12);

void peak_rss(benchmark::State& state) {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  state.counters["peak_rss_MB"] = ru.ru_maxrss / 1024.0;
}

// Fourier functions (8) on one window covering the record, p_j and q_j for j = 0..3, two-sinusoid input.
void BM_ModalFourier(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const ctid::InputGenerator g = ctid::InputGenerator::sinusoid(4.0, 1.0) + ctid::InputGenerator::sinusoid(1.5, 0.0, 0.7);
  const Eigen::VectorXd t = ctid::time_grid(kTs, N);
  const ctid::IdData d(g(t), ctid::lsim(kS3.to_state_space(), g, t), kTs);
  ctid::ModalOptions o{.shifts = kShifts, .max_order = 3, .functions = 8};
  for (auto _ : state) {
    auto r = ctid::modal_estimate(d, g, o);
    benchmark::DoNotOptimize(r.parameters.values.data());
  }
  state.SetItemsProcessed(state.iterations() * N);
  peak_rss(state);
}
BENCHMARK(BM_ModalFourier)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

// Discrete least squares on the validity windows of a piecewise-constant input (level every 0.5 s).
void BM_ModalDiscrete(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const Eigen::VectorXd u = ctid::prbs(N, {.register_length = 10, .clock_period = 500});
  const ctid::IdData d(u, ctid::lsim(kS3, u, ctid::time_grid(kTs, N)), kTs);
  ctid::ModalOptions o{.shifts = kShifts, .basis = ctid::ModalBasis::Discrete};
  o.windows = ctid::piecewise_constant_windows(d, kShifts(2));
  for (auto _ : state) {
    auto r = ctid::modal_estimate(d, d.u(), o);
    benchmark::DoNotOptimize(r.parameters.values.data());
  }
  state.SetItemsProcessed(state.iterations() * N);
  peak_rss(state);
}
BENCHMARK(BM_ModalDiscrete)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

// Theorem 4.3 on a lightly damped 4th-order free response, as many instant pairs as the record holds
// (interval = spacing = 20 samples, Simpson).
void BM_FreeResponsePoles(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const ctid::TransferFunction sys(Eigen::VectorXd{{1.0}},
                                   ctid::Polynomial::from_roots(Eigen::Vector4cd({-0.001, 2}, {-0.001, -2}, {-0.002, 5},
                                                                                  {-0.002, -5}))
                                       .coefficients());
  const Eigen::VectorXd y = ctid::lsim(ctid::phase_variable_form(sys), ctid::InputGenerator::constant(0.0),
                                       ctid::time_grid(kTs, N), Eigen::Vector4d(1, 0, 0, 0));
  ctid::FreeResponseOptions o{.shifts = Eigen::Vector4d(40, 80, 120, 160) * kTs, .start = 0.16, .interval = 0.02,
                              .spacing = 0.02, .pairs = (N - 1 - 160 - 20) / 20 + 1};
  for (auto _ : state) {
    auto r = ctid::free_response_poles(y, kTs, o);
    benchmark::DoNotOptimize(r.poles.data());
  }
  state.SetItemsProcessed(state.iterations() * N);
  peak_rss(state);
}
BENCHMARK(BM_FreeResponsePoles)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();
