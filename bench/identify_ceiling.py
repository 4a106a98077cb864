"""How well can ``mmg identify`` fit the records it is fitted to? (the in-sample ceiling)

A held-out figure of a procedure cannot be expected above what the same procedure reaches on its own
training records.  This fits ``esso_osaka_3m`` in each hull form asked (``--hull``: the Kijima config,
the cross-flow config, both by default) on every shared FRT-DS-ESSO record of ``--records`` with
``mmg identify``'s defaults (:func:`trials.measured.identify.identify`) and scores every training record
three ways, heading RMS [deg] over the whole record and over its first ``--horizon`` s:

* ``scaled``: the Froude-scaled ``esso_osaka_3m`` replayed open loop from the record's first sample (the
  model every figure of docs/benchmark_frt.md is compared with);
* ``identified``: the identified model replayed the same way (what a prediction of the record would be);
* ``fit``: the fit's own replay of the record, from its fitted start state (``--initial-state fit``, the
  default of ``mmg identify``; the first sample with ``sample``) and with the record's own
  nuisance effects (``--nuisance``, e.g. ``current``: a steady current fitted to each record alone, which no
  prediction of an unseen record can have).  With ``--nuisance`` this is a bound the model form cannot
  pass on these records even with a disturbance of its own per record.

Printed: one row per record, then per model the mean, the ratio of the scaled mean to it and on how
many records it is lower than the scaled model.  ``--json FILE`` writes the figures.

Usage: ``python bench/identify_ceiling.py [--hull kijima crossflow] [--nuisance current] [--initial-state fit|sample]
[--records turning zigzag random berthing] [--json out.json]`` (a fit of 35 records: about 5 minutes per
hull form on 2 cores; with a per-record nuisance about twice that).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

SHIP = "esso_osaka_3m"
SUBSETS = ("turning", "zigzag", "random", "berthing")


def _rms_deg(err_rad: np.ndarray, t: np.ndarray, horizon: float) -> tuple[float, float]:
    """Heading RMS [deg] over the whole record and over its first ``horizon`` s (non-finite samples: NaN)."""
    e = np.degrees(np.asarray(err_rad, float))
    if not np.all(np.isfinite(e)):
        return float("nan"), float("nan")
    first = t - t[0] <= horizon
    return float(np.sqrt(np.mean(e ** 2))), float(np.sqrt(np.mean(e[first] ** 2)))


def run(form: str, paths: list, nuisance: tuple, horizon: float, initial_state: str = "fit") -> dict:
    """Fit ``form`` on ``paths`` and score every record three ways (module docstring)."""
    import mmg
    from trials.measured.identify import identify, load_runs
    from trials.measured.nested import hull_candidates

    hull_ship = hull_candidates(SHIP, (form,))[form].ship
    scaled = mmg.load_ship(SHIP)
    runs = load_runs(hull_ship, paths, say=lambda *_: None)
    t0 = time.perf_counter()
    ident = identify(hull_ship, runs, initial=scaled, record_nuisance=nuisance, initial_state=initial_state)
    secs = time.perf_counter() - t0
    fit_err = [d[:, 3] for d in ident.fit_residuals()]
    rows = {}
    for r, e in zip(ident.runs, fit_err):
        out = {}
        for key, model in (("scaled", "initial"), ("identified", "identified")):
            rp = ident.replay(r, model)
            out[key] = _rms_deg(rp.pred[:, 5] - rp.run.meas[:, 5], rp.run.t, horizon)
        out["fit"] = _rms_deg(e, r.t, horizon)
        rows[r.name] = out
    return {"form": form, "nuisance": list(nuisance), "initial_state": initial_state, "seconds": secs, "stages": list(ident.stages),
            "records": rows}


def _summary(res: dict) -> list[str]:
    rows = res["records"]
    out = []
    for k, label in ((0, "whole record"), (1, "first horizon")):
        s = np.array([v["scaled"][k] for v in rows.values()])
        for m in ("identified", "fit"):
            x = np.array([v[m][k] for v in rows.values()])
            ok = np.isfinite(x) & np.isfinite(s)
            out.append(f"{res['form']} {label}: {m} mean {np.mean(x[ok]):.2f} deg against scaled {np.mean(s[ok]):.2f} "
                       f"(ratio {np.mean(s[ok]) / np.mean(x[ok]):.2f}x), lower on {int(np.sum(x[ok] < s[ok]))} of "
                       f"{int(ok.sum())}; {int((~ok).sum())} not finite")
    return out


def main(argv=None) -> int:
    from trials.files.data import frt_folder

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hull", nargs="+", choices=("kijima", "crossflow"), default=["kijima", "crossflow"])
    ap.add_argument("--records", nargs="+", choices=SUBSETS, default=list(SUBSETS))
    ap.add_argument("--nuisance", nargs="+", default=(), metavar="EFFECT",
                    help="effects fitted once per record (mmg.effects, e.g. current)")
    ap.add_argument("--horizon", type=float, default=60.0, help="the short window [s] (default 60)")
    ap.add_argument("--initial-state", choices=("fit", "sample"), default="fit",
                    help="each record's start state in the fit (mmg identify --initial-state; default fit)")
    ap.add_argument("--json", default=None, metavar="FILE")
    a = ap.parse_args(argv)
    data = frt_folder()
    paths = [p for sub in a.records for p in sorted((Path(data) / sub).glob("*.csv"))]
    if not paths:
        print(f"no records under {data}")
        return 1
    results = []
    for form in a.hull:
        print(f"fitting {form} on {len(paths)} records{' with per-record ' + ', '.join(a.nuisance) if a.nuisance else ''}"
              " ...", flush=True)
        res = run(form, paths, tuple(a.nuisance), a.horizon, a.initial_state)
        results.append(res)
        print(f"{form}: fitted in {res['seconds']:.0f} s; stages {[s['evaluations'] for s in res['stages']]} "
              f"evaluations")
        print(f"| record | heading [deg] scaled / identified / fit | first {a.horizon:g} s scaled / identified / fit |")
        print("|---|---|---|")
        for name, v in res["records"].items():
            c = lambda k: " / ".join(f"{v[m][k]:.1f}" for m in ("scaled", "identified", "fit"))  # noqa: E731
            print(f"| {name} | {c(0)} | {c(1)} |")
        for line in _summary(res):
            print(line)
        sys.stdout.flush()
    if a.json:
        Path(a.json).write_text(json.dumps(results, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
