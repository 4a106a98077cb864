"""How far apart are the fits of a cross-validation's folds? (the generalisation gap)

Each outer fold of ``bench/identify_cv.py`` fits the model on about three quarters of the records; its JSON
(``--json``) keeps each fold's fitted values.  Were the identified parameters set by the physics the
records share, the fold fits would lie close together: their spread would match the statistical
uncertainty the fit states.  Where they differ by more, what a fit learns depends on which records it was
given, and an unseen record is predicted by a model that would have come out otherwise had it been
among them: the gap between the in-sample and the held-out figures.

Per parameter this prints the prior (the config value the fit starts from, and its prior std,
:func:`ekf.identify.free_parameters`), each fold's fitted value, whether the folds disagree in sign, the
folds' spread (max - min) in prior stds, and the delete-a-group jackknife standard error of a fit on all
the records, sqrt((K - 1) / K * sum_i (theta_i - mean theta)^2) over the K folds (each fold leaves one
group of records out: a standard error that counts the record-to-record variation).  With ``--ship
DIR/ship.yaml`` (``mmg identify`` on all the records, which writes the fit's covariance) it also prints
that covariance's standard error and the jackknife's ratio to it.

The computation is :mod:`trials.measured.foldspread`'s (``mmg identify --cv`` reports the same check).
``--refit K --max-nfev N`` fits fold K's training records (every record the JSON does not put in fold K)
again with N evaluations a stage instead of the run's, and prints each value beside the run's and its shift
in jackknife standard errors: whether the folds' spread is where each fit stopped rather than what the
records say (the fits of ``bench/identify_cv.py`` stop at ``mmg identify``'s default 30).

The jackknife needs every fold to have fitted the same candidate (a fixed hull form: ``--hull kijima``);
folds of different forms are printed without it.

    python bench/fold_values.py NESTED.json [--ship DIR/ship.yaml] [--prior 0.5] [--refit K --max-nfev 90]
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

SHIP = "esso_osaka_3m"


def priors(form: str, names, width: float) -> dict:
    """{name: (prior value, prior std)} of the fit's free parameters for hull form ``form``."""
    from ekf.identify import free_parameters
    from mmg.model import pack
    from trials.measured.nested import hull_candidates

    ship = hull_candidates(SHIP, (form,))[form].ship
    return {p.name: (p.prior, p.sigma) for p in free_parameters(pack(ship), ship.hull.names, list(names), width,
                                                                     hull_terms=ship.hull.terms)}


def table(nested: dict, width: float = 0.5, covariance=None) -> tuple[list[str], dict]:
    """The printed rows and a summary dict (module docstring)."""
    from trials.measured.foldspread import fold_spread

    sp = fold_spread(nested["records"], None if covariance is None else dict(zip(covariance.names, covariance.std())))
    choices, values, names = sp.choices, sp.values, sp.names
    forms = {c.split(",")[0] for c in choices}
    pri = priors(next(iter(forms)), names, width) if len(forms) == 1 else {}
    head = ("| parameter | prior | prior std | " + " | ".join(f"fold {k}" for k in range(len(values)))
            + " | signs differ | spread / prior std | jackknife SE | fit's SE | ratio |")
    rows = [f"folds' choices: {', '.join(choices)}", head, "|" + "---|" * (head.count("|") - 1)]
    summ = {"n": len(names), "sign": 0, "spread_over_2": 0, "ratios": {}}
    for j, n in enumerate(names):
        th = values[:, j]
        p, s = pri.get(n, (np.nan, np.nan))
        signs = bool(sp.sign_differs[j])
        spread = (th.max() - th.min()) / s if s > 0 else np.nan
        jk, se, ratio = sp.jackknife[j], sp.stated[j], sp.ratio[j]
        summ["sign"] += signs
        summ["spread_over_2"] += bool(spread > 2.0)
        if np.isfinite(ratio):
            summ["ratios"][n] = ratio
        rows.append(f"| {n} | {p:+.4g} | {s:.3g} | " + " | ".join(f"{x:+.4g}" for x in th)
                    + f" | {'yes' if signs else ''} | {spread:.1f} | {jk:.3g} | {se:.3g} | {ratio:.1f} |")
    return rows, summ


def refit(nested: dict, fold: int, max_nfev: int) -> list[str]:
    """Fit fold ``fold``'s training records again with ``max_nfev`` evaluations a stage (module docstring)."""
    import mmg
    from trials.measured.foldspread import fold_spread
    from trials.measured.identify import identify, load_runs
    from trials.measured.nested import hull_candidates
    from trials.files.data import frt_folder

    recs = nested["records"]
    choice = next(r["choice"] for r in recs if r["fold"] == fold)
    form = choice.split(",")[0]
    if "," in choice:
        raise SystemExit(f"--refit: fold {fold} chose {choice!r}; only a plain hull form is refitted")
    kept = {r["name"] for r in recs if r["fold"] == fold}
    if frt_folder() is None:
        raise SystemExit("--refit: FRT-DS-ESSO data not found (set MMG_FRT_DATA)")
    paths = [p for p in sorted(Path(frt_folder()).glob("*/*.csv")) if p.stem in {r["name"] for r in recs}]
    ship = hull_candidates(SHIP, (form,))[form].ship
    runs = load_runs(ship, [p for p in paths if p.stem not in kept], say=lambda *_: None)
    ident = identify(ship, runs, initial=mmg.load_ship(SHIP), max_nfev=max_nfev,
                     progress=lambda i, c, st: print(f"  {st}, iteration {i}: cost {c:.5g}", file=sys.stderr))
    new = ident.fit.values()
    sp = fold_spread(recs)
    old = sp.values[sorted({r["fold"] for r in recs}).index(fold)]
    rows = [f"fold {fold} ({form}, {len(runs)} training records) refitted at {max_nfev} evaluations a stage: "
            + ", ".join(f"{st['evaluations']} evaluations, status {st['status']}" for st in ident.stages),
            "| parameter | run's value | refitted | shift / jackknife SE |", "|---|---|---|---|"]
    shifts = []
    for j, n in enumerate(sp.names):
        v = new.get(n, np.nan)                   # nan: the refit left it out (no record to fit it on)
        d = (v - old[j]) / sp.jackknife[j] if sp.jackknife[j] > 0 else np.nan
        shifts.append(abs(d))
        rows.append(f"| {n} | {old[j]:+.4g} | {v:+.4g} | {d:+.2f} |")
    rows.append(f"shift / jackknife SE: median {np.nanmedian(shifts):.2f}, largest {np.nanmax(shifts):.2f}")
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json", type=Path, help="bench/identify_cv.py --json output")
    ap.add_argument("--ship", default=None, help="a ship YAML with a covariance section (mmg identify on all records)")
    ap.add_argument("--prior", type=float, default=0.5, help="the fits' prior width (relative std; default 0.5)")
    ap.add_argument("--refit", type=int, default=None, metavar="K", help="fit fold K's training records again")
    ap.add_argument("--max-nfev", type=int, default=90, help="with --refit: evaluations a stage (default 90)")
    a = ap.parse_args(argv)
    if a.refit is not None:
        print("\n".join(refit(json.loads(a.json.read_text()), a.refit, a.max_nfev)))
        return 0
    cov = None
    if a.ship:
        from mmg.ship import load_ship

        cov = load_ship(a.ship).covariance
    rows, s = table(json.loads(a.json.read_text()), a.prior, cov)
    print("\n".join(rows))
    line = (f"{s['n']} parameters: the folds disagree in sign on {s['sign']}; spread over 2 prior stds on "
            f"{s['spread_over_2']}")
    if s["ratios"]:
        r = np.array(list(s["ratios"].values()))
        line += (f"; jackknife SE / the fit's SE: median {np.median(r):.1f}, above 3 on {int(np.sum(r > 3))} of "
                 f"{len(r)}")
    print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
