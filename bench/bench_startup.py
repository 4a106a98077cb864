"""What a user feels: one 35 deg turn in a fresh process, ours against shipmmg's, and
``mmg simulate`` of ST35 with its CSVs and PNGs, whole processes, warm caches.

    python bench/bench_startup.py [--runs 5] [--baseline REV]

Each command runs once to warm the caches (numba's, the OS's), then A and B alternate
``--runs`` times; the medians and the median of the pairwise ratios A/B are printed.
The shipmmg turn is its own KVLCC2 L7 test case (200 s, RK45 at its default tolerance);
ours is the Esso Osaka ST35 through the public API (3000 s of RK4 at 0.1 s): each tool's
natural first use.  Needs the ``bench`` extra (shipmmg).

It also times our turn against itself with the JIT (``MMG_AOT=0``: numba imported, the kernels
loaded from numba's cache) instead of the ahead-of-time compiled module (:mod:`mmg._aot`): the
before/after figure of that module.

``--baseline REV`` (a git revision, e.g. ``HEAD~3``) instead times ``mmg simulate st35`` of that
revision against this checkout's, interleaved pair by pair in fresh processes (the revision is
checked out into a temporary git worktree; its numba cache is warmed by a first run), and prints
both medians and the median ratio now/baseline: a before/after figure that holds on a shared,
noisy machine.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

OURS = ("import mmg; r = mmg.simulate(mmg.turning('esso_osaka', rudder='35 deg', speed='10 kn', duration='3000 s')); "
        "print(round(r.metrics()['tactical_diameter_L'], 3))")
SHIPMMG = """
import numpy as np
from shipmmg.mmg_3dof import (Mmg3DofBasicParams, Mmg3DofManeuveringParams, simulate_mmg_3dof)
b = Mmg3DofBasicParams(L_pp=7.00, B=1.27, d=0.46, x_G=0.25, D_p=0.216, m=3.27 * 1025, I_zG=3.27 * 1025 * (0.25 * 7.00) ** 2,
    A_R=0.0539, η=0.626, m_x=0.022 * (0.5 * 1025 * 7.00 ** 2 * 0.46), m_y=0.223 * (0.5 * 1025 * 7.00 ** 2 * 0.46),
    J_z=0.011 * (0.5 * 1025 * 7.00 ** 4 * 0.46), f_α=2.747, ϵ=1.09, t_R=0.387, x_R=-0.500 * 7.00, a_H=0.312,
    x_H=-0.464 * 7.00, γ_R_minus=0.395, γ_R_plus=0.640, l_R=-0.710, κ=0.50, t_P=0.220, w_P0=0.40, x_P=-0.690)
m = Mmg3DofManeuveringParams(k_0=0.2931, k_1=-0.2753, k_2=-0.1385, R_0_dash=0.022, X_vv_dash=-0.040, X_vr_dash=0.002,
    X_rr_dash=0.011, X_vvvv_dash=0.771, Y_v_dash=-0.315, Y_r_dash=0.083, Y_vvv_dash=-1.607, Y_vvr_dash=0.379,
    Y_vrr_dash=-0.391, Y_rrr_dash=0.008, N_v_dash=-0.137, N_r_dash=-0.049, N_vvv_dash=-0.030, N_vvr_dash=-0.294,
    N_vrr_dash=0.055, N_rrr_dash=-0.013)
t = np.linspace(0, 200, 2000)
sol = simulate_mmg_3dof(b, m, list(t), list(np.full(len(t), np.radians(35))), list(np.full(len(t), 17.95)),
                        u0=2.29 * 0.512, ρ=1025.0)
print(sol.sol(t)[0][-1])
"""


FLOOR = "import numpy, numba, numba.np.arraymath"
"""What any numba-compiled tool pays in a fresh process before its own code runs: numpy, numba and the
array-math registry numba loads at its first compiled call (which imports scipy.linalg for BLAS)."""


def once(cmd, cwd) -> float:
    """Wall time of one run; ``cmd`` may start with ``VAR=value`` words (set in its environment)."""
    env = dict(os.environ)
    while cmd and "=" in cmd[0] and not cmd[0].startswith("-"):
        k, v = cmd[0].split("=", 1)
        env[k] = v
        cmd = cmd[1:]
    t0 = time.perf_counter()
    subprocess.run(cmd, cwd=cwd, check=True, capture_output=True, env=env)
    return time.perf_counter() - t0


def pair(a, b, runs: int, cwd) -> tuple[float, float, float]:
    once(a, cwd)
    once(b, cwd)
    ta, tb, ratios = [], [], []
    for _ in range(runs):
        x, y = once(a, cwd), once(b, cwd)
        ta.append(x)
        tb.append(y)
        ratios.append(x / y)
    return statistics.median(ta), statistics.median(tb), statistics.median(ratios)


def simulate_vs_baseline(rev: str, runs: int) -> None:
    """``mmg simulate st35`` of this checkout against revision ``rev``, interleaved, fresh processes."""
    with tempfile.TemporaryDirectory() as td:
        wt = Path(td) / "baseline"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(wt), rev], check=True,
                       capture_output=True)
        try:
            def cmd(src, out):
                env = {**os.environ, "PYTHONPATH": str(src)}
                return lambda: subprocess.run([sys.executable, "-m", "trials.cli", "simulate", "st35", "--out", out],
                                              cwd=td, env=env, check=True, capture_output=True)
            now, base = cmd(ROOT, "now"), cmd(wt, "base")
            for f in (now, base, now, base):        # warm both numba caches and the OS
                f()
            tn, tb, ratios = [], [], []
            for _ in range(runs):
                t0 = time.perf_counter()
                now()
                t1 = time.perf_counter()
                base()
                t2 = time.perf_counter()
                tn.append(t1 - t0)
                tb.append(t2 - t1)
                ratios.append((t1 - t0) / (t2 - t1))
            print(f"mmg simulate st35: this checkout {statistics.median(tn):.2f} s, {rev} {statistics.median(tb):.2f} s, "
                  f"ratio now/{rev} {statistics.median(ratios):.2f} (median of {runs} interleaved pairs)")
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(wt)], capture_output=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--baseline", default=None, help="git revision to time mmg simulate st35 against")
    args = ap.parse_args()
    if args.baseline:
        simulate_vs_baseline(args.baseline, args.runs)
        return
    with tempfile.TemporaryDirectory() as td:
        try:
            import shipmmg  # noqa: F401
            a, b, r = pair([sys.executable, "-c", OURS], [sys.executable, "-c", SHIPMMG], args.runs, td)
            print(f"one turn in a fresh process: ours (API, 3000 s) {a:.2f} s, shipmmg (200 s) {b:.2f} s, "
                  f"ratio ours/shipmmg {r:.2f} (median of {args.runs} pairs; target <= 1)")
            f, b2, r2 = pair([sys.executable, "-c", FLOOR], [sys.executable, "-c", SHIPMMG], args.runs, td)
            print(f"  the floor of a numba tool ({FLOOR!r}, nothing of ours) {f:.2f} s: "
                  f"{r2:.2f} x shipmmg's whole turn ({b2:.2f} s)")
        except ImportError:
            print("shipmmg not installed (pip install 'mmg-toolkit[bench]'): turn comparison skipped")
        a, j, r = pair([sys.executable, "-c", OURS], ["MMG_AOT=0", sys.executable, "-c", OURS], args.runs, td)
        print(f"  ours with the ahead-of-time compiled kernels (mmg._aot) {a:.2f} s, with the JIT (MMG_AOT=0, "
              f"numba imported) {j:.2f} s: ratio AOT/JIT {r:.2f}")
        t = []
        once(["mmg", "simulate", "st35", "--out", "o"], td)
        for _ in range(args.runs):
            t.append(once(["mmg", "simulate", "st35", "--out", "o"], td))
        print(f"mmg simulate st35 with log.csv, truth.csv, metrics.json and 2 PNGs: median {statistics.median(t):.2f} s "
              f"(min {min(t):.2f}; target <= 1.2 s warm)")


if __name__ == "__main__":
    main()
