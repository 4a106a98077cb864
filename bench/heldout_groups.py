"""Held-out heading RMS on whole groups of the shared random and berthing runs, in two fixed folds.

A stand-in for runs the model has never seen: each fold holds out about half of the random runs
(cuts of one run together) and about half of the berthing runs, identifies the model with
:func:`trials.measured.identify.identify` on every other shared record (all turning and zigzag
records, the other random and berthing runs), and replays the held-out records open-loop with the
identified model and with the Froude-scaled prior (``--ship``, default ``esso_osaka_3m``).  Printed:
per held-out record the heading RMS [deg] of both, per kind the means and their ratio (scaled over
identified: above 1 the identification helps), and the same over all held-out records.

Folds (:data:`FOLDS`; fixed before any result was seen):

* A: random 06-Aug-2020_16_24_25 _1/_4/_5/_6 (consecutive pieces of one run), random
  31-Jul-2020_14_52_18; berthing 11_07_23, 13_09_11.
* B: random 03-Aug-2020_11_04_37, 31-Jul-2020_12_29_58, 31-Jul-2020_12_48_39; berthing 11_14_47,
  11_21_46, 13_37_05.

Usage::

    python bench/heldout_groups.py --data ../shared/data/frt-ds-esso [--free ...] [--initial-state ...]
        [--weighting ...] [--velocity-weight W] [--max-nfev N] [--json OUT]
    python bench/heldout_groups.py --data ../shared/data/frt-ds-esso --from RUNDIR

``--from RUNDIR`` builds the table from earlier ``mmg predict --json`` files
``RUNDIR/<fold>/pred_scaled.json`` and ``RUNDIR/<fold>/pred_identified.json`` (no fit), so the
figures of command-line runs, of any version of the code, are tabulated the same way.  One fold's
fit takes about 4-6 minutes on two cores.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

__all__ = ["FOLDS", "KINDS", "HeldoutTable", "heldout_table", "rows_from_predict", "fold_paths", "run_fold"]

FOLDS = {
    "A": ("random/random_06-Aug-2020_16_24_25_1.csv", "random/random_06-Aug-2020_16_24_25_4.csv",
          "random/random_06-Aug-2020_16_24_25_5.csv", "random/random_06-Aug-2020_16_24_25_6.csv",
          "random/random_31-Jul-2020_14_52_18.csv",
          "berthing/berthing_12-Nov-2020_11_07_23.csv", "berthing/berthing_12-Nov-2020_13_09_11.csv"),
    "B": ("random/random_03-Aug-2020_11_04_37.csv", "random/random_31-Jul-2020_12_29_58.csv",
          "random/random_31-Jul-2020_12_48_39.csv",
          "berthing/berthing_12-Nov-2020_11_14_47.csv", "berthing/berthing_12-Nov-2020_11_21_46.csv",
          "berthing/berthing_12-Nov-2020_13_37_05.csv"),
}
"""Held-out records of each fold, relative to the FRT-DS-ESSO folder; each trains on all other records."""

KINDS = ("turning", "zigzag", "random", "berthing")
"""Record kinds: the FRT-DS-ESSO sub-folder a record lies in."""


@dataclass(frozen=True)
class HeldoutTable:
    """Held-out heading RMS per record and per kind.

    Attributes
    ----------
    rows : tuple of dict
        One per held-out record: ``fold``, ``record``, ``kind``, ``scaled_deg``, ``identified_deg``
        (heading RMS [deg] of the scaled and the identified model; NaN where the replay diverged).
    kinds : dict
        Per kind present: ``n`` records, ``n_diverged`` (either model NaN; left out of the means),
        ``scaled_deg`` and ``identified_deg`` (means [deg]), ``ratio`` (scaled over identified),
        ``n_better`` (records the identified model predicts with the lower heading RMS) and the medians
        ``scaled_median_deg``, ``identified_median_deg`` [deg] (one spinning replay can carry a mean).
    overall : dict
        The same over all held-out records, plus ``kind_mean_ratio``: the mean over kinds of the
        scaled means over the mean over kinds of the identified means (every kind alike).
    """

    rows: tuple
    kinds: dict
    overall: dict

    def to_json(self) -> dict:
        """``{"rows": [...], "kinds": {...}, "overall": {...}}``, NaN as None."""
        clean = (lambda v: None if isinstance(v, float) and not math.isfinite(v) else v)  # noqa: E731
        return {"rows": [{k: clean(v) for k, v in r.items()} for r in self.rows],
                "kinds": {k: {a: clean(b) for a, b in d.items()} for k, d in self.kinds.items()},
                "overall": {k: clean(v) for k, v in self.overall.items()}}

    def to_pandas(self):
        """One row per held-out record (columns fold, record, kind, scaled_deg, identified_deg)."""
        import pandas as pd

        return pd.DataFrame(list(self.rows))

    def to_markdown(self) -> str:
        """The per-record table, then the per-kind and overall means, as Markdown."""
        f = (lambda v: "nan" if not math.isfinite(v) else f"{v:.1f}")  # noqa: E731
        g = (lambda v: "nan" if not math.isfinite(v) else f"{v:.2f}x")  # noqa: E731
        out = ["| fold | record | kind | scaled heading RMS [deg] | identified heading RMS [deg] |",
               "|---|---|---|---|---|"]
        out += [f"| {r['fold']} | {r['record']} | {r['kind']} | {f(r['scaled_deg'])} | {f(r['identified_deg'])} |"
                for r in self.rows]
        out += ["", "| kind | records | diverged | scaled mean [deg] | identified mean [deg] | ratio of means "
                "| identified better | scaled median [deg] | identified median [deg] |", "|---|---|---|---|---|---|---|---|---|"]
        for k, d in list(self.kinds.items()) + [("all", self.overall)]:
            out.append(f"| {k} | {d['n']} | {d['n_diverged']} | {f(d['scaled_deg'])} | {f(d['identified_deg'])} "
                       f"| {g(d['ratio'])} | {d['n_better']} | {f(d['scaled_median_deg'])} "
                       f"| {f(d['identified_median_deg'])} |")
        out.append(f"\nmean over kinds: ratio {g(self.overall['kind_mean_ratio'])}")
        return "\n".join(out)


def _means(rows) -> dict:
    ok = [r for r in rows if math.isfinite(r["scaled_deg"]) and math.isfinite(r["identified_deg"])]
    s = sum(r["scaled_deg"] for r in ok) / len(ok) if ok else math.nan
    i = sum(r["identified_deg"] for r in ok) / len(ok) if ok else math.nan
    return {"n": len(rows), "n_diverged": len(rows) - len(ok), "scaled_deg": s, "identified_deg": i,
            "ratio": s / i if ok and i > 0 else math.nan,
            "n_better": sum(r["identified_deg"] < r["scaled_deg"] for r in ok),
            "scaled_median_deg": _median([r["scaled_deg"] for r in ok]),
            "identified_median_deg": _median([r["identified_deg"] for r in ok])}


def _median(xs) -> float:
    xs = sorted(xs)
    n = len(xs)
    return math.nan if n == 0 else (xs[n // 2] if n % 2 else 0.5 * (xs[n // 2 - 1] + xs[n // 2]))


def heldout_table(rows) -> HeldoutTable:
    """The per-kind and overall means of held-out heading RMS rows (see :class:`HeldoutTable`).

    Parameters
    ----------
    rows : iterable of dict
        ``fold``, ``record``, ``kind``, ``scaled_deg``, ``identified_deg`` each.

    Returns
    -------
    HeldoutTable
        Kinds in the order of :data:`KINDS` (others after, alphabetically); a diverged replay (NaN)
        counted but left out of the means.
    """
    rows = tuple(dict(r, scaled_deg=float(r["scaled_deg"]), identified_deg=float(r["identified_deg"]))
                 for r in rows)
    present = {r["kind"] for r in rows}
    order = [k for k in KINDS if k in present] + sorted(present - set(KINDS))
    kinds = {k: _means([r for r in rows if r["kind"] == k]) for k in order}
    overall = _means(rows)
    km = [d for d in kinds.values() if math.isfinite(d["ratio"])]
    overall["kind_mean_ratio"] = (sum(d["scaled_deg"] for d in km) / sum(d["identified_deg"] for d in km)
                                  if km else math.nan)
    return HeldoutTable(rows=rows, kinds=kinds, overall=overall)


def _kind_of(path) -> str:
    return Path(str(path)).parent.name


def _heading(run: dict) -> float:
    v = run.get("heading_rms_deg")
    return math.nan if v is None else float(v)


def rows_from_predict(fold: str, scaled: dict, identified: dict) -> list[dict]:
    """Rows of :func:`heldout_table` from two ``mmg predict --json`` documents of the same records
    (``scaled``: the prior ship's, ``identified``: the identified ship's), matched by file."""
    ident = {Path(r["file"]).name: r for r in identified["runs"]}
    rows = []
    for r in scaled["runs"]:
        name = Path(r["file"]).name
        if name not in ident:
            raise ValueError(f"{name}: in the scaled model's predictions but not the identified one's")
        rows.append({"fold": fold, "record": Path(name).stem, "kind": _kind_of(r["file"]),
                     "scaled_deg": _heading(r), "identified_deg": _heading(ident[name])})
    return rows


def fold_paths(data: Path, fold: str) -> tuple[list[Path], list[Path]]:
    """(training records, held-out records) of ``fold``: every CSV under ``data``'s kind folders not
    held out trains."""
    held = [data / p for p in FOLDS[fold]]
    missing = [str(p) for p in held if not p.is_file()]
    if missing:
        raise FileNotFoundError(f"{missing[0]}: held-out record of fold {fold} not found")
    train = sorted(p for k in KINDS for p in (data / k).glob("*.csv") if p not in held)
    return train, held


def run_fold(data: Path, fold: str, ship_name: str = "esso_osaka_3m", free=None, **options) -> list[dict]:
    """Identify on ``fold``'s training records (``free``, ``options``: :func:`trials.measured.identify.identify`'s;
    defaults when omitted) and replay its held-out ones with the identified and the scaled ship."""
    from mmg.ship import load_ship
    from trials.measured.identify import DEFAULT_FREE, identify
    from trials.measured.predict import predict

    ship = load_ship(ship_name)
    train, held = fold_paths(data, fold)
    ident = identify(ship, [str(p) for p in train], free=tuple(free) if free else DEFAULT_FREE, **options)
    doc = lambda s: predict(s, [str(p) for p in held]).to_json()  # noqa: E731
    return rows_from_predict(fold, doc(ship), doc(ident.ship))


def _options(a) -> dict:
    o = {}
    if a.initial_state:
        o["initial_state"] = a.initial_state
    if a.weighting:
        o["record_weighting"] = a.weighting
    if a.velocity_weight is not None:
        o["velocity_weight"] = a.velocity_weight
    if a.max_nfev is not None:
        o["max_nfev"] = a.max_nfev
    return o


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--data", type=Path, required=True, help="the FRT-DS-ESSO folder")
    p.add_argument("--folds", nargs="+", default=list(FOLDS), choices=list(FOLDS))
    p.add_argument("--ship", default="esso_osaka_3m", help="prior ship (bundled name or YAML)")
    p.add_argument("--free", nargs="+", help="identify's free set (default its DEFAULT_FREE)")
    p.add_argument("--initial-state", choices=("fit", "sample"))
    p.add_argument("--weighting", choices=("samples", "equal", "relative"))
    p.add_argument("--velocity-weight", type=float)
    p.add_argument("--max-nfev", type=int)
    p.add_argument("--from", dest="from_dir", type=Path,
                   help="tabulate RUNDIR/<fold>/pred_scaled.json and pred_identified.json instead of fitting")
    p.add_argument("--json", type=Path, help="also write the table as JSON")
    a = p.parse_args(argv)
    if not a.data.is_dir():
        print(f"{a.data}: not a folder (the FRT-DS-ESSO data)", file=sys.stderr)
        return 2
    rows = []
    for fold in a.folds:
        if a.from_dir is not None:
            rd = lambda n: json.loads((a.from_dir / fold / n).read_text())  # noqa: E731
            rows += rows_from_predict(fold, rd("pred_scaled.json"), rd("pred_identified.json"))
        else:
            rows += run_fold(a.data, fold, a.ship, a.free, **_options(a))
    table = heldout_table(rows)
    print(table.to_markdown())
    if a.json:
        a.json.write_text(json.dumps(table.to_json(), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
