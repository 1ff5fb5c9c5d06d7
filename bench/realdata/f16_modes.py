"""F-16 ground vibration test (docs/gallery.md): how do the frequency and damping of the wing-torsion mode
(about 7.3 Hz) change with the excitation level?

For each of the 7 full-grid multisine records (force -> Acceleration2, next to the nonlinear interface):
the frequency response at the excited lines in 6.3-8.3 Hz, averaged over periods 2-5 (estimation) and
6-9 (validation; period 1 holds the transient), a 6th-order continuous-time transfer function fitted to
the estimation response by ctid.tf_from_frequency (Sanathanan-Koerner, then output error), and its
modes. A mode whose half-power bandwidth 2 zeta f_n is narrower than the line spacing (0.049 Hz) cannot be
resolved by these data (it fits single lines) and is not reported. Prints one line per level and writes
f16_modes.csv (and f16_frf.png when matplotlib is available) into OUT_DIR.

Usage: python3 f16_modes.py DATA_DIR OUT_DIR
"""
import csv
import pathlib
import sys

import numpy as np

import ctid

P, FS = 8192, 400.0  # samples per period, sampling frequency (Hz)
BAND = (6.3, 8.3)    # Hz
ORDER = 6


def spectra(d, first, last):
    """Period-averaged FRF Acceleration2/Force at the excited lines in BAND, periods [first, last)."""
    F = np.fft.rfft(d[P * first:P * last].reshape(-1, P, d.shape[1]), axis=1).mean(axis=0)
    f = np.arange(F.shape[0]) * FS / P
    U = F[:, 0]
    lines = (np.abs(U) > 0.1 * np.abs(U).max()) & (f > BAND[0]) & (f < BAND[1])
    return 2 * np.pi * f[lines], F[lines, 3] / U[lines]


def fit_percent(g, gh):
    return 100 * (1 - np.linalg.norm(g - gh) / np.linalg.norm(g - g.mean()))


def main(data_dir, out_dir):
    data_dir, out_dir = pathlib.Path(data_dir), pathlib.Path(out_dir)
    files = sorted(data_dir.glob("F16Data_FullMSine_Level*.csv"), key=lambda p: p.name.split("Level")[1][0])
    rows, curves = [], []
    for path in files:
        level = int(path.name.split("Level")[1][0])
        d = np.genfromtxt(path, delimiter=",", skip_header=1, usecols=(0, 1, 2, 3, 4))
        force_rms = np.sqrt(np.mean(d[P:, 0] ** 2))
        w, g = spectra(d, 1, 5)
        _, g_val = spectra(d, 5, 9)
        r = ctid.tf_from_frequency((w, g), ORDER + 1, ORDER)  # biproper: acceleration over force
        if not r.usable():
            print(f"level {level}: not usable ({r.why_not_usable()})")
            continue
        p = r.model.poles()
        p = p[p.imag > 0]
        fn, zeta = np.abs(p) / (2 * np.pi), -p.real / np.abs(p)
        resolved = 2 * zeta * fn >= FS / P
        torsion = [(f, z) for f, z, ok in zip(fn, zeta, resolved) if ok and 6.9 < f < 7.5]
        if not torsion:
            print(f"level {level}: no resolved mode in 6.9-7.5 Hz (modes {list(zip(fn, zeta))})")
            continue
        f_t, z_t = max(torsion, key=lambda m: m[1])
        row = dict(level=level, force_rms=force_rms, f_torsion=f_t, zeta_torsion=z_t,
                   fit_est=r.fit.fit_percent, fit_val=fit_percent(g_val, r.model.freqresp(w)),
                   unresolved=int((~resolved).sum()))
        rows.append(row)
        curves.append((level, force_rms, w, g_val, r.model))
        print(f"level {level}: force {force_rms:5.1f} N rms  torsion mode {f_t:.3f} Hz, damping {100 * z_t:.2f} %  "
              f"FRF fit {row['fit_est']:.1f} % (estimation), {row['fit_val']:.1f} % (validation periods)  "
              f"unresolved modes {row['unresolved']}")
    out_dir.mkdir(parents=True, exist_ok=True)
    with open(out_dir / "f16_modes.csv", "w", newline="") as fh:
        wr = csv.DictWriter(fh, fieldnames=list(rows[0]))
        wr.writeheader()
        wr.writerows(rows)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(8, 4.5))
    wf = np.linspace(2 * np.pi * BAND[0], 2 * np.pi * BAND[1], 800)
    for level, force_rms, w, g_val, model in curves:
        if level not in (1, 3, 7):
            continue
        line, = ax.semilogy(w / (2 * np.pi), np.abs(g_val), ".", ms=3, label=f"measured, {force_rms:.0f} N rms")
        ax.semilogy(wf / (2 * np.pi), np.abs(model.freqresp(wf)), "-", color=line.get_color(), lw=1,
                    label=f"6th-order CT fit, {force_rms:.0f} N rms")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("|Acceleration2 / Force|")
    ax.set_title("F-16 GVT: the torsion mode moves down and widens as the force grows")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out_dir / "f16_frf.png", dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
