"""How large the house is, per package: lines, modules, the longest function and the one with the
most parameters, for the checkout or a revision.

    python bench/code_size.py [--rev REV] [--top 5]

Lines are physical lines of ``.py`` files (docstrings and comments included, as a reader meets
them); a function's length is from its ``def`` to its last line; parameters count every named
argument (``self`` and ``cls`` excluded, ``*args``/``**kwargs`` counted once each).  With
``--rev`` the files are read from git (``git show REV:path``), so a past layout can be measured
beside today's.
"""
from __future__ import annotations

import argparse
import ast
import subprocess
from collections import defaultdict
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGES = ("mmg", "ekf", "trials")


def _files(rev: str | None) -> dict[str, str]:
    if rev is None:
        return {str(p.relative_to(REPO)): p.read_text() for pkg in PACKAGES for p in (REPO / pkg).rglob("*.py")}
    names = subprocess.run(["git", "ls-tree", "-r", "--name-only", rev, "--", *PACKAGES], cwd=REPO, check=True,
                           capture_output=True, text=True).stdout.split()
    return {n: subprocess.run(["git", "show", f"{rev}:{n}"], cwd=REPO, check=True, capture_output=True,
                              text=True).stdout for n in names if n.endswith(".py")}


def _params(fn) -> int:
    a = fn.args
    names = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]
    names = [n for n in names if n not in ("self", "cls")]
    return len(names) + (a.vararg is not None) + (a.kwarg is not None)


def functions(path: str, text: str):
    """(qualified name, lines, parameters) of every function in the file."""
    out = []

    def walk(node, prefix):
        for ch in ast.iter_child_nodes(node):
            if isinstance(ch, (ast.FunctionDef, ast.AsyncFunctionDef)):
                q = f"{prefix}{ch.name}"
                out.append((f"{path}:{q}", ch.end_lineno - ch.lineno + 1, _params(ch)))
                walk(ch, q + ".")
            elif isinstance(ch, ast.ClassDef):
                walk(ch, f"{prefix}{ch.name}.")
    walk(ast.parse(text), "")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", default=None, help="a git revision (default: the working tree)")
    ap.add_argument("--top", type=int, default=3, help="longest functions listed per package")
    a = ap.parse_args(argv)
    files = _files(a.rev)
    stats = defaultdict(lambda: {"lines": 0, "modules": 0, "fns": []})
    for path, text in files.items():
        parts = Path(path).parts
        key = "/".join(parts[:2]) if len(parts) > 2 else parts[0]
        for k in {parts[0], key}:
            stats[k]["lines"] += len(text.splitlines())
            stats[k]["modules"] += 1
            stats[k]["fns"] += functions(path, text)
    print(f"{'package':22s} {'lines':>6s} {'modules':>7s}  longest function (lines, parameters) / most parameters")
    for k in sorted(stats):
        s = stats[k]
        if not s["fns"]:
            continue
        longest = sorted(s["fns"], key=lambda f: -f[1])[:a.top]
        most = max(s["fns"], key=lambda f: f[2])
        print(f"{k:22s} {s['lines']:6d} {s['modules']:7d}  "
              + "; ".join(f"{n.split(':')[-1]} ({ln}, {p})" for n, ln, p in longest)
              + f" / {most[0].split(':')[-1]} ({most[1]}, {most[2]})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
