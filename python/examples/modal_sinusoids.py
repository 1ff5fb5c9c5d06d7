"""El-Shafey (1987): a transfer function from a two-sinusoid test by modal functions (runs in CI).

Question: the plant is driven by two known sinusoids from rest; can the model be read off the modal
parameters (Theorems 4.1 and 4.2) without any iterative search?
"""
import math

import numpy as np

import ctid

plant = ctid.TransferFunction([13.0, 52.0], [1.0, 4.0, 30.0, 52.0])
ts = math.pi / 420
g = ctid.InputGenerator.sinusoid(4.0, 1.0) + ctid.InputGenerator.sinusoid(1.5, 0.0, 0.7)
t = ctid.time_grid(ts, 1500)
data = ctid.IdData.from_arrays(g(t), plant.simulate(g(t), t, "foh"), ts=ts)
r = ctid.modal_fit(data, 3, input=g, shifts=np.array([40, 80, 120]) * ts, functions=10)
print(r)
assert np.allclose(r.model.den, plant.den, rtol=1e-3)
