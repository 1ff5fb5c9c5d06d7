"""One table of settings per method. The registry (ctid.methods / ctid.settings, read from the
C++ tables that the CLI's --help also prints) must match the Python options classes name for name, and the
defaults Python reads must be those the registry documents."""
import math

import pytest

import ctid


def _python_default_matches(kind, text, value):
    if kind == "real":
        return value == pytest.approx(float(text), rel=1e-5) or (math.isinf(value) and text in ("inf", "-inf"))
    if kind == "integer":
        return value == int(text)
    if kind == "flag":
        return value is (text == "1")
    if kind == "choice":
        return value == text
    if kind == "list of reals":
        return (text == "none" and len(value) == 0) or list(value) == [float(x) for x in text.split(",")]
    if kind in ("values by name", "bounds by name"):
        return text == "" and value == {}
    if kind == "list of names":
        return (text == "none" and list(value) == []) or list(value) == text.split(",")
    if kind == "transfer function":
        return (text == "none" and value is None) or isinstance(value, ctid.TransferFunction)
    raise AssertionError(kind)


def test_registry_matches_the_python_options_classes():
    assert len(ctid.methods()) >= 11
    for method in ctid.methods():
        settings = ctid.settings(method)
        classes = [getattr(ctid._ctid, s) for s in ctid._ctid.method_structs(method)]
        assert [n for c in classes for n in c._names] == [s["name"] for s in settings], method
        for s in settings:
            cls = next(c for c in classes if s["name"] in c._names)
            value = getattr(cls(), s["name"])
            assert _python_default_matches(s["kind"], s["default"], value), (method, s, value)
            assert s["doc"], (method, s["name"])


def test_every_setting_is_a_keyword_of_its_function_and_round_trips():
    # Each setting given to the keyword layer with a value of its kind lands in the options struct.
    examples = {"real": 0.25, "integer": 3, "flag": True, "list of reals": [0.5, 1.5],
                "values by name": {"a1": 2.0}, "bounds by name": {"a1": (0.0, 10.0)},
                "transfer function": ctid.TransferFunction([1.0], [0.1, 1.0])}
    for method in ctid.methods():
        for struct in ctid._ctid.method_structs(method):
            cls = getattr(ctid._ctid, struct)
            for s in ctid.settings(method):
                if s["name"] not in cls._names:
                    continue
                if s["kind"] == "choice":
                    value = s["range"].split("|")[-1]
                elif s["kind"] == "list of names":
                    value = ["e(k-1)"] if "noise" in s["name"] else ["y^2"]
                else:
                    value = examples[s["kind"]]
                o = ctid._options(cls, method, {s["name"]: value})
                got = getattr(o, s["name"])
                if s["kind"] == "transfer function":
                    assert got.den == pytest.approx([0.1, 1.0]) or got.den == pytest.approx([1.0, 10.0])
                elif s["kind"] == "bounds by name":
                    assert got == {"a1": (0.0, 10.0)}
                elif s["kind"] == "list of names":
                    assert list(got) == value
                elif s["kind"] == "list of reals":
                    assert list(got) == [0.5, 1.5]
                else:
                    assert got == value, (method, s["name"], got)


def test_unknown_or_mistyped_settings_name_the_closest_valid_one():
    d = ctid.IdData.from_arrays([0.0, 1.0, 1.0, 0.0] * 10, [0.0, 0.5, 0.8, 0.4] * 10, ts=0.1)
    with pytest.raises(TypeError, match="unknown option 'tau_grid'; did you mean 'tau_grid_size'"):
        ctid.lssvf(d, 1, 1, tau_grid=5)
    with pytest.raises(TypeError, match="did you mean 'reference_at_plant_input'"):
        ctid._options(ctid._ctid.ClosedLoopOptions, "srivc_closed_loop", {"reference_at_plant": False})
    with pytest.raises(ctid.InvalidOptions, match="weights must be one of riemann, trapezoidal"):
        ctid.lssvf(d, 1, 1, weights="simpson")
    with pytest.raises(ctid.InvalidOptions, match="max_iterations takes a whole number"):
        ctid.srivc(d, 1, 1, max_iterations=2.5)
    with pytest.raises(ctid.InvalidOptions, match=r"tau must be > 0, or 0 \(automatic\) \(got -1 s\)"):
        ctid.lssvf(d, 1, 1, tau=-1.0)
    with pytest.raises(ctid.InvalidOptions, match="'srvic' is not a method; did you mean 'srivc'"):
        ctid.settings("srvic")


def test_diagnostics_are_declared_per_method():
    # The keys of a result's diagnostics are declared (name, kind, unit, doc) in the library's
    # catalogue, and each method lists those it can report (the C++ registry, MethodInfo::diagnostics).
    import numpy as np
    every = {d["name"]: d for d in ctid.diagnostics()}
    assert every["noise_variance"]["unit"] == "y^2" and every["noise_variance"]["kind"] == "scalar"
    assert every["x0"]["per_record"] and every["x0"]["kind"] == "vector"
    srivc = [d["name"] for d in ctid.diagnostics("srivc")]
    assert "noise_variance" in srivc and "delay" in srivc and "tau" not in srivc
    g = ctid.TransferFunction([2.0], [1.0, 1.0])
    u = ctid.prbs(1000, register_length=8, clock_period=5)
    d = ctid.IdData.from_arrays(u, g.simulate(u, 0.01 * np.arange(u.size)), ts=0.01)
    r = ctid.srivc(d, 1, 1)
    assert set(r.diagnostics.scalars) <= set(srivc)
    assert r.diagnostics.scalars["noise_variance"] >= 0
    with pytest.raises(ctid.InvalidOptions, match="'srvic' is not a method"):
        ctid.diagnostics("srvic")


def test_batch_rls_svf_matches_the_recursive_estimator():
    # ctid.rls_svf(data, ...) is the recursion of ctid.rls_svf_recursive run over the record (same final estimate).
    import numpy as np
    g = ctid.TransferFunction([2.0], [1.0, 1.0])
    u = ctid.prbs(2000, register_length=8, clock_period=5)
    t = 0.01 * np.arange(u.size)
    d = ctid.IdData.from_arrays(u, g.simulate(u, t), ts=0.01)
    r = ctid.rls_svf(d, 1, 1, tau=0.5)
    rec = ctid.rls_svf_recursive(1, 1, tau=0.5)
    rec.run(t, u, d.y[:, 0])
    np.testing.assert_allclose(r.parameters.values, rec.parameters(), rtol=1e-12)
    assert r.parameters.values == pytest.approx([1.0, 2.0], rel=1e-3)  # noise-free record of 2/(s + 1)
    assert r.fit.fit_percent > 99.0
    # The continuous-time recursion (RJ 56-57) by the same option name as in C++ and the CLI.
    c = ctid.rls_svf(d, 1, 1, tau=0.5, recursion="continuous", alpha=0.1)
    rec = ctid.rls_svf_recursive(1, 1, tau=0.5, recursion="continuous", alpha=0.1)
    rec.run(t, u, d.y[:, 0])
    np.testing.assert_allclose(c.parameters.values, rec.parameters(), rtol=1e-12)
    assert c.parameters.values == pytest.approx([1.0, 2.0], rel=1e-3)
    with pytest.raises(ctid.InvalidOptions, match="forgetting 0.99"):
        ctid.rls_svf(d, 1, 1, recursion="continuous", forgetting=0.99)
