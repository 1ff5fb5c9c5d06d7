"""Benchmark: one grey-box fit of a 25 000-sample record — a mass on a spring with viscous and Coulomb
friction, 4 parameters and one initial state, from a start 20 % off — timed on one core (median of 5). Two friction
laws: smoothed, fc tanh(v/0.05), and the discontinuous fc sign(v) with stick-slip (the mass is at rest for part of
the record: located switchings, Filippov sliding while it sticks, sensitivity jumps; docs/methods/greybox.md).
Run: PYTHONPATH=build/python /usr/bin/python3 bench/greybox_friction.py   (numbers go to docs/benchmarks.md)."""
import statistics
import time

import numpy as np

import ctid


def model(law, k, c, fc, m):
    return {"inputs": ["u"], "states": ["q", "v"], "outputs": {"y": "q"},
            "parameters": {"k": k, "c": c, "fc": {"value": fc, "lower": 0}, "m": {"value": m, "lower": 0.01}},
            "equations": {"q": "v", "v": f"(u - k*q - c*v - fc*{law})/m"}, "initial": {"q": "estimate", "v": 0}}


n, ts = 25000, 0.01
for law, amplitude, fc in (("tanh(v/0.05)", 3.0, 0.3), ("sign(v)", 1.5, 0.5)):
    rng = np.random.default_rng(1)
    u = np.repeat(rng.uniform(-amplitude, amplitude, n // 150 + 1), 150)[:n].reshape(-1, 1)
    sim = ctid.greybox_model(model(law, 2.0, 0.4, fc, 1.0)).simulate(u, np.arange(n) * ts, x0=[0.1, 0.0], rtol=1e-10)
    at_rest = int(np.sum(np.abs(np.diff(sim.y[:, 0])) < 1e-12))
    data = ctid.IdData(u, sim.y + rng.normal(0, 0.01, sim.y.shape), ts)
    start = model(law, 2.4, 0.5, 0.8 * fc, 1.2)
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        r = ctid.greybox(data, start)
        times.append(time.perf_counter() - t0)
    assert r.usable(), r.why_not_usable()
    print(f"greybox friction {law}, N = {n} ({at_rest} samples at rest): median {statistics.median(times):.3f} s over "
          f"5 fits ({r.summary.iterations} iterations; k = {r.parameters.values[0]:.4f}, fc = {r.parameters.values[2]:.4f})")
