import numpy as np
import pytest

import ctid


def test_from_arrays_shapes_names_and_times():
    u = np.arange(10.0)
    y = np.column_stack([np.sin(u), np.cos(u)])
    d = ctid.IdData.from_arrays(u, y, ts=0.5, t0=1.0, input_names=["v"], output_names=["a", "b"], intersample="foh")
    assert len(d) == 10 and d.nu == 1 and d.ny == 2
    assert d.u.shape == (10, 1) and d.y.shape == (10, 2)
    np.testing.assert_array_equal(d.y, y)
    assert d.ts == 0.5 and d.times[-1] == pytest.approx(5.5)
    assert d.input_names == ["v"] and d.output_names == ["a", "b"] and d.intersample == ["foh"]
    irregular = ctid.IdData.from_arrays(u, y[:, 0], t=np.cumsum(np.linspace(0.1, 0.2, 10)))
    assert not irregular.is_uniform
    est, val = d.split(0.7)
    assert len(est) == 7 and len(val) == 3


def test_bad_input_raises_value_errors_naming_the_problem():
    with pytest.raises(ctid.InvalidArgument, match="999"):
        ctid.IdData.from_arrays(np.zeros(1000), np.zeros(999), ts=0.1)
    with pytest.raises(ValueError, match="NaN|non-finite|Inf"):
        ctid.IdData.from_arrays(np.zeros(5), np.array([0, 1, np.nan, 2, 3.0]), ts=0.1)
    with pytest.raises(ctid.InvalidArgument, match="either ts"):
        ctid.IdData.from_arrays(np.zeros(5), np.zeros(5))
    with pytest.raises(ctid.InvalidArgument, match="shape"):
        ctid.IdData.from_arrays(np.zeros((5, 1, 1)), np.zeros(5), ts=1.0)
    with pytest.raises(ctid.FileError):
        ctid.load("/nonexistent/file.csv", inputs=["u"], outputs=["y"], ts=1.0)
    assert issubclass(ctid.InvalidOptions, ValueError) and issubclass(ctid.FileError, OSError)


def test_load_bundled_dryer(tmp_path):
    from conftest import EXAMPLES_DATA
    d = ctid.load(str(EXAMPLES_DATA / "dryer.dat"), inputs=["1"], outputs=["2"], ts=0.08)
    assert len(d) == 1000 and d.ts == 0.08


def test_load_takes_the_command_lines_defaults(tmp_path):
    """ctid.load without columns chooses as ctid fit does (the library's choose_record): the column named t is the
    time axis; of two other columns the first is the input and the second the output; with the output named, every
    other column is an input; rows='2:4' and detrend='mean' as --samples and --detrend."""
    f = tmp_path / "r.csv"
    f.write_text("t,u,y\n0,1,2\n0.5,3,4\n1,5,6\n1.5,7,9\n")
    d = ctid.load(str(f))
    assert d.nu == 1 and d.ny == 1 and d.ts == pytest.approx(0.5, rel=1e-12)
    assert list(d.input_names) == ["u"] and list(d.output_names) == ["y"]
    part = ctid.load(str(f), rows="2:4", detrend="mean")
    assert len(part) == 3 and part.y.mean() == pytest.approx(0.0, abs=1e-13)
    assert part.u[:, 0] == pytest.approx([-2.0, 0.0, 2.0], abs=1e-13)  # 3, 5, 7 minus their mean 5
    with pytest.raises(ctid.InvalidOptions, match="'0' is not a row number"):
        ctid.load(str(f), rows="0:2")
    g = tmp_path / "miso.csv"
    g.write_text("t,u1,u2,y\n0,1,0,2\n0.5,3,1,4\n1,5,0,6\n")
    with pytest.raises(ctid.InvalidArgument, match="choose the input and output columns"):
        ctid.load(str(g))  # three columns besides the time: which is the output is not guessed
    assert list(ctid.load(str(g), outputs=["y"]).input_names) == ["u1", "u2"]


def test_from_pandas_when_available():
    # pandas is installed by scripts/install-deps.sh (python3-pandas); elsewhere the test skips.
    pd = pytest.importorskip("pandas")
    frame = pd.DataFrame({"t": np.arange(5) * 0.1, "u": np.ones(5, dtype=int), "y": np.arange(5.0),
                          "w": np.linspace(0, 1, 5)})
    d = ctid.IdData.from_pandas(frame, inputs=["u", "w"], outputs=["y"], time="t")
    assert d.input_names == ["u", "w"] and d.output_names == ["y"] and len(d) == 5
    np.testing.assert_array_equal(d.u, frame[["u", "w"]].to_numpy(dtype=float))  # ints converted, columns kept
    np.testing.assert_array_equal(d.y[:, 0], frame["y"].to_numpy())
    assert d.is_uniform and d.ts == pytest.approx(0.1)
    assert ctid.IdData.from_pandas(frame, inputs=["u"], outputs=["y"], ts=0.5).times[-1] == pytest.approx(2.0)
    with pytest.raises(KeyError, match="nope"):
        ctid.IdData.from_pandas(frame, inputs=["nope"], outputs=["y"], ts=1.0)
    bad = frame.assign(y=[0.0, 1.0, float("nan"), 3.0, 4.0])
    with pytest.raises(ValueError, match="NaN|non-finite|Inf"):
        ctid.IdData.from_pandas(bad, inputs=["u"], outputs=["y"], ts=1.0)