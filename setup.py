"""Builds ctid's Python module with CMake for `pip install --no-build-isolation .` (see pyproject.toml).

The extension ctid._ctid is the CMake target _ctid (python/CMakeLists.txt): configured in build-python/cmake
(Release, unity batches, no tests, tool or benchmarks; the Python running pip), built, and copied into the wheel
next to the pure-Python package python/ctid. CTID_CMAKE_BUILD_DIR=DIR builds in an existing CMake tree instead
(no reconfiguration: only `cmake --build DIR --target _ctid`), e.g. the tree `make build` made. CTID_BUILD_JOBS sets
the parallel jobs (default: the machine's cores). Needs cmake, a C++20 compiler and scripts/install-deps.sh's packages.
"""
import os
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def version():
    m = re.search(r"project\(ctid VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text())
    if not m:
        raise RuntimeError("setup.py: no 'project(ctid VERSION x.y.z' in CMakeLists.txt")
    return m.group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        jobs = os.environ.get("CTID_BUILD_JOBS", str(os.cpu_count() or 2))
        tree = os.environ.get("CTID_CMAKE_BUILD_DIR")
        if tree:
            tree = Path(tree).resolve()
            if not (tree / "CMakeCache.txt").is_file():
                sys.exit("setup.py: CTID_CMAKE_BUILD_DIR=%s is not a configured CMake build tree" % tree)
        else:
            tree = ROOT / "build-python" / "cmake"
            subprocess.check_call([
                "cmake", "-S", str(ROOT), "-B", str(tree), "-DCMAKE_BUILD_TYPE=Release", "-DCTID_UNITY_BUILD=ON",
                "-DCTID_BUILD_TESTS=OFF", "-DCTID_BUILD_APPS=OFF", "-DCTID_BUILD_BENCHMARKS=OFF",
                "-DCTID_BUILD_PYTHON=ON", "-DPython_EXECUTABLE=" + sys.executable])
        subprocess.check_call(["cmake", "--build", str(tree), "--target", "_ctid", "-j", jobs])
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = sorted((tree / "python" / "ctid").glob("_ctid*.so"))
        if not built:
            sys.exit("setup.py: the CMake build made no _ctid module in %s" % (tree / "python" / "ctid"))
        if not built[-1].name.endswith(suffix):
            sys.exit("setup.py: %s was built for another Python than %s (expected the suffix %s)"
                     % (built[-1], sys.executable, suffix))
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[-1], target)


(ROOT / "build-python").mkdir(exist_ok=True)
setup(
    version=version(),
    packages=["ctid"],
    package_dir={"": "python"},
    ext_modules=[Extension("ctid._ctid", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": "build-python"}, "egg_info": {"egg_base": "build-python"}},
    zip_safe=False,
)
