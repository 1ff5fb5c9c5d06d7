"""Benchmark: multiple shooting of an unstable plant — the magnetic levitation of
python/examples/greybox_levitation.py (k i^2 / y^2, open-loop pole +44 1/s) from PD-loop records of 3 000, 12 000
and 24 000 samples (automatic segments of 25 samples: 120, 480 and 960 segments, 2 free states each), one core,
median of 3 fits. The Jacobian is block sparse and the normal equations are solved by Eigen's simplicial LDL^T.
Run: PYTHONPATH=build/python taskset -c 0 /usr/bin/python3 bench/greybox_shooting.py   (numbers: docs/benchmarks.md)."""
import statistics
import time

import numpy as np

import ctid

loop = {"inputs": ["r"], "states": ["y", "v"], "outputs": {"y": "y", "i": "3.132092 + 600*(y - r) + 9*v"},
        "parameters": {"k": 1e-4, "c": 2.0, "g": 9.81},
        "equations": {"y": "v", "v": "g - k*(3.132092 + 600*(y - r) + 9*v)^2/y^2 - c*v"},
        "initial": {"y": 0.01, "v": 0}}
plant = {"inputs": ["i"], "states": ["y", "v"], "outputs": {"y": "y"},
         "parameters": {"k": {"value": 1.3e-4, "lower": 0}, "c": {"value": 1.0, "lower": 0},
                        "g": {"value": 9.81, "fixed": True}},
         "equations": {"y": "v", "v": "g - k*i^2/y^2 - c*v"}, "initial": {"y": "estimate", "v": "estimate"}}
ts = 0.001
for n in (3000, 12000, 24000):
    t = np.arange(n) * ts
    r = (0.01 + 0.0015 * np.sin(2 * np.pi * 0.7 * t) + 0.001 * np.sin(2 * np.pi * 2.3 * t)).reshape(-1, 1)
    closed = ctid.greybox_model(loop).simulate(r, t, intersample="foh", rtol=1e-11)
    assert closed.ok(), closed.message
    gap = closed.y[:, 0] + np.random.default_rng(2).normal(0.0, 1e-5, n)
    data = ctid.IdData.from_arrays(closed.y[:, 1], gap, ts=ts, intersample="foh")
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        fit = ctid.greybox(data, plant)
        times.append(time.perf_counter() - t0)
    assert fit.usable(), fit.why_not_usable()
    k = fit.parameters.values[fit.parameters.names.index("k")]
    print(f"levitation, N = {n}: {int(fit.diagnostics.scalars['segments'])} segments, "
          f"{fit.summary.iterations} iterations, median {statistics.median(times):.2f} s (k = {k:.6g})")
