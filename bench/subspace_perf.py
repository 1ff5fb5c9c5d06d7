"""Benchmark: the subspace start on a 3-input 3-output record, nx = 8, N = 1e5 samples (Ts = 0.01 s,
held random levels, noise-free), one core, median of 3 runs; and the largest matrix it forms.
Run: PYTHONPATH=build/python taskset -c 0 /usr/bin/python3 bench/subspace_perf.py   (numbers: docs/benchmarks.md)."""
import statistics
import time

import numpy as np

import ctid

rng = np.random.default_rng(1)
nx, nu, ny, N, ts = 8, 3, 3, 100000, 0.01
A = rng.standard_normal((nx, nx))
A -= (np.max(np.linalg.eigvals(A).real) + 0.5) * np.eye(nx)  # stable, slowest pole at -0.5 1/s
system = ctid.StateSpace(A, rng.standard_normal((nx, nu)), rng.standard_normal((ny, nx)), np.zeros((ny, nu)))
u = np.repeat(rng.uniform(-1, 1, size=(N // 10 + 1, nu)), 10, axis=0)[:N]
y = np.array(ctid.simulate(system, ctid.IdData(u, np.zeros((N, ny)), ts))).reshape(N, ny)
data = ctid.IdData(u, y, ts)
for label, kw in (("discrete route (MOESP + logm)", {"route": "discrete"}),
                  ("lambda route, tau = 0.1 s given", {"route": "lambda", "tau": 0.1}),
                  ("lambda route, tau searched (8 values)", {"route": "lambda"})):
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        r = ctid.subspace(data, nx, **kw)
        times.append(time.perf_counter() - t0)
    r_ = nx + 2
    m = 2 * r_ * (nu + ny) if kw["route"] == "discrete" else 2 * r_ * nu + r_ * ny
    print(f"{label}: {statistics.median(times):.2f} s (median of 3), fit {r.fit.fit_percent:.3f} %, "
          f"largest matrix: Gram {m} x {m}")
