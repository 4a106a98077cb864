"""Compiled code never goes stale: the cache key covers every source file the compiled
code depends on, found by walking the packages (:func:`mmg._jit.source_key`), not a list of files.

On a temporary copy of the package a physics function the compiled code calls is moved into a new
module of its own (fresh processes then give the same numbers) and edited there by a factor: the next
fresh process uses the edit, with no cache cleared and no list updated.  Before, numba keyed each
cached function by its own file, and the hand-kept lists of files named no new module: the edit was
silently ignored (stale code, as once when the replay returned NaN after an edit of the model).

* fast: :func:`mmg.model.hull_scales` (compiled, cached) calls :func:`mmg.nondim.force_scale`, moved
  into ``mmg/scales.py`` and doubled there;
* slow (cold compiles of everything, three times): :func:`mmg.model.rudder`, moved into
  ``mmg/rudder_force.py``, its normal force doubled there; the simulation (the ahead-of-time
  module), the replay and the EKF pass then give what the original code gives for a rudder of twice
  the area (the normal force is linear in the area, exactly: a power-of-two factor).
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

from .conftest import REPO


def _copy(tmp_path):
    """The packages and configs copied (no caches), as a fresh checkout."""
    root = tmp_path / "repo"
    ignore = shutil.ignore_patterns("__pycache__", "*.so", "*.nbi", "*.nbc")
    for d in ("mmg", "ekf", "trials", "configs"):
        shutil.copytree(REPO / d, root / d, ignore=ignore)
    shutil.copy(REPO / "pyproject.toml", root / "pyproject.toml")
    return root


def _run(root, code: str, *args) -> dict:
    """Run ``code`` in a fresh process on the copy (its own caches, in its __pycache__); its last line of
    output is JSON."""
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "MMG_AOT", "NUMBA_DISABLE_JIT")}
    env["PYTHONPATH"] = str(root)
    out = subprocess.run([sys.executable, "-c", code, *args], cwd=root, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def _move(root, function: str, source: str, new: str, header: str) -> str:
    """Cut the compiled ``function`` (its decorator to the next blank line pair) out of ``mmg/<source>``
    into the new module ``mmg/<new>`` (``header`` first); ``mmg/<source>`` imports it back at its end.
    Returns the function's text."""
    src = root / "mmg" / source
    text = src.read_text()
    m = re.search(rf"\n(@njit\([^\n]*\)\ndef {function}\(.*?)\n\n\n", text, re.S)
    assert m, function
    body = m.group(1)
    src.write_text(text.replace(body + "\n", "") + f"\nfrom .{new[:-3]} import {function}  # noqa: E402\n")
    (root / "mmg" / new).write_text(header + "\n\n" + body + "\n")
    return body


def _edit(root, new: str, old: str, edited: str) -> None:
    f = root / "mmg" / new
    text = f.read_text()
    assert text.count(old) == 1, old
    f.write_text(text.replace(old, edited))


def test_the_key_covers_every_file_of_a_package_and_of_the_compiled_packages_it_imports(tmp_path, monkeypatch):
    from mmg import _jit

    for name, code in (("kq_lib", "X = 1\n"), ("kq_app", "import kq_lib\nimport kq_other\n"), ("kq_other", "")):
        (tmp_path / name).mkdir()
        (tmp_path / name / "__init__.py").write_text(code)
    monkeypatch.syspath_prepend(str(tmp_path))
    import kq_app  # noqa: F401

    monkeypatch.setattr(_jit, "_packages", _jit._packages | {"kq_lib", "kq_app"})    # kq_other: no compiled code

    def keys():
        monkeypatch.setattr(_jit, "_keys", {})
        return _jit.source_key("kq_lib.sub"), _jit.source_key("kq_app")

    lib, app = keys()
    assert lib.startswith("kq_lib-") and app.startswith("kq_app-")
    (tmp_path / "kq_lib" / "physics.py").write_text("def f(x):\n    return x\n")        # a new file
    lib2, app2 = keys()
    assert lib2 != lib and app2 != app
    (tmp_path / "kq_lib" / "physics.py").write_text("def f(x):\n    return -x\n")       # an edit (same size)
    lib3, app3 = keys()
    assert lib3 != lib2 and app3 != app2
    (tmp_path / "kq_other" / "more.py").write_text("Y = 2\n")                           # not compiled code's
    assert keys() == (lib3, app3)
    (tmp_path / "kq_app" / "__init__.py").write_text("import kq_lib\nimport kq_other  # edited\n")
    assert keys()[0] == lib3 and keys()[1] != app3                                        # the app only


SCALES = """
import json
from mmg.model import hull_scales, pack
from mmg.ship import load_ship
print(json.dumps(list(hull_scales(2.0, 3.0, pack(load_ship("esso_osaka")).p))))
"""


def test_an_edit_of_a_function_moved_into_a_new_module_is_compiled(tmp_path):
    root = _copy(tmp_path)
    before = _run(root, SCALES)
    _move(root, "force_scale", "nondim.py", "scales.py", "from ._jit import njit")
    assert _run(root, SCALES) == before                            # moved: the same numbers
    _edit(root, "scales.py", "return 0.5 * rho * L * T * U * U", "return 1.0 * rho * L * T * U * U")
    after = _run(root, SCALES)
    assert after[0] == 2.0 * before[0] and after[1] == 2.0 * before[1]    # the force scale doubled
    assert after[2] == before[2]                                   # the moment scale did not change


WORK = r"""
import json, sys
import numpy as np
import mmg.model as M

factors = [float(a) for a in sys.argv[1:]]
area = [1.0]
_pack = M.pack


def pack(*a, **k):                      # the rudder area times the factor
    pk = _pack(*a, **k)
    pk.p[M.P_AR] *= area[0]
    return pk


M.pack = pack                           # before the modules that import it
import mmg
from ekf.data import estimable_names
from ekf.filter import run_filter
from mmg.replay import ReplayInputs, replay
from mmg.ship import load_ship

ship = load_ship("esso_osaka")
out = {}
for f in factors:
    area[0] = f
    r = mmg.simulate(mmg.turning(ship, rudder="35 deg", speed="10 kn", duration="300 s"))
    s = r.states
    pk = pack(ship)
    k = slice(None, None, 10)            # 1 s samples
    rigid = [M.U_, M.V_, M.R_, M.X_, M.Y_, M.PSI_]
    rep = replay(pk, ReplayInputs(r.t[k], s[k, M.DELTA_], s[k, M.N_]), s[0, rigid])
    names = estimable_names(ship)
    slots = np.array([list(ship.hull.names).index(n) for n in names])
    meas = s[k][:, [M.U_, M.V_, M.R_, M.N_]]
    z0 = np.r_[meas[0], pk.hull_coef[slots]]
    P0 = np.diag(np.r_[np.full(4, 1e-6), np.full(len(names), 1e-6)])
    est = run_filter(pk, slots, r.t[k], meas, s[k, M.DELTA_], z0, P0, np.eye(4) * 1e-6, nis_max=0.0)
    out[str(f)] = {"simulate": s[-1].tolist(), "replay": rep[-1].tolist(), "ekf": est.z[-1].tolist()}
print(json.dumps(out))
"""


@pytest.mark.slow
def test_simulation_replay_and_ekf_use_an_edit_in_a_new_module(tmp_path):
    root = _copy(tmp_path)
    ref = _run(root, WORK, "1.0", "2.0")                           # the original code; a rudder twice the area
    for what in ("simulate", "replay", "ekf"):
        a, b = np.array(ref["1.0"][what]), np.array(ref["2.0"][what])
        assert np.all(np.isfinite(a)) and np.max(np.abs(a - b)) > 1e-3 * np.max(np.abs(a)), what
    body = _move(root, "rudder", "model.py", "rudder_force.py",
                 "import numpy as np\n\nfrom ._inlining import hot_loops_only\nfrom ._jit import njit\n")
    import mmg.model as M

    calls = set(re.findall(r"(?<![\w.])([A-Za-z_]\w*)\(", body)) - {"rudder", "njit"}    # model helpers it calls
    names = sorted(set(re.findall(r"\bP_[A-Z0-9_]+\b", body)) | {c for c in calls if hasattr(M, c)})
    _edit(root, "rudder_force.py", "import numpy as np\n", f"import numpy as np\n\nfrom .model import {', '.join(names)}\n")
    moved = _run(root, WORK, "1.0")["1.0"]
    for what in ("simulate", "replay", "ekf"):                     # moved: the same numbers
        np.testing.assert_allclose(moved[what], ref["1.0"][what], rtol=1e-12, atol=1e-12, err_msg=what)
    _edit(root, "rudder_force.py", "FN = 0.5 * p[P_RHO]", "FN = 1.0 * p[P_RHO]")    # the normal force doubled
    edited = _run(root, WORK, "1.0")["1.0"]
    stale = [what for what in ("simulate", "replay", "ekf")       # each as with a rudder of twice the area
             if not np.allclose(edited[what], ref["2.0"][what], rtol=1e-9, atol=1e-12)]
    assert stale == []


def test_folders_of_other_sources_unused_for_a_week_are_removed(tmp_path, monkeypatch):
    import time

    from mmg import _jit

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    root = tmp_path / "mmg-toolkit"
    week = time.time() - 8 * 86400
    for name, when in (("mmg-old", week), ("mmg-recent", time.time() - 3600), ("ekf-old", week)):
        (root / name).mkdir(parents=True)
        os.utime(root / name, (when, when))
    monkeypatch.setitem(_jit._keys, "mmg", "mmg-new")
    assert _jit.cache_folder("mmg.model") == root / "mmg-new"
    assert sorted(p.name for p in root.iterdir()) == ["ekf-old", "mmg-new", "mmg-recent"]
