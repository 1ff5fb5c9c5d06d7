#!/usr/bin/env python3
"""Run every shell block of README.md and docs/**/*.md verbatim ("every documented command runs").

Each ```sh block runs with bash -e -o pipefail in a scratch folder per Markdown file (the blocks of one file in
order, so a later block may use what an earlier one wrote), where `ctid` is the built command-line tool on PATH,
`build/ctid` is the same tool (the README's spelling) and `build/python` the Python package beside it, `examples/` is the source tree's, and `../shared` is the
shared data folder when it exists (a block that names ../shared is skipped, saying so, when it does not).
A block preceded by the line `<!-- doc-test: skip: REASON -->` is not run; REASON is printed and must not be empty.
Every command must exit 0. Usage: run_doc_blocks.py SOURCE_DIR CTID_BINARY [SHARED_DIR] [--only FILE.md ...]
Exit 1 naming each failing block (file, line, its stderr) or a skip marker without a reason."""
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

BLOCK = re.compile(r"^```(sh|bash|shell)\s*$")
SKIP = re.compile(r"^<!-- doc-test: skip:(.*)-->\s*$")


def blocks(md):
    """(first line number, text, skip reason or None) of every shell block of a Markdown file."""
    lines = md.read_text(encoding="utf-8").splitlines()
    out, i = [], 0
    while i < len(lines):
        if BLOCK.match(lines[i]):
            start = i + 1
            j = start
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            m = SKIP.match(lines[i - 1]) if i > 0 else None
            out.append((start + 1, "\n".join(lines[start:j]) + "\n", m.group(1).strip() if m else None))
            i = j + 1
        else:
            i += 1
    return out


def main(argv):
    only = []
    if "--only" in argv:
        k = argv.index("--only")
        only, argv = argv[k + 1:], argv[:k]
    if len(argv) < 3:
        print(__doc__)
        return 2
    src, ctid = pathlib.Path(argv[1]).resolve(), pathlib.Path(argv[2]).resolve()
    shared = pathlib.Path(argv[3]).resolve() if len(argv) > 3 else src.parent / "shared"
    files = [src / "README.md"] + sorted((src / "docs").rglob("*.md"))
    if only:
        files = [f for f in files if f.name in only]
    failures, ran, skipped = [], 0, 0
    root = pathlib.Path(tempfile.mkdtemp(prefix="ctid-doc-blocks-"))
    try:
        bindir = root / "bin"
        bindir.mkdir()
        (bindir / "ctid").symlink_to(ctid)
        if shared.is_dir():
            (root / "shared").symlink_to(shared)
        env = dict(os.environ, PATH=f"{bindir}:{os.environ.get('PATH', '')}")
        for md in files:
            rel = md.relative_to(src)
            work = root / str(rel).replace("/", "_").replace(".md", "")
            (work / "build").mkdir(parents=True)
            (work / "build" / "ctid").symlink_to(ctid)
            if (ctid.parent / "python").is_dir():  # the Python package beside the tool: PYTHONPATH=build/python
                (work / "build" / "python").symlink_to(ctid.parent / "python")
            (work / "examples").symlink_to(src / "examples")
            for line, text, reason in blocks(md):
                where = f"{rel}:{line}"
                if reason is not None:
                    if not reason:
                        failures.append(f"{where}: a skip marker needs a reason")
                    print(f"skip {where}: {reason}")
                    skipped += 1
                    continue
                if "../shared" in text and not shared.is_dir():
                    print(f"skip {where}: needs ../shared (not present)")
                    skipped += 1
                    continue
                if "build/python" in text and not (ctid.parent / "python").is_dir():
                    print(f"skip {where}: needs the Python package, not built beside {ctid} (the sanitizer "
                          "build has none; the Release build runs this block)")
                    skipped += 1
                    continue
                t0 = time.monotonic()
                p = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", text], cwd=work, env=env,
                                   capture_output=True, text=True, timeout=600)
                ran += 1
                dt = time.monotonic() - t0
                if p.returncode != 0:
                    failures.append(f"{where}: exit {p.returncode}\n--- block\n{text}--- stdout (tail)\n"
                                    f"{p.stdout[-1500:]}--- stderr (tail)\n{p.stderr[-1500:]}")
                    print(f"FAIL {where} ({dt:.1f} s)")
                else:
                    print(f"ok   {where} ({dt:.1f} s)")
    finally:
        shutil.rmtree(root, ignore_errors=True)
    for f in failures:
        print(f"\n{f}")
    print(f"\n{ran} blocks run, {skipped} skipped, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
