"""Benchmark (issue 15): one grey-box fit of a 25 000-sample record — a mass on a spring with viscous and smoothed
Coulomb friction, 4 parameters and one initial state, from a start 20 % off — timed on one core (median of 5).
Run: PYTHONPATH=build/python /usr/bin/python3 bench/greybox_friction.py   (numbers go to docs/benchmarks.md)."""
import statistics
import time

import numpy as np

import ctid

MODEL = {"inputs": ["u"], "states": ["q", "v"], "outputs": {"y": "q"},
         "parameters": {"k": 2.0, "c": 0.4, "fc": {"value": 0.3, "lower": 0}, "m": {"value": 1.0, "lower": 0.01}},
         "equations": {"q": "v", "v": "(u - k*q - c*v - fc*tanh(v/0.05))/m"}, "initial": {"q": "estimate", "v": 0}}
START = dict(MODEL, parameters={"k": 2.4, "c": 0.5, "fc": {"value": 0.24, "lower": 0}, "m": {"value": 1.2, "lower": 0.01}})

rng = np.random.default_rng(1)
n, ts = 25000, 0.01
u = np.repeat(rng.uniform(-3, 3, n // 150 + 1), 150)[:n].reshape(-1, 1)
sim = ctid.greybox_model(MODEL).simulate(u, np.arange(n) * ts, x0=[0.1, 0.0], rtol=1e-10)
data = ctid.IdData(u, sim.y + rng.normal(0, 0.01, sim.y.shape), ts)
times = []
for _ in range(5):
    t0 = time.perf_counter()
    r = ctid.greybox(data, START)
    times.append(time.perf_counter() - t0)
assert r.usable(), r.why_not_usable()
print(f"greybox friction, N = {n}: median {statistics.median(times):.3f} s over 5 fits "
      f"({r.summary.iterations} iterations; k = {r.parameters.values[0]:.4f}, fc = {r.parameters.values[2]:.4f})")
