#!/usr/bin/env python3
"""The worked example of docs/architecture.md, checked: the toy estimator static_gain, registered by one line in
its own source file, runs from the command-line tool and from Python by its name and appears in their help and
method lists; and the page shows its two files exactly as they are.

Usage: check_toy.py --source SOURCE_DIR (--cli CTID_TOY | --python-path DIR). The record is y = 2.5 u + e with a
deterministic input and disturbance; the reference gain is computed here from the same numbers (sum u y / sum u u),
and the tool's estimate must equal it to 1e-9 (relative). Exit 1 naming the first check that fails."""
import argparse
import os
import pathlib
import re
import subprocess
import sys
import tempfile


def record():
    """400 samples: u a pseudo-random level in [-1, 1] (a linear congruential generator), y = 2.5 u + e."""
    x, rows = 12345, []
    for k in range(400):
        x = (1103515245 * x + 12345) % 2**31
        u = 2.0 * x / 2**31 - 1.0
        rows.append((k * 0.01, u, 2.5 * u + 0.05 * ((k * 7919) % 13 - 6) / 6))
    return rows


def reference_gain(rows, ridge=0.0):
    return sum(u * y for _, u, y in rows) / (sum(u * u for _, u, _ in rows) + ridge)


def check_page(source):
    """Each file of the toy appears verbatim in docs/architecture.md, in the code block after its marker line."""
    page = (source / "docs" / "architecture.md").read_text(encoding="utf-8")
    for name in ("static_gain.hpp", "static_gain.cpp"):
        marker = f"<!-- file: examples/toy_estimator/{name} -->"
        m = re.search(re.escape(marker) + r"\n```cpp\n(.*?)```\n", page, re.S)
        if not m:
            sys.exit(f"docs/architecture.md: no ```cpp block after '{marker}'")
        if m.group(1) != (source / "examples" / "toy_estimator" / name).read_text(encoding="utf-8"):
            sys.exit(f"docs/architecture.md: the block of {name} differs from examples/toy_estimator/{name}")


def close(a, b, what):
    if abs(a - b) > 1e-9 * abs(b):
        sys.exit(f"{what}: {a!r}, expected {b!r} (sum u y / (sum u u + ridge))")


def check_cli(cli, folder, rows):
    data = folder / "gain.csv"
    data.write_text("t,u,y\n" + "".join(f"{t!r},{u!r},{y!r}\n" for t, u, y in rows))
    run = lambda *a: subprocess.run([cli, *a], capture_output=True, text=True)
    help_all = run("fit", "--help")
    if help_all.returncode != 0 or "static_gain" not in help_all.stdout:
        sys.exit("ctid fit --help does not list static_gain:\n" + help_all.stdout + help_all.stderr)
    help_one = run("fit", "--method", "static_gain", "--help")
    if "ridge" not in help_one.stdout or "toy: y = K u by least squares" not in help_one.stdout:
        sys.exit("ctid fit --method static_gain --help does not list its setting ridge:\n" + help_one.stdout)
    out = folder / "gain.json"
    fit = run("fit", str(data), "--method", "static_gain", "--set", "ridge=4", "--json", str(out))
    if fit.returncode != 0:
        sys.exit(f"ctid fit --method static_gain exited {fit.returncode}:\n{fit.stdout}{fit.stderr}")
    import json
    result = json.loads(out.read_text())
    if result["method"] != "static_gain":
        sys.exit(f"the result file records method {result['method']!r}")
    close(result["parameters"][0]["value"], reference_gain(rows, 4.0), "ctid fit --method static_gain --set ridge=4")
    bad = run("fit", str(data), "--method", "static_gain", "--set", "ridg=1")
    if bad.returncode != 2 or "did you mean 'ridge'" not in bad.stderr:
        sys.exit(f"a misspelt setting: exit {bad.returncode}, {bad.stderr!r}")
    batch = run("batch", str(data), "--method", "static_gain", "--out", str(folder / "rows.csv"))
    if batch.returncode != 0 or "static_gain" not in (folder / "rows.csv").read_text():
        sys.exit(f"ctid batch --method static_gain exited {batch.returncode}:\n{batch.stdout}{batch.stderr}")


def check_python(path, rows):
    code = f"""
import sys
sys.path.insert(0, {str(path)!r})
import numpy as np
import ctid
assert "static_gain" in ctid.fit_methods(), ctid.fit_methods()
rows = {rows!r}
d = ctid.IdData.from_arrays(np.array([r[1] for r in rows]), np.array([r[2] for r in rows]), ts=0.01)
r = ctid.fit(d, "static_gain", ridge=4.0)
print(repr(float(r.parameters.values[0])))
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit("Python: ctid.fit(d, 'static_gain') failed:\n" + done.stderr)
    close(float(done.stdout.strip().splitlines()[-1]), reference_gain(rows, 4.0), "ctid.fit(d, 'static_gain', ridge=4)")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True)
    ap.add_argument("--cli")
    ap.add_argument("--python-path")
    a = ap.parse_args()
    source = pathlib.Path(a.source)
    check_page(source)
    rows = record()
    with tempfile.TemporaryDirectory() as tmp:
        if a.cli:
            check_cli(a.cli, pathlib.Path(tmp), rows)
        if a.python_path:
            check_python(a.python_path, rows)
    print("the toy estimator runs by its name from", "the CLI" if a.cli else "Python", "and the page shows its files")


if __name__ == "__main__":
    main()
