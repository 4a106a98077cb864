"""Time the augmented EKF: one pass over 3000 s at 0.1 s (30 000 steps), median of 5 after
compilation, and the full 4-trial single-seed Rhee & Kim reproduction.

    python bench/bench_ekf.py [--skip-reproduce]
"""
from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from ekf.estimate import P0_for, R_for, initial_state, load_config  # noqa: E402
from ekf.filter import run_filter  # noqa: E402
from trials.estimation import data_from_trial  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--skip-reproduce", action="store_true")
    a = ap.parse_args()
    cfg = load_config()
    with tempfile.TemporaryDirectory() as td:
        data = data_from_trial("zz20", cfg)
        m = data.meas
        args = (data.packed, data.slots, m.t, m.z(), m.delta, initial_state(data, cfg),
                P0_for(cfg, data.names, data.reference), R_for(cfg, data.name))
        t0 = time.perf_counter()
        run_filter(*args, trial=data.name)
        first = time.perf_counter() - t0
        times = []
        for _ in range(5):
            t0 = time.perf_counter()
            run_filter(*args, trial=data.name)
            times.append(time.perf_counter() - t0)
        print(f"EKF pass, {len(m.t) - 1} steps ({m.t[-1]:.0f} s at {m.t[1] - m.t[0]:.1f} s): "
              f"median {statistics.median(times):.3f} s of 5 (min {min(times):.3f} s; first call incl. "
              f"compilation/cache load {first:.2f} s)")
        if not a.skip_reproduce:
            from trials.rhee_kim import reproduce_rhee_kim

            t0 = time.perf_counter()
            reproduce_rhee_kim(Path(td) / "rk", plots=False, verbose=False)
            print(f"Rhee & Kim reproduction (ST35, ZZ10, ZZ20, S-type 120; simulate + preprocess + EKF + "
                  f"reports without figures): {time.perf_counter() - t0:.2f} s")


if __name__ == "__main__":
    main()
