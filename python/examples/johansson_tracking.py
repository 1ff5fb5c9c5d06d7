"""Johansson (1986): LSSVF on a record, then recursive tracking of a parameter that changes (runs in CI).

Question: the gain of a first-order plant doubles at t = 20 s; how fast does recursive identification
with the z = 1/(1 + p tau) operator and forgetting follow it?
"""
import numpy as np

import ctid

ts = 0.01
t = ctid.time_grid(ts, 4000)
u = ctid.prbs(4000, register_length=8, clock_period=10)
g1, g2 = ctid.TransferFunction([1.0], [1.0, 0.5]), ctid.TransferFunction([2.0], [1.0, 0.5])
# Plant switching at 20 s: simulate both halves continuing from the first half's state (first order:
# the state is the output), i.e. y' = -0.5 y + b u.
y = np.empty(4000)
y[:2000] = g1.simulate(u[:2000], t[:2000])
tail = g2.simulate(u[2000:], t[2000:] - t[2000])
y[2000:] = tail + y[1999] * np.exp(-0.5 * (t[2000:] - t[1999]))

batch = ctid.lssvf(ctid.IdData.from_arrays(u[:2000], y[:2000], ts=ts), 1, 1, tau=0.5)
print("LSSVF on the first 20 s:", batch.model)

rls = ctid.rls_svf_recursive(1, 1, tau=0.5, forgetting=0.995)
history = rls.run(t, u, y)
b0 = history[:, 1]
settled = np.argmax(np.abs(b0[2000:] - 2.0) < 0.1) * ts
print(f"b0 before the change {b0[1999]:.3f}, at the end {b0[-1]:.3f}; within 5 % of the new gain {settled:.2f} s after it")
assert abs(batch.parameters["b0"] - 1.0) < 1e-2 and abs(b0[-1] - 2.0) < 0.02 and settled < 5.0
