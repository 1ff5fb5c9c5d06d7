"""The library's registry from Python: ctid.fit runs every method that fits records, by its name, on a small record
of its kind (the structure keywords its capabilities call for), gives what the method's own function gives, and
refuses what the method does not take. The same walk from the command line is tests/cli/cli_fit_test.cpp's
Cli.EveryRegisteredFitRunsFromTheCommandLine."""
import os
import subprocess

import numpy as np
import pytest

import ctid
from conftest import EXAMPLES_DATA


def _example(name, outputs=1):
    """A record of `ctid example-data NAME`: the columns after a time column t are the inputs, then the outputs."""
    e = ctid.example_data(name)
    columns, values = e.columns, np.asarray(e.values)
    first = 1 if columns[0] == "t" else 0
    ts = values[1, 0] - values[0, 0] if first else 0.0025
    u, y = values[:, first:values.shape[1] - outputs], values[:, values.shape[1] - outputs:]
    return ctid.IdData.from_arrays(u, y, ts=ts)


def _keywords(method):
    caps = ctid.method_capabilities(method)
    if caps["greybox_model"]:
        return _example("spring"), {"model": EXAMPLES_DATA / "spring_greybox.json"}
    if caps["narx_model"] or method == "narx":
        return _example("bl"), {"degree": 2, "ylag": 2, "ulag": 2}
    kw = {}
    if caps["needs_orders"]:
        kw.update(nb=1, nf=2)
    if caps["physical_model"]:
        kw.update(model="k*(s + z)/(s^2 + a*s + b)", parameters={"k": 0.8, "z": 2.5, "a": 1.0, "b": 3.5}, route="raw")
    if caps["nx"]:
        kw.update(nx=2)
    return _example("second"), kw


def test_every_registered_fit_runs_from_python_by_its_name():
    fits = ctid.fit_methods()
    assert len(fits) >= 15 and set(fits) <= set(ctid.methods())
    for method in fits:
        data, kw = _keywords(method)
        result, ran, settings = ctid._fit(data, method, **kw)
        assert ran == method
        assert result.model.__class__.__name__ in {"TransferFunction", "MisoModel", "StateSpace", "FsfModel",
                                                   "NarxModel", "NdeModel", "GreyboxModel"}
        assert result.fit.fit_percent > 0, (method, result.why_not_usable())
        # Every result class prints the library's text (ssest's StateSpaceResult included), in repr and notebooks.
        text = repr(result)
        assert text.startswith(type(result.model).__name__ + ": ") and "\ntermination: " in text, (method, text)
        assert "\nfit: " in text and "object at 0x" not in text, (method, text)
        assert result._repr_html_().startswith("<pre>") and result.report() == text
        # Every setting of the method with the value used (the raw physical route uses the window a of the FSF's).
        if method != "physical":
            assert {name for name, _ in settings} >= {s["name"] for s in ctid.settings(method)}, method


def test_fit_equals_the_methods_own_function():
    data = _example("second")
    a = ctid.fit(data, "srivc", nb=1, nf=2, max_iterations=30)
    b = ctid.srivc(data, 1, 2, max_iterations=30)
    assert list(a.parameters.values) == list(b.parameters.values)  # bit for bit
    assert list(a.parameters.std) == list(b.parameters.std)
    # Without a method: srivc with orders, srivc_auto without (as ctid fit).
    assert ctid.fit(data, nb=1, nf=2).model.den == pytest.approx(b.model.den, rel=1e-12)
    auto = ctid._fit(data)
    assert auto[1] == "srivc_auto"
    # An alias runs the method under its registry name.
    assert ctid._fit(data, "srivc-auto")[1] == "srivc_auto"


def test_fit_refuses_what_a_method_does_not_take():
    data = _example("second")
    with pytest.raises(ctid.InvalidOptions, match="oe: needs transfer-function orders"):
        ctid.fit(data, "oe")
    with pytest.raises(TypeError, match="srivc: unknown option 'max_iteration'; did you mean 'max_iterations'"):
        ctid.fit(data, "srivc", nb=1, nf=2, max_iteration=5)
    with pytest.raises(ctid.InvalidOptions, match="max_iterations takes a whole number"):
        ctid.fit(data, "srivc", nb=1, nf=2, max_iterations=True)
    with pytest.raises(ctid.InvalidArgument, match="fsf: fits one record \\(got 2\\)"):
        ctid.fit([data, data], "fsf")
    with pytest.raises(ctid.InvalidOptions, match="'srivcc' is not a method; did you mean 'srivc'"):
        ctid.fit(data, "srivcc")
    with pytest.raises(TypeError, match="takes no model"):
        ctid.fit(data, "srivc", nb=1, nf=2, model="k/s")


def test_capabilities_describe_each_method():
    caps = ctid.method_capabilities("srivc")
    assert caps["records"] and caps["several_records"] and caps["several_inputs"] and caps["references"]
    assert caps["model_types"] == ["transfer_function", "miso"]
    assert ctid.method_capabilities("srivc_auto")["aliases"] == ["srivc-auto"]
    assert ctid.method_capabilities("srivc_auto")["default_detrend"] == "mean"
    assert not ctid.method_capabilities("srivc_miso")["records"]
    assert ctid.method_capabilities("srivc_miso")["reached_by"] == "srivc on records with several inputs"


@pytest.mark.skipif(not os.environ.get("CTID_CLI"), reason="the command line is not built (CTID_CLI unset)")
def test_simulate_equals_the_command_line_for_every_model_type(tmp_path):
    # One rule for the initial state: ctid.simulate(result, record, initial) equals `ctid simulate RESULT RECORD
    # --initial ...` to 1e-12 of the output's scale, for a result of every model type fitted on the first part of a
    # record and simulated on the rest, for each initial condition and the default; both refuse the same ones.
    cases = [("second", 1000, "srivc", {"nb": 1, "nf": 2}), ("second", 1000, "ssest", {"nx": 2}),
             ("second", 1000, "fsf", {}), ("miso", 1000, "srivc", {"orders": [(1, 2, 0), (1, 2, 0)]}),
             ("bl", 600, "narx", {"degree": 2, "ylag": 2, "ulag": 2}),
             ("bl", 600, "kia", {"degree": 2, "ylag": 2, "ulag": 2}),
             ("spring", 900, "greybox", {"model": EXAMPLES_DATA / "spring_greybox.json"})]
    for name, first, method, kw in cases:
        e = ctid.example_data(name)
        values = np.asarray(e.values)
        timed = e.columns[0] == "t"
        ins = list(e.columns[1 if timed else 0:-1])
        second = tmp_path / f"{name}2.csv"
        with open(second, "w") as f:
            f.write(",".join(e.columns) + "\n")
            for row in values[first:]:
                f.write(",".join(repr(float(x)) for x in row) + "\n")
        def record(rows):
            u, y = values[rows, 1 if timed else 0:-1], values[rows, -1]
            return (ctid.IdData.from_arrays(u, y, t=values[rows, 0]) if timed else
                    ctid.IdData.from_arrays(u, y, ts=0.0025))
        result, ran, _ = ctid._fit(record(slice(0, first)), method, **kw)
        path = tmp_path / f"{name}_{method}.json"
        ctid.write_result(str(path), result, ran)
        back = ctid.read_result(str(path)).result
        d2 = record(slice(first, len(values)))
        columns = (["--time", "t"] if timed else ["--ts", "0.0025"]) + sum((["--input", c] for c in ins), []) + \
            ["--output", e.columns[-1]]
        for initial in (None, "rest", "measured", "estimated"):
            cmd = [os.environ["CTID_CLI"], "simulate", str(path), str(second)] + columns + \
                (["--initial", initial] if initial else [])
            cli = subprocess.run(cmd, capture_output=True, text=True)
            try:
                import warnings
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", RuntimeWarning)
                    y = np.atleast_2d(ctid.simulate(back, d2, initial).T).T
            except ValueError:
                assert cli.returncode == 2, (name, method, initial, cli.stderr)
                continue
            if not np.all(np.isfinite(y)):
                assert cli.returncode == 1, (name, method, initial, cli.stderr)
                continue
            assert cli.returncode == 0, (name, method, initial, cli.stderr)
            table = np.loadtxt(cli.stdout.splitlines()[1:], delimiter=",", ndmin=2)
            ycli = table[:, -y.shape[1]:]
            assert np.max(np.abs(ycli - y)) <= 1e-12 * max(1.0, np.max(np.abs(y))), (name, method, initial)
