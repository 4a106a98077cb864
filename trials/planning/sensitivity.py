"""Derivative sensitivity of Rhee & Kim (1999) section 3.2, eqs. (21)-(22).

For every trial of a group and every one of the 12 sway/yaw derivatives c_i:

1. simulate the trial with the ship file's derivatives (the reference run);
2. set c_i to 120 % of its value, simulate again from the *same* start state with the
   *same* command law (trim rudder, switching logic), and put c_i back;
3. sum over the record (every integration step, 0.1 s) the **absolute** differences of
   u, v and r between the perturbed and the reference run: d_u[i, k], d_v[i, k], d_r[i, k]
   for derivative i in trial k.  (The paper says "add all the differences"; signed
   differences of an oscillating record cancel, so absolute values are used.)

Eq. (21): S'[i, k] = d_u[i, k] / sum_{i,k} d_u + d_v[i, k] / sum_{i,k} d_v + d_r[i, k] / sum_{i,k} d_r,
so each channel is normalised by its total over *all derivatives and all trials being
compared* (which also removes the units: m/s, m/s, rad/s) and sum_{i,k} S' = 3.
Eq. (22): S[i, k] = 100 S'[i, k] / 3 [%]; the whole group sums to 100 %.  A sensitivity
therefore depends on which trials are compared (see :mod:`trials.planning.fisher` for a measure
that does not).

A trial whose perturbed run stops early (speed collapse) is compared over the common
length.  The simulations are the compiled MMG loop (:func:`mmg.integrate.integrate`) with
the derivative written into the packed ship's coefficient slot; one trial's 13 runs are
one task of :func:`trials.files.sweep.run_sweep`.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from mmg.integrate import integrate
from mmg.simulation import prepare

DERIVATIVES = ("Y_beta", "Y_r", "Y_bb", "Y_rr", "Y_bbr", "Y_brr",
               "N_beta", "N_r", "N_bb", "N_rr", "N_bbr", "N_brr")
LINEAR = ("Y_beta", "Y_r", "N_beta", "N_r")
NONLINEAR = tuple(n for n in DERIVATIVES if n not in LINEAR)
CHANNELS = ("u", "v", "r")
PERTURBATION = 1.2


@dataclass(frozen=True)
class TrialDifferences:
    """Summed absolute differences of u, v, r for one trial: ``sums[i, c]`` (12 x 3), SI units."""

    trial: str
    sums: np.ndarray
    duration: float
    completed: bool


def trial_differences(trial, names=DERIVATIVES, factor: float = PERTURBATION) -> TrialDifferences:
    """Steps 1-5 of section 3.2 for one :class:`trials.runs.trial.Trial`: the 12 x 3 table of sums."""
    pk, eq = prepare(trial.ship, trial.u0, trial.n0, trial.trim, trial.effects)
    law = trial.command_law(trim_rudder=eq.delta, psi0=0.0)
    x0 = eq.state()
    _, ref, _, done = integrate(pk, x0, law, trial.duration, trial.dt)
    sums = np.zeros((len(names), len(CHANNELS)))
    all_done = done
    for i, name in enumerate(names):
        coef = pk.hull_coef.copy()
        j = trial.ship.hull.index(name)
        coef[j] *= factor
        _, st, _, d = integrate(replace(pk, hull_coef=coef), x0, law, trial.duration, trial.dt)
        all_done &= d
        m = min(len(st), len(ref))
        sums[i] = np.abs(st[:m, :3] - ref[:m, :3]).sum(axis=0)
    return TrialDifferences(trial.name, sums, float(trial.duration), bool(all_done))


def normalise(diffs: list[TrialDifferences], names=DERIVATIVES) -> pd.DataFrame:
    """Eqs. (21)-(22) over the trials in ``diffs``: long table trial, derivative, sensitivity_pct (+ raw sums)."""
    D = np.stack([d.sums for d in diffs])          # (trials, derivatives, channels)
    tot = D.sum(axis=(0, 1))                        # s_u, s_v, s_r over the whole group
    Sp = (D / np.where(tot > 0, tot, 1.0)).sum(axis=2)   # eq. (21)
    S = 100.0 * Sp / len(CHANNELS)                  # eq. (22)
    rows = []
    for k, d in enumerate(diffs):
        for i, n in enumerate(names):
            rows.append({"trial": d.trial, "derivative": n, "group": "linear" if n in LINEAR else "nonlinear",
                         "sensitivity_pct": S[k, i], "sum_abs_du_m_s": D[k, i, 0], "sum_abs_dv_m_s": D[k, i, 1],
                         "sum_abs_dr_rad_s": D[k, i, 2]})
    return pd.DataFrame(rows)


def _task(trial):
    return trial_differences(trial)


def sensitivity(trials, *, backend: str = "loky", n_jobs: int | None = None, progress: bool = True,
                client=None) -> pd.DataFrame:
    """Sensitivities (eqs. 21-22, %) of the 12 derivatives in each trial, normalised over ``trials``."""
    from ..files.sweep import run_sweep

    trials = list(trials)
    diffs = run_sweep(_task, trials, backend=backend, n_jobs=n_jobs, labels=[t.name for t in trials],
                      progress=progress, client=client)
    return normalise(diffs)


def group_differences(trials, **kw) -> list[TrialDifferences]:
    """The raw per-trial tables, for renormalising over several groups without re-simulating."""
    from ..files.sweep import run_sweep

    trials = list(trials)
    return run_sweep(_task, trials, labels=[t.name for t in trials], **kw)


def group_sums(df: pd.DataFrame) -> pd.DataFrame:
    """Fig. 14: per trial the sum of the linear, the nonlinear and all sensitivities [%]."""
    g = df.pivot_table(index="trial", columns="group", values="sensitivity_pct", aggfunc="sum", sort=False)
    g["total"] = g.sum(axis=1)
    return g[["linear", "nonlinear", "total"]]


def efficiency(err: pd.DataFrame) -> pd.DataFrame:
    """Fig. 28: estimation efficiency per trial and group, normalised over the trials [%].

    ``err`` long table with columns trial, coeff (or derivative), err_pct.  The efficiency of a
    group is 1 / (sum of the % errors of its derivatives) (Rhee & Kim section 6.2); each group's
    efficiencies are then divided by their sum over the trials and given in %.
    """
    col = "coeff" if "coeff" in err else "derivative"
    rows = {}
    for trial, g in err.groupby("trial", sort=False):
        e = dict(zip(g[col], g["err_pct"]))
        rows[trial] = {"linear": 1.0 / sum(e[n] for n in LINEAR), "nonlinear": 1.0 / sum(e[n] for n in NONLINEAR),
                       "overall": 1.0 / sum(e[n] for n in DERIVATIVES)}
    out = pd.DataFrame(rows).T
    return 100.0 * out / out.sum(axis=0)
