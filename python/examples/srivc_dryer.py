"""SRIVC and tfest on the bundled DaISy hair dryer, validated on held-out data (runs in CI).

Question: what continuous-time model explains the dryer's air temperature from the heater voltage?
"""
import os
import pathlib

import ctid

data_dir = pathlib.Path(os.environ.get("CTID_EXAMPLES_DATA_DIR", pathlib.Path(__file__).resolve().parents[2] / "examples" / "data"))
raw = ctid.load(str(data_dir / "dryer.dat"), inputs=["1"], outputs=["2"], ts=0.08)
u, y = raw.u - raw.u.mean(), raw.y - raw.y.mean()
data = ctid.IdData.from_arrays(u, y, ts=0.08)
est, val = data.split(0.7)

r = ctid.srivc(est, nb=2, nf=2, nk=2)  # two-sample delay, second order
print(r)
yv = ctid.simulate(r, val)
fit = ctid.fit_percent(val.y[:, 0], yv)
print(f"validation fit (held-out 30 %): {fit:.1f} %")
refined = ctid.tfest(est, nb=2, nf=2, nk=2)
print(f"tfest validation fit: {ctid.fit_percent(val.y[:, 0], ctid.simulate(refined, val)):.1f} %")

if os.environ.get("MPLBACKEND"):
    import ctid.plot
    import matplotlib.pyplot as plt
    ctid.plot.compare(val, r, refined, labels=["srivc", "tfest"])
    plt.close("all")
assert r.usable() and fit > 85
