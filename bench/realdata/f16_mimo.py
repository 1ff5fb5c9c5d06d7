"""F-16 ground vibration test, the whole 2-15 Hz band (docs/gallery.md): the modes of a MIMO continuous-time
state-space model (force -> the three accelerations) at each of the 7 excitation levels, with their standard deviations.

For each full-grid multisine record: the FRF matrix (1 input x 3 outputs) at the 267 excited lines of 2-15 Hz by
ctid.frf_from_periodic from periods 2-5 (period 1 holds the transient; estimation) and from periods 6-9
(validation); ctid.ssest on the estimation FRF (the frequency-domain subspace start refined by weighted least
squares, each output's error variance estimated from the residuals: use_variance=False, because the period-to-period
variance misses the nonlinear distortion of the single realisation, see chi2 below), nx = NX states; its modes
between 2 and 15 Hz with one-standard-deviation bounds; the FRF fit of the same model on the validation periods. A
mode narrower than the line spacing (half-power bandwidth 2 zeta f_n < 0.049 Hz) is not resolved by these data and
is not listed. Writes f16_mimo_modes.csv (level, force, mode f, std, zeta, std) and f16_mimo.csv (per level: fits,
chi2 of the data variances, seconds) into OUT_DIR.

Usage: python3 f16_mimo.py DATA_DIR OUT_DIR [NX]
"""
import csv
import pathlib
import sys
import time

import numpy as np

import ctid

P, TS = 8192, 1 / 400.0  # samples per period, sampling period (s)
BAND = (2.0, 15.0)        # Hz


def record(d, first, last):
    """Periods [first, last) (0-based) of the force and the three accelerations as an IdData."""
    rows = d[P * first:P * last]
    return ctid.IdData(rows[:, [0]], rows[:, 2:5], TS)


def frf_fit(fd, model):
    """100 (1 - ||G - Ghat|| / ||G||) over all entries and lines."""
    g = np.array([m[:, 0] for m in fd.matrices])
    gh = np.array([m[:, 0] for m in model.frequency_response(fd.w)])
    return 100 * (1 - np.linalg.norm(g - gh) / np.linalg.norm(g))


def main(data_dir, out_dir, nx):
    data_dir, out_dir = pathlib.Path(data_dir), pathlib.Path(out_dir)
    files = sorted(data_dir.glob("F16Data_FullMSine_Level*.csv"), key=lambda p: p.name.split("Level")[1][0])
    levels, modes = [], []
    for path in files:
        level = int(path.name.split("Level")[1][0])
        d = np.genfromtxt(path, delimiter=",", skip_header=1, usecols=(0, 1, 2, 3, 4))
        force_rms = np.sqrt(np.mean(d[P:, 0] ** 2))
        est = ctid.frf_from_periodic([record(d, 0, 5)], P, skip=1)
        val = ctid.frf_from_periodic([record(d, 5, 9)], P, skip=0)
        t0 = time.perf_counter()
        r = ctid.ssest(est, nx, use_variance=False)
        seconds = time.perf_counter() - t0
        # The data variances' view of the same model: chi2 per degree of freedom with the period-to-period variances.
        chi2 = ctid.ssest(est, initial=r.model, max_iterations=1).diagnostics.scalars["chi2_per_dof"]
        if not r.usable():
            print(f"level {level}: not usable ({r.why_not_usable()})")
            continue
        fit_val = frf_fit(val, r.model)
        levels.append(dict(level=level, force_rms=round(force_rms, 1), nx=nx, fit_est=round(r.fit.fit_percent, 2),
                           fit_val=round(fit_val, 2), chi2_data_variance=round(chi2, 1),
                           iterations=r.summary.iterations, seconds=round(seconds, 2)))
        wn_std, zeta_std = r.diagnostics.vectors["mode_wn_std"], r.diagnostics.vectors["mode_zeta_std"]
        listed = []
        for m, sw, sz in zip(r.model.modes(), wn_std, zeta_std):
            f = m["wn"] / (2 * np.pi)
            if m["pole"].imag <= 0 or not BAND[0] <= f <= BAND[1] or 2 * m["zeta"] * f < 1 / (P * TS):
                continue
            modes.append(dict(level=level, force_rms=round(force_rms, 1), f_hz=f, f_std=sw / (2 * np.pi), zeta=m["zeta"],
                              zeta_std=sz))
            listed.append(f"{f:.3f}+-{sw / (2 * np.pi):.3f} Hz ({100 * m['zeta']:.2f}+-{100 * sz:.2f} %)")
        print(f"level {level}: force {force_rms:5.1f} N rms  nx {nx}  FRF fit {r.fit.fit_percent:.1f} % (periods 2-5), "
              f"{fit_val:.1f} % (6-9)  chi2 with the data variances {chi2:.0f}  {r.summary.iterations} iterations "
              f"{seconds:.1f} s")
        print("   modes: " + ", ".join(listed))
    out_dir.mkdir(parents=True, exist_ok=True)
    for name, rows in (("f16_mimo.csv", levels), ("f16_mimo_modes.csv", modes)):
        with open(out_dir / name, "w", newline="") as fh:
            wr = csv.DictWriter(fh, fieldnames=list(rows[0]))
            wr.writeheader()
            wr.writerows(rows)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 20)
