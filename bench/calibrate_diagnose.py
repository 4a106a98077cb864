"""Calibrate the naming floors of ``mmg diagnose`` (:mod:`trials.measured.decision`) on the clean
records of the mismatch family, and write them to the packaged ``configs/calibration/diagnose.yaml``:
the command over :func:`trials.measured.calibration.calibrate` (its module docstring gives the rule).

Input: the JSON of ``python bench/bench_diagnose.py --mismatch --tag _cal --seed0 1000 --effects none``
(clean records of ships that differ from the config as real ships do, diagnosed as a user would,
with no floor: ``MMG_DIAGNOSE_CALIBRATION=none``), and runs with effects.  The floors are checked
afterwards on fresh seeds (the bench's ``--seed0`` differs), never on the records that set them.

    python bench/calibrate_diagnose.py bench/out/diagnose_mismatch_cal.json[:KIND] ... [--alpha 0.05] [--write]
        [--kinds turn turn_pair [--effects EFFECT ...]] [--ship esso_osaka] [--out FILE]

``--ship`` is the config the runs diagnosed (``bench_diagnose.py --mismatch --ship``; its length
makes the floors' sqrt(gL) units); ``--out`` writes another file than the packaged one (a
calibration of another ship, used through ``MMG_DIAGNOSE_CALIBRATION=FILE``).

``PATH:KIND`` takes only the records of one kind of a run (``turn``, ``zigzag``): a run made with
another diagnosis of the other kind (e.g. the rudder's inflow also freed on zigzags) still calibrates
this one.  ``--kinds`` writes only those kinds' floors
(:func:`trials.measured.calibration.merge_kinds`), the others kept from the packaged file: where
the diagnosis of one kind of record changes, its runs recalibrate that kind alone; ``--effects``
with it writes only those effects' floors of those kinds (``--kinds zigzag --effects current_along
current_across``: the floors of a current's parts on zigzags, in their units, the rest kept).
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

from trials.measured.calibration import calibrate, merge_kinds, only_kind, short_of_name
from trials.measured.diagnose.decision import speed_part_units


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bench_json", nargs="+", help="the calibration runs' JSON (clean, and with effects); "
                    "PATH:KIND takes only that run's records of one kind (turn, zigzag)")
    ap.add_argument("--alpha", type=float, default=0.05)
    ap.add_argument("--write", action="store_true", help=f"write {OUT.relative_to(REPO)}")
    ap.add_argument("--kinds", nargs="+", default=None, metavar="KIND",
                    help="write only these kinds' floors (turn, zigzag, turn_pair); the others kept from the packaged file")
    ap.add_argument("--effects", nargs="+", default=None, metavar="EFFECT",
                    help="with --kinds: write only these effects' floors, clean samples and units (e.g. current_along "
                         "current_across); every other figure kept from the packaged file")
    ap.add_argument("--along-unit", choices=("sqrt(gL)", "U"), default="sqrt(gL)",
                    help="the unit of a current's part along the heading on zigzags: sqrt(gL) (default, as packaged) "
                         "or U (a fraction of the records' median speed over ground)")
    ap.add_argument("--ship", default="esso_osaka", help="the config the runs diagnosed (default esso_osaka)")
    ap.add_argument("--out", type=Path, default=OUT, help="the file --write writes (default the packaged one)")
    a = ap.parse_args(argv)
    if a.effects and not a.kinds:
        ap.error("--effects: writes those effects' floors of the --kinds given; give --kinds with it")
    import yaml

    import mmg

    records = []
    for p in a.bench_json:
        p, _, kind = p.partition(":")
        data = json.loads(Path(p).read_text())
        recs = data["records"] if isinstance(data, dict) else data
        records += [r for r in recs if not kind or only_kind(r, kind) is not None]
    L = mmg.load_ship(mmg.ship_path(a.ship)).particulars.L
    ships = {r.get("ship", "esso_osaka") for r in records}
    if ships != {a.ship}:
        ap.error(f"--ship {a.ship}: the runs diagnosed {sorted(ships)}")
    cal = calibrate(records, L, a.alpha, speed_part_units() if a.along_unit == "U" else None)
    print("not named at the size to detect (floor above it):", {k: sorted(v) for k, v in cal.hidden.items()})
    for row in cal.to_pandas().itertuples():
        v = np.asarray(cal.clean[row.effect][row.kind])
        print(f"{row.effect:14s} {row.kind:7s} n {row.samples:3d}  passing dBIC,z {row.passing:3d}  max {row.max_passing:.4g}  "
              f"rms of passing {np.sqrt(np.mean(v[v > 0] ** 2)) if np.any(v > 0) else 0.0:.4g}  floor {row.floor:.4g} "
              f"{row.unit}")
    doc = {"source": f"python bench/calibrate_diagnose.py {' '.join(Path(p).name for p in a.bench_json)} --alpha {a.alpha} "
                     f"({cal.n_clean} clean records and {cal.n_effects} with effects of the mismatch family, seeds of "
                     f"those bench runs; {datetime.date.today().isoformat()})", **cal.to_json()}
    print("residual floors (u, v / U, r L / U, heading deg):", cal.residual_floors)
    k, n = short_of_name(records, L)
    print(f"clean records with a candidate short of a name (reported not_identifiable; packaged floors): {k} of {n}")
    if a.kinds:
        old = yaml.safe_load(a.out.read_text()) if a.out.exists() else {}
        what = ", ".join(a.kinds) + (f" ({', '.join(a.effects)})" if a.effects else "")
        source = f"{old.get('source', '')}; then for {what} only: {doc['source']}".lstrip("; ")
        doc = {"source": source, **{k: v for k, v in merge_kinds(old, doc, a.kinds, a.effects).items() if k != "source"}}
    if a.write:
        kept = (yaml.safe_load(a.out.read_text()) or {}) if a.out.exists() else {}
        if "model_form" in kept:             # chosen on principle, not calibrated here: carried over as it is
            doc["model_form"] = kept["model_form"]
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_text("# Written by bench/calibrate_diagnose.py: the naming floors of mmg diagnose "
                         "(trials/measured/diagnose/decision.py).\n" + yaml.safe_dump(doc, sort_keys=False))
        print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
