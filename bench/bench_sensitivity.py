"""Time the Rhee & Kim sensitivity runs: 5 trials x 13 simulations of 3000 s at 0.1 s (65 runs).

    python bench/bench_sensitivity.py [--backend loky|serial|threads] [--jobs N]

Trials: ST35, ZZ10, ZZ20, S-type 60, S-type 120.  The compiled simulator is warmed up first
(numba cache load), then the whole eq. 21-22 computation is timed end to end, including the
worker start-up of the parallel backend.  Target: <= 10 s on the 2-core machine.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from trials.planning.sensitivity import sensitivity, trial_differences  # noqa: E402
from trials.files.sweep import default_jobs  # noqa: E402
from trials.runs.trial import load_trial  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
STEMS = ("st35", "zz10", "zz20", "stype60", "stype120")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--backend", default=None, choices=["loky", "serial", "threads"],
                    help="one backend (default: serial, then loky on all cores)")
    ap.add_argument("--jobs", type=int, default=None)
    a = ap.parse_args()
    trials = [load_trial(REPO / "configs" / "trials" / f"{s}.yaml") for s in STEMS]
    t0 = time.perf_counter()
    trial_differences(replace(trials[1], duration=10.0))       # compile / load the numba cache
    warm = time.perf_counter() - t0
    nsim = len(trials) * 13
    print(f"sensitivity of {len(trials)} trials ({', '.join(t.name for t in trials)}): {nsim} simulations of "
          f"{trials[0].duration:.0f} s at {trials[0].dt} s (warm-up {warm:.2f} s not counted)")
    for backend in [a.backend] if a.backend else ["serial", "loky"]:
        t0 = time.perf_counter()
        df = sensitivity(trials, backend=backend, n_jobs=a.jobs, progress=False)
        wall = time.perf_counter() - t0
        jobs = 1 if backend == "serial" else (a.jobs or default_jobs())
        print(f"  backend {backend:6s} {jobs} worker(s) on {os.cpu_count()} cores: {wall:5.2f} s wall "
              f"({wall / nsim * 1000:.0f} ms per simulation incl. worker start-up), group sum "
              f"{df.sensitivity_pct.sum():.6f} % -> {'PASS' if wall <= 10 else 'FAIL'} (target <= 10 s)")


if __name__ == "__main__":
    main()
