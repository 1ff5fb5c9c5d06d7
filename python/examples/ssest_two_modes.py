"""MIMO continuous-time state space by output error: ssest (docs/methods/state-space.md).

The two-mode system of the subspace example (2 rad/s with zeta 0.05, 5 rad/s with zeta 0.2; two inputs, two
outputs), 2000 samples every 0.05 s with 10 dB of white noise on each output, split into two records of one system.
ssest starts from the subspace estimate and refines it by output error: each mode's natural frequency and damping
come with standard deviations, and those agree with the Cramer-Rao bound computed at the true system."""
import sys

import numpy as np

import ctid

A = np.zeros((4, 4))
A[:2, :2] = [[0, 1], [-4, -0.2]]
A[2:, 2:] = [[0, 1], [-25, -2]]
B = np.array([[0, 0], [1, 0.5], [0, 0], [-0.4, 1]])
C = np.array([[4, 0.5, 10, 0], [1, -1, 20, 2]])
truth = ctid.StateSpace(A, B, C, np.zeros((2, 2)))

rng = np.random.default_rng(4)
N, ts = 2000, 0.05
u = np.repeat(rng.uniform(-1, 1, size=(N // 7 + 1, 2)), 7, axis=0)[:N]
clean = np.array(ctid.simulate(truth, ctid.IdData(u, np.zeros((N, 2)), ts))).reshape(N, 2)
noise_variance = clean.var(axis=0) / 10  # 10 dB
y = clean + rng.standard_normal((N, 2)) * np.sqrt(noise_variance)
records = [ctid.IdData(u[:1200], y[:1200], ts), ctid.IdData(u[1200:], y[1200:], ts)]

r = ctid.ssest(records, 4, estimate_d=False)
bound = ctid.ssest_crlb(truth, records, noise_variance, estimate_d=False)
print(f"usable: {r.usable()}, {r.summary.iterations} iterations, fit {r.fit.fit_percent:.1f} % "
      f"(subspace start {r.diagnostics.scalars['start_fit_percent']:.1f} %)")
wn_std, zeta_std = r.diagnostics.vectors["mode_wn_std"], r.diagnostics.vectors["mode_zeta_std"]
for k, (mode, true) in enumerate(zip(r.model.modes(), truth.modes())):
    print(f"  wn = {mode['wn']:.4f} +- {wn_std[k]:.4f} rad/s (true {true['wn']:.1f}, bound "
          f"{bound.diagnostics.vectors['mode_wn_std'][k]:.4f}), zeta = {mode['zeta']:.4f} +- {zeta_std[k]:.4f} "
          f"(true {true['zeta']:.2f})")
    # Each estimate within 4 of its standard deviations, and the reported spread within 20 % of the bound.
    if abs(mode["wn"] - true["wn"]) > 4 * wn_std[k] or abs(mode["zeta"] - true["zeta"]) > 4 * zeta_std[k]:
        sys.exit(f"mode {k}: the estimate is not within 4 standard deviations of the truth")
    if abs(wn_std[k] / bound.diagnostics.vectors["mode_wn_std"][k] - 1) > 0.2:
        sys.exit(f"mode {k}: the reported standard deviation is not the Cramer-Rao bound's")
# The frequency response with its standard deviation at the slow resonance.
mag_std, phase_std = ctid.frequency_response_std(r, np.array([2.0]), 0, 0)
print(f"|G11(j2)| standard deviation {mag_std[0]:.3f}, phase {np.degrees(phase_std[0]):.2f} degrees")
if not r.usable():
    sys.exit(r.why_not_usable())
