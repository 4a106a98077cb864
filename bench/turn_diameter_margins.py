"""The smallest-turning-circle check (:func:`trials.analysis.metrics.check_turning_diameters`) on every turn:
the real FRT-DS-ESSO 3 m turning record with L = 3 m, the full-scale diagnose-dev turns with L = 325 m,
the project's ST35 log and truth, a KVLCC2 L7 35 deg turn simulated from its zigzag config; each with
its tactical and steady diameter [L] and the margin to :data:`MIN_TURN_DIAMETER_L` (> 1: accepted), and
the largest wrong length at which it would still be accepted (the turn's diameter in metres / 1 L).

Run: ``python bench/turn_diameter_margins.py`` (about a minute; classes whose data are absent are left out).
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from trials.analysis.metrics import MIN_TURN_DIAMETER_L, record_metrics  # noqa: E402
from trials.files.logio import read_record  # noqa: E402

SHARED = REPO.parent / "shared" / "data"


def simulated(out: Path) -> list[tuple[str, Path, float]]:
    from trials.files.logwrite import log_columns, truth_columns, write_table
    from trials.runs.run import run_trial
    from trials.runs.trial import load_trial

    kv = yaml.safe_load((REPO / "configs" / "trials" / "kvlcc2_zz20.yaml").read_text())
    kv.update(name="KVLCC2 ST35", manoeuvre={"kind": "turning", "rudder": "35 deg"}, duration="300 s")
    (out / "kv_st35.yaml").write_text(yaml.safe_dump(kv))
    rows = []
    for cfg, L in ((REPO / "configs" / "trials" / "st35.yaml", 325.0), (out / "kv_st35.yaml", 7.0)):
        run = run_trial(load_trial(cfg))
        r, meta, wind = run.result, run.log_meta(), run.apparent_wind()
        log, truth = out / f"{cfg.stem}_log.csv", out / f"{cfg.stem}_truth.csv"
        write_table(log, log_columns(r.t, r.x, r.y, r.psi, run.sog, r.n, run.trial.log, wind=wind), meta)
        write_table(truth, truth_columns(r.t, r.states, r.orders, wind=wind), meta)
        rows += [(f"project {cfg.stem} log", log, L), (f"project {cfg.stem} truth", truth, L)]
    return rows


def main() -> int:
    rows = [(f"FRT 3 m {p.stem}", p, 3.0) for p in sorted((SHARED / "frt-ds-esso" / "turning").glob("*.csv"))]
    man = SHARED / "diagnose-dev" / "manifest.json"
    if man.is_file():
        files = json.loads(man.read_text())["files"]
        rows += [(f"dev full-scale {Path(f['file']).stem}", SHARED / "diagnose-dev" / f["file"], 325.0)
                 for f in files if f["trial_definition"]["kind"] in ("turn", "turning")]
    print(f"bound: tactical and steady diameter >= {MIN_TURN_DIAMETER_L:g} L")
    print(f"{'record':34s} {'L m':>6s} {'tactical L':>10s} {'steady L':>9s} {'margin':>7s} {'accepted up to L m':>19s}")
    worst = float("inf")
    with tempfile.TemporaryDirectory() as tmp:
        rows += simulated(Path(tmp))
        for name, p, L in rows:
            m = record_metrics(read_record(p, length_m=L), kind="turning", length=L)
            ds = [d for d in (m["tactical_diameter_L"], m["steady_diameter_L"]) if d is not None]
            margin = min(ds) / MIN_TURN_DIAMETER_L
            worst = min(worst, margin)
            fmt = lambda d: f"{d:.3g}" if d is not None else "-"  # noqa: E731
            print(f"{name:34s} {L:6g} {fmt(m['tactical_diameter_L']):>10s} {fmt(m['steady_diameter_L']):>9s} "
                  f"{margin:7.3g} {min(ds) * L / MIN_TURN_DIAMETER_L:19.3g}")
    print(f"smallest margin: {worst:.3g}")
    return 0 if worst > 1 else 1


if __name__ == "__main__":
    sys.exit(main())
