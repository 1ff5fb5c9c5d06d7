"""Multiple shooting for an unstable plant (docs/methods/greybox.md#unstable-and-integrating-plants): a steel ball
held under an electromagnet, gap y (m), pulled up by k i^2 / y^2 against gravity — unstable in open loop (pole
+44 1/s at a 1 cm gap). The record comes from a PD loop around it (simulated here: reference two sines, the current
i = i0 + 600 (y - r) + 9 dy/dt); the fit is of the open-loop plant from the recorded current to the measured gap.

A free run of the plant escapes within a fraction of a second from any start, so single shooting (segments=1)
cannot even begin; ctid sees the escape and switches to multiple shooting by itself. Measurement noise 10 um: the
estimates must cover the truth within three standard deviations."""
import numpy as np

import ctid

loop = {  # the closed loop, to make the record
    "inputs": ["r"], "states": ["y", "v"],
    "outputs": {"y": "y", "i": "3.132092 + 600*(y - r) + 9*v"},
    "parameters": {"k": 1e-4, "c": 2.0, "g": 9.81},
    "equations": {"y": "v", "v": "g - k*(3.132092 + 600*(y - r) + 9*v)^2/y^2 - c*v"},
    "initial": {"y": 0.01, "v": 0},
}
n, ts = 3000, 0.001
t = np.arange(n) * ts
r = (0.01 + 0.0015 * np.sin(2 * np.pi * 0.7 * t) + 0.001 * np.sin(2 * np.pi * 2.3 * t)).reshape(-1, 1)
closed = ctid.greybox_model(loop).simulate(r, t, intersample="foh", rtol=1e-11)
assert closed.ok(), closed.message
rng = np.random.default_rng(2)
gap = closed.y[:, 0] + rng.normal(0.0, 1e-5, n)
data = ctid.IdData.from_arrays(closed.y[:, 1], gap, ts=ts, intersample="foh")  # the current: a continuous signal

plant = {  # what is identified: the open-loop physics, k and c unknown, gravity known
    "inputs": ["i"], "states": ["y", "v"], "outputs": {"y": "y"},
    "parameters": {"k": {"value": 1.3e-4, "lower": 0}, "c": {"value": 1.0, "lower": 0}, "g": {"value": 9.81, "fixed": True}},
    "equations": {"y": "v", "v": "g - k*i^2/y^2 - c*v"},
    "initial": {"y": "estimate", "v": "estimate"},
}
single = ctid.greybox(data, plant, segments=1)
print("single shooting:", single.why_not_usable())
assert not single.usable()

fit = ctid.greybox(data, plant)  # segments=0: automatic
print(repr(fit))
assert fit.usable(), fit.why_not_usable()
print("segments:", fit.diagnostics.scalars["segments"], " continuity defect:", fit.diagnostics.scalars["continuity_defect"])
for name, value in [("k", 1e-4), ("c", 2.0)]:
    i = fit.parameters.names.index(name)
    est, sd = fit.parameters.values[i], fit.parameters.std[i]
    print(f"{name} = {est:.6g} +- {sd:.2g}   (true {value})")
    assert abs(est - value) < 3 * sd, name
