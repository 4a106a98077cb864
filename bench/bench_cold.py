"""Benchmark: cold against warm numba cache, whole processes.

Each case runs with ``NUMBA_CACHE_DIR`` pointing at a fresh temporary folder (cold: every
compiled function is compiled, as on a fresh install or a CI run), then again with the same
folder (warm: everything loaded from the cache), and, with ``--warmup``, cold again after
``python -m trials.cli.warmup`` (the warm-up's wall time counted in).  Prints wall times, the ratios
and the number of specialisations compiled in the cold run (cache index entries written).
Run from the repository root:

    PYTHONPATH=. python bench/bench_cold.py [--cases simulate estimate] [--suite] [--warmup]

``--suite`` adds the fast test suite (``pytest -m "not slow"``, about 4 min warm).
"""
from __future__ import annotations

import argparse
import os
import pickle
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

CASES = {
    "simulate": ["-m", "trials.cli", "simulate", "configs/trials/st35.yaml", "--out", "{tmp}/sim"],
    "estimate": ["-m", "trials.cli", "estimate", "configs/trials/zz20.yaml", "--no-plots", "--out", "{tmp}/est"],
    "suite": ["-m", "pytest", "-q", "-m", "not slow", "-p", "no:cacheprovider"],
}


def specialisations(cache: Path) -> int:
    """Number of compiled specialisations held in a numba cache folder (entries of its indexes)."""
    n = 0
    for idx in cache.rglob("*.nbi"):
        try:
            with open(idx, "rb") as f:
                pickle.load(f)                       # the stamp
                data = f.read()
            n += len(pickle.loads(data)[1])
        except Exception:                            # another numba's format: count the data files
            n += len(list(idx.parent.glob(idx.name.rsplit(".", 2)[0] + "*.nbc")))
    return n


def run(args, cache: Path, tmp: Path) -> float:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    cmd = [sys.executable] + [a.format(tmp=tmp) for a in args]
    t0 = time.perf_counter()
    r = subprocess.run(cmd, cwd=REPO, env=env, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({r.returncode}):\n{r.stdout[-3000:]}\n{r.stderr[-2000:]}")
    last = r.stdout.strip().splitlines()[-1:] if "pytest" in args else []
    if last:
        print(f"  ({last[0]})", flush=True)
    return dt


def main():
    # started in the background (``cmd &``), the shell hands us SIGINT ignored, and every child would
    # inherit it: the suite's Ctrl-C tests would then fail; restore Python's handler (children get SIG_DFL)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", nargs="+", default=["simulate", "estimate"], choices=sorted(CASES))
    ap.add_argument("--suite", action="store_true", help="add the fast test suite")
    ap.add_argument("--warmup", action="store_true", help="also: cold after python -m trials.cli.warmup")
    a = ap.parse_args()
    cases = list(a.cases) + (["suite"] if a.suite and "suite" not in a.cases else [])
    with tempfile.TemporaryDirectory(prefix="bench_cold_") as td:
        td = Path(td)
        for name in cases:
            cache = td / f"cache_{name}"
            cold = run(CASES[name], cache, td)
            nspec = specialisations(cache)
            warm = run(CASES[name], cache, td)
            line = (f"{name}: cold {cold:.1f} s ({nspec} specialisations compiled), warm {warm:.1f} s, "
                    f"cold / warm {cold / warm:.2f}")
            if a.warmup:
                cache2 = td / f"cache_{name}_w"
                wu = run(["-m", "trials.cli.warmup", "--quiet"], cache2, td)
                after = run(CASES[name], cache2, td)
                line += (f"; warmup {wu:.1f} s + cold-after-warmup {after:.1f} s = {wu + after:.1f} s, "
                         f"(warmup + run) / warm {(wu + after) / warm:.2f}")
                shutil.rmtree(cache2, ignore_errors=True)
            print(line, flush=True)
            shutil.rmtree(cache, ignore_errors=True)


if __name__ == "__main__":
    main()
