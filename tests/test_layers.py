"""The layers, checked from the source's import statements (those inside functions included).

physics (``mmg.*``) < estimators (``ekf.*``) < trials, data, reports and the CLI (``trials.*``).
Inside ``trials`` every module belongs to a sub-package, and each sub-package may import only the
ones :data:`MAY_IMPORT` names for it (as its ``__init__`` docstring says):

    files < analysis < runs < estimates < planning < papers < cli, with measured above analysis
    (beside runs: it needs no simulated trial) and below cli, imo above runs and measured and below
    cli; ekf only from measured upwards.

No module imports from a layer above its own, no module imports a top-level package facade
(``import mmg``: that ``__init__`` re-exports from every layer, so it is for users, not for the
library's own modules), and there is no import cycle between modules (a sub-package's
``__init__`` counts as a module).  The top-level ``__init__`` facades are the one exception:
they may re-export from any layer.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("mmg", "ekf", "trials")
LAYER = {"mmg": 0, "ekf": 1, "trials": 2}

# what each trials sub-package may import besides itself (mmg, ekf: the layers below trials)
_LOW = {"mmg"}
MAY_IMPORT = {
    "files": _LOW,
    "analysis": _LOW | {"files"},
    "runs": _LOW | {"files", "analysis"},
    "measured": _LOW | {"ekf", "files", "analysis"},
    "estimates": _LOW | {"ekf", "files", "analysis", "runs"},
    "planning": _LOW | {"ekf", "files", "analysis", "runs", "estimates"},
    "papers": _LOW | {"ekf", "files", "analysis", "runs", "estimates", "planning"},
    "imo": _LOW | {"ekf", "files", "analysis", "runs", "measured"},
    "cli": _LOW | {"ekf", "files", "analysis", "runs", "measured", "estimates", "planning", "papers", "imo"},
}


def _part(name: str) -> str:
    """``mmg``, ``ekf``, or the trials sub-package (``files``, ``runs``, ...) module ``name`` is in."""
    parts = name.split(".")
    return parts[1] if parts[0] == "trials" and len(parts) > 1 else parts[0]


def modules(root: Path) -> dict[str, Path]:
    """Dotted module name -> file, for every .py file of the packages under ``root``."""
    out = {}
    for pkg in PACKAGES:
        for f in sorted((root / pkg).rglob("*.py")):
            parts = list(f.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = f
    return out


def imports_of(name: str, path: Path, known: dict) -> set[str]:
    """The project modules (or packages) that module ``name`` imports, anywhere in its body."""
    is_pkg = path.name == "__init__.py"
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                pkg = name.split(".") if is_pkg else name.split(".")[:-1]
                pkg = pkg[: len(pkg) - (node.level - 1)]
                base = ".".join(pkg + ([base] if base else []))
            # "from a import b": b may be a module of package a, or a name defined in a
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names]
        for t in targets:
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t and t != name:
                found.add(t)
    return found


def graph(root: Path) -> tuple[dict, dict]:
    mods = modules(root)
    return mods, {m: imports_of(m, f, mods) for m, f in mods.items()}


def violations(root: Path) -> list[str]:
    """Every upward import, facade import and cycle under ``root``, as readable lines."""
    mods, edges = graph(root)
    facades = set(PACKAGES) & set(mods)      # the top-level package facades (a sub-package's __init__ is a module)
    out = []
    for m, deps in edges.items():
        if m in facades:
            continue
        for d in sorted(deps):
            if d in facades:
                out.append(f"{m} imports the package facade {d} (import the module that defines the name)")
            elif LAYER[d.split(".")[0]] > LAYER[m.split(".")[0]]:
                out.append(f"{m} (layer {m.split('.')[0]}) imports {d} from a layer above")
            elif m.startswith("trials.") and _part(m) in MAY_IMPORT and _part(d) != _part(m) \
                    and _part(d) not in MAY_IMPORT[_part(m)]:
                out.append(f"{m} (trials.{_part(m)}) imports {d}: trials.{_part(m)} may import only "
                           f"{', '.join(sorted(MAY_IMPORT[_part(m)]))}")
    for m in mods:
        if m.startswith("trials.") and _part(m) not in MAY_IMPORT:
            out.append(f"{m} is in no trials sub-package of MAY_IMPORT (put it in the one it belongs to)")
    # cycles among the non-facade modules (depth-first search; each cycle reported once)
    inner = {m: {d for d in deps if d not in facades} for m, deps in edges.items() if m not in facades}
    state, stack, seen = {}, [], set()

    def visit(v):
        state[v] = 1
        stack.append(v)
        for w in sorted(inner[v]):
            if state.get(w) == 1:
                cyc = stack[stack.index(w):] + [w]
                key = frozenset(cyc)
                if key not in seen:
                    seen.add(key)
                    out.append("import cycle: " + " -> ".join(cyc))
            elif w not in state:
                visit(w)
        stack.pop()
        state[v] = 2

    for v in sorted(inner):
        if v not in state:
            visit(v)
    return out


def test_no_upward_imports_and_no_cycles():
    bad = violations(ROOT)
    assert not bad, "\n".join(bad)


def _tree(tmp_path: Path, files: dict) -> Path:
    for rel, text in files.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    for pkg in PACKAGES:
        (tmp_path / pkg).mkdir(exist_ok=True)
        (tmp_path / pkg / "__init__.py").touch()
    return tmp_path


@pytest.mark.parametrize("files, expect", [
    ({"mmg/a.py": "def f():\n    from trials.runs.b import g\n", "trials/runs/b.py": "g = 1\n"}, "from a layer above"),
    ({"ekf/a.py": "from trials.files import b\n", "trials/files/b.py": ""}, "from a layer above"),
    ({"trials/runs/a.py": "from .b import x\n", "trials/runs/b.py": "def h():\n    from . import a\n"},
     "import cycle"),
    ({"trials/files/a.py": "import mmg\n", "mmg/b.py": ""}, "package facade"),
    ({"ekf/sub/__init__.py": "", "ekf/sub/a.py": "from ...trials.files import c\n", "trials/files/c.py": ""},
     "from a layer above"),
    # inside trials: a sub-package importing one above it or beside it, or ekf below measured
    ({"trials/files/a.py": "def f():\n    from ..runs.b import g\n", "trials/runs/b.py": ""}, "may import only"),
    ({"trials/analysis/nomoto/a.py": "from trials.planning import b\n", "trials/planning/b.py": ""},
     "may import only"),
    ({"trials/measured/a.py": "from trials.runs.b import g\n", "trials/runs/b.py": ""}, "may import only"),
    ({"trials/runs/a.py": "from ekf import b\n", "ekf/b.py": ""}, "may import only"),
    ({"trials/a.py": ""}, "in no trials sub-package"),
])
def test_the_checker_catches(tmp_path, files, expect):
    """The checker itself: an upward import (also inside a function or relative), a cycle and a facade
    import are each reported; the same trees without them pass."""
    bad = violations(_tree(tmp_path, files))
    assert any(expect in b for b in bad), bad


def test_the_checker_accepts_downward_imports(tmp_path):
    root = _tree(tmp_path, {"mmg/a.py": "", "ekf/b.py": "from mmg.a import x\n",
                            "trials/estimates/c.py": "from ekf import b\nfrom mmg import a\n"
                                                     "from ..runs import d\nfrom trials.files.e import y\n",
                            "trials/runs/d.py": "from ..analysis.nomoto.f import z\n", "trials/files/e.py": "",
                            "trials/analysis/nomoto/f.py": "from trials.files import e\n",
                            "trials/cli/g.py": "from ..measured import h\nfrom ..papers import i\n",
                            "trials/measured/h.py": "", "trials/papers/i.py": "",
                            "mmg/__init__.py": "def __getattr__(n):\n    from trials.runs import d\n"})
    assert violations(root) == []
