"""The physical checks of ``mmg identify`` (docs/physical_checks.md) on the shared FRT-DS-ESSO
records, group by group: the energy balance of each ship unpowered at the states the group's records
log and over the box they span (``trials.measured.physical``), and its replays' divergences.

    python bench/physical_checks.py [--ships esso_osaka_3m esso_osaka_3m_crossflow DIR/ship.yaml ...]
                                    [--prior esso_osaka_3m]

A ship YAML written by ``mmg identify`` is checked against ``--prior`` (the "prior" columns)."""
from __future__ import annotations

import argparse
import glob
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
GROUPS = ("turning", "zigzag", "random", "berthing")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ships", nargs="+", default=["esso_osaka_3m", "esso_osaka_3m_crossflow"])
    ap.add_argument("--prior", default=None, help="the prior a ship YAML is checked against (default: itself)")
    a = ap.parse_args(argv)
    import mmg
    from trials.measured.identify import load_runs
    from trials.measured.physical import physical_check
    from trials.measured.predict import replay_record

    data = REPO.parent / "shared" / "data" / "frt-ds-esso"
    for name in a.ships:
        ship = mmg.load_ship(name)
        prior = mmg.load_ship(a.prior) if a.prior else ship
        for g in GROUPS:
            runs = load_runs(ship, sorted(glob.glob(str(data / g / "*.csv"))), say=lambda m: None)
            c = physical_check(ship, prior, runs, [replay_record(ship, r) for r in runs])
            print(f"{name} | {g} ({len(runs)} records) | logged: {c.logged.describe()} | box: {c.box.describe()} | "
                  f"prior logged {c.prior_logged.n_failing}/{c.prior_logged.n_states}, box "
                  f"{c.prior_box.n_failing}/{c.prior_box.n_states} | divergences {len(c.divergences)}", flush=True)
            for d in c.divergences:
                print(f"    {d.describe()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
