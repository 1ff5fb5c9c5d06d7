import numpy as np
import pytest

import ctid


def test_fsf_step_response_of_a_plant_with_bands(plant):
    # G(s) = 4/(s^2 + 0.8 s + 4) settles (to 1e-3) within 20 s: T = 20 s = 1000 samples, 31 filters.
    g, d = plant
    r = ctid.fsf(d, T=20.0, n=31)
    assert r.usable()
    t = np.linspace(0, 20, 201)
    s, sd = r.model.step(t), r.model.step_std(t)
    assert sd[0] == 0 and np.all(sd[1:] > 0)  # the step response at t = 0 is exactly 0
    # The estimate is within 4 std (plus the truncation of the 31-filter model, < 0.02) of the true response.
    assert np.all(np.abs(s - g.step(t)) < 4 * sd + 0.02)
    assert s[-1] == pytest.approx(1.0, abs=0.05)


def test_fsf_options_are_checked(plant):
    _, d = plant
    with pytest.raises(ctid.InvalidOptions, match="n"):
        ctid.fsf(d, T=20.0, n=30)  # even
    with pytest.raises(TypeError, match="unknown option"):
        ctid.fsf(d, T=20.0, filters=31)


def test_fsf_from_spectra_equals_the_time_domain_fit(plant):
    # GW 24-29: with records zero-padded to L >= M + N the frequency-domain normal equations are the time-domain
    # ones, so theta agrees to rounding (C++ test: 1e-8 with the window a = 2; here a = 0.5 and relative 1e-8).
    _, d = plant
    u, y = d.u[:, 0], d.y[:, 0]
    L = 1 << int(np.ceil(np.log2(len(u) + 1000)))
    td = ctid.fsf(d, T=20.0, n=31, a=0.5)
    fd = ctid.fsf_from_spectra(ctid.one_sided_dft(u, L), ctid.one_sided_dft(y, L), L, d.ts, T=20.0, n=31, a=0.5)
    assert fd.usable()
    assert np.max(np.abs(fd.model.theta - td.model.theta)) < 1e-8 * np.max(np.abs(td.model.theta))
    with pytest.raises(ctid.InvalidOptions):
        ctid.fsf_from_spectra(ctid.one_sided_dft(u, L), ctid.one_sided_dft(y, L), L, d.ts, T=20.0, n=31, b=1.0)
