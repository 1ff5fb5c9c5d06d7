"""Continuous-time state space from periodic records through their FRF matrix (docs/methods/state-space.md).

The two-mode system of the other state-space examples (2 rad/s with zeta 0.05, 5 rad/s with zeta 0.2; two inputs,
two outputs). Two experiments, each a multisine (lines 2-60 of a 25.6 s period) on one input, six periods sampled
every 0.05 s, the first period spoiled by a transient, white noise on the outputs. ctid.frf_from_periodic drops the
first period, averages the other five and returns the FRF matrix at the 59 excited lines with the variance of each
entry; ctid.ssest fits a state-space model to it (frequency-domain subspace start, then weighted least squares) with
each mode's standard deviation. The modes must lie within 4 standard deviations of the truth."""
import sys

import numpy as np

import ctid

A = np.zeros((4, 4))
A[:2, :2] = [[0, 1], [-4, -0.2]]
A[2:, 2:] = [[0, 1], [-25, -2]]
B = np.array([[0, 0], [1, 0.5], [0, 0], [-0.4, 1]])
C = np.array([[4, 0.5, 10, 0], [1, -1, 20, 2]])
truth = ctid.StateSpace(A, B, C, np.zeros((2, 2)))

P, periods, ts = 512, 6, 0.05
rng = np.random.default_rng(3)
t = np.arange(P * periods) * ts
lines = 2 * np.pi * np.arange(2, 61) / (P * ts)
G = truth.frequency_response(lines)  # the steady state, line by line
records = []
for j in range(2):
    phase = rng.uniform(0, 2 * np.pi, lines.size)
    u = np.zeros((t.size, 2))
    u[:, j] = np.cos(np.outer(t, lines) + phase).sum(axis=1)
    y = sum(np.abs(g[:, j]) * np.cos(np.outer(t, [1, 1]) * w + p + np.angle(g[:, j]))
            for w, p, g in zip(lines, phase, G))
    y[:P] += 5 * np.exp(-0.1 * t[:P, None]) * np.cos(2 * t[:P, None])  # a transient in the first period
    records.append(ctid.IdData(u, y + 0.5 * rng.standard_normal(y.shape), ts))

frf = ctid.frf_from_periodic(records, P, skip=1)
r = ctid.ssest(frf, 4, estimate_d=False)
print(f"{len(frf)} lines, usable: {r.usable()}, fit {r.fit.fit_percent:.2f} %, "
      f"chi2 per degree of freedom {r.diagnostics.scalars['chi2_per_dof']:.2f}")
wn_std, zeta_std = r.diagnostics.vectors["mode_wn_std"], r.diagnostics.vectors["mode_zeta_std"]
for k, (mode, true) in enumerate(zip(r.model.modes(), truth.modes())):
    print(f"  wn = {mode['wn']:.5f} +- {wn_std[k]:.5f} rad/s (true {true['wn']:.1f}), "
          f"zeta = {mode['zeta']:.5f} +- {zeta_std[k]:.5f} (true {true['zeta']:.2f})")
    if abs(mode["wn"] - true["wn"]) > 4 * wn_std[k] or abs(mode["zeta"] - true["zeta"]) > 4 * zeta_std[k]:
        sys.exit(f"mode {k}: the estimate is not within 4 standard deviations of the truth")
if not r.usable():
    sys.exit(r.why_not_usable())
