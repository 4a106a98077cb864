"""Which records keep the held-out figure from 3x? (the gap, class by class)

The target is a mean heading RMS over the kept-out records at least 3 times lower than the
Froude-scaled model's.  The mean is over records of four kinds (the shared folders: turns, zigzags, random
runs, berthing runs) whose open-loop heading errors differ by an order of magnitude, so a few kinds may
decide it.  From a nested cross-validation's JSON (``bench/identify_cv.py --json``) this prints, per kind,
the mean heading RMS of the scaled and the identified model and the kind's share of the identified
model's sum; each fold's mean and choice; then the mean the random runs would need for 3x with the other
kinds as they are.

With ``--in-sample CEILING.json`` (``bench/identify_ceiling.py --json``: the model fitted on every record,
replayed on its own training records from their first samples) it also prints what the held-out mean
would be were one kind predicted as well as the in-sample fit predicts it (that kind's held-out figures
replaced by the in-sample ones, record by record), and with every kind so: how much of the gap between
the in-sample and the held-out figure each kind carries.  The in-sample figures are a bound no
prediction of an unseen record reaches, not a target.

    python bench/frt_gap.py NESTED.json [--in-sample CEILING.json] [--form kijima]
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

KINDS = ("turn", "zigzag", "random", "berthing")
"""The record kinds, by the record name's first word (the shared folders turning/, zigzag/, random/, berthing/)."""
TARGET = 3.0


def kind_of(name: str) -> str:
    """The kind of a record by its name's first word (``turn_cut_...`` is a turn)."""
    return name.split("_")[0]


def fold_means(nested: dict) -> dict:
    """{fold: (its choice, the identified model's mean whole-record heading RMS [deg] over its kept-out records)}."""
    out = {}
    for f in sorted({r["fold"] for r in nested["records"]}):
        rs = [r for r in nested["records"] if r["fold"] == f]
        out[f] = (rs[0].get("choice", ""), float(np.mean([r["identified"]["heading_rms_deg"] for r in rs])))
    return out


def held_out(nested: dict) -> dict:
    """{record: (scaled, identified)} whole-record heading RMS [deg] of a nested cross-validation's JSON."""
    return {r["name"]: (r["scaled"]["heading_rms_deg"], r["identified"]["heading_rms_deg"]) for r in nested["records"]}


def in_sample(ceiling: list, form: str | None = None) -> dict:
    """{record: identified whole-record heading RMS [deg]} of ``bench/identify_ceiling.py``'s JSON (the first
    fit, or the one of hull form ``form``)."""
    fits = [f for f in ceiling if form is None or f["form"] == form]
    if not fits:
        raise SystemExit(f"no fit of form {form!r} in the in-sample JSON")
    return {n: v["identified"][0] for n, v in fits[0]["records"].items()}


def kind_table(rows: dict) -> list[dict]:
    """Per kind: the number of records, the mean scaled and identified heading RMS and the kind's share of
    the identified sum."""
    total = sum(i for _, i in rows.values())
    out = []
    for k in KINDS:
        v = [x for n, x in rows.items() if kind_of(n) == k]
        if v:
            s, i = np.array(v).T
            out.append({"kind": k, "n": len(v), "scaled": float(s.mean()), "identified": float(i.mean()),
                        "share": float(i.sum() / total)})
    return out


def needed_mean(rows: dict, kind: str, target: float = TARGET) -> float:
    """The mean heading RMS ``kind``'s records would need for the whole mean to be ``target`` times lower
    than the scaled model's, the other records' identified figures as they are."""
    s = np.array([x[0] for x in rows.values()])
    mine = [n for n in rows if kind_of(n) == kind]
    others = sum(rows[n][1] for n in rows if kind_of(n) != kind)
    return float((s.mean() / target * len(rows) - others) / len(mine))


def ratio_with(rows: dict, replaced: dict, kinds) -> float:
    """Scaled over identified mean heading RMS with the records of ``kinds`` given ``replaced``'s figures."""
    s = np.mean([x[0] for x in rows.values()])
    i = np.mean([replaced[n] if kind_of(n) in kinds else x[1] for n, x in rows.items()])
    return float(s / i)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("nested", type=Path)
    ap.add_argument("--in-sample", type=Path, default=None)
    ap.add_argument("--form", default=None, help="which fit of the in-sample JSON (default: its first)")
    a = ap.parse_args(argv)
    nested = json.loads(a.nested.read_text())
    rows = held_out(nested)
    s = np.mean([x[0] for x in rows.values()])
    i = np.mean([x[1] for x in rows.values()])
    print(f"{a.nested.name}: {len(rows)} kept-out records, mean heading RMS scaled {s:.2f} / identified {i:.2f} deg "
          f"({s / i:.2f}x)")
    print("| kind | records | scaled [deg] | identified [deg] | share of the identified sum |\n|---|---|---|---|---|")
    for r in kind_table(rows):
        print(f"| {r['kind']} | {r['n']} | {r['scaled']:.1f} | {r['identified']:.1f} | {r['share']:.0%} |")
    print("per fold, the identified model's mean over its kept-out records: " + "; ".join(
        f"fold {f} ({c}) {m:.2f} deg" for f, (c, m) in fold_means(nested).items()))
    print(f"for {TARGET:g}x with the other kinds as they are, the random runs would need a mean of "
          f"{needed_mean(rows, 'random'):.1f} deg")
    if a.in_sample:
        ins = in_sample(json.loads(a.in_sample.read_text()), a.form)
        missing = sorted(set(rows) - set(ins))
        if missing:
            raise SystemExit(f"{a.in_sample}: no in-sample figure for {', '.join(missing)}")
        print(f"in sample ({a.in_sample.name}): {s / np.mean([ins[n] for n in rows]):.2f}x; held out with one kind "
              f"at its in-sample figures:")
        for k in KINDS:
            print(f"  {k}: {ratio_with(rows, ins, (k,)):.2f}x")
        print(f"  all but random: {ratio_with(rows, ins, tuple(k for k in KINDS if k != 'random')):.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
