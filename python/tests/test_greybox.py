"""ctid.greybox: the model as a dict or a file, the fit, result files and simulation from Python."""
import numpy as np
import pytest

import ctid

MODEL = {
    "inputs": ["u"], "states": ["x"], "outputs": {"y": "x"},
    "parameters": {"a": {"value": 1.0, "lower": 0}, "b": 2.0},
    "equations": {"x": "-a*x*abs(x) + b*u"},
    "initial": {"x": "estimate"},
}


def record(a=0.7, b=1.5, x0=0.2, n=800, ts=0.02, seed=2):
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.uniform(-1, 1, n // 40 + 1), 40)[:n].reshape(-1, 1)
    m = ctid.greybox_model(MODEL).with_parameters([a, b])
    s = m.simulate(u, np.arange(n) * ts, x0=[x0], rtol=1e-11)
    assert s.ok()
    return ctid.IdData(u, s.y, ts)


def test_noise_free_record_gives_the_parameters_back(tmp_path):
    r = ctid.greybox(record(), MODEL)
    assert r.usable(), r.why_not_usable()
    # Noise-free simulation at rtol 1e-11: the estimates to 1e-6 (the fit's own integration tolerance 1e-8).
    assert r.parameters.names == ["a", "b", "x(0)"]
    np.testing.assert_allclose(r.parameters.values, [0.7, 1.5, 0.2], rtol=1e-6)
    # A result file round-trips with its model (the fitted initial state in the model file).
    path = tmp_path / "r.json"
    ctid.write_result(str(path), r, "greybox")
    back = ctid.read_result(str(path)).result
    assert isinstance(back.model, ctid.GreyboxModel)
    assert back.model == r.model
    assert back.model.initial_state[0] == pytest.approx(0.2, abs=1e-6)


def test_options_and_errors_are_named():
    d = record()
    r = ctid.greybox(d, MODEL, fixed={"b": 1.5}, starts=3, seed=4)
    assert r.parameters.fixed == [False, True, False]
    assert r.parameters.values[0] == pytest.approx(0.7, rel=1e-6)
    with pytest.raises(ctid.InvalidOptions, match="did you mean 'b'"):
        ctid.greybox(d, MODEL, fixed={"bb": 1.0})
    with pytest.raises(ctid.FileError, match="unknown name 'z'"):
        ctid.greybox(d, dict(MODEL, equations={"x": "-a*z"}))
    with pytest.raises(TypeError, match="dict, a path or a GreyboxModel"):
        ctid.greybox(d, 3)
    assert "starts" in [s["name"] for s in ctid.settings("greybox")]


def test_simulate_from_the_first_samples_only():
    d = record(x0=0.5)
    m = ctid.greybox_model(MODEL).with_parameters([0.7, 1.5])
    # The state from the first 20 samples (the benchmark protocol): the whole record reproduced (noise-free data).
    y = ctid.simulate(m, d, "estimated", initial_samples=20)
    np.testing.assert_allclose(y, d.y[:, 0], atol=1e-6)


def test_a_stiff_model_and_sign_friction():
    # An actuator 1e5 1/s ahead of a 0.5 s lag, sampled at 0.01 s: the explicit integrator would need ~300 steps per
    # sample; integrator="auto" (the default) falls back to BDF, whose output matches the exact linear simulation.
    stiff = {"inputs": ["u"], "states": ["x1", "x2"], "outputs": {"y": "x2"},
             "parameters": {"b": 2.0, "tau": 0.5, "k1": {"value": 1e5, "fixed": True}},
             "equations": {"x1": "k1*(b*u - x1)", "x2": "(x1 - x2)/tau"}, "initial": {"x1": 0, "x2": 0}}
    n, ts = 300, 0.01
    u = np.repeat(np.random.default_rng(3).uniform(-1, 1, n // 50 + 1), 50)[:n].reshape(-1, 1)
    t = np.arange(n) * ts
    m = ctid.greybox_model(stiff)
    explicit = m.simulate(u, t, integrator="explicit", rtol=1e-10)
    assert not explicit.ok() and "integrator=bdf" in explicit.message
    s = m.simulate(u, t, rtol=1e-10)
    assert s.ok() and s.integrator == "bdf"
    exact = ctid.TransferFunction([2e5], [0.5, 0.5e5 + 1, 1e5]).simulate(u[:, 0], t)
    np.testing.assert_allclose(s.y[:, 0], exact, atol=1e-7 * np.abs(exact).max())  # rtol 1e-10 BDF (2.4e-9 measured)
    r = ctid.greybox(ctid.IdData(u, exact.reshape(-1, 1), ts), dict(stiff, parameters={
        "b": 1.5, "tau": 0.7, "k1": {"value": 1e5, "fixed": True}}), integrator="bdf")
    assert r.usable(), r.why_not_usable()
    np.testing.assert_allclose(r.parameters.values[:2], [2.0, 0.5], rtol=1e-6)
    # Coulomb friction sign(v): the mass sticks (Filippov sliding) while the force is below fc.
    friction = {"inputs": ["u"], "states": ["q", "v"], "outputs": {"y": "q"}, "parameters": {"fc": 1.0},
                "equations": {"q": "v", "v": "u - fc*sign(v)"}, "initial": {"q": 0, "v": 0}}
    u2 = np.full((200, 1), 0.5)
    u2[100:] = 1.5  # above fc from 1 s on: it slides with acceleration 0.5
    f = ctid.greybox_model(friction).simulate(u2, np.arange(200) * 0.01, rtol=1e-10)
    assert f.ok(), f.message
    assert np.abs(f.x[:101, 1]).max() < 1e-12  # at rest
    np.testing.assert_allclose(f.x[150, 0], 0.25 * 0.5 ** 2, rtol=1e-8)  # q = a t^2 / 2 with a = 0.5, t = 0.5 s


def test_a_non_finite_initial_state_is_refused():
    # Before: x0=[nan] simulated from 0, silently. The message names the state and the value.
    m = ctid.greybox_model(MODEL)
    u = np.zeros((10, 1))
    with pytest.raises(ValueError, match=r"x0\[0\] \(x\(0\)\) is nan"):
        m.simulate(u, np.arange(10) * 0.1, x0=[float("nan")])
