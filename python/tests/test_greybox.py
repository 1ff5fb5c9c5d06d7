"""ctid.greybox (issue 15): the model as a dict or a file, the fit, result files and simulation from Python."""
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
