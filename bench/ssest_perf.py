"""Benchmark: ssest on a 3-input 3-output record, nx = 8, N = 1e5 samples (Ts = 0.01 s, held random
levels, 20 dB of white noise on each output), one core, median of 3 runs: the subspace start (tau searched, and tau
given) and the output-error refinement (time, iterations), the peak memory of the process, and the accuracy of the
modes. Two systems: four well-separated modes (wn 0.5, 1.3, 3, 7 rad/s; zeta 0.1, 0.3, 0.05, 0.5; random B, C) and
the random A of bench/subspace_perf.py (poles from -0.5 to -5.7 1/s, some nearly cancelled by zeros).
Run: PYTHONPATH=build/python taskset -c 0 /usr/bin/python3 bench/ssest_perf.py   (numbers: docs/benchmarks.md)."""
import resource
import statistics
import time

import numpy as np

import ctid

nx, nu, ny, N, ts = 8, 3, 3, 100000, 0.01


def modal_system(rng):
    A = np.zeros((nx, nx))
    for i, (wn, z) in enumerate(zip((0.5, 1.3, 3.0, 7.0), (0.1, 0.3, 0.05, 0.5))):
        s, w = -z * wn, wn * np.sqrt(1 - z * z)
        A[2 * i:2 * i + 2, 2 * i:2 * i + 2] = [[s, w], [-w, s]]
    return ctid.StateSpace(A, rng.standard_normal((nx, nu)), rng.standard_normal((ny, nx)), np.zeros((ny, nu)))


def random_system(rng):
    A = rng.standard_normal((nx, nx))
    A -= (np.max(np.linalg.eigvals(A).real) + 0.5) * np.eye(nx)
    return ctid.StateSpace(A, rng.standard_normal((nx, nu)), rng.standard_normal((ny, nx)), np.zeros((ny, nu)))


def pole_error(truth, model):
    p, q = truth.poles(), model.poles()
    return max(min(abs(a - b) / abs(a) for b in q) for a in p)


def median_time(f, runs=3):
    times, out = [], None
    for _ in range(runs):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


for name, make in (("four modes", modal_system), ("random A", random_system)):
    rng = np.random.default_rng(1)
    system = make(rng)
    u = np.repeat(rng.uniform(-1, 1, size=(N // 10 + 1, nu)), 10, axis=0)[:N]
    y = np.array(ctid.simulate(system, ctid.IdData(u, np.zeros((N, ny)), ts))).reshape(N, ny)
    y += rng.standard_normal((N, ny)) * y.std(axis=0) / 10  # 20 dB
    data = ctid.IdData(u, y, ts)
    t_search, start = median_time(lambda: ctid.subspace(data, nx, estimate_d=False))
    tau = start.diagnostics.scalars["tau"]
    t_given, _ = median_time(lambda: ctid.subspace(data, nx, estimate_d=False, tau=tau))
    t_all, r = median_time(lambda: ctid.ssest(data, nx, estimate_d=False, start_tau=tau))
    print(f"{name}: subspace start {t_search:.2f} s (tau searched, chose {tau:.3g} s), {t_given:.2f} s (tau given); "
          f"ssest from the start with tau given {t_all:.2f} s, refinement {t_all - t_given:.2f} s, "
          f"{r.summary.iterations} iterations ({r.summary.termination}) after "
          f"{r.diagnostics.scalars.get('warm_up_iterations', 0):.0f} on the record's beginnings; fit {start.fit.fit_percent:.2f} -> "
          f"{r.fit.fit_percent:.2f} % (noise limit 90.05 %); largest relative pole error {pole_error(system, start.model):.3g} "
          f"-> {pole_error(system, r.model):.3g}")
print(f"peak resident memory of the process: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB "
      f"(the record: {N * (nu + ny) * 8 / 1e6:.1f} MB)")
