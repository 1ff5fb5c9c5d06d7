"""Plots of data, fits and models on matplotlib (imported only when a function here is called).

Every function returns the matplotlib Figure it drew on (its panels are ``fig.axes``): a new figure with constrained
layout — laid out again at every draw, so that labels, legends and titles are neither clipped nor overlapping — or,
with ``ax=``, the figure of the axes given. Responses, grids, horizons, bands and the comparison's numbers are the
library's, the same the HTML report and ``ctid compare`` show.
"""
import numpy as np

from . import FsfModel, InvalidArgument, MisoModel, StateSpace, TransferFunction, _ctid, drawn_models, \
    frequency_response, impulse_response, magnitude_band, response_band, response_horizon, step_response


def _figure(ax, n=1, height=2.4):
    """(figure, list of n axes): the axes given (one, or a sequence of n), or a new constrained-layout figure."""
    if ax is not None:
        axes = list(np.atleast_1d(ax))
        if len(axes) != n:
            raise InvalidArgument(f"plot: this plot has {n} panel(s); ax= gave {len(axes)} axes")
        return axes[0].figure, axes
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(n, 1, figsize=(7, 0.8 + height * n), squeeze=False, layout="constrained")
    return fig, list(axes[:, 0])


def _names(models, labels):
    if labels is not None and len(labels) != len(models):
        raise InvalidArgument(f"plot: {len(labels)} labels for {len(models)} models")
    return list(labels) if labels is not None else [type(getattr(m, "model", m)).__name__ for m in models]


def compare(data, *models, labels=None, initial=None, ax=None):
    """Measured output against each model's simulation, one panel per output, fit % in the legend — scored as
    ``ctid.compare`` and ``ctid compare`` score them (each model from its validation initial condition: the state
    that fits the record best for linear and grey-box models, the measured history for NARX/NDE; ``initial`` overrides
    it for all)."""
    from . import compare as _compare
    fig, axes = _figure(ax, data.ny)
    cs = _compare(data, list(zip(_names(models, labels), models)), initial=initial)
    t = data.times
    for j, a in enumerate(axes):
        a.plot(t, data.y[:, j], color="0.3", lw=1, label="measured")
        for c in cs:
            f = c.fits[j].fit_percent
            a.plot(t, c.simulation.y[:, j], lw=1,
                   label=f"{c.name} (fit {f:.1f} %)" if np.isfinite(f) else f"{c.name} (diverges)")
        a.set_ylabel(data.output_names[j] if len(data.output_names) > j and data.output_names[j] else f"y{j + 1}")
        a.legend(loc="best", fontsize="small")
    axes[-1].set_xlabel("time (s)")
    return fig


def residuals(data, model, max_lag=25, initial=None, ax=None):
    """Residual autocorrelation and the input-residual cross-correlation of each input with their 99 % bounds (first
    output), from the same simulation and tests as ``ctid.compare``."""
    from . import compare as _compare
    c = _compare(data, [("model", model)], initial=initial, max_lag=max_lag)[0]
    if len(c.whiteness[0].lags) == 0:
        raise InvalidArgument("plot.residuals: no residual test: " + (c.simulation.problem or "zero or too few residuals"))
    tests = [("residual autocorrelation", c.whiteness[0])]
    tests += [(f"input {i + 1} - residual cross-correlation", x) for i, x in enumerate(c.independence[0])]
    fig, axes = _figure(ax, len(tests), 2.0)
    for a, (title, t) in zip(axes, tests):
        a.vlines(t.lags, 0, t.values, lw=2)
        a.axhspan(-t.bound, t.bound, color="C0", alpha=0.15)
        a.set_title(f"{title}: {t.n_outside} lag(s) outside the 99 % bounds", fontsize="small")
    axes[-1].set_xlabel("lag (samples)")
    return fig


def _phase_deg(h):
    """Unwrapped phase in degrees, each column on the branch where its first value lies in (-180, 180]."""
    ph = np.degrees(np.unwrap(np.angle(h), axis=0))
    return ph - 360.0 * np.round(ph[:1] / 360.0 - 1e-9)


def bode(model, w=None, data=None, confidence=True, ax=None):
    """Bode magnitude (dB) and phase (deg) of a linear model or result, one curve per input. The default grid spans two
    decades around the poles and, with ``data``, ends at the record's Nyquist frequency pi/Ts (beyond it the data say
    nothing). The phase is unwrapped and starts in (-180, 180], with ticks every 45/90/180 degrees. With
    confidence=True the 95 % bands: FSF models +-2 std from the covariance; transfer-function results 2.5-97.5 % of 200
    draws from the parameter covariance, for the magnitude and the phase (the report's bands)."""
    from matplotlib.ticker import MultipleLocator
    fig, axes = _figure(ax, 2)
    m = getattr(model, "model", model)
    if w is None:
        w_max = np.pi / data.ts if data is not None and data.is_uniform else 0.0
        if not isinstance(m, (TransferFunction, MisoModel, StateSpace, FsfModel)):
            raise InvalidArgument(f"bode: give w for a {type(m).__name__}")
        w = _ctid.model_frequency_grid(m, w_max)  # the library's default grid (the report's)
    w = np.asarray(w, dtype=float)
    h = frequency_response(m, w)  # the library's (the report's): a multi-input model gives a curve per input
    ph = _phase_deg(h)
    axes[0].semilogx(w, 20 * np.log10(np.abs(h)), lw=1.2)
    axes[1].semilogx(w, ph, lw=1.2)
    if confidence:
        mag = phase = None
        if isinstance(m, FsfModel) and m.covariance.size:
            s = m.freqresp_std(w)
            band = 2 * np.hypot(s.real, s.imag)
            mag = np.maximum(np.abs(h) - band, 1e-300), np.abs(h) + band
        elif isinstance(m, TransferFunction) and hasattr(model, "parameters"):
            mag = magnitude_band(model, w)  # 2.5-97.5 % of 200 seeded draws
            def drawn_phase(g):  # on the estimate's branch at the first frequency, as the report's band
                p = np.degrees(np.unwrap(np.angle(g.freqresp(w))))
                return p + 360.0 * np.round((ph[0] - p[0]) / 360.0)
            phase = response_band(model, drawn_phase)
        if mag is not None:
            axes[0].fill_between(w, 20 * np.log10(mag[0]), 20 * np.log10(mag[1]), alpha=0.25, lw=0,
                                 label="95 % band")
        if phase is not None:
            axes[1].fill_between(w, phase[0], phase[1], alpha=0.25, lw=0)
    span = np.nanmax(ph) - np.nanmin(ph) if ph.size else 0.0
    axes[1].yaxis.set_major_locator(MultipleLocator(45 if span <= 270 else 90 if span <= 720 else 180))
    axes[0].set_ylabel("magnitude (dB)")
    axes[1].set_ylabel("phase (deg)")
    axes[1].set_xlabel("frequency (rad/s)")
    for a in axes:
        a.set_xlim(w[0], w[-1])
        a.grid(True, which="both", alpha=0.3)
    return fig


def pzmap(model, confidence=True, ax=None):
    """Poles (x) and zeros (o) of a transfer function or result; with confidence=True and a result with a covariance,
    the poles and zeros of 200 models drawn from it as a pale cloud (the report's pole-zero map): a wide cloud is a
    pole the data pin down poorly, a zero cloud over a pole cloud a likely cancellation."""
    fig, (a,) = _figure(ax, 1, 4.0)
    m = getattr(model, "model", model)
    if not isinstance(m, TransferFunction):
        raise InvalidArgument(f"pzmap: needs a transfer function (got {type(m).__name__})")
    p, z = np.asarray(m.poles()), np.asarray(m.zeros())
    # The map shows the dynamics, as the report's: up to 5 times the largest pole magnitude (the zeros' without poles).
    reach = max(5 * np.abs(p if p.size else z).max(initial=0.0), 1e-300)
    if confidence and hasattr(model, "parameters"):
        draws = drawn_models(model)
        if draws:
            dp = np.concatenate([np.asarray(g.poles()) for g in draws])
            dz = np.concatenate([np.asarray(g.zeros()) for g in draws] + [np.zeros(0, complex)])
            dp, dz = dp[np.abs(dp) <= reach], dz[np.abs(dz) <= reach]
            a.plot(dp.real, dp.imag, ".", color="C0", ms=3, alpha=0.3, label=f"poles of {len(draws)} drawn models")
            if dz.size:
                a.plot(dz.real, dz.imag, ".", color="C3", ms=3, alpha=0.3, label="their zeros")
    a.plot(p.real, p.imag, "x", color="C0", ms=9, mew=2, label="poles")
    far = z[np.abs(z) > reach]
    z = z[np.abs(z) <= reach]
    if z.size:
        a.plot(z.real, z.imag, "o", mfc="none", color="C3", ms=9, mew=2, label="zeros")
    if far.size:
        a.set_title("zeros beyond the map: " + ", ".join(f"{x:.4g}" for x in far), fontsize="small")
    a.axhline(0, color="0.7", lw=0.8, ls="--")
    a.axvline(0, color="0.7", lw=0.8, ls="--")
    a.set_xlabel("real part (1/s)")
    a.set_ylabel("imaginary part (rad/s)")
    a.legend(loc="best", fontsize="small")
    return fig


def _response(kind, model, t, ax):
    fig, (a,) = _figure(ax)
    m = getattr(model, "model", model)
    if t is None:
        if isinstance(m, FsfModel):
            t = np.linspace(0, m.T, 400)
        elif isinstance(m, (TransferFunction, MisoModel)):
            t = np.linspace(0, response_horizon(m.channels if isinstance(m, MisoModel) else [m], 10.0), 400)
        else:
            raise InvalidArgument(f"{kind}: give t for a {type(m).__name__}")
    y = step_response(m, t) if kind == "step" else impulse_response(m, t)  # the library's, as the report's
    a.plot(t, y, lw=1.2)
    if isinstance(m, FsfModel) and m.covariance.size:
        s = m.step_std(t) if kind == "step" else m.impulse_std(t)
        a.fill_between(t, y - 2 * s, y + 2 * s, alpha=0.25, lw=0)
    a.set_xlabel("time (s)")
    a.set_ylabel(f"{kind} response")
    a.grid(True, alpha=0.3)
    return fig


def step(model, t=None, ax=None):
    """Step response (FSF models with a +-2 std band)."""
    return _response("step", model, t, ax)


def impulse(model, t=None, ax=None):
    """Impulse response (FSF models with a +-2 std band)."""
    return _response("impulse", model, t, ax)
