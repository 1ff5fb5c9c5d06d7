import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

import ctid  # noqa: E402
import ctid.plot  # noqa: E402


def test_plots_draw_and_return_axes(plant, tmp_path):
    import matplotlib.pyplot as plt
    g, d = plant
    r = ctid.srivc(d, 1, 2)
    f = ctid.fsf(d, T=20.0, n=31)
    ax = ctid.plot.compare(d, r, f, labels=["srivc", "fsf"])
    assert len(ax.lines) == 3 and "fit" in ax.get_legend().get_texts()[1].get_text()
    axes = ctid.plot.residuals(d, r)
    assert "outside" in axes[0].get_title()
    axes = ctid.plot.bode(r)
    assert len(axes[0].lines) == 1 and len(axes[0].collections) == 1  # the confidence band
    axes = ctid.plot.bode(f)
    assert len(axes[0].collections) == 1
    ax = ctid.plot.step(f)
    y = ax.lines[0].get_ydata()
    assert y[-1] == pytest.approx(1.0, abs=0.05)
    ctid.plot.impulse(r)
    # A two-input model: a Bode and step curve per channel; the responses are the channels' columns.
    t = ctid.time_grid(0.02, 2000)
    u2 = ctid.prbs(2000, register_length=8, clock_period=7)
    d2 = ctid.IdData.from_arrays(np.column_stack([d.u[:, 0], u2]), d.y[:, 0] + g.simulate(u2, t), ts=0.02)
    m = ctid.srivc_miso(d2, [(1, 2, 0), (1, 2, 0)])
    assert m.model.freqresp([1.0, 2.0]).shape == (2, 2) and m.model.step(t).shape == (2000, 2)
    np.testing.assert_allclose(m.model.step(t)[:, 1], m.model.channels[1].step(t))
    assert len(ctid.plot.bode(m)[0].lines) == 2 and len(ctid.plot.step(m).lines) == 2
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
