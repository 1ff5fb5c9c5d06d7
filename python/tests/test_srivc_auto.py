"""srivc_auto: the default route of `ctid fit`, the same function in Python; IdData.detrend."""
import numpy as np
import pytest

import ctid
from conftest import EXAMPLES_DATA


def test_srivc_auto_on_the_hair_dryer_chooses_a_structure_that_validates():
    # The bundled DaISy hair dryer (Ts = 0.08 s): estimated on the first 500 samples with their means removed, the
    # same offsets taken off the last 500, simulated there from the initial state that fits them best (as the C++
    # test SrivcAuto.HairDryerValidatesAbove85Percent, measured 89.7 %): >= 85 %.
    raw = np.loadtxt(EXAMPLES_DATA / "dryer.dat")
    u, y = raw[:, 0], raw[:, 1]
    est = ctid.IdData.from_arrays(u[:500], y[:500], ts=0.08)
    centred = est.detrend()
    assert np.allclose(centred.u.mean(axis=0), 0.0, atol=1e-12)
    assert np.allclose(centred.y[:, 0], y[:500] - y[:500].mean())
    r = ctid.srivc_auto(centred)
    assert r.usable()
    assert len(r.diagnostics.vectors["structure_nb"]) == 12  # nf 1..3, nb 1..nf, with and without a delay
    val = ctid.IdData.from_arrays(u[500:] - u[:500].mean(), y[500:] - y[:500].mean(), ts=0.08)
    sim = np.asarray(ctid.simulate(r.model, val, initial="estimated")).ravel()
    fit = 100 * (1 - np.linalg.norm(val.y[:, 0] - sim) / np.linalg.norm(val.y[:, 0] - val.y[:, 0].mean()))
    assert fit >= 85.0


def test_srivc_auto_options_and_detrend_kinds():
    d = ctid.IdData.from_arrays(np.arange(50.0), 2 * np.arange(50.0) + 1, ts=0.1)
    assert np.allclose(d.detrend("linear").y, 0.0, atol=1e-9)
    with pytest.raises(Exception, match="mean' or 'linear"):
        d.detrend("quadratic")
    with pytest.raises(TypeError, match="nf_max"):
        ctid.srivc_auto(d, nf_maximum=2)


def test_a_held_out_record_takes_the_estimation_records_trend():
    # IdData.remove_trend: the validation part of a record gets the estimation part's means (not its own), as
    # `ctid fit --validate-samples` does. y = 2 t + 1 at Ts = 0.1: the first 30 samples' mean is 3.9; removed from
    # the last 20 samples (t = 3.0 .. 4.9) it leaves 2 t + 1 - 3.9.
    d = ctid.IdData.from_arrays(np.arange(50.0), 2 * (0.1 * np.arange(50.0)) + 1, ts=0.1)
    est, val = d.slice(0, 30), d.slice(30, 50)
    e, trend = est.detrend_with_trend("mean")
    assert np.allclose(e.y.mean(), 0.0, atol=1e-12)
    assert abs(trend.y_offset[0] - 3.9) < 1e-12
    held = val.remove_trend(trend)
    assert np.allclose(held.y[:, 0], 2 * val.times + 1 - 3.9, atol=1e-12)
    assert "TrendInfo(" in repr(trend)
    with pytest.raises(Exception, match="the trend is of 1 input"):
        ctid.IdData.from_arrays(np.ones((5, 2)), np.arange(5.0), ts=0.1).remove_trend(trend)
