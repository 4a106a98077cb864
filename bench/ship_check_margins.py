"""The record-against-ship check (:mod:`trials.files.shipcheck`) on every record class, valid and crossed.

Valid: the real FRT-DS-ESSO 3 m model records (turning, zigzag, random, berthing) with the 3 m
ships, the full-scale diagnose-dev logs (another simulator) with ``esso_osaka``, the project's
own simulated logs and truth files (``configs/trials/*.yaml``) with their ship.  Crossed: each
of them with a ship of another size.  Per class it prints the range of the statistics the check
judges (Froude number, r L / U, the propeller tip speed pi n D; the lower r L / U bound only over records whose heading changes
by more than ``TURNING_DEG``), the verdict counts and the margin to the threshold (the factor
by which the nearest record of the class stays on its side: > 1 is inside for a valid class,
outside for a crossed one; "-" where the statistic does not decide).

Run: ``python bench/ship_check_margins.py`` (about a minute; classes whose data are absent are left out).
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from mmg.errors import InputError  # noqa: E402
from mmg.ship import load_ship  # noqa: E402
from trials.files import shipcheck as sc  # noqa: E402
from trials.files.logio import read_record  # noqa: E402

SHARED = REPO.parent / "shared" / "data"


def _frt_files():
    return sorted((SHARED / "frt-ds-esso").glob("*/*.csv"))


def _dev_files():
    return sorted((SHARED / "diagnose-dev" / "data").glob("*.csv"))


def simulated(out: Path) -> dict:
    """Simulate every configs/trials/*.yaml into ``out``: {trial stem: (ship name, [log, truth])}."""
    import yaml

    from trials.files.logwrite import log_columns, truth_columns, write_table
    from trials.runs.run import run_trial
    from trials.runs.trial import load_trial

    sims = {}
    for cfg in sorted((REPO / "configs" / "trials").glob("*.yaml")):
        run = run_trial(load_trial(cfg))
        r, meta, wind = run.result, run.log_meta(), run.apparent_wind()
        log, truth = out / f"{cfg.stem}_log.csv", out / f"{cfg.stem}_truth.csv"
        write_table(log, log_columns(r.t, r.x, r.y, r.psi, run.sog, r.n, run.trial.log, wind=wind), meta)
        write_table(truth, truth_columns(r.t, r.states, r.orders, wind=wind), meta)
        sims[cfg.stem] = (yaml.safe_load(cfg.read_text())["ship"], [log, truth])
    return sims


def judge(path: Path, ship) -> tuple[dict | None, str]:
    """(statistics, verdict) of one record with one ship, read as the commands read it."""
    try:
        rec = read_record(path, length_m=ship.particulars.L)
        stats = sc.record_statistics(rec, ship.particulars.L)
    except InputError:
        stats = None                         # the reader refuses it (its unit checks)
    try:
        sc.read_for_ship(path, ship)         # as the commands read it
    except sc.ShipMismatch as e:
        return stats, f"refused: {e.field}"
    except InputError as e:
        return stats, f"refused by the reader, not as another ship's ({e.field})"
    return stats, "accepted"


def _range(vals):
    v = [x for x in vals if np.isfinite(x)]
    return f"{min(v):.3g}-{max(v):.3g}" if v else "-"


def summarise(name: str, valid: bool, rows: list, D: float) -> str:
    st = [s for s, _ in rows if s is not None]
    tip = [sc.tip_speed(s["rps"], D) for s in st]
    fn = [s["froude"] for s in st]
    tr = [s["turn_rate"] for s in st]
    tl = [s["turn_rate"] for s in st if s["heading_range_deg"] > sc.TURNING_DEG]
    verdicts: dict = {}
    for _, v in rows:
        verdicts[v] = verdicts.get(v, 0) + 1
    fin = lambda x: [a for a in x if np.isfinite(a)]  # noqa: E731
    if valid:       # how far the worst record stays inside each bound
        m = [sc.FROUDE_MAX / max(fin(fn)) if fin(fn) else np.nan,
             sc.TURN_RATE_MAX / max(fin(tr)) if fin(tr) else np.nan,
             min(fin(tl)) / sc.TURN_RATE_MIN if fin(tl) else np.nan,
             sc.TIP_SPEED_MAX / max(fin(tip)) if fin(tip) else np.nan]
    else:           # how far the nearest record stays outside the bound that refuses the class
        m = [min(fin(fn)) / sc.FROUDE_MAX if fin(fn) else np.nan,
             min(fin(tr)) / sc.TURN_RATE_MAX if fin(tr) else np.nan,
             sc.TURN_RATE_MIN / max(fin(tl)) if fin(tl) else np.nan,
             min(fin(tip)) / sc.TIP_SPEED_MAX if fin(tip) else np.nan]
    ms = " ".join(f"{x:6.3g}" if np.isfinite(x) else "     -" for x in m)
    vs = ", ".join(f"{k} {n}" for k, n in sorted(verdicts.items()))
    return f"{name:44s} {len(rows):3d} {_range(fn):>15s} {_range(tr):>15s} {_range(tl):>15s} {_range(tip):>11s}  {ms}   {vs}"


def main() -> int:
    ships = {k: load_ship(k) for k in ("esso_osaka_3m", "esso_osaka_3m_crossflow", "esso_osaka", "kvlcc2_l7")}
    classes = []
    frt, dev = _frt_files(), _dev_files()
    if frt:
        for k in ("esso_osaka_3m", "esso_osaka_3m_crossflow"):
            classes.append((f"FRT 3 m records / {k}", True, frt, k))
        classes.append(("FRT 3 m records / esso_osaka (325 m)", False, frt, "esso_osaka"))
    if dev:
        classes.append(("diagnose-dev full-scale / esso_osaka", True, dev, "esso_osaka"))
        classes.append(("diagnose-dev full-scale / esso_osaka_3m", False, dev, "esso_osaka_3m"))
        classes.append(("diagnose-dev full-scale / kvlcc2_l7", False, dev, "kvlcc2_l7"))
    with tempfile.TemporaryDirectory() as tmp:
        sims = simulated(Path(tmp))
        esso = [p for k, (s, ps) in sims.items() if s == "esso_osaka" for p in ps]
        kv = [p for k, (s, ps) in sims.items() if s == "kvlcc2_l7" for p in ps]
        classes += [("project logs+truth (Esso) / esso_osaka", True, esso, "esso_osaka"),
                    ("project logs+truth (Esso) / esso_osaka_3m", False, esso, "esso_osaka_3m"),
                    ("project KVLCC2 log+truth / kvlcc2_l7", True, kv, "kvlcc2_l7"),
                    ("project KVLCC2 log+truth / esso_osaka", False, kv, "esso_osaka"),
                    ("project KVLCC2 log+truth / esso_osaka_3m", False, kv, "esso_osaka_3m")]
        print(f"thresholds: Froude <= {sc.FROUDE_MAX:g}; r L/U (p99, moving) <= {sc.TURN_RATE_MAX:g}; "
              f">= {sc.TURN_RATE_MIN:g} when the heading changes > {sc.TURNING_DEG:g} deg; "
              f"tip speed pi n D (p99) <= {sc.TIP_SPEED_MAX:g} m/s")
        print(f"{'class (records / ship)':44s} {'n':>3s} {'Fn p99':>15s} {'rL/U p99':>15s} {'rL/U turning':>15s} {'tip m/s':>11s}  "
              f"margins: Fn, r'max, r'min, tip   verdicts")
        bad, units = 0, []
        for name, valid, files, ship in classes:
            rows = [judge(p, ships[ship]) for p in files]
            print(summarise(name, valid, rows, ships[ship].propeller.D))
            if valid:            # the same records with n in rpm or rad/s: how far outside the tip-speed bound
                tips = [sc.tip_speed(st["rps"], ships[ship].propeller.D) for st, _ in rows if st is not None]
                tips = [x for x in tips if np.isfinite(x) and x > 0]
                if tips:
                    units.append(f"{name:44s} n in rpm: margin {60 * min(tips) / sc.TIP_SPEED_MAX:6.3g}; "
                                 f"in rad/s: margin {2 * np.pi * min(tips) / sc.TIP_SPEED_MAX:6.3g}")
            ok = [v == "accepted" for _, v in rows]
            bad += sum(not o for o in ok) if valid else sum(ok)
        print("valid records with the propeller speed in another unit (margin > 1: refused by the tip speed):")
        print("\n".join(units))
    print(f"wrong verdicts: {bad}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
