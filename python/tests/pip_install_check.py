"""ctest python.pip_install: `pip install --no-build-isolation --no-deps --no-index --target T .` from the
source tree, offline with Debian's pip and setuptools, reusing the test build's CMake tree (CTID_CMAKE_BUILD_DIR:
nothing is recompiled); then, from another folder and without PYTHONPATH to the build tree, `import ctid` loads the
installed package and fits. Usage: pip_install_check.py SOURCE_DIR CMAKE_BUILD_DIR"""
import os
import subprocess
import sys
import tempfile

src, build = sys.argv[1], sys.argv[2]
with tempfile.TemporaryDirectory() as tmp:
    target = os.path.join(tmp, "site")
    env = dict(os.environ, CTID_CMAKE_BUILD_DIR=build, PIP_NO_INPUT="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    env.pop("PYTHONPATH", None)
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-build-isolation", "--no-deps", "--no-index",
                    "--target", target, src], env=env, check=True)
    # Noise-free 3/(s + 2) under a random binary input: SRIVC recovers a1 = 2 and b0 = 3 (to 1e-6; the exact
    # simulation and the fit agree to the solver's accuracy).
    check = """
import os, sys, numpy as np, ctid
assert os.path.realpath(ctid.__file__).startswith(os.path.realpath(sys.argv[1])), ctid.__file__
g = ctid.TransferFunction([3.0], [1.0, 2.0])
u = ctid.random_binary(2000, seed=1, clock_period=5)
d = ctid.IdData.from_arrays(u, np.zeros(2000), ts=0.01)
d = ctid.IdData.from_arrays(u, ctid.simulate(g, d), ts=0.01)
r = ctid.srivc(d, 1, 1)
a = dict(zip(r.parameters.names, r.parameters.values))
assert abs(a["a1"] - 2.0) < 1e-6 and abs(a["b0"] - 3.0) < 1e-6, a
print("pip-installed ctid %s from %s: a1 = %.8f, b0 = %.8f" % (ctid.__version__, os.path.dirname(ctid.__file__), a["a1"], a["b0"]))
"""
    env["PYTHONPATH"] = target
    subprocess.run([sys.executable, "-c", check, target], env=env, cwd=tmp, check=True)
