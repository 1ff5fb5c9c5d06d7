"""Gawthrop & Wang (2005): compress a noisy record into a step response with error bands, then fit the
physical parameters of a known structure (runs in CI).

Question: a mass-spring-damper with unknown gain k, natural frequency w and damping z; what are they?
"""
import numpy as np

import ctid

truth = ctid.TransferFunction([4.0], [1.0, 0.8, 4.0])  # k = 1, w = 2 rad/s, z = 0.2
u = ctid.prbs(2000, register_length=9, clock_period=3)
t = ctid.time_grid(0.02, 2000)
data = ctid.IdData.from_arrays(u, ctid.add_noise_snr(truth.simulate(u, t), 20.0, 3), ts=0.02)

compressed = ctid.fsf(data, T=20.0, n=31)  # 20 s settling time, 31 frequency-sampling filters
ts_ = np.array([1.0, 2.0, 5.0, 20.0])
for tt, s, sd in zip(ts_, compressed.model.step(ts_), compressed.model.step_std(ts_)):
    print(f"step response at {tt:4.1f} s: {s:.3f} +- {2 * sd:.3f} (true {truth.step(np.array([tt]))[0]:.3f})")

model = ctid.PhysicalModel("k*w^2/(s^2 + 2*z*w*s + w^2)", ["k", "w", "z"])
r = ctid.fit_physical_step(model, {"k": 0.5, "w": 1.0, "z": {"initial": 0.5, "lower": 0.0}}, compressed)
print(r)
assert abs(r.parameters["w"] - 2.0) < 0.1 and abs(r.parameters["z"] - 0.2) < 0.02
