"""Where a command's compile time goes on a cold numba cache: every compiled function, per process.

Runs ``mmg ARGS`` (default: the cold first ``mmg estimate configs/trials/zz20.yaml --no-plots``) with
``NUMBA_CACHE_DIR`` pointing at a fresh temporary folder and a numba compile-event listener
(``numba.core.event``) in the command and in every Python process it starts (the background
warm-up child included), installed through a ``sitecustomize`` on ``PYTHONPATH``.  Prints, per
process, each top-level compilation (start and end [s] after the command started, duration, the
function) and the time spent holding LLVM's lock (code generation), then the command's wall time.
Run from the repository root:

    python bench/compile_profile.py [--depth 0] [-- estimate configs/trials/zz20.yaml --no-plots]

``--depth 1`` also lists the compilations nested in the top-level ones (the callees each compiled
for).  A listener costs a little: the wall time is a few tenths of a second above
``bench/bench_cold.py``'s.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

SITECUSTOMIZE = '''
import atexit, os, sys, time
if os.environ.get("MMG_COMPILE_PROFILE"):
    from numba.core import event as _ev
    _T0 = float(os.environ["MMG_COMPILE_PROFILE_T0"])
    _recs = []

    class _Listener(_ev.Listener):
        def __init__(self):
            self.open = []

        def on_start(self, e):
            self.open.append(time.time())

        def on_end(self, e):
            t0 = self.open.pop()
            d = e.data or {}
            f = getattr(d.get("dispatcher"), "py_func", None)
            _recs.append((t0 - _T0, time.time() - _T0, e.kind, len(self.open), f.__qualname__ if f else ""))

    _ev.register("numba:compile", _Listener())
    _ev.register("numba:llvm_lock", _Listener())

    @atexit.register
    def _dump():
        with open(os.path.join(os.environ["MMG_COMPILE_PROFILE"], f"{os.getpid()}.txt"), "w") as fh:
            fh.write(" ".join(sys.argv) + "\\n")
            for r in sorted(_recs):
                fh.write("%.3f %.3f %s %d %s\\n" % r)
'''


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--depth", type=int, default=0, help="nesting depth of the compilations listed (0: top level)")
    ap.add_argument("args", nargs="*", help="the mmg command's arguments (after --)")
    a = ap.parse_args(argv)
    args = a.args or ["estimate", "configs/trials/zz20.yaml", "--no-plots"]
    with tempfile.TemporaryDirectory(prefix="mmg-compile-profile-") as tmp:
        tmp = Path(tmp)
        (tmp / "site").mkdir()
        (tmp / "site" / "sitecustomize.py").write_text(SITECUSTOMIZE)
        (tmp / "events").mkdir()
        if args[0] in ("estimate", "simulate") and "--out" not in args:
            args = args + ["--out", str(tmp / "out")]
        t0 = time.time()
        env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp / "cache"), MMG_COMPILE_PROFILE=str(tmp / "events"),
                   MMG_COMPILE_PROFILE_T0=repr(t0),
                   PYTHONPATH=os.pathsep.join([str(tmp / "site"), str(REPO), os.environ.get("PYTHONPATH", "")]))
        r = subprocess.run([sys.executable, "-m", "trials.cli", *args], cwd=REPO, env=env, capture_output=True,
                           text=True)
        wall = time.time() - t0
        if r.returncode != 0:
            print(r.stdout[-2000:], r.stderr[-2000:], sep="\n")
            return r.returncode
        for f in sorted((tmp / "events").glob("*.txt")):
            lines = f.read_text().splitlines()
            print(f"process: {Path(lines[0].split()[0]).name} {' '.join(lines[0].split()[1:])}")
            llvm = 0.0
            for line in lines[1:]:
                s, e, kind, depth, name = line.split(" ", 4) + [""] * (5 - len(line.split(" ", 4)))
                s, e, depth = float(s), float(e), int(depth)
                if kind == "numba:llvm_lock":
                    llvm += (e - s) if depth == 0 else 0.0
                elif depth <= a.depth:
                    print(f"  {'  ' * depth}{s:7.2f} {e:7.2f} {e - s:6.2f} s  {name}")
            print(f"  LLVM (lock held): {llvm:.2f} s")
        print(f"mmg {' '.join(a.args or ['estimate', 'configs/trials/zz20.yaml', '--no-plots'])}: {wall:.1f} s wall, "
              f"cold cache")
    return 0


if __name__ == "__main__":
    sys.exit(main())
