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


def test_modal_fit_on_several_records_is_one_joint_estimate():
    # Two records of S3 from rest with different piecewise-constant inputs (Ts = pi/320, shifts
    # 16, 32, 48 samples, Walsh), noise-free: the joint fit is S3 to 1e-6 as in the C++ test ModalFit.SeveralRecords...
    ts = math.pi / 320

    def record(levels, hold, cycles):
        u = np.repeat(np.tile(levels, cycles), hold).astype(float)
        t = ctid.time_grid(ts, len(u))
        return ctid.IdData.from_arrays(u, S3.simulate(u, t), ts=ts)

    d1, d2 = record([1, 2, -1, -2], 80, 2), record([-1.5, 0.5, 2.5, -0.5], 96, 1)
    r = ctid.modal_fit([d1, d2], 2, shifts=np.array([16, 32, 48]) * ts, basis="walsh")
    assert r.usable()
    np.testing.assert_allclose(r.model.den, S3.den, rtol=1e-6)
    np.testing.assert_allclose(r.model.num, S3.num, rtol=1e-5)
    assert r.diagnostics.scalars["experiments"] == 2
    with pytest.raises(ValueError, match="windows are times of one record"):
        ctid.modal_fit([d1, d2], 2, shifts=np.array([16, 32, 48]) * ts, windows=[(0.5, 0.2)])


def test_free_response_poles_theorem_4_3():
    tw = 2 * math.pi / 3 / 666
    t = ctid.time_grid(tw, 2000)
    y = np.exp(-t) * np.sin(3 * t) + np.cos(100 * t)
    p = ctid.free_response_poles(y, tw, shifts=np.array([33, 66, 99, 132]) * tw, start=132 * tw, interval=33 * tw,
                                 spacing=33 * tw, pairs=10)
    assert max(abs(p.poles.imag)) == pytest.approx(100, abs=0.1)
    assert sorted(abs(p.poles.imag))[0] == pytest.approx(3, abs=0.01)


def test_compare_poles_is_what_ctid_poles_prints():
    # The same record: compare_poles with the instants chosen from it (start = the largest shift, interval = spacing
    # = the first shift, as many pairs as fit) gives free_response_poles' estimate with those settings to round-off,
    # and Prony at spacing 33 samples aliases the 100 rad/s mode (|Im| <= pi/T) where the data matrix does not.
    tw = 2 * math.pi / 3 / 666
    t = ctid.time_grid(tw, 2000)
    y = np.exp(-t) * np.sin(3 * t) + np.cos(100 * t)
    c = ctid.compare_poles(y, tw, 4, shifts=np.array([33, 66, 99, 132]) * tw)
    fr = c.free_response
    assert fr.start == pytest.approx(132 * tw) and fr.interval == pytest.approx(33 * tw)
    assert fr.pairs == (2000 - 1 - 132 - 33) // 33 + 1
    direct = ctid.free_response_poles(y, tw, shifts=fr.shifts, start=fr.start, interval=fr.interval,
                                      spacing=fr.spacing, pairs=fr.pairs)
    np.testing.assert_allclose(np.sort_complex(c.data_matrix.poles), np.sort_complex(direct.poles), rtol=1e-12)
    assert max(abs(c.data_matrix.poles.imag)) == pytest.approx(100, abs=0.1)
    assert c.prony is not None and c.prony_options.spacing == 33
    assert max(abs(c.prony.poles.imag)) <= math.pi / (33 * tw) + 1e-9
    # Its repr is the library's text that ctid poles prints: both estimates, each pole to 6 digits.
    text = repr(c)
    assert text.startswith("data-matrix method (Theorem 4.3, El-Shafey 1987):") and "\nProny (order 4, T = 33" in text
    for p in c.data_matrix.poles:
        assert "%.6g%+.6gj" % (p.real, p.imag) in text
    with pytest.raises(ctid.InvalidOptions, match="3 shifts; order 4 needs 4"):
        ctid.compare_poles(y, tw, 4, shifts=np.array([33, 66, 99]) * tw)
    # Shifts left out: chosen on Prony's pre-estimate and stated; 100 rad/s still found (C++ test: within 0.1).
    a = ctid.compare_poles(y, tw, 4)
    assert len(a.choices) == 1 and "Prony's pre-estimate" in a.choices[0]
    assert max(abs(a.data_matrix.poles.imag)) == pytest.approx(100, abs=0.1)


def test_modal_frequency_response_from_a_square_wave():
    # El-Shafey Ex. 5.1 (as tests/estimate/modal_test.cpp): S3 under a +-1 square wave of period 2 pi, Ts = pi/420;
    # p_0 from the constant-input windows; H(jk) at the odd harmonics within 2e-6 of the truth (C++: same bound).
    ts = math.pi / 420
    u = np.where((np.arange(1000) // 420) % 2 == 0, 1.0, -1.0)
    d = ctid.IdData.from_arrays(u, S3.simulate(u, ctid.time_grid(ts, 1000)), ts=ts)
    shifts = np.array([40, 80, 120]) * ts
    m = ctid.modal_estimate(d, d.u, shifts=shifts, basis="discrete",
                            windows=ctid.piecewise_constant_windows(d, shifts[-1]))
    assert m.usable() and m.model.order == 3
    h = ctid.modal_frequency_response(d, m, 2 * math.pi, [1, 3, 5, 7, 9, 11], 120 * ts)
    k = np.array([1, 3, 5, 7, 9, 11])
    np.testing.assert_allclose(h.response.w, k)
    truth = S3.freqresp(k.astype(float))
    assert np.max(np.abs(h.response.response - truth) / np.abs(truth)) < 2e-6
    assert h.nu[0, 0] == pytest.approx(1.4363, abs=1e-4)  # Table 5.1, first row
    with pytest.raises(ctid.InvalidArgument):
        ctid.modal_frequency_response(d, m, 2 * math.pi, [2], 120 * ts)  # even harmonics are not excited
    with pytest.raises(ValueError, match="must be one of"):
        ctid.modal_frequency_response(d, m, 2 * math.pi, [1], 120 * ts, rule="gauss")
    # The same as one call (ctid response --method modal --kind frequency): the same windows and shifts give the
    # same response to round-off.
    one = ctid.modal_response(d, 3, "frequency", period=2 * math.pi, harmonics=[1, 3, 5, 7, 9, 11],
                              window_start=120 * ts, shifts=shifts)
    np.testing.assert_allclose(one.frequency.response.response, h.response.response, rtol=1e-12)
    assert one.p0.usable() and len(one.modal.windows) > 0
    # Its repr is the text ctid response prints: the p_0 line, then one line per harmonic with |H| to 6 digits.
    lines = repr(one).splitlines()
    assert lines[0].startswith("modal parameters p_0:") and len(lines) == 1 + 6
    for line, g in zip(lines[1:], one.frequency.response.response):
        assert "|H| = %.6g " % abs(g) in line
    with pytest.raises(ctid.InvalidOptions, match="give the period"):
        ctid.modal_response(d, 3, "frequency", shifts=shifts)
    # A misspelt keyword names the closest setting of either table (ModalResponseOptions or ModalOptions).
    with pytest.raises(TypeError, match="unknown option 'horizn'; did you mean 'horizon'"):
        ctid.modal_response(d, 3, "step", period=1.0, horizn=2.0, shifts=shifts)
    with pytest.raises(TypeError, match="unknown option 'shifs'; did you mean 'shifts'"):
        ctid.modal_response(d, 3, "step", period=1.0, shifs=shifts)


def test_modal_step_and_impulse_responses_and_the_observer():
    # El-Shafey Ex. 5.2/5.3 (modal_test.cpp): S3, levels +1, +2, -1, -2 of 80 Ts each, Ts = pi/320, T = 20 Ts:
    # the step response equals the true one to 1e-9, the impulse response (negative shifts) to 1e-5, p_1 and q_10
    # the published (-1.6728, 8.1618, 11.2474) and 17.736 to 5e-4 relative.
    ts = math.pi / 320
    T = 20 * ts
    u = np.repeat([1.0, 2.0, -1.0, -2.0], 80)
    d = ctid.IdData.from_arrays(u, S3.simulate(u, ctid.time_grid(ts, 320)), ts=ts)
    shifts = np.array([T, 2 * T, 3 * T])
    m = ctid.modal_estimate(d, d.u, shifts=shifts, basis="discrete", windows=ctid.piecewise_constant_windows(d, 3 * T))
    g = ctid.modal_step_response(d, m, T, 640 * ts)
    assert np.max(np.abs(g.value - S3.step(g.t))) < 1e-9
    imp = ctid.modal_impulse_from_step(g, -np.array([40, 80, 120]) * ts, 192 * ts)
    assert np.max(np.abs(imp.impulse.value - S3.impulse(imp.impulse.t))) < 1e-5
    np.testing.assert_allclose(imp.p1, [-1.6728, 8.1618, 11.2474], atol=5e-4 * 11.25)
    assert imp.q10 == pytest.approx(17.736, rel=5e-4)
    # Minimum-time observer (ch. 6) from the model: after n = 3 level periods the reconstructed phase-variable
    # state reproduces the output (x_1 = y) to 1e-9; before, NaN.
    obs = ctid.DeadbeatObserver.from_model(S3, T, ts)
    assert obs.order == 3 and obs.offsets == 20
    x = obs.reconstruct(d)
    assert np.isnan(x[59, 0])
    assert np.max(np.abs(x[60:, 0] - d.y[60:, 0])) < 1e-9
    with pytest.raises(ctid.InvalidArgument):
        ctid.modal_step_response(d, m, 10 * ts, 640 * ts)  # shifts are not multiples of the level period
    # ES-C14: S3 = (13 s + 52)/(s^3 + 4 s^2 + 30 s + 52) has b~ = (0, 13, 52 - 4 * 13) = (0, 13, 0); an unstable
    # plant, (13 s + 52)/(s^3 + s^2 + 24 s - 26), has (0, 13, 39) (1e-8, exact modal quantities).
    p3 = ctid.modal_parameters(S3, shifts, 3).P[3]
    np.testing.assert_allclose(obs.markov_parameters(p3), [0.0, 13.0, 0.0], atol=1e-8)
    unstable = ctid.TransferFunction([13.0, 52.0], [1.0, 1.0, 24.0, -26.0])
    ou = ctid.DeadbeatObserver.from_model(unstable, T, ts)
    np.testing.assert_allclose(ou.markov_parameters(ctid.modal_parameters(unstable, shifts, 3).P[3]),
                               [0.0, 13.0, 39.0], atol=1e-8)
    integrator = ctid.TransferFunction([13.0, 52.0], [1.0, 4.0, 30.0, 0.0])
    with pytest.raises(ctid.InvalidArgument, match="pole at s = 0"):
        ctid.DeadbeatObserver.from_model(integrator, T, ts).markov_parameters(
            ctid.modal_parameters(integrator, shifts, 3).P[3])


def test_prony_aliases_where_the_data_matrix_does_not():
    # A 100 rad/s cosine sampled at 33 Tw = 2 pi / (3 * 666) * 33 s per Prony sample aliases: Prony returns the
    # frequency modulo 2 pi / T and says so.
    tw = 2 * math.pi / 3 / 666
    t = ctid.time_grid(tw, 2000)
    y = np.exp(-t) * np.sin(3 * t) + np.cos(100 * t)
    p = ctid.prony(y, tw, order=4, spacing=33, equations=40)
    assert any("alias" in w or "2 pi" in w for w in p.warnings)
    assert max(abs(p.poles.imag)) <= math.pi / (33 * tw) + 1e-9


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
    # In k/(m s^2 + c s + k) only m/k and c/k matter: not usable, naming the three (as the CLI test).
    scaled = ctid.PhysicalModel("k/(m*s^2 + c*s + k)", ["k", "m", "c"])
    bad = ctid.fit_physical_raw(scaled, {"k": 1.0, "m": 1.0, "c": 1.0}, d)
    assert not bad.usable() and "cannot separate k, m and c" in bad.why_not_usable()


def test_recursive_johansson_tracks_a_first_order_plant():
    g = ctid.TransferFunction([2.0], [1.0, 0.5])
    t = ctid.time_grid(0.01, 4000)
    u = ctid.prbs(4000, register_length=8, clock_period=10)
    est = ctid.rls_svf_recursive(1, 1, tau=0.5)
    history = est.run(t, u, g.simulate(u, t))
    assert history.shape == (4000, 2)
    np.testing.assert_allclose(est.parameters(), [0.5, 2.0], rtol=1e-3)  # noise-free: a1 = 0.5, b0 = 2


def test_physical_raw_route_estimates_the_initial_state():
    # As PhysicalRaw.TheInitialStateOfARecordNotAtRestIsEstimated: 1/(m s^2 + d s + k) from the state (0.8, -1.2).
    g = ctid.TransferFunction([1.0], [0.5, 0.4, 2.0])
    n = 1500
    u = ctid.prbs(n, register_length=8, clock_period=15)
    rest = ctid.IdData.from_arrays(u, g.simulate(u, ctid.time_grid(0.01, n)), ts=0.01)
    y = np.asarray(ctid.simulate(g, rest, "estimated", x0=[0.8, -1.2])).reshape(-1)
    d = ctid.IdData.from_arrays(u, y, ts=0.01)
    model = ctid.PhysicalModel("1/(m*s^2 + d*s + k)", ["m", "d", "k"])
    r = ctid.fit_physical_raw(model, {"m": 0.8, "d": 0.2, "k": 1.5}, d, estimate_initial_state=True)
    assert r.usable(), r.why_not_usable()
    assert np.allclose(r.parameters.values, [0.5, 0.4, 2.0], rtol=1e-6)
    assert np.allclose(r.diagnostics.vectors["x0"], [0.8, -1.2], atol=1e-5)
