#!/usr/bin/env python3
"""Layering check (docs/architecture.md): a lower layer never includes a higher one.

Order: core -> internal -> data, poly -> model -> simulate -> signal -> validate -> estimate -> io.
Every #include "..." of a ctid header in include/ctid/<layer>/ and src/<layer>/ is resolved to the layer it
belongs to (ctid/<layer>/x.hpp, internal/x.hpp, or a private header next to the including file) and must not
rank above the including file's layer. The front ends (apps/ and python/src/) stand above every layer and may
include public headers only (ctid/...) and their own headers beside them, never src/ or internal/ ones.
Exit 1 listing every violation as FILE:LINE: LAYER includes HIGHER.
Usage: check_layers.py REPO_ROOT     (check_layers.py --self-test: the check finds planted violations)
"""
import pathlib
import re
import sys

RANK = {"core": 0, "internal": 1, "data": 2, "poly": 2, "model": 3, "simulate": 4, "signal": 5, "validate": 6,
        "estimate": 7, "io": 8}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def layer_of_include(target, including):
    parts = pathlib.PurePosixPath(target).parts
    if parts[0] == "ctid" and len(parts) >= 3:
        return parts[1]
    if parts[0] == "ctid":
        return "umbrella"  # ctid/ctid.hpp: everything
    if parts[0] == "internal":
        return "internal"
    if len(parts) == 1:  # a private header beside the including file
        return layer_of_file(including.parent / target)
    return parts[0]


def layer_of_file(path):
    parts = path.parts
    for anchor in ("ctid", "src"):
        if anchor in parts:
            i = len(parts) - 1 - parts[::-1].index(anchor)
            if i + 1 < len(parts) - 1:
                return parts[i + 1]
    return None


def front_end_violations(root, f):
    """Includes of a front-end file (apps/, python/src/) that are not public headers or its own headers."""
    bad, checked = [], 0
    for n, line in enumerate(f.read_text().splitlines(), 1):
        m = INCLUDE.match(line)
        if not m:
            continue
        checked += 1
        target = pathlib.PurePosixPath(m.group(1))
        public = target.parts[0] == "ctid" and (root / "include" / target).is_file()
        own = len(target.parts) == 1 and (f.parent / target).is_file()
        if not (public or own):
            bad.append(f"{f.relative_to(root)}:{n}: the front end includes {m.group(1)}, which is not a public header")
    return bad, checked


def main(root):
    root = pathlib.Path(root)
    files = sorted(list((root / "include" / "ctid").rglob("*.hpp")) + list((root / "src").rglob("*.[ch]pp")))
    front = sorted(list((root / "apps").rglob("*.[ch]pp")) + list((root / "python" / "src").rglob("*.[ch]pp")))
    bad, checked = [], 0
    for f in front:
        b, c = front_end_violations(root, f)
        bad += b
        checked += c
    for f in files:
        own = layer_of_file(f.relative_to(root))
        if own not in RANK:
            continue
        for n, line in enumerate(f.read_text().splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            target = layer_of_include(m.group(1), f.relative_to(root))
            checked += 1
            if target == "umbrella" or (target in RANK and RANK[target] > RANK[own]):
                bad.append(f"{f.relative_to(root)}:{n}: {own} includes {m.group(1)} ({target})")
            elif target not in RANK:
                bad.append(f"{f.relative_to(root)}:{n}: {own} includes {m.group(1)}, which is in no layer")
    for b in bad:
        print(b)
    print(f"{len(files) + len(front)} files, {checked} includes checked, {len(bad)} against the layer order")
    return 1 if bad else 0


def self_test():
    """Plant five violations and three allowed includes in a scratch tree; the check must report exactly five."""
    import contextlib
    import io
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        root = pathlib.Path(d)
        for rel, text in {
            "src/model/a.cpp": '#include "ctid/estimate/transfer_function/srivc.hpp"\n#include "ctid/poly/polynomial.hpp"\n',
            "include/ctid/core/b.hpp": '#include "internal/ode.hpp"\n',
            "src/simulate/c.cpp": '#include "ctid/ctid.hpp"\n',
            "include/ctid/ctid.hpp": "",
            "apps/tool/own.hpp": "",
            "apps/tool/main.cpp": '#include "ctid/ctid.hpp"\n#include "own.hpp"\n#include "internal/ode.hpp"\n',
            "python/src/module.cpp": '#include "../../src/data/record_refs.hpp"\n',
        }.items():
            (root / rel).parent.mkdir(parents=True, exist_ok=True)
            (root / rel).write_text(text)
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            code = main(root)
        found = out.getvalue().splitlines()[:-1]  # one line per violation, then the summary
        assert code == 1 and len(found) == 5, out.getvalue()
        print("self-test: 5 planted violations found")
    return 0


if __name__ == "__main__":
    sys.exit(self_test() if sys.argv[1:] == ["--self-test"] else main(sys.argv[1] if len(sys.argv) > 1 else "."))
