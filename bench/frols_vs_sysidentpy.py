"""FROLS of ctid and of SysIdentPy on the same records, in the same run (speed ratios only from one run).

    PYTHONPATH=build/python:SYSIDENTPY_SRC /usr/bin/python3 bench/frols_vs_sysidentpy.py [--sizes 1000,10000,100000]

SysIdentPy is run from its source tree (the `fetch` snapshot of github.com/wilsonrljr/sysidentpy; nothing of it is
in ctid). Problem: SysIdentPy's benchmark set-up — polynomial degree 2, input and output lags 1..16 (561 candidates
with the constant), a degree-2 NARX record of N samples; FROLS with 20 terms, and with the model size chosen by AIC
over 20 sizes. SysIdentPy: FROLS(order_selection=False, n_terms=20) and FROLS(order_selection=True,
n_info_values=20, info_criteria="aic"), model_type="NARMAX", estimator LeastSquares, basis Polynomial(degree=2).
ctid: ctid.frols(record, ctid.narx_candidates(2, 16, 16), max_terms=20 [, criterion="aic"]), the same record.
Times: the least of 3 runs (1 run where a fit takes over 10 s). The selected terms of both are compared.
"""
import argparse

import numpy as np

import ctid
from timing import least_time


def record(n):
    rng = np.random.default_rng(1)
    u = rng.standard_normal(n)
    e = 0.05 * rng.standard_normal(n)
    y = np.zeros(n)
    for k in range(2, n):
        y[k] = (0.5 * y[k - 1] - 0.2 * y[k - 2] + 0.3 * u[k - 1] + 0.2 * u[k - 2] + 0.1 * y[k - 1] * u[k - 1]
                - 0.05 * y[k - 2] ** 2 + e[k])
    return u, y


def sid_terms(final_model):
    """SysIdentPy's term codes (1000 + j: y(k-j), 2000 + j: u(k-j), 0: none) as ctid's factor names."""
    name = {1: "y", 2: "u"}
    return {tuple(sorted(f"{name[c // 1000]}(k-{c % 1000})" for c in row if c)) or ("1",) for row in final_model}


def ctid_terms(names):
    return {tuple(sorted(n.split("*"))) if n not in ("1", "constant") else ("1",) for n in names}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="1000,10000,100000")
    ap.add_argument("--aic-sizes", default="1000,10000")
    a = ap.parse_args()
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.model_structure_selection import FROLS
    from sysidentpy.parameter_estimation import LeastSquares

    cand = ctid.narx_candidates(2, 16, 16)
    print(f"candidates: {len(cand)}")
    print("| N | criterion | ctid | SysIdentPy | ctid speed-up (same run) | same terms |")
    print("|---:|---|---:|---:|---:|---|")
    aic_sizes = {int(s) for s in a.aic_sizes.split(",") if s}
    for n in (int(s) for s in a.sizes.split(",")):
        u, y = record(n)
        data = ctid.IdData.from_arrays(u, y, ts=1.0)
        for crit in ("20 terms", "AIC") if n in aic_sizes else ("20 terms",):
            opts = dict(max_terms=20) if crit == "20 terms" else dict(max_terms=20, criterion="aic")
            t_c, r = least_time(lambda: ctid.frols(data, cand, **opts), 3, slow=10.0)

            def sid():
                m = FROLS(order_selection=crit == "AIC", n_terms=None if crit == "AIC" else 20, n_info_values=20,
                          info_criteria="aic", ylag=16, xlag=16, model_type="NARMAX", estimator=LeastSquares(),
                          basis_function=Polynomial(degree=2))
                m.fit(X=u.reshape(-1, 1), y=y.reshape(-1, 1))
                return m
            t_s, m = least_time(sid, 3, slow=10.0)
            a_terms, b_terms = ctid_terms(r.parameters.names), sid_terms(m.final_model)
            same = "yes" if a_terms == b_terms else f"{len(a_terms & b_terms)} common"
            print(f"| {n} | {crit} | {1e3 * t_c:.1f} ms | {t_s:.2f} s | {t_s / t_c:.0f}x | "
                  f"{same} ({len(a_terms)} / {len(b_terms)} terms) |", flush=True)


if __name__ == "__main__":
    main()
