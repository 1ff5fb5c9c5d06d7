"""Nonlinear grey-box identification (docs/methods/greybox.md): a mass on a spring with viscous and Coulomb
friction, written as state equations with named parameters, fitted by output error with exact sensitivities.

The data are simulated here (the model's own integrator, 10 dB-free: noise std 0.01 on a position of about 1), so
the script can check that the estimates cover the true values within three standard deviations."""
import numpy as np

import ctid

model = {
    "inputs": ["u"], "states": ["q", "v"], "outputs": {"y": "q"},
    "parameters": {"k": 2.0, "c": 0.4, "fc": {"value": 0.3, "lower": 0}, "m": {"value": 1.0, "lower": 0.01}},
    # Coulomb friction smoothed over 0.05 m/s (tanh); sign(v) is accepted too (see the page on kinks).
    "equations": {"q": "v", "v": "(u - k*q - c*v - fc*tanh(v/0.05))/m"},
    "initial": {"q": "estimate", "v": 0},
}
truth = ctid.greybox_model(model)

rng = np.random.default_rng(1)
n, ts = 3000, 0.01
u = np.repeat(rng.uniform(-3, 3, n // 150 + 1), 150)[:n].reshape(-1, 1)  # held random levels
t = np.arange(n) * ts
clean = truth.simulate(u, t, x0=[0.1, 0.0], rtol=1e-11)
assert clean.ok(), clean.message
y = clean.y + rng.normal(0.0, 0.01, clean.y.shape)
data = ctid.IdData(u, y, ts)

# Start far from the truth; four starts (the model's values and three drawn within the bounds).
start = dict(model, parameters={"k": 0.5, "c": 2.0, "fc": {"value": 0.05, "lower": 0}, "m": {"value": 3.0, "lower": 0.01}})
r = ctid.greybox(data, start, starts=4, seed=1)
print(repr(r))
assert r.usable(), r.why_not_usable()
for name, value in [("k", 2.0), ("c", 0.4), ("fc", 0.3), ("m", 1.0)]:
    i = r.parameters.names.index(name)
    est, sd = r.parameters.values[i], r.parameters.std[i]
    print(f"{name:3s} = {est:8.4f} +- {sd:.4f}   (true {value})")
    assert abs(est - value) < 3 * sd, name
print("q(0) =", r.parameters.values[r.parameters.names.index("q(0)")])
