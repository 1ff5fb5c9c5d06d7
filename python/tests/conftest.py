import os
import pathlib

import numpy as np
import pytest

import ctid

EXAMPLES_DATA = pathlib.Path(os.environ.get("CTID_EXAMPLES_DATA_DIR",
                                            pathlib.Path(__file__).resolve().parents[2] / "examples" / "data"))
SHARED_DATA = pathlib.Path(os.environ.get("CTID_SHARED_DATA_DIR",
                                          pathlib.Path(__file__).resolve().parents[3] / "shared" / "data"))


@pytest.fixture
def plant():
    """G(s) = 4/(s^2 + 0.8 s + 4) with a PRBS input (2000 samples at 20 ms) and 20 dB output noise."""
    g = ctid.TransferFunction([4.0], [1.0, 0.8, 4.0])
    u = ctid.prbs(2000, register_length=9, clock_period=3)
    y = g.simulate(u, ctid.time_grid(0.02, 2000))
    return g, ctid.IdData.from_arrays(u, ctid.add_noise_snr(y, 20.0, 3), ts=0.02)


@pytest.fixture
def bl33():
    """Billings & Li system (33), +-1 input held at 400 Hz, 1000 samples, noise-free."""
    m = ctid.NdeModel(["y", "Dy", "D^2y", "u", "y^2", "y*Dy"], np.array([1, 0.002, 1e-4, -1, 0.1, -0.006]))
    rng = np.random.default_rng(11)
    u = np.where(rng.random(1000) < 0.5, -1.0, 1.0)
    y = m.simulate(u, ctid.time_grid(0.0025, 1000), rtol=1e-11).y
    return m, ctid.IdData.from_arrays(u, y, ts=0.0025)
