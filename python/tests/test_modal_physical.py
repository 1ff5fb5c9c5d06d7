import math

import numpy as np
import pytest

import ctid

S3 = ctid.TransferFunction([13.0, 52.0], [1.0, 4.0, 30.0, 52.0])  # El-Shafey's third-order example


def test_modal_fit_two_sinusoid_test_recovers_s3():
    # As examples/modal_tour.cpp: Ts = pi/420, shifts 40, 80, 120 samples, two sinusoids, noise-free.
    ts = math.pi / 420
    g = ctid.InputGenerator.sinusoid(4.0, 1.0) + ctid.InputGenerator.sinusoid(1.5, 0.0, 0.7)
    t = ctid.time_grid(ts, 1500)
    d = ctid.IdData.from_arrays(g(t), S3.simulate(g(t), t, "foh"), ts=ts)
    # FOH simulation of a smooth input: the record differs from the exact response by ~1e-6.
    r = ctid.modal_fit(d, 3, input=g, shifts=np.array([40, 80, 120]) * ts, functions=10)
    assert r.usable()
    np.testing.assert_allclose(r.model.den, S3.den, rtol=1e-3)
    assert abs(r.model.num[0]) < 1e-3  # nb = n = 3: the s^2 coefficient of the true numerator is 0
    np.testing.assert_allclose(r.model.num[1:], S3.num, rtol=1e-3)


def test_free_response_poles_theorem_4_3():
    tw = 2 * math.pi / 3 / 666
    t = ctid.time_grid(tw, 2000)
    y = np.exp(-t) * np.sin(3 * t) + np.cos(100 * t)
    p = ctid.free_response_poles(y, tw, shifts=np.array([33, 66, 99, 132]) * tw, start=132 * tw, interval=33 * tw,
                                 spacing=33 * tw, pairs=10)
    assert max(abs(p.poles.imag)) == pytest.approx(100, abs=0.1)
    assert sorted(abs(p.poles.imag))[0] == pytest.approx(3, abs=0.01)


def test_physical_parameters_from_the_fsf_step_response(plant):
    # G(s) = k w^2/(s^2 + 2 z w s + w^2) with k = 1, w = 2, z = 0.2 (the plant fixture) at 20 dB.
    _, d = plant
    compressed = ctid.fsf(d, T=20.0, n=31)
    model = ctid.PhysicalModel("k*w^2/(s^2 + 2*z*w*s + w^2)", ["k", "w", "z"])
    r = ctid.fit_physical_step(model, {"k": 0.5, "w": 1.0, "z": {"initial": 0.5, "lower": 0.0}}, compressed)
    assert r.usable()
    for name, value in {"k": 1.0, "w": 2.0, "z": 0.2}.items():
        assert r.parameters[name] == pytest.approx(value, rel=0.05), name
    raw = ctid.fit_physical_raw(model, {"k": 0.5, "w": 1.0, "z": 0.5}, d)
    assert raw.parameters["w"] == pytest.approx(2.0, rel=0.01)
    with pytest.raises(ctid.InvalidArgument, match="q"):
        ctid.PhysicalModel("k/(s + q)", ["k"])


def test_recursive_johansson_tracks_a_first_order_plant():
    g = ctid.TransferFunction([2.0], [1.0, 0.5])
    t = ctid.time_grid(0.01, 4000)
    u = ctid.prbs(4000, register_length=8, clock_period=10)
    est = ctid.rls_svf(1, 1, tau=0.5)
    history = est.run(t, u, g.simulate(u, t))
    assert history.shape == (4000, 2)
    np.testing.assert_allclose(est.parameters(), [0.5, 2.0], rtol=1e-3)  # noise-free: a1 = 0.5, b0 = 2
