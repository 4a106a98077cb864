"""Trial design: which trial of a given duration tells most about the nonlinear derivatives?

Families searched (all from the trial files' 10 kn approach, 3000 s at 0.1 s, the same log):

* ``S-type psi_S`` - S-type with 35 deg rudder, switching heading psi_S swept (Rhee & Kim
  section 6.1 tried 60, 90, 120, 180 deg);
* ``zigzag a/a``   - zigzag with rudder = switching heading = a, swept;
* ``zigzag 35/a``  - zigzag with full 35 deg rudder, switching heading a swept;
* ``S-type 120, rudder`` - S-type 120 with the rudder angle swept.

Criterion (lower is better): the mean over the 8 nonlinear derivatives of the Cramer-Rao bound
on the standard deviation relative to the derivative's value, in % (A-optimality on the
relative scale), from :mod:`trials.planning.fisher` with the ``log`` noise model (the information in
the 5 s log actually recorded).  The D-criterion (geometric-mean relative std,
det^(1/16)) and the median relative std (N_bb, nearly zero, has ~100 % relative std in every
trial and dominates the mean) are reported beside it.  Both are computed twice: with the rudder known (columns
``mean_rel_crb_nonlinear_pct`` ...) and, as the log has no rudder channel, with the timing of
every rudder movement a nuisance (prior std ``rudder_timing``, 0.15 s; columns prefixed
``timing_``; :func:`trials.planning.fisher.fisher`).  A trial with many short rudder movements loses
more to the second.  Every point is one task of :func:`trials.files.sweep.run_sweep`.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from mmg.units import DEG

from .fisher import crb, criteria, fisher, tangent

CRITERION = "mean_rel_crb_nonlinear_pct"
TIMING = "timing_"          # column prefix of the criteria with the rudder timing unknown


def variant(base, family: str, value_deg: float):
    """A copy of ``base`` (any loaded trial; its approach, duration and log are kept) for one design point."""
    v = float(value_deg) * DEG
    if family == "S-type psi_S":
        m, kind, name = {"rudder": 35 * DEG, "switch_heading": v, "first": "starboard"}, "stype", f"S-type {value_deg:g}"
    elif family == "zigzag a/a":
        m, kind, name = {"rudder": v, "heading": v, "first": "starboard"}, "zigzag", f"ZZ{value_deg:g}"
    elif family == "zigzag 35/a":
        m, kind, name = {"rudder": 35 * DEG, "heading": v, "first": "starboard"}, "zigzag", f"ZZ35/{value_deg:g}"
    elif family == "S-type 120, rudder":
        m, kind, name = ({"rudder": v, "switch_heading": 120 * DEG, "first": "starboard"}, "stype",
                         f"S-type 120 rudder {value_deg:g}")
    else:
        raise ValueError(f"unknown design family {family!r}")
    return replace(base, name=name, kind=kind, manoeuvre=m)


DEFAULT_GRID = {
    "S-type psi_S": [20, 30, 45, 60, 75, 90, 105, 120, 135, 150, 180, 240, 360],
    "zigzag a/a": [5, 10, 15, 20, 25, 30, 35],
    "zigzag 35/a": [5, 10, 20, 30, 45, 60, 90, 120],
    "S-type 120, rudder": [10, 15, 20, 25, 30, 35],
}
PARAM = {"S-type psi_S": "psi_S_deg", "zigzag a/a": "angle_deg", "zigzag 35/a": "angle_deg",
         "S-type 120, rudder": "rudder_deg"}


def _task(args):
    base, family, value, noise, rudder_timing = args
    tr = variant(base, family, value) if family else base
    tan = tangent(tr, rudder_timing=rudder_timing is not None)
    I, names = fisher(tan, noise)
    row = {"family": family or "reference", "value_deg": value, "trial": tr.name,
           **criteria(I, names, tan.values), **{f"crb_{k}": v for k, v in crb(I, names).items()}}
    if rudder_timing is not None:
        It, nt = fisher(tan, noise, rudder_timing=rudder_timing)
        row["rudder_movements"] = tan.S_tau.shape[2]
        row.update({TIMING + k: v for k, v in criteria(It, nt, tan.values).items()})
    return row


def search(base, grid: dict | None = None, references=(), noise: str = "log", rudder_timing: float | None = 0.15,
           **sweep_kw) -> pd.DataFrame:
    """Criteria for every design point of ``grid`` (family -> parameter values [deg]) and for the
    ``references`` (loaded trials, e.g. the paper's S-type 120); one row per trial.

    noise: noise model of :func:`trials.planning.fisher.fisher`; rudder_timing: prior std [s] of the
    per-movement timing nuisances of the ``timing_`` criteria (None: rudder-known criteria only);
    sweep_kw: :func:`trials.files.sweep.run_sweep` options (backend, n_jobs, progress).
    """
    from ..files.sweep import run_sweep

    grid = DEFAULT_GRID if grid is None else grid
    tasks = [(base, fam, v, noise, rudder_timing) for fam, vals in grid.items() for v in vals]
    tasks += [(ref, None, np.nan, noise, rudder_timing) for ref in references]
    labels = [variant(base, f, v).name if f else t.name for t, f, v, *_ in tasks]
    rows = run_sweep(_task, tasks, labels=labels, **sweep_kw)
    df = pd.DataFrame(rows)
    df.insert(1, "param", df["family"].map(PARAM).fillna(""))
    return df


def best(df: pd.DataFrame, criterion: str = CRITERION) -> pd.Series:
    """The design point with the lowest criterion."""
    return df.loc[df[criterion].idxmin()]
