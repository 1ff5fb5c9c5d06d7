"""TransferFunction.simulate against SciPy's c2d + lfilter, measured in the same run.

    PYTHONPATH=build/python /usr/bin/python3 bench/simulate_vs_scipy.py [--samples 1000000]

Models: Butterworth-like low-pass filters of order 2, 4 and 8 (poles on a circle of radius 10 rad/s), ZOH input
(white noise), Ts = 10 ms. Times are the least of 7 runs. ctid: simulate(u, t) into a new array, and into a reused
array (out=); simulate(u, Ts), the sampling period instead of the times (what lfilter is given: no times to read and
check), into a new array; the speed-up is SciPy's time over this one's. SciPy: scipy.signal.cont2discrete of the
transfer function (ZOH) then lfilter, the way a SciPy user simulates a sampled transfer function, timed without the
(one-off) c2d; and dlsim of the discretised state space for reference. Accuracy: the largest difference from an
exact reference (SciPy's matrix-exponential discretisation of the state space, run through dlsim) relative to the
output's range.
"""
import argparse

import numpy as np
import scipy.signal as ss

import ctid
from timing import least_time


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=1_000_000)
    a = ap.parse_args()
    n, h = a.samples, 0.01
    u = np.random.default_rng(1).standard_normal(n)
    t = ctid.time_grid(h, n)
    buf = np.empty(n)
    print(f"N = {n}, Ts = {h} s, ZOH; times in ms (least of 7)")
    print("| order | ctid simulate(u, t) | ctid simulate(u, t, out=) | ctid simulate(u, Ts) | SciPy c2d + lfilter "
          "| ctid speed-up | SciPy dlsim (ss) | error ctid | error lfilter |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for order in (2, 4, 8):
        poles = 10.0 * np.exp(1j * np.pi * (2 * np.arange(1, order + 1) + order - 1) / (2 * order))
        den = np.real(np.poly(poles))
        num = [den[-1]]
        g = ctid.TransferFunction(num, den)
        t_ctid, y = least_time(lambda: g.simulate(u, t), 7)
        t_out, _ = least_time(lambda: g.simulate(u, t, out=buf), 7)
        t_ts, y_ts = least_time(lambda: g.simulate(u, h), 7)
        assert np.array_equal(y_ts, y)
        bd, ad, _ = ss.cont2discrete((num, den), h, method="zoh")
        bd = np.ravel(bd)
        t_lf, y_lf = least_time(lambda: ss.lfilter(bd, ad, u), 7)
        A, B, C, D = ss.tf2ss(num, den)
        sysd = ss.cont2discrete((A, B, C, D), h, method="zoh")
        t_dl, (_, y_ref, _) = least_time(lambda: ss.dlsim(sysd, u), 1)
        y_ref = y_ref[:, 0]
        scale = np.ptp(y_ref)
        err_c = np.max(np.abs(y - y_ref)) / scale
        err_l = np.max(np.abs(y_lf - y_ref)) / scale
        print(f"| {order} | {1e3 * t_ctid:.1f} | {1e3 * t_out:.1f} | {1e3 * t_ts:.1f} | {1e3 * t_lf:.1f} | "
              f"{t_lf / t_ts:.2f}x | "
              f"{1e3 * t_dl:.0f} | {err_c:.1e} | {err_l:.1e} |")


if __name__ == "__main__":
    main()
