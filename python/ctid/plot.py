"""Plots of data, fits and models on matplotlib (imported only when a function here is called).

Every function draws on `ax` (or new axes) and returns the axes it drew on.
"""
import numpy as np

from . import FsfModel, InvalidArgument, MisoModel, TransferFunction, frequency_grid, frequency_response, \
    impulse_response, input_residual_crosscorrelation, step_response, \
    magnitude_band, residual_autocorrelation, response_horizon, simulate


def _axes(ax, n=1):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(n, 1, figsize=(7, 2.6 * n), squeeze=False)
    fig.tight_layout()
    return axes[:, 0] if n > 1 else axes[0, 0]


def compare(data, *models, labels=None, ax=None):
    """Measured output against the simulated output of each model (legend: fit %)."""
    from . import fit_percent
    ax = _axes(ax)
    t = data.times
    y = data.y[:, 0]
    ax.plot(t, y, color="0.3", lw=1, label="measured")
    for i, m in enumerate(models):
        yh = simulate(m, data)
        ok = np.isfinite(yh)
        fit = fit_percent(y[ok], yh[ok]) if ok.any() else float("nan")
        name = labels[i] if labels else type(getattr(m, "model", m)).__name__
        ax.plot(t, yh, lw=1, label=f"{name} (fit {fit:.1f} %)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel(data.output_names[0] if data.output_names else "y")
    ax.legend(loc="best", fontsize="small")
    return ax


def residuals(data, model, max_lag=25, ax=None):
    """Residual autocorrelation and input-residual cross-correlation with their 99 % bounds."""
    axes = _axes(ax, 2)
    e = data.y[:, 0] - simulate(model, data)
    e = e[np.isfinite(e)]
    tests = [("residual autocorrelation", residual_autocorrelation(e, max_lag)),
             ("input-residual cross-correlation", input_residual_crosscorrelation(data.u[-len(e):, 0], e, max_lag))]
    for a, (title, c) in zip(axes, tests):
        a.vlines(c.lags, 0, c.values, lw=2)
        a.axhspan(-c.bound, c.bound, color="C0", alpha=0.15)
        a.set_title(f"{title}: {c.n_outside} lag(s) outside", fontsize="small")
        a.set_xlabel("lag (samples)")
    return axes


def bode(model, w=None, confidence=True, ax=None):
    """Bode magnitude (dB) and phase (deg); with confidence=True a band of +-2 std (FSF: from the
    parameter covariance exactly; transfer-function results: 2.5-97.5 % of 200 draws from it)."""
    axes = _axes(ax, 2)
    m = getattr(model, "model", model)
    if w is None:
        if isinstance(m, (TransferFunction, MisoModel)):
            poles = np.concatenate([g.poles() for g in m.channels]) if isinstance(m, MisoModel) else m.poles()
            w = frequency_grid(poles, 0.0, 400)  # the report's grid
        elif isinstance(m, FsfModel):
            w = np.linspace(0.5 * 2 * np.pi / m.T, np.pi / m.delta * 0.95, 400)
        else:
            raise InvalidArgument(f"bode: give w for a {type(m).__name__}")
    h = frequency_response(m, w)  # the library's (the report's): a multi-input model gives a curve per input
    axes[0].semilogx(w, 20 * np.log10(np.abs(h)), lw=1.2)
    axes[1].semilogx(w, np.degrees(np.unwrap(np.angle(h), axis=0)), lw=1.2)
    if confidence:
        lo = hi = None
        if isinstance(m, FsfModel) and m.covariance.size:
            s = m.freqresp_std(w)
            band = 2 * np.hypot(s.real, s.imag)
            lo, hi = np.maximum(np.abs(h) - band, 1e-300), np.abs(h) + band
        elif isinstance(m, TransferFunction) and hasattr(model, "parameters"):
            band = magnitude_band(model, w)  # the report's band: 2.5-97.5 % of 200 seeded draws
            if band is not None:
                lo, hi = band
        if lo is not None:
            axes[0].fill_between(w, 20 * np.log10(lo), 20 * np.log10(hi), alpha=0.25, lw=0)
    axes[0].set_ylabel("magnitude (dB)")
    axes[1].set_ylabel("phase (deg)")
    axes[1].set_xlabel("frequency (rad/s)")
    return axes


def _response(kind, model, t, ax):
    ax = _axes(ax)
    m = getattr(model, "model", model)
    if t is None:
        if isinstance(m, FsfModel):
            t = np.linspace(0, m.T, 400)
        elif isinstance(m, (TransferFunction, MisoModel)):
            t = np.linspace(0, response_horizon(m.channels if isinstance(m, MisoModel) else [m], 10.0), 400)
        else:
            raise InvalidArgument(f"{kind}: give t for a {type(m).__name__}")
    y = step_response(m, t) if kind == "step" else impulse_response(m, t)  # the library's, as the report's
    ax.plot(t, y, lw=1.2)
    if isinstance(m, FsfModel) and m.covariance.size:
        s = m.step_std(t) if kind == "step" else m.impulse_std(t)
        ax.fill_between(t, y - 2 * s, y + 2 * s, alpha=0.25, lw=0)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"{kind} response")
    return ax


def step(model, t=None, ax=None):
    """Step response (FSF models with a +-2 std band)."""
    return _response("step", model, t, ax)


def impulse(model, t=None, ax=None):
    """Impulse response (FSF models with a +-2 std band)."""
    return _response("impulse", model, t, ax)
