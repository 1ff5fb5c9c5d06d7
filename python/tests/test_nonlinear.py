import numpy as np
import pytest

import ctid


def test_narx_kia_and_refinement_reconstruct_bl33(bl33):
    truth, d = bl33
    r = ctid.frols(d, ctid.narx_candidates(2, 6, 6), max_terms=20, criterion="aic")
    assert r.usable() and len(r.parameters) <= 20
    assert "ERR" not in repr(r.model)  # the model prints as an equation
    lin = ctid.kia_linear(r.model, y_order=2, u_order=0)
    q = ctid.kia_quadratic(r.model, lin.model, candidates=["y^2", "y*Dy"])
    refined = ctid.nde_oe(d, q.model)
    assert refined.usable()
    # Noise-free record: KIA within 1 %, its output-error refinement within 0.1 % (as the C++ tests).
    for name in ["Dy", "D^2y", "u", "y^2", "y*Dy"]:
        c = truth.coefficient(name)
        assert q.model.normalized().coefficient(name) == pytest.approx(c, rel=0.01), name
        assert refined.model.coefficient(name) == pytest.approx(c, rel=1e-3), name
    assert "y*Dy" in repr(refined.model)


def test_gfrf_and_harmonic_probing(bl33):
    truth, d = bl33
    r = ctid.frols(d, ctid.narx_candidates(2, 6, 6), max_terms=20, criterion="aic")
    # H_1 at 10 rad/s: the NARX kernel (hold factor removed) against the NDE's.
    assert abs(r.model.gfrf([10j]) - truth.h1(10j)) < 2e-3 * abs(truth.h1(10j))
    h2 = r.model.gfrf([10j, 30j])
    assert abs(h2 - truth.h2(10j, 30j)) < 0.05 * abs(truth.h2(10j, 30j))


def test_narmax_options_nested_and_enum_errors(bl33):
    _, d = bl33
    r = ctid.narmax(d, ctid.narx_candidates(1, 2, 2), frols={"max_terms": 4}, iterations=3)
    assert r.summary.termination in ("completed", "converged")
    with pytest.raises(ValueError, match="criterion.*aic"):
        ctid.frols(d, ctid.narx_candidates(1, 2, 2), criterion="akaike")
    with pytest.raises(ctid.InvalidArgument, match="w"):
        ctid.frols(d, ["y(k-1)*w(k-2)"])


def test_nde_simulation_reports_an_escape():
    m = ctid.NdeModel(["Dy", "y^2", "u"], np.array([1.0, -1.0, 5.0]))  # Dy = y^2 - 5u blows up for u < 0
    s = m.simulate(-np.ones(100), ctid.time_grid(0.01, 100))
    assert not s.ok() and s.termination == "numerical_failure" and "escapes" in s.message
    assert np.isnan(s.y[-1])
