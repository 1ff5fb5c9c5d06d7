// Time and memory per sample of SRIVC, OE, FROLS and lsim from N = 1e4 to 1e7 on one core: the time per
// sample should not grow with N (no allocation whose page faults grow with the record, no temporaries that fall out
// of cache); the peak memory of one fit above the record itself, in bytes per sample, shows the O(N) constant.
// Run: build/bench/bench_per_sample [N_MAX=10000000] [METHODS=srivc,oe,oe-start,frols,frols-passes,lsim,lsim-data,lsim-new]
//
// Problems: SRIVC and OE fit the Rao-Garnier system (-6400 s + 1600)/(s^4 + 5 s^3 + 408 s^2 + 416 s + 1600) (nb = 2,
// nf = 4) to a PRBS response at Ts = 10 ms with 10 dB output noise (oe-start: from a given start, the system with each
// coefficient 5 % off, so without the LSSVF and SRIVC start-up fits); lsim simulates it (ZOH) into a buffer reused
// from run to run (lsim_into with the sample times, which it reads to check they are uniform), lsim-data the same from
// the IdData record (its sampling period, no times read), lsim-new into a new vector each time (its pages faulted anew
// above glibc's mmap threshold); FROLS selects 5 terms of the 15 degree-2 candidates of lags 1..2 (constant included)
// for a NARX record of the same length. Each fit is repeated until 2 s have passed (at least twice); the least time
// is kept. "minor faults" are the page faults of one fit (getrusage), "peak" the process's resident high-water mark
// during one fit (reset through /proc/self/clear_refs before it) less the resident size before it.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>

#include "ctid/ctid.hpp"
#include "narx_record.hpp"

namespace {
const ctid::TransferFunction kRao(Eigen::VectorXd{{-6400.0, 1600.0}}, Eigen::VectorXd{{1.0, 5.0, 408.0, 416.0, 1600.0}});
const ctid::TransferFunction kStart(Eigen::VectorXd{{-6400.0 * 1.05, 1600.0 * 0.95}},
                                    Eigen::VectorXd{{1.0, 5.0 * 1.05, 408.0 * 0.95, 416.0 * 1.05, 1600.0 * 0.95}});

long status_kb(const char* key) {
  std::ifstream f("/proc/self/status");
  for (std::string line; std::getline(f, line);)
    if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + std::string(key).size() + 1);
  return -1;
}

// What one run did: its iterations and its passes over the record (SRIVC, FROLS: one per iteration; OE: every cost
// evaluation of its search, rejected steps included, and how many of them also made the Jacobian).
struct Work {
  int iterations = 1, passes = 1, jacobians = 0;
};

struct Measure {
  double seconds, faults, peak_mb;
  Work work;
};

Work iterations(int it) { return {it, it, 0}; }
Work oe_work(const ctid::Result<ctid::TransferFunction>& r) {
  return {r.summary.iterations, static_cast<int>(r.diagnostics.get(ctid::diagnostic::evaluations)),
          static_cast<int>(r.diagnostics.get(ctid::diagnostic::jacobian_evaluations))};
}

Measure measure(const std::function<Work()>& fit) {
  double best = 1e300, faults = 0, peak = 0;
  Work work;
  const auto start = std::chrono::steady_clock::now();
  for (int rep = 0; rep < 2 || std::chrono::steady_clock::now() - start < std::chrono::seconds(2); ++rep) {
    std::ofstream("/proc/self/clear_refs") << "5";  // VmHWM := VmRSS
    const long rss0 = status_kb("VmRSS:");
    rusage r0{}, r1{};
    getrusage(RUSAGE_SELF, &r0);
    const auto t0 = std::chrono::steady_clock::now();
    const Work w = fit();
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    getrusage(RUSAGE_SELF, &r1);
    if (dt < best) {
      best = dt;
      faults = static_cast<double>(r1.ru_minflt - r0.ru_minflt);
      peak = (status_kb("VmHWM:") - rss0) / 1024.0;
      work = w;
    }
  }
  return {best, faults, peak, work};
}

}  // namespace

int main(int argc, char** argv) {
  const long n_max = argc > 1 ? std::atol(argv[1]) : 10000000;
  const std::string only = argc > 2 ? "," + std::string(argv[2]) + "," : "";
  std::printf("| method | N | iterations | passes (with the Jacobian) | ms per fit | ns per sample | ns per sample and pass | minor faults per fit | "
              "peak MB above the record | bytes per sample |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (long N = 10000; N <= n_max; N *= 10) {
    const int n = static_cast<int>(N);
    const Eigen::VectorXd u = ctid::prbs(n, {.register_length = 16, .clock_period = 7});
    const Eigen::VectorXd t = ctid::time_grid(0.01, n);
    const ctid::IdData d(u, ctid::add_noise_snr(ctid::lsim(kRao, u, t), 10.0, 1), 0.01);
    const ctid::IdData nd = bench::narx_record(n);
    const auto cand = ctid::narx_candidates(2, 2, 2);
    Eigen::VectorXd ybuf(n);
    const std::pair<const char*, std::function<Work()>> cases[] = {
        {"srivc", [&] { return iterations(ctid::srivc(d, {2, 4, 0}).summary.iterations); }},
        {"oe", [&] { return oe_work(ctid::oe(d, {2, 4, 0})); }},
        {"oe-start", [&] {  // from a given start 5 % off: the search alone, without the LSSVF and SRIVC start
           return oe_work(ctid::oe(d, {2, 4, 0}, {.initial = kStart}));
         }},
        {"frols", [&] { return iterations(ctid::frols(nd, cand, {.max_terms = 5}).summary.iterations); }},
        {"frols-passes", [&] {  // the K + 2 passes route (auto takes the Gram matrix for these 15 candidates)
           return iterations(ctid::frols(nd, cand, {.max_terms = 5, .route = ctid::FrolsRoute::Passes}).summary.iterations);
         }},
        {"lsim", [&] {
           ctid::lsim_into(kRao, u, t, ctid::Intersample::Zoh, ybuf);
           return Work{};
         }},
        {"lsim-data", [&] {
           ctid::lsim_into(kRao, d, 0, ybuf);
           return Work{};
         }},
        {"lsim-new", [&] { return iterations(static_cast<int>(ctid::lsim(kRao, u, t).size() > 0)); }},
    };
    for (const auto& [name, fit] : cases) {
      if (!only.empty() && only.find("," + std::string(name) + ",") == std::string::npos) continue;
      const Measure m = measure(fit);
      const std::string passes = std::to_string(m.work.passes) +
                                 (m.work.jacobians ? " (" + std::to_string(m.work.jacobians) + ")" : "");
      std::printf("| %s | %.0e | %d | %s | %.1f | %.1f | %.1f | %.0f | %.1f | %.1f |\n", name, static_cast<double>(N),
                  m.work.iterations, passes.c_str(), 1e3 * m.seconds, 1e9 * m.seconds / N,
                  1e9 * m.seconds / N / std::max(1, m.work.passes), m.faults, m.peak_mb, m.peak_mb * 1048576.0 / N);
      std::fflush(stdout);
    }
  }
}
