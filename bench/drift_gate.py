"""What freeing the drift terms on a turn (``trials.measured.diagnose._drift_terms``) buys on
clean records: per record the baseline's heading residual, the fall that freeing them brings
(against the baseline fitted on by as many evaluations: the gate's figure, freed or not) and the
dBIC of freeing them, on clean turns of the mismatch family and on the main job's
ST35 files (the ship that made them): the figures the size gate (:data:`~trials.measured.diagnose.DRIFT_FALL_MIN`)
was checked on, and dBIC beside them (the gate asks no dBIC of its own).

    python bench/drift_gate.py [--seed0 1000] [--n 24] [--jobs 2]
"""
from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

_H = re.compile(r"heading ([0-9.e+-]+) deg")


def _gate(ship, rec) -> tuple:
    from trials.measured.diagnose import diagnose

    lines = []
    diagnose(ship, [rec], candidates=[], say=lines.append)
    base = next(float(_H.search(x).group(1)) for x in lines if x.startswith("baseline (ship fitted"))
    g = next((x for x in lines if "drift terms" in x), "")
    dbic = float(re.search(r"dBIC ([0-9.e+-]+)", g).group(1)) if g else float("nan")
    fall = re.search(r"heading residual ([0-9.e+-]+) deg less", g)
    return base, float(fall.group(1)) if fall else 0.0, dbic, "freed" in g


def _family_one(args):
    import mmg
    import diagnose_mismatch as dm
    from trials.measured.mismatch import trial_records

    seed0, i = args
    ship = mmg.load_ship("esso_osaka")
    member, factors = dm._family(seed0)[i % dm.FAMILY_SIZE]
    trial = ("turn35", "turn35p")[i % 2]
    rec = trial_records(ship, member, trial, None, seed=seed0 + i, name=f"clean_{i}")
    return (f"clean_{i} {trial} {factors['hull_form']}", *_gate(ship, rec))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed0", type=int, default=1000)
    ap.add_argument("--n", type=int, default=24)
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args(argv)
    import subprocess

    from joblib import Parallel, delayed

    import mmg
    from mmg.resources import config_path

    rows = Parallel(n_jobs=a.jobs)(delayed(_family_one)((a.seed0, i)) for i in range(a.n))
    ship = mmg.load_ship("esso_osaka")
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, "-m", "trials.cli", "simulate", str(config_path("trials", "st35.yaml")),
                        "--out", tmp], check=True, capture_output=True)
        for f in ("log.csv", "truth.csv"):
            rows.append((f"st35 {f}", *_gate(ship, str(Path(tmp) / f))))
    # fall: the gate's, against the baseline fitted on by as many evaluations (diagnose._drift_terms)
    print(f"{'record':32s} {'heading baseline':>16s} {'fall':>9s} {'dBIC':>8s} freed")
    for name, b, fall, d, freed in rows:
        print(f"{name:32s} {b:16.4f} {fall:9.4f} {d:8.1f} {freed}")


if __name__ == "__main__":
    main()
