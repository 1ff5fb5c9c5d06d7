import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

import ctid  # noqa: E402
import ctid.plot  # noqa: E402


def _no_overlap(fig):
    # After drawing, the panels' full extents (tick labels, axis labels, titles, legends) lie inside the figure and
    # do not overlap one another (1 pixel of slack).
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    boxes = [a.get_tightbbox(r) for a in fig.axes]
    W, H = fig.bbox.width, fig.bbox.height
    for b in boxes:
        assert b.x0 >= -1 and b.y0 >= -1 and b.x1 <= W + 1 and b.y1 <= H + 1, (b, W, H)
    for i in range(len(boxes)):
        for k in range(i + 1, len(boxes)):
            a, b = boxes[i], boxes[k]
            assert a.y0 >= b.y1 - 1 or b.y0 >= a.y1 - 1 or a.x0 >= b.x1 - 1 or b.x0 >= a.x1 - 1, (a, b)


def test_plots_draw_and_return_figures(plant, tmp_path):
    import matplotlib.pyplot as plt
    g, d = plant
    r = ctid.srivc(d, 1, 2)
    f = ctid.fsf(d, T=20.0, n=31)
    fig = ctid.plot.compare(d, r, f, labels=["srivc", "fsf"])
    ax = fig.axes[0]
    assert len(ax.lines) == 3 and "fit" in ax.get_legend().get_texts()[1].get_text()
    # The legend's fit is ctid.compare's (validation initial condition), to its printed digit.
    fit = ctid.compare(d, {"srivc": r})[0].fits[0].fit_percent
    assert f"srivc (fit {fit:.1f} %)" == ax.get_legend().get_texts()[1].get_text()
    _no_overlap(fig)
    fig = ctid.plot.residuals(d, r)
    assert "outside" in fig.axes[0].get_title() and len(fig.axes) == 2
    _no_overlap(fig)
    fig = ctid.plot.bode(r)
    assert len(fig.axes[0].lines) == 1 and len(fig.axes[0].collections) == 1  # the magnitude band
    assert len(fig.axes[1].collections) == 1                                  # the phase band
    # 4/(s^2 + 0.8 s + 4): the phase starts at 0 (not -360 or +360) and ends near -180 deg; ticks every 45 deg.
    ph = fig.axes[1].lines[0].get_ydata()
    assert abs(ph[0]) < 1 and -180 <= ph[-1] < -170
    ticks = fig.axes[1].get_yticks()
    assert np.allclose(np.diff(ticks), 45)
    _no_overlap(fig)
    # With the record, the grid ends at its Nyquist frequency pi/Ts (157.08 rad/s at Ts = 0.02 s).
    w = ctid.plot.bode(r, data=d).axes[0].lines[0].get_xdata()
    assert w[-1] == pytest.approx(np.pi / 0.02, rel=1e-12) and w[-1] < ctid.plot.bode(r).axes[0].lines[0].get_xdata()[-1]
    fig = ctid.plot.bode(f)
    assert len(fig.axes[0].collections) == 1
    fig = ctid.plot.step(f)
    y = fig.axes[0].lines[0].get_ydata()
    assert y[-1] == pytest.approx(1.0, abs=0.05)
    ctid.plot.impulse(r)
    # The pole-zero map: the estimate's 2 poles and the 200 drawn models' 400.
    fig = ctid.plot.pzmap(r)
    assert [len(l.get_xdata()) for l in fig.axes[0].lines[:1]] == [400] and len(fig.axes[0].lines[1].get_xdata()) == 2
    _no_overlap(fig)
    # Axes given: drawn on them, their figure returned; the wrong number of axes is named.
    fig0, axes0 = plt.subplots(2, 1)
    assert ctid.plot.bode(r, ax=axes0) is fig0
    with pytest.raises(ctid.InvalidArgument, match="2 panel"):
        ctid.plot.bode(r, ax=axes0[0])
    # A two-input model: a Bode and step curve per channel; the responses are the channels' columns.
    t = ctid.time_grid(0.02, 2000)
    u2 = ctid.prbs(2000, register_length=8, clock_period=7)
    d2 = ctid.IdData.from_arrays(np.column_stack([d.u[:, 0], u2]), d.y[:, 0] + g.simulate(u2, t), ts=0.02)
    m = ctid.srivc_miso(d2, [(1, 2, 0), (1, 2, 0)])
    assert m.model.freqresp([1.0, 2.0]).shape == (2, 2) and m.model.step(t).shape == (2000, 2)
    np.testing.assert_allclose(m.model.step(t)[:, 1], m.model.channels[1].step(t))
    assert len(ctid.plot.bode(m).axes[0].lines) == 2 and len(ctid.plot.step(m).axes[0].lines) == 2
    plt.savefig(tmp_path / "last.png")
    assert (tmp_path / "last.png").stat().st_size > 1000
    plt.close("all")


def test_html_report_from_python(plant, tmp_path):
    _, d = plant
    r = ctid.srivc(d, 1, 2)
    path = tmp_path / "r.html"
    ctid.html_report(d, r, str(path), method="srivc", settings={"nb": "1", "nf": "2"})
    text = path.read_text()
    assert "Residual tests" in text and "srivc" in text and text.count('class="plot"') == 10
    with pytest.raises(ctid.FileError):
        ctid.html_report(d, r, str(tmp_path / "missing" / "r.html"))
