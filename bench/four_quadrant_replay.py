"""Open-loop replays of the shared FRT-DS-ESSO random and berthing records (four quadrants).

Each record of ``random/`` and ``berthing/`` in the data folder ($MMG_FRT_DATA, else
../shared/data/frt-ds-esso beside the repository) is replayed open loop from its first sample with
its measured rudder and revolutions (:func:`trials.measured.predict.replay_record`, wind as the ship
config says) and scored: heading RMS over the whole record and over its first 60 s [deg], final
position error [m, L], the time a replay diverged (non-finite state) if it did, and the share of
samples with the propeller astern (n < 0) and the ship moving astern (u < 0).  Most records turn
the propeller astern only after 40-250 s, so a second replay starts from the measured state at the
first astern order (n < 0) and is scored over the 60 s after it ("60 s from n<0").

    python bench/four_quadrant_replay.py [--ship esso_osaka_3m] [--hull-astern end_for_end] [--json out.json]
        [--compare before.json]

``--compare`` prints the figures of an earlier run (e.g. of the code before a change) beside these.
"""
from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SHORT_S = 60.0


def _data() -> Path:
    return Path(os.environ.get("MMG_FRT_DATA") or REPO.parent / "shared" / "data" / "frt-ds-esso")


def score(rp, short_s: float = SHORT_S) -> dict:
    """Heading RMS whole / first ``short_s`` s [deg], final position error [m, L], divergence time."""
    t, m, p = rp.run.t, rp.run.meas, rp.pred
    out = {"n_astern": float(np.mean(rp.run.inputs.n < 0)), "u_astern": float(np.mean(m[:, 0] < 0)),
           "diverged_at": rp.diverged_at, "duration_s": float(t[-1] - t[0])}
    if rp.diverged_at is not None:
        return {**out, "heading_rms_deg": math.nan, "heading_rms_60_deg": math.nan, "speed_rms_mps": math.nan,
                "final_error_m": math.nan, "final_error_L": math.nan}
    dpsi = np.degrees(p[:, 5] - m[:, 5])
    first = t - t[0] <= short_s
    e = float(np.hypot(p[-1, 3] - m[-1, 3], p[-1, 4] - m[-1, 4]))
    return {**out, "heading_rms_deg": float(np.sqrt(np.mean(dpsi ** 2))),
            "heading_rms_60_deg": float(np.sqrt(np.mean(dpsi[first] ** 2))),
            "speed_rms_mps": rp.scores()["speed_rms_mps"],
            "final_error_m": e, "final_error_L": e / rp.L}


def _fmt(x, spec=".1f") -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def main(argv=None) -> int:
    import argparse

    if not os.environ.get("PYTHONPATH"):
        sys.path.insert(0, str(REPO))
    from mmg.ship import load_ship
    from trials.files.logio import read_record
    from trials.measured.predict import replay_record

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ship", default="esso_osaka_3m")
    ap.add_argument("--json", help="write the figures to this file")
    ap.add_argument("--compare", help="figures of an earlier run (--json) printed beside these")
    ap.add_argument("--hull-astern", choices=("as_ahead", "end_for_end"),
                    help="how the hull acts astern, over the config's hull.astern (mmg.model.astern_factor)")
    a = ap.parse_args(argv)
    ship = load_ship(a.ship)
    if a.hull_astern:
        ship = ship.with_hull_astern(a.hull_astern)
    files = sorted(_data().glob("random/*.csv")) + sorted(_data().glob("berthing/*.csv"))
    if not files:
        print(f"no records in {_data()}")
        return 1
    before = json.loads(Path(a.compare).read_text()) if a.compare else {}
    rows = {}
    hdr = ("| record | n<0 | u<0 | heading RMS [deg] | first 60 s [deg] | 60 s from n<0 [deg] | speed RMS [m/s] | "
           "final error [m] | final error [L] | diverged at [s] |")
    print(hdr)
    print("|---|---|---|---|---|---|---|---|---|---|")
    for f in files:
        rec = read_record(f, length_m=ship.particulars.L)
        s = score(replay_record(ship, rec))
        t0 = float(rec.t[np.argmax(rec.n < 0)]) if (rec.n < 0).any() else None
        s["heading_rms_60_astern_deg"] = math.nan if t0 is None else score(replay_record(ship, rec, start=t0))[
            "heading_rms_60_deg"]
        rows[f.name] = s
        b = before.get(f.name)
        pair = lambda k, spec=".1f": (_fmt(b.get(k), spec) + " → " if b else "") + _fmt(s[k], spec)  # noqa: E731
        print(f"| {f.parent.name}/{f.stem} | {s['n_astern']:.0%} | {s['u_astern']:.0%} | {pair('heading_rms_deg')} | "
              f"{pair('heading_rms_60_deg')} | {pair('heading_rms_60_astern_deg')} | "
              f"{pair('speed_rms_mps', '.3f')} | {pair('final_error_m', '.2f')} | {pair('final_error_L', '.2f')} | "
              f"{(_fmt(b['diverged_at']) + ' → ' if b else '') + _fmt(s['diverged_at'])} |", flush=True)
    ok = [s for s in rows.values() if s["diverged_at"] is None]
    if ok:
        print(f"mean speed RMS {np.mean([s['speed_rms_mps'] for s in ok]):.3f} m/s; "
              f"mean heading RMS {np.mean([s['heading_rms_deg'] for s in ok]):.1f} deg, first 60 s "
              f"{np.mean([s['heading_rms_60_deg'] for s in ok]):.1f} deg, 60 s from the first n < 0 "
              f"{np.nanmean([s['heading_rms_60_astern_deg'] for s in ok]):.1f} deg over {len(ok)} of {len(rows)} "
              f"replays that did not diverge")
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
