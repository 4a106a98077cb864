"""Rhee & Kim (1999) Table 10 reproduced: ST35, ZZ10, ZZ20 and S-type 120, one noise seed.

:func:`reproduce_rhee_kim` simulates the four trials, recovers their measurements from the
5 s logs, runs the augmented EKF on each and returns (and writes) the paper's final value
and % error beside ours for every derivative.

The paper's "real" column in Table 10 differs from its own Table 2 (our ship file) in two
places, Y_rr 0.4683E-1 (Table 2: 0.4686E-1) and N_bbr -0.1623 (Table 2: -0.1625); we keep
the paper's printed errors as printed and compute ours against Table 2, the values the
simulation used. Table 10 prints N_rr under ST35 as 0.2141E-1 without its minus sign (its
3.76 % error only fits -0.2141E-1); we restore the sign.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from ekf.data import PAPER_DERIVATIVES as DERIVATIVES
from ekf.estimate import estimate, joint_estimate, load_config
from mmg.resources import trial_path

from .estimation import data_from_trial, write_reports

TRIALS = {"ST35": "st35.yaml", "ZZ10": "zz10.yaml", "ZZ20": "zz20.yaml", "S-type 120": "stype120.yaml"}

# Table 10 as printed: real, then (final, err %) per trial.
PAPER_REAL = {"Y_beta": 0.3998, "Y_r": 0.8774e-1, "Y_bb": 0.6732, "Y_rr": 0.4683e-1, "Y_bbr": -0.1389,
              "Y_brr": 0.4123, "N_beta": 0.1337, "N_r": -0.5433e-1, "N_bb": -0.5180e-3, "N_rr": -0.2224e-1,
              "N_bbr": -0.1623, "N_brr": -0.1204}
PAPER = {
    "ST35": {"Y_beta": (0.3892, 2.65), "Y_r": (0.9217e-1, 5.04), "Y_bb": (0.7193, 6.84), "Y_rr": (0.3902e-1, 16.74),
             "Y_bbr": (-0.1793, 29.07), "Y_brr": (0.4286, 3.96), "N_beta": (0.1363, 1.91), "N_r": (-0.5553e-1, 2.21),
             "N_bb": (-0.5970e-3, 15.33), "N_rr": (-0.2141e-1, 3.76), "N_bbr": (-0.1766, 8.73),
             "N_brr": (-0.1169, 2.90)},
    "ZZ10": {"Y_beta": (0.3907, 2.26), "Y_r": (0.9041e-1, 3.04), "Y_bb": (0.7388, 9.74), "Y_rr": (0.3984e-1, 14.98),
             "Y_bbr": (-0.1707, 22.84), "Y_brr": (0.4716, 14.38), "N_beta": (0.1326, 0.82), "N_r": (-0.5459e-1, 0.48),
             "N_bb": (-0.5950e-3, 14.95), "N_rr": (-0.1534e-1, 31.05), "N_bbr": (-0.1922, 18.32),
             "N_brr": (-0.1394, 15.82)},
    "ZZ20": {"Y_beta": (0.3964, 0.85), "Y_r": (0.8895e-1, 1.37), "Y_bb": (0.6950, 3.23), "Y_rr": (0.4240e-1, 9.54),
             "Y_bbr": (-0.1773, 27.64), "Y_brr": (0.4409, 6.94), "N_beta": (0.1337, 0.01), "N_r": (-0.5486e-1, 0.97),
             "N_bb": (-0.5240e-3, 1.19), "N_rr": (-0.1903e-1, 14.42), "N_bbr": (-0.1793, 10.27),
             "N_brr": (-0.1248, 3.72)},
    "S-type 120": {"Y_beta": (0.3990, 0.18), "Y_r": (0.8859e-1, 0.96), "Y_bb": (0.6825, 1.38),
                   "Y_rr": (0.4317e-1, 7.88), "Y_bbr": (-0.1822, 31.14), "Y_brr": (0.4350, 5.50),
                   "N_beta": (0.1350, 0.90), "N_r": (-0.5524e-1, 1.67), "N_bb": (-0.5540e-3, 7.02),
                   "N_rr": (-0.2070e-1, 6.92), "N_bbr": (-0.1724, 6.11), "N_brr": (-0.1197, 0.57)},
}


def comparison(ests) -> pd.DataFrame:
    """Per trial and derivative: the paper's final and % error beside ours."""
    rows = []
    for e in ests:
        err = e.errors_pct()
        for n in DERIVATIVES:
            pf, pe = PAPER.get(e.name, {}).get(n, (np.nan, np.nan))
            rows.append({"trial": e.name, "coeff": n, "real": e.data.true_values[n],
                         "paper_real": PAPER_REAL[n], "paper_final": pf, "paper_err_pct": pe,
                         "our_final": e.final[n], "our_err_pct": err[n]})
    return pd.DataFrame(rows)


def reproduce_rhee_kim(out_dir, seed: int | None = None, config=None, trials=None, plots: bool = True,
                       verbose: bool = True, joint: bool = True, runs: dict | None = None,
                       keep: dict | None = None) -> pd.DataFrame:
    """Run ST35, ZZ10, ZZ20 and S-type 120 and compare with Table 10; returns the comparison table.

    Writes into ``out_dir``: comparison.csv/.md and the estimation reports (estimates.json,
    error_table.csv/.md, convergence_*.png, preprocessing figures, free_run.json).
    ``seed`` replaces every trial's noise seed (None keeps each trial file's own).
    ``joint`` adds rows for trial "joint": one filter run through all the trials in turn
    (:func:`ekf.estimate.joint_estimate`); the paper has no such column.
    ``runs``: already simulated trials by name (``{"ST35": TrialRun, ...}``), reused instead of
    simulating them again; ``keep``: a dict that receives the ``datas`` and ``estimates`` for
    callers that go on from them (the main job's output-error section).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg = load_config(config)
    ests = []
    datas = []
    t0 = time.perf_counter()
    for name in trials or TRIALS:
        src = (runs or {}).get(name) or trial_path(TRIALS[name].removesuffix(".yaml"))
        data = data_from_trial(src, cfg, seed=seed)
        datas.append(data)
        ests.append(estimate(data, cfg))
        if verbose:
            print(f"  {name}: done ({time.perf_counter() - t0:.1f} s)", flush=True)
    if joint and len(datas) > 1:
        ests.append(joint_estimate(datas, cfg, name="joint"))
    write_reports(ests, out, plots=plots)
    if keep is not None:
        keep.update(datas=datas, estimates=ests)
    df = comparison(ests)
    df.to_csv(out / "comparison.csv", index=False, float_format="%.6g")
    wide = df.pivot(index="coeff", columns="trial", values=["paper_err_pct", "our_err_pct"]).reindex(DERIVATIVES)
    names = [e.name for e in ests]
    heads = [f"{t} paper % | {t} ours %" if t in PAPER else f"{t} ours %" for t in names]
    lines = ["| coeff | " + " | ".join(heads) + " |",
             "|---|" + "".join("---|---|" if t in PAPER else "---|" for t in names)]
    for n in DERIVATIVES:
        cells = []
        for t in names:
            if t in PAPER:
                cells.append(f"{wide.loc[n, ('paper_err_pct', t)]:.2f}")
            cells.append(f"{wide.loc[n, ('our_err_pct', t)]:.2f}")
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    (out / "comparison.md").write_text(
        "Rhee & Kim (1999) Table 10 vs this toolkit (seed "
        f"{seed if seed is not None else 'of each trial file'}): final-value % errors. \"joint\" is one filter "
        "run through the four trials in turn; the paper has no such column.\n\n" + "\n".join(lines) + "\n")
    if verbose:
        print(df.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    return df
