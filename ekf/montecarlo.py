"""Monte Carlo over log-noise seeds: mean +- std of the final % errors per trial and derivative.

    python -m ekf.montecarlo OUT_DIR [N_SEEDS]

Each run simulates the trial with a new noise seed, recovers the measurements and runs
the augmented EKF; runs go to ``n_jobs`` joblib workers with a progress line per run.
A run whose filter diverges is counted and left out of the statistics.
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from .estimate import REPO, data_from_trial, estimate, load_config
from .filter import DERIVATIVES, FilterDivergence
from .reproduce import PAPER, TRIALS


def _one(trial_file: str, seed: int, cfg: dict) -> dict:
    with tempfile.TemporaryDirectory(prefix="ekf-mc-") as td:
        data = data_from_trial(trial_file, cfg, seed=seed, workdir=td)
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
    from trials.sweep import run_sweep

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg = load_config(config)
    jobs = [(str(REPO / "configs" / "trials" / TRIALS[t]), first_seed + s, cfg)
            for t in (trials or TRIALS) for s in range(n_seeds)]
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


if __name__ == "__main__" and len(sys.argv) > 1 and sys.argv[1] == "--summarise-only":
    print("\n".join(group_table(pd.read_csv(Path(sys.argv[2]) / "summary.csv"))))
elif __name__ == "__main__":
    monte_carlo(sys.argv[1] if len(sys.argv) > 1 else "out/ekf_montecarlo",
                int(sys.argv[2]) if len(sys.argv) > 2 else 20)
