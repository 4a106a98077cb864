"""Whole-record against short-horizon prediction, by kind of record, from one ``mmg predict --json`` file.

Per kind of FRT-DS-ESSO record (the shared folders: turns, zigzags, random runs, berthing runs;
``bench/frt_gap.py``'s grouping by the record's name): the number of records and of 60 s windows, the
mean over the records of the whole-record heading RMS [deg] and of each record's mean over its windows
restarted from the measured state (``window``: heading RMS [deg], final position error [m] and [L]);
records whose whole replay diverged (null) are left out of the whole-record mean and counted.

    mmg predict --ship esso_osaka_3m ../shared/data/frt-ds-esso/*/*.csv --window 60 --every 30 --json w.json
    python bench/window_kinds.py w.json
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from frt_gap import KINDS, kind_of  # noqa: E402  (the record kinds, defined once)


def _mean(values) -> float | None:
    v = [x for x in values if x is not None and np.isfinite(x)]
    return float(np.mean(v)) if v else None


def kind_rows(doc: dict) -> list[dict]:
    """Per kind of record in ``doc`` (``mmg predict``'s JSON, each run with its ``window``): ``kind``, ``n``
    (records), ``windows`` (their number), ``heading_rms_deg`` (mean whole-record heading RMS over the
    records that stayed finite, ``n_whole`` of them), ``window_heading_rms_deg``, ``window_position_error_m``,
    ``window_position_error_L`` (means over the records of each record's window means); None where no
    record gives a finite figure."""
    out = []
    for kind in KINDS:
        runs = [r for r in doc["runs"] if kind_of(r["name"]) == kind]
        if not runs:
            continue
        whole = [r["heading_rms_deg"] for r in runs]
        out.append({"kind": kind, "n": len(runs), "windows": sum(r["window"]["n_windows"] for r in runs),
                    "heading_rms_deg": _mean(whole), "n_whole": sum(x is not None and np.isfinite(x) for x in whole),
                    **{f"window_{k}": _mean(r["window"][k] for r in runs)
                       for k in ("heading_rms_deg", "position_error_m", "position_error_L")}})
    return out


def table(rows: list[dict], window_s: float, every_s: float) -> list[str]:
    """:func:`kind_rows` as a Markdown table."""
    f = lambda v, fmt: "-" if v is None else fmt.format(v)  # noqa: E731
    out = [f"| kind | records | windows | whole record: heading RMS [deg] | {window_s:g} s windows every {every_s:g} s: "
           f"heading RMS [deg] | final position error [m] | [L] |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        whole = f(r["heading_rms_deg"], "{:.1f}") + ("" if r["n_whole"] == r["n"] else f" ({r['n_whole']} finite)")
        out.append(f"| {r['kind']} | {r['n']} | {r['windows']} | {whole} | {f(r['window_heading_rms_deg'], '{:.1f}')} | "
                   f"{f(r['window_position_error_m'], '{:.2f}')} | {f(r['window_position_error_L'], '{:.2f}')} |")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("predict_json", type=Path, help="mmg predict --json output (each run with its 'window')")
    a = ap.parse_args(argv)
    doc = json.loads(a.predict_json.read_text())
    if not doc.get("runs") or any("window" not in r for r in doc["runs"]):
        raise SystemExit(f"{a.predict_json}: runs: no 'window' scores (an mmg predict JSON with the windows)")
    w = [r["window"] for r in doc["runs"]]           # a record shorter than a window has a shorter one
    print("\n".join(table(kind_rows(doc), max(x["window_s"] for x in w), w[0]["every_s"])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
