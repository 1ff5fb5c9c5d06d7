"""Billings & Li (1999): NARMAX from noisy data, the continuous-time equation by the Kernel Invariance
Algorithm, refined by output error (runs in CI).

Question: y'' and y' terms plus y^2 and y*y' nonlinearities drive this record; which equation is it?
"""
import numpy as np

import ctid

truth = ctid.NdeModel(["y", "Dy", "D^2y", "u", "y^2", "y*Dy"], np.array([1, 0.002, 1e-4, -1, 0.1, -0.006]))
rng = np.random.default_rng(11)
u = np.where(rng.random(1000) < 0.5, -1.0, 1.0)
t = ctid.time_grid(0.0025, 1000)
y = ctid.add_noise_snr(truth.simulate(u, t, rtol=1e-11).y, 20.0, 7)
data = ctid.IdData.from_arrays(u, y, ts=0.0025)

narx = ctid.narmax(data, ctid.narx_candidates(2, 6, 6), max_terms=20, criterion="aic")
process = narx.model.process()
print("NARX:", process)
lin = ctid.kia_linear(process, y_order=2, u_order=0)
kia = ctid.kia_quadratic(process, lin.model, candidates=["y^2", "y*Dy"])
refined = ctid.nde_oe(data, kia.model)
print("true:   ", truth)
print("KIA:    ", kia.model.normalized())
print(refined)
worst = max(abs(refined.model.coefficient(n) / truth.coefficient(n) - 1) for n in ["Dy", "D^2y", "u", "y^2", "y*Dy"])
print(f"largest coefficient error after refinement: {100 * worst:.2f} %")
assert worst < 0.1
