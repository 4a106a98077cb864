"""Calibrate the naming floors of ``mmg diagnose`` (:mod:`trials.measured.decision`) on the clean
records of the mismatch family, and write them to the packaged ``configs/calibration/diagnose.yaml``.

Input: the JSON of ``python bench/bench_diagnose.py --mismatch --tag _cal --seed0 1000`` (clean
records of ships that differ from the config as real ships do, diagnosed as a user would).  For
every clean record, the first search round tries each candidate on top of the fitted ship: its
*clean magnitude* is the candidate's :func:`~trials.measured.decision.magnitude` there, whether or
not its dBIC and z clear their thresholds (on 3500 s records they mostly do; counting all keeps
the floor on the safe side).  Per effect and kind of
record (turn, zigzag) the floor is

    floor = Q_half-normal(1 - alpha / m) * RMS(clean magnitudes)

the quantile of a half-normal law with the clean magnitudes' RMS as its scale, at the level that
holds the chance of any of the m candidates crossing its floor on a clean record to alpha (0.05,
the acceptance's false-alarm rate; m the number of candidates).  The half-normal is the law of |x|
for a zero-mean normal x: the size a fitted effect takes from the ship's own mismatch, which has
no preferred sign or direction.  A parametric tail, not the sample maximum: 20 records per kind
cannot place a 1 % quantile on their own.  The floors are checked afterwards on fresh seeds (the
bench's ``--seed0`` differs), never on the records that set them.

    python bench/calibrate_diagnose.py bench/out/diagnose_mismatch_cal.json [--alpha 0.05] [--write]
"""
from __future__ import annotations

import argparse
import datetime
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
OUT = REPO / "configs" / "calibration" / "diagnose.yaml"


def clean_magnitudes(records, L: float) -> dict:
    """({effect: {kind: [clean magnitude per clean record]}}, the same of whether dBIC and z cleared)
    from the first search round."""
    from trials.measured.decision import BIC_THRESHOLD, Z_THRESHOLD, magnitude

    out: dict = {}
    passes: dict = {}
    for rec in records:
        if rec.get("truth"):
            continue
        rounds = rec.get("rounds") or []
        if not rounds:
            continue
        kind = rounds[0].get("kind") or ("turn" if str(rec.get("trial", "")).startswith("turn") else "zigzag")
        for c in rounds[0]["candidates"]:
            m = magnitude(c["effect"], c["parameters"], L)
            out.setdefault(c["effect"], {}).setdefault(kind, []).append(float(m))
            passes.setdefault(c["effect"], {}).setdefault(kind, []).append(
                bool(c["delta_bic"] > BIC_THRESHOLD and c["z"] > Z_THRESHOLD))
    return out, passes


def floors(clean: dict, alpha: float) -> dict:
    """{effect: {kind: floor}}: the half-normal quantile at 1 - alpha / m times the RMS."""
    from scipy.stats import halfnorm

    m = max(len(clean), 1)
    q = float(halfnorm.ppf(1.0 - alpha / m))
    return {e: {k: float(f"{q * float(np.sqrt(np.mean(np.square(v)))):.4g}") for k, v in kinds.items()}
            for e, kinds in clean.items()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bench_json")
    ap.add_argument("--alpha", type=float, default=0.05)
    ap.add_argument("--write", action="store_true", help=f"write {OUT.relative_to(REPO)}")
    a = ap.parse_args(argv)
    import yaml

    import mmg

    data = json.loads(Path(a.bench_json).read_text())
    records = data["records"] if isinstance(data, dict) else data
    L = mmg.load_ship("esso_osaka").particulars.L
    clean, passes = clean_magnitudes(records, L)
    fl = floors(clean, a.alpha)
    n = sum(1 for r in records if not r.get("truth"))
    for e, kinds in clean.items():
        for k, v in kinds.items():
            v = np.asarray(v)
            print(f"{e:14s} {k:7s} n {len(v):3d}  passing dBIC,z {sum(passes[e][k]):3d}  max {v.max():.4g}  "
                  f"rms {np.sqrt(np.mean(v * v)):.4g}  floor {fl[e][k]:.4g}")
    doc = {"source": f"python bench/calibrate_diagnose.py {Path(a.bench_json).name} --alpha {a.alpha} "
                     f"({n} clean records of the mismatch family, seeds of that bench run; "
                     f"{datetime.date.today().isoformat()})",
           "alpha": a.alpha, "units": {"current": "sqrt(gL)", "rudder_offset": "deg", "heading_bias": "deg",
                                       "wind": "1", "shallow_water": "T/H"},
           "floors": fl, "clean": {e: {k: [float(f"{x:.4g}") for x in v] for k, v in kinds.items()}
                                   for e, kinds in clean.items()}}
    if a.write:
        OUT.parent.mkdir(parents=True, exist_ok=True)
        OUT.write_text("# Written by bench/calibrate_diagnose.py: the naming floors of mmg diagnose "
                       "(trials/measured/decision.py).\n" + yaml.safe_dump(doc, sort_keys=False))
        print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
