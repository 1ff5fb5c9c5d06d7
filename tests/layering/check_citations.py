#!/usr/bin/env python3
"""The repository stands alone: no code, test, script or page cites a document that is not in it.

A reader has the repository and the published papers, so a citation names a paper with its equation or table, or
a file of the repository (docs/methods/*.md keeps the reconstructions and misprints of the four source papers).
This check fails on the names of planning documents and tracker items that live outside the repository. Exit 1
listing every FILE:LINE that has one.
Usage: check_citations.py REPO_ROOT     (check_citations.py --self-test: the check finds planted citations)
"""
import pathlib
import re
import sys

# Built from pieces so that this file does not match itself.
OUTSIDE = re.compile("|".join([r"DESIGN" + r"\.md", r"SEEDS" + r"-SPEC", r"\b[Ii]ssue" + r" #?[0-9]+"]))
FOLDERS = ["apps", "bench", "cmake", "docs", "examples", "include", "python", "scripts", "src", "tests", ".ci"]
SUFFIXES = {".cpp", ".hpp", ".h", ".c", ".py", ".md", ".txt", ".cmake", ".sh", ".json", ".toml", ".in", ".m", ""}


def files(root):
    for name in ["CMakeLists.txt", "Makefile", "README.md", "CONTRIBUTING.md", "setup.py", "pyproject.toml",
                 "CMakePresets.json"]:
        if (root / name).is_file():
            yield root / name
    for folder in FOLDERS:
        for f in sorted((root / folder).rglob("*")):
            if f.is_file() and f.suffix in SUFFIXES and "corpus" not in f.parts and "__pycache__" not in f.parts:
                yield f


def main(root):
    root = pathlib.Path(root)
    bad, n = [], 0
    for f in files(root):
        n += 1
        try:
            text = f.read_text()
        except UnicodeDecodeError:
            continue
        for i, line in enumerate(text.splitlines(), 1):
            if OUTSIDE.search(line):
                bad.append(f"{f.relative_to(root)}:{i}: cites what the repository does not contain: {line.strip()[:100]}")
    for b in bad:
        print(b)
    print(f"{n} files, {len(bad)} lines citing documents outside the repository")
    return 1 if bad else 0


def self_test():
    """Plant three citations and one clean line; the check must report exactly three."""
    import contextlib
    import io
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        root = pathlib.Path(d)
        for rel, text in {
            "src/a.cpp": "// see " + "DESIGN" + ".md\n// Gawthrop & Wang 2005, eq. 27\n",
            "docs/b.md": "as in " + "SEEDS" + "-SPEC GW.3\n",
            "tests/c.py": "# " + "Issue" + " 13: no crash\n",
        }.items():
            (root / rel).parent.mkdir(parents=True, exist_ok=True)
            (root / rel).write_text(text)
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            code = main(root)
        found = out.getvalue().splitlines()[:-1]
        assert code == 1 and len(found) == 3, out.getvalue()
        print("self-test: 3 planted citations found")
    return 0


if __name__ == "__main__":
    sys.exit(self_test() if sys.argv[1:] == ["--self-test"] else main(sys.argv[1] if len(sys.argv) > 1 else "."))
