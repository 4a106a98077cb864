"""Monte Carlo over log-noise seeds of the three estimators: the paper EKF, the raw-log EKF and
the joint output-error fit.

``mmg montecarlo OUT --seeds 20``, ``mmg log-filter OUT --seeds 20`` and ``mmg output-error OUT
--seeds 20`` run them.  Each run simulates the trial with a new noise seed (in memory),
recovers the measurements and runs the estimator; runs go through
:func:`trials.files.sweep.run_sweep` (both cores, a progress line per run).  A run whose filter
diverges is counted and left out of the statistics.
"""
from __future__ import annotations

import functools
import time
from pathlib import Path

import numpy as np
import pandas as pd

from ekf.data import PAPER_DERIVATIVES as DERIVATIVES
from ekf.estimate import estimate, load_config
from ekf.filter import FilterDivergence
from ekf.log_filter import run_log_filter
from ekf.output_error import refine
from mmg.errors import InputError
from mmg.resources import trial_path
from mmg.rudder import REBUILT_KINDS, reversal_timing_errors

from .estimation import data_from_trial
from .rhee_kim import PAPER, TRIALS
from ..files.sweep import run_sweep
from ..runs.trial import load_trial

PAPER_TRIALS = tuple(TRIALS)


def paper_trial_file(name: str) -> str:
    """The bundled trial file of one of Rhee & Kim's trials (``"ST35"``, ``"ZZ10"``, ``"ZZ20"``, ``"S-type 120"``)."""
    return str(trial_path(TRIALS[name].removesuffix(".yaml")))


@functools.lru_cache(maxsize=16)
def _run_of(trial_file: str):
    """The trial simulated once per worker process: the seeds change only the log's noise."""
    from ..runs.run import run_trial

    return run_trial(load_trial(trial_file))


def _one(trial_file: str, seed: int, cfg: dict) -> dict:
    data = data_from_trial(_run_of(trial_file), cfg, seed=seed)
    try:
        e = estimate(data, cfg)
    except FilterDivergence as exc:
        return {"trial": data.name, "seed": seed, "diverged": str(exc)}
    return {"trial": data.name, "seed": seed, "diverged": "", **e.errors_pct(),
            **{f"final_{n}": v for n, v in e.final.items()}}


def _task(task) -> dict:
    return _one(*task)


def monte_carlo(out_dir, n_seeds: int = 20, trials=None, n_jobs: int = 2, first_seed: int = 1000,
                config=None, verbose: bool = True, backend: str = "loky") -> pd.DataFrame:
    """Run ``n_seeds`` seeds of each trial; writes runs.csv and summary.csv/.md; returns the summary.

    summary: one row per (trial, derivative) with mean and std of the % error, the number of
    runs that converged, and the paper's single-run % error (Table 10) beside it.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg = load_config(config)
    jobs = [(paper_trial_file(t), first_seed + s, cfg) for t in (trials or TRIALS) for s in range(n_seeds)]
    rows = run_sweep(_task, jobs, backend=backend, n_jobs=n_jobs, progress=verbose,
                     labels=[f"{Path(f).stem} seed {s}" for f, s, _ in jobs])
    runs = pd.DataFrame(rows)
    runs.to_csv(out / "runs.csv", index=False, float_format="%.6g")
    summ = []
    for trial, g in runs.groupby("trial", sort=False):
        ok = g[g["diverged"] == ""]
        for n in DERIVATIVES:
            vals = ok[n].to_numpy(dtype=float) if n in ok else np.array([])
            summ.append({"trial": trial, "coeff": n, "mean_err_pct": float(np.mean(vals)) if len(vals) else np.nan,
                         "std_err_pct": float(np.std(vals, ddof=1)) if len(vals) > 1 else np.nan,
                         "runs": len(vals), "diverged": int((g["diverged"] != "").sum()),
                         "paper_err_pct": PAPER.get(trial, {}).get(n, (np.nan, np.nan))[1]})
    summary = pd.DataFrame(summ)
    summary.to_csv(out / "summary.csv", index=False, float_format="%.4g")
    lines = [f"Monte Carlo over {n_seeds} log-noise seeds per trial (seeds {first_seed}-{first_seed + n_seeds - 1}): "
             "final % error, mean +- std (paper: its single run, Table 10)\n",
             "| coeff | " + " | ".join(f"{t} ours | {t} paper" for t in summary["trial"].unique()) + " |",
             "|---|" + "---|" * (2 * summary["trial"].nunique())]
    for n in DERIVATIVES:
        cells = []
        for t in summary["trial"].unique():
            r = summary[(summary.trial == t) & (summary.coeff == n)].iloc[0]
            cells += [f"{r.mean_err_pct:.2f} +- {r.std_err_pct:.2f}", f"{r.paper_err_pct:.2f}"]
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    lines += ["", *group_table(summary)]
    (out / "summary.md").write_text("\n".join(lines) + "\n")
    if verbose:
        print("\n".join(lines))
    return summary


LINEAR = ("Y_beta", "Y_r", "N_beta", "N_r")


def group_table(summary: pd.DataFrame) -> list[str]:
    """Mean % error of the linear, nonlinear and all derivatives per trial, ours (MC mean) and the
    paper's (Table 10), with the best trial of each group: the paper's qualitative claims in numbers."""
    rows = []
    for t in summary["trial"].unique():
        g = summary[summary.trial == t]
        lin = g.coeff.isin(LINEAR)
        rows.append((t, g[lin].mean_err_pct.mean(), g[~lin].mean_err_pct.mean(), g.mean_err_pct.mean(),
                     g[lin].paper_err_pct.mean(), g[~lin].paper_err_pct.mean(), g.paper_err_pct.mean()))
    out = ["Mean % error by group (lower is better): ours (Monte Carlo mean) | paper (Table 10)", "",
           "| trial | linear ours | nonlinear ours | all ours | linear paper | nonlinear paper | all paper |",
           "|---|---|---|---|---|---|---|"]
    out += [f"| {r[0]} | " + " | ".join(f"{v:.2f}" for v in r[1:]) + " |" for r in rows]
    for k, label in ((1, "linear"), (2, "nonlinear"), (3, "all")):
        ours = sorted(rows, key=lambda r: r[k])
        paper = sorted(rows, key=lambda r: r[k + 3])
        out.append(f"\nbest {label}: ours {' < '.join(r[0] for r in ours)}; paper {' < '.join(r[0] for r in paper)}")
    return out

# --------------------------------------------------------------------------- raw-log EKF


def _timing_error(data) -> dict:
    """How far the rebuilt rudder's reversals are from the truth file's (rms, max [s], count)."""
    if data.truth is None or getattr(data.truth, "delta", None) is None:
        return {}
    e = reversal_timing_errors(data.meas.t, data.meas.delta, data.truth.t, data.truth.delta)
    if len(e) == 0:
        return {"rudder_timing_n": 0, "rudder_timing_rms_s": np.nan, "rudder_timing_max_s": np.nan}
    return {"rudder_timing_n": len(e), "rudder_timing_rms_s": float(np.sqrt(np.mean(e ** 2))),
            "rudder_timing_max_s": float(np.abs(e).max())}


def _log_one(trial_file: str, seed: int, cfg: dict, q, sigma_tau: float = 0.15, rudder: str = "rebuilt") -> dict:
    data = data_from_trial(_run_of(trial_file), cfg, seed=seed)
    try:
        res = run_log_filter(data, data.record, cfg, q=q, sigma_tau=sigma_tau, rudder=rudder)
    except FilterDivergence as exc:
        return {"trial": data.name, "seed": seed, "diverged": str(exc), "rudder": rudder, "sigma_tau_s": sigma_tau}
    tv = data.true_values
    fin = res.final
    return {"trial": data.name, "seed": seed, "diverged": "", "rudder": rudder, "sigma_tau_s": sigma_tau,
            **_timing_error(data),
            **{n: 100.0 * abs(fin[n] - tv[n]) / abs(tv[n]) for n in fin},
            **{f"final_{n}": v for n, v in fin.items()},
            "mean_nis": float(np.nanmean(res.nis))}


def _log_task(task) -> dict:
    return _log_one(*task)


def log_filter_monte_carlo(out_dir, n_seeds: int = 20, trials=None, n_jobs: int = 2, first_seed: int = 1000,
                config=None, q=None, sigma_tau: float = 0.15, verbose: bool = True, backend: str = "loky",
                rudder: str = "rebuilt"):
    """``n_seeds`` seeds per trial; writes OUT/runs.csv (one row per trial and seed, with the
    ``trial_file`` it came from); returns it.

    trials: names of the paper's trials (ST35, ZZ10, ZZ20, S-type 120: the default) or paths
    of turning / zigzag / S-type trial YAMLs; rudder: "rebuilt" (default) or "true"
    (:func:`run_log_filter`).
    """
    cfg = load_config(config)
    files = [paper_trial_file(t) if t in TRIALS else str(Path(t).resolve()) for t in (trials or TRIALS)]
    for f in files:                       # all inputs checked before any run or output
        if not Path(f).is_file():
            raise InputError(f, "trials", f"neither one of {', '.join(TRIALS)} nor a trial YAML")
        if (kind := load_trial(f).kind) not in REBUILT_KINDS:
            raise InputError(f, "manoeuvre.kind", f"the raw-log EKF rebuilds the rudder of turning, zigzag and "
                                                  f"S-type trials only, not {kind}")
    jobs = [(f, first_seed + s, cfg, q, sigma_tau, rudder) for f in files for s in range(n_seeds)]
    rows = run_sweep(_log_task, jobs, backend=backend, n_jobs=n_jobs, progress=verbose,
                     labels=[f"{Path(j[0]).stem} seed {j[1]}" for j in jobs])
    runs = pd.DataFrame(rows)
    runs.insert(2, "trial_file", [j[0] for j in jobs])
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    runs.to_csv(out / "runs.csv", index=False, float_format="%.8g")
    return runs


# --------------------------------------------------------------------------- joint output error


def _oe_one(seed: int, trials, cfg, rudder: str) -> dict:
    datas = [data_from_trial(_run_of(paper_trial_file(t)), cfg, seed=seed) for t in trials]
    tv = datas[0].true_values
    try:
        ekf, res = refine(datas, cfg, rudder=rudder)
    except FilterDivergence as exc:
        return {"seed": seed, "diverged": str(exc)}
    row = {"seed": seed, "diverged": "", "seconds": res.seconds, "chi2_dof": res.chi2_per_dof, "nfev": res.nfev}
    for n in DERIVATIVES:
        row[f"ekf_{n}"] = 100.0 * abs(ekf[n] - tv[n]) / abs(tv[n]) if ekf else np.nan
        row[f"oe_{n}"] = 100.0 * abs(res.final[n] - tv[n]) / abs(tv[n])
        row[f"oe_signed_{n}"] = 100.0 * (res.final[n] - tv[n]) / abs(tv[n])
        row[f"se_{n}"] = 100.0 * res.std_errors[n] / abs(tv[n])
        row[f"final_{n}"] = res.final[n]
    return row


def _oe_task(task) -> dict:
    return _oe_one(*task)


def output_error_monte_carlo(out_dir, n_seeds: int = 20, trials=PAPER_TRIALS, n_jobs: int = 2, first_seed: int = 1000,
                config=None, rudder: str = "ramp", verbose: bool = True, ekf_summary=None, backend: str = "loky"):
    """Seeds x (joint EKF, then joint output error); writes runs.csv, summary.csv/.md; returns the summary."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg = load_config(config)
    seeds = [first_seed + s for s in range(n_seeds)]
    t0 = time.perf_counter()
    rows = run_sweep(_oe_task, [(s, tuple(trials), cfg, rudder) for s in seeds], backend=backend,
                     n_jobs=n_jobs, progress=verbose, labels=[f"seed {s}" for s in seeds])
    runs = pd.DataFrame(rows)
    runs.to_csv(out / "runs.csv", index=False, float_format="%.6g")
    if verbose:
        print(f"  {len(seeds)} seeds in {time.perf_counter() - t0:.0f} s on {n_jobs} workers", flush=True)
    return summarise(out, trials, rudder, ekf_summary, verbose)


def summarise(out_dir, trials=PAPER_TRIALS, rudder: str = "ramp", ekf_summary=None, verbose: bool = True):
    """summary.csv/.md from ``OUT/runs.csv``: per derivative the joint EKF and output-error % errors
    (mean +- std over seeds), the OE signed bias and spread, the OE standard error from (J^T W J)^-1
    and the spread / standard-error ratio (about 1 when the fit is noise-limited), and, when an
    :func:`monte_carlo` summary.csv is given, the per-trial EKF's best trial beside them."""
    out = Path(out_dir)
    runs = pd.read_csv(out / "runs.csv", dtype={"diverged": str})
    runs["diverged"] = runs["diverged"].fillna("")
    ok = runs[runs["diverged"] == ""]
    per_trial = None
    if ekf_summary is not None and Path(ekf_summary).exists():
        per_trial = pd.read_csv(ekf_summary)
    summ = []
    for n in DERIVATIVES:
        row = {"coeff": n}
        if per_trial is not None:
            g = per_trial[per_trial.coeff == n].sort_values("mean_err_pct")
            b = g.iloc[0]
            row.update(ekf1_trial=b.trial, ekf1_mean=b.mean_err_pct, ekf1_std=b.std_err_pct)
        row.update({"ekf_mean": ok[f"ekf_{n}"].mean(), "ekf_std": ok[f"ekf_{n}"].std(ddof=1),
                    "oe_mean": ok[f"oe_{n}"].mean(), "oe_std": ok[f"oe_{n}"].std(ddof=1),
                    "oe_bias": ok[f"oe_signed_{n}"].mean(), "oe_spread": ok[f"oe_signed_{n}"].std(ddof=1),
                    "crb_se": ok[f"se_{n}"].mean()})
        row["spread_over_se"] = row["oe_spread"] / row["crb_se"]
        row["within_5pct"] = bool(row["oe_mean"] < 5.0)
        summ.append(row)
    summary = pd.DataFrame(summ)
    summary.to_csv(out / "summary.csv", index=False, float_format="%.4g")
    label = " + ".join(trials)
    seeds = ok["seed"].astype(int)
    chi = ok["chi2_dof"].astype(float)
    lines = [f"Joint estimate over {label}; {len(ok)} of {len(runs)} seeds ({seeds.min()}-{seeds.max()}) at the "
             f"paper's log noise, full 3000 s trials, rudder: {rudder}. % error of the final value: mean +- std over seeds.",
             f"Output-error chi2/dof over seeds: {chi.min():.3f}-{chi.max():.3f} (median {chi.median():.3f}); "
             f"mean {ok['seconds'].astype(float).mean():.0f} s per OE fit.",
             "OE signed = mean +- std of the signed % error; OE std err = standard error from (J^T W J)^-1 "
             "(mean over seeds); spread/SE = std of the signed error over the standard error.",
             ""]
    head = "| coeff | "
    sep = "|---|"
    if per_trial is not None:
        head += "best single-trial EKF % | "
        sep += "---|"
    head += "joint EKF % | output error % | OE signed % | OE std err % | spread/SE | < 5 % |"
    sep += "---|---|---|---|---|---|"
    lines += [head, sep]
    for _, r in summary.iterrows():
        cell = f"| {r.coeff} | "
        if per_trial is not None:
            cell += f"{r.ekf1_mean:.2f} +- {r.ekf1_std:.2f} ({r.ekf1_trial}) | "
        cell += (f"{r.ekf_mean:.2f} +- {r.ekf_std:.2f} | {r.oe_mean:.3f} +- {r.oe_std:.3f} | "
                 f"{r.oe_bias:+.3f} +- {r.oe_spread:.3f} | {r.crb_se:.3f} | {r.spread_over_se:.2f} | "
                 f"{'yes' if r.within_5pct else 'no'} |")
        lines.append(cell)
    (out / "summary.md").write_text("\n".join(lines) + "\n")
    if verbose:
        print("\n".join(lines))
    return summary
