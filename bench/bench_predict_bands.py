"""Prediction-band speed: ``mmg predict --samples 200`` of one 600 s record at 10 Hz; target <= 30 s on 2 cores.

The record as ``bench/bench_replay.py`` takes it (the longest FRT-DS-ESSO record cut to its first 600 s, or a
simulated one without the data).  The ship: the 3 m model with a stated covariance (N_r, N_rr, kappa,
w_P0 at 5 % of their values, the wind scale at 0.1; its ``state_range`` the record's own, what
``--support physical`` would check ships over, :func:`trials.measured.draws.support_of`) and a run spread (u, v 0.005 m/s,
heading 0.02 rad), so every draw changes the ship and the start.  Times :func:`trials.measured.bands.prediction_bands` (the
numba cache loaded by one replay first), once per ``--jobs`` value, and prints the band's figures too.

    python bench/bench_predict_bands.py [--samples N] [--jobs 1 2]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))
TARGET_S = 30.0


def main(argv=None) -> int:
    import argparse

    import mmg
    from bench_replay import _record
    from trials.measured.bands import prediction_bands
    from trials.measured.identify.covariance import training_state_range
    from trials.measured.predict import measured_run, replay_record

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=200)
    ap.add_argument("--jobs", type=int, nargs="+", default=[2])
    a = ap.parse_args(argv)
    ship = mmg.load_ship("esso_osaka_3m")
    rec, what = _record(ship)
    run = measured_run(ship, rec, wind=True)
    replay_record(ship, run)                              # compiles (or loads the numba cache)
    names = ["N_r", "N_rr", "kappa", "w_P0"]
    mean = [ship.hull.value("N_r"), ship.hull.value("N_rr"), ship.rudder.kappa, ship.propeller.w_P0[0]]
    cov = {"names": names + ["wind_scale"], "values": mean + [1.0],
           "matrix": np.diag([(0.05 * m) ** 2 for m in mean] + [0.01]).tolist(), "state_range": training_state_range([run])}
    spread = {"names": ["start.u", "start.v", "start.psi"], "std": [0.005, 0.005, 0.02]}
    print(f"{what}: {len(run.t)} samples, wind {run.wind}; {a.samples} draws")
    for jobs in a.jobs:
        t0 = time.perf_counter()
        b = prediction_bands(ship, run, a.samples, seed=0, covariance=cov, run_spread=spread, jobs=jobs)
        dt = time.perf_counter() - t0
        print(f"{jobs} thread(s): {dt:.2f} s ({dt / a.samples * 1e3:.1f} ms a draw); target {TARGET_S:g} s: "
              f"{'meets' if dt <= TARGET_S else 'MISSES'} it; coverage {100 * b.coverage90:.0f} %, median width "
              f"{b.median_width_deg:.3g} deg, {b.diverged} diverged, {b.rejected} candidates rejected")
    return 0


if __name__ == "__main__":
    sys.exit(main())
