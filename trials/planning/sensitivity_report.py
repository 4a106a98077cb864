"""Sensitivity studies as written reports: derivative sensitivities of given trials (Rhee & Kim
eqs. 21-22), the paper's figures, Cramer-Rao bounds beside a Monte Carlo, the trial-design search.

Each function writes into ``out`` (a folder or a staging object with ``.path(name)``, see
:class:`trials.files.output.StagedOutput`) and returns its table.  ``mmg sensitivity`` is the command
line over them:

    mmg sensitivity TRIAL.yaml [TRIAL.yaml ...] --out DIR [--fisher]
    mmg sensitivity --paper-figures --out DIR [--ekf-comparison comparison.csv]
    mmg sensitivity --crb-vs-mc MC_DIR [MC_DIR ...] --out DIR [--mc-seeds N] [--rudder-timing S]
    mmg sensitivity --design --out DIR
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from mmg.errors import InputError

from mmg.resources import trial_path

from ..files.output import out_path

# Rhee & Kim's figure groups: (file stem, title, trial files)
FIGURES = [
    ("fig02_conventional", "Fig. 2 - sensitivity in conventional trials: ST35, ZZ10, ZZ20", ["st35", "zz10", "zz20"]),
    ("fig08_09_sine_sawtooth", "Figs 8-9 - sine and sawtooth vs conventional: ST35, ZZ10, ZZ20, Sine, Sawtooth", ["st35", "zz10", "zz20", "sine", "sawtooth"]),
    ("fig12_stype", "Fig. 12 - sensitivity between S-type trials: S-type 60, 120, 180",
     ["stype60", "stype120", "stype180"]),
    ("fig13_conventional_vs_stype120", "Fig. 13 - conventional trials vs S-type 120: ST35, ZZ10, ZZ20, S-type 120",
     ["st35", "zz10", "zz20", "stype120"]),
]
FIG14_GROUP = "fig13_conventional_vs_stype120"
EKF_TRIALS = {"ST35": "st35", "ZZ10": "zz10", "ZZ20": "zz20", "S-type 120": "stype120"}


def _load(paths):
    from ..runs.trial import load_trial

    return [load_trial(p) for p in paths]


def _md(df: pd.DataFrame, fmt="{:.3g}") -> str:
    cols = [str(c) for c in df.columns]
    lines = ["| " + " | ".join([df.index.name or ""] + cols) + " |", "|" + "---|" * (len(cols) + 1)]
    for idx, r in df.iterrows():
        lines.append("| " + " | ".join([str(idx)] + [fmt.format(v) if isinstance(v, (float, np.floating)) else str(v)
                                                       for v in r.to_numpy()]) + " |")
    return "\n".join(lines) + "\n"


def _wide(df: pd.DataFrame) -> pd.DataFrame:
    from .sensitivity import DERIVATIVES

    trials = list(dict.fromkeys(df["trial"]))
    w = df.pivot(index="derivative", columns="trial", values="sensitivity_pct").reindex(DERIVATIVES)[trials]
    w.index.name = "derivative"
    return w


# --------------------------------------------------------------------------- trials given on the command line

def trial_sensitivities(trial_files, out, fisher_bounds: bool = False, backend: str = "loky", n_jobs=None) -> pd.DataFrame:
    """Sensitivities of the given trials, normalised together (sensitivity.csv/.md/.png,
    group_sums.csv/.png; with ``fisher_bounds`` crb_std.csv); returns the long table."""
    from .sensitivity import group_sums, sensitivity
    from .sensitivity_plots import plot_groups, plot_sensitivity

    stage = out_path(out)
    trials = _load(trial_files)
    names = [t.name for t in trials]
    if len(set(names)) != len(names):
        raise InputError(" ".join(map(str, trial_files)), "name", f"two trials share a name ({', '.join(names)}); "
                                                                  "the sensitivities are per trial name")
    df = sensitivity(trials, backend=backend, n_jobs=n_jobs)
    df.to_csv(stage.path("sensitivity.csv"), index=False, float_format="%.6g")
    w = _wide(df)
    stage.path("sensitivity.md").write_text(
        f"Sensitivity [%] (Rhee & Kim eq. 22, absolute differences; the group sums to 100 %): {', '.join(names)}\n\n"
        + _md(w, "{:.2f}"))
    plot_sensitivity(df, stage.path("sensitivity.png"))
    gs = group_sums(df)
    gs.to_csv(stage.path("group_sums.csv"), float_format="%.6g")
    plot_groups(gs, stage.path("group_sums.png"), f"Sum of sensitivities: {', '.join(names)}",
                "sum of sensitivities [%] (eq. 22)")
    print(f"sensitivity [%] (eq. 22, absolute differences summed over the record; group total 100 %):")
    print(w.round(2).to_string())
    print(gs.round(2).to_string())
    if fisher_bounds:
        from .fisher import crb, fisher, tangent

        rows = []
        for t in trials:
            tan = tangent(t)
            c = crb(*fisher(tan, "log"))
            rows.append({"trial": t.name, **c})
        cr = pd.DataFrame(rows).set_index("trial")
        cr.to_csv(stage.path("crb_std.csv"), float_format="%.6g")
        print("Cramer-Rao bound on the standard deviation (log noise model):")
        print(cr.T.to_string(float_format=lambda v: f"{v:.3g}"))
    return df


# --------------------------------------------------------------------------- the paper's figures

def read_comparison(path) -> pd.DataFrame:
    """The EKF reproduction's comparison.csv (trial, coeff, our_err_pct[, paper_err_pct]), checked."""
    try:
        cmp_ = pd.read_csv(path)
    except FileNotFoundError:
        raise InputError(str(path), "", "file not found") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as e:
        raise InputError(str(path), "", f"not a readable CSV ({str(e).splitlines()[0]})") from None
    need = {"trial", "coeff", "our_err_pct"}
    if not need <= set(cmp_.columns):
        raise InputError(str(path), ",".join(sorted(need - set(cmp_.columns))),
                         "missing column(s); expected the comparison.csv of mmg reproduce / reproduce_rhee_kim")
    missing = set(EKF_TRIALS) - set(cmp_["trial"])
    if missing:
        raise InputError(str(path), "trial", f"no rows for {', '.join(sorted(missing))}")
    return cmp_


def paper_figures(out, ekf_comparison=None, backend: str = "loky", n_jobs=None, verbose: bool = True) -> dict:
    """Figs 2, 8-9, 12, 13, 14 and 28 into ``out`` (a folder path or a StagedOutput); returns the tables.

    Each distinct trial is simulated once (13 runs), then each figure's group is normalised
    by eqs. (21)-(22) on its own.  Fig. 28 needs the EKF's final % errors: ``ekf_comparison``
    (comparison.csv of :func:`trials.estimates.rhee_kim.reproduce_rhee_kim`, columns trial, coeff,
    our_err_pct, paper_err_pct), or None to run that reproduction here (one noise seed per trial).
    """
    from .sensitivity import efficiency, group_differences, group_sums, normalise
    from .sensitivity_plots import plot_groups, plot_sensitivity

    P = out.path if hasattr(out, "path") else (lambda n: Path(out) / n)
    if not hasattr(out, "path"):
        Path(out).mkdir(parents=True, exist_ok=True)
    stems = list(dict.fromkeys(s for _, _, group in FIGURES for s in group))
    trials = _load([trial_path(s) for s in stems])
    t0 = time.perf_counter()
    diffs = dict(zip(stems, group_differences(trials, backend=backend, n_jobs=n_jobs, progress=verbose)))
    if verbose:
        print(f"simulated {len(stems)} trials x 13 runs in {time.perf_counter() - t0:.1f} s")
    tables = {}
    md = ["# Sensitivity figures (Rhee & Kim 1999, section 3.2 and 6.1)\n",
          "Sensitivity S of eq. (22) in %: absolute differences of u, v, r between the run with one derivative "
          "at 120 % and the reference run, summed over every 0.1 s step of the 3000 s record, each channel "
          "normalised over all derivatives and trials of the figure; each figure's bars sum to 100 %.\n"]
    for stem, title, group in FIGURES:
        df = normalise([diffs[s] for s in group])
        tables[stem] = df
        df.to_csv(P(f"{stem}.csv"), index=False, float_format="%.6g")
        plot_sensitivity(df, P(f"{stem}.png"), title)
        md += [f"## {title}\n", _md(_wide(df), "{:.2f}")]
    gs = group_sums(tables[FIG14_GROUP])
    tables["fig14_sums"] = gs
    gs.to_csv(P("fig14_sums.csv"), float_format="%.6g")
    plot_groups(gs, P("fig14_sums.png"), "Fig. 14 - sums of sensitivities: ST35, ZZ10, ZZ20, S-type 120", "sum of sensitivities [%] (eq. 22)")
    md += ["## Fig. 14 - sums of linear, nonlinear and all sensitivities [%] (group of Fig. 13)\n", _md(gs, "{:.2f}")]
    # Fig. 28 from the EKF's % errors
    if ekf_comparison is None:
        from ..estimates.rhee_kim import reproduce_rhee_kim

        if verbose:
            print("running the EKF on ST35, ZZ10, ZZ20, S-type 120 for Fig. 28 ...", flush=True)
        cmp_ = reproduce_rhee_kim(Path(str(P("ekf/comparison.csv"))).parent, plots=False, verbose=False, joint=False)
    else:
        cmp_ = read_comparison(ekf_comparison)
    cmp_ = cmp_[cmp_["trial"].isin(EKF_TRIALS)]
    ours = efficiency(cmp_.rename(columns={"our_err_pct": "err_pct"})[["trial", "coeff", "err_pct"]])
    tables["fig28_efficiency"] = ours
    ours.to_csv(P("fig28_efficiency.csv"), float_format="%.6g")
    plot_groups(ours, P("fig28_efficiency.png"), "Fig. 28 - estimation efficiency (EKF): "
                                                 + ", ".join(ours.index), "normalised efficiency [%] (1 / sum of % errors)")
    md += ["## Fig. 28 - estimation efficiency, ours [%] (1 / sum of the group's % errors, normalised over the trials)\n",
           _md(ours, "{:.1f}")]
    if "paper_err_pct" in cmp_:
        paper = efficiency(cmp_.rename(columns={"paper_err_pct": "err_pct"})[["trial", "coeff", "err_pct"]])
        tables["fig28_paper"] = paper
        paper.to_csv(P("fig28_efficiency_paper_table10.csv"), float_format="%.6g")
        md += ["## Fig. 28 - the same from the paper's Table 10 errors [%]\n", _md(paper, "{:.1f}")]
    P("sensitivity_figures.md").write_text("\n".join(md))
    if verbose:
        print("\n".join(md))
    return tables


# --------------------------------------------------------------------------- CRB vs Monte Carlo

def _read_runs(mc_dirs, n_seeds: int, verbose: bool) -> tuple[pd.DataFrame, str]:
    """The runs.csv of every Monte Carlo folder, concatenated (a single missing folder is run)."""
    dirs = [mc_dirs] if isinstance(mc_dirs, (str, Path)) else list(mc_dirs)
    csvs = [Path(d) / "runs.csv" for d in dirs]
    if len(csvs) == 1 and not csvs[0].exists():
        from ..estimates.montecarlo import monte_carlo

        if verbose:
            print(f"no {csvs[0]}: running the EKF Monte Carlo ({n_seeds} seeds per trial) ...", flush=True)
        monte_carlo(dirs[0], n_seeds=n_seeds, verbose=verbose)
    parts = []
    for c in csvs:
        if not c.is_file():
            raise InputError(str(c), "", "file not found (a Monte Carlo folder holds runs.csv)")
        r = pd.read_csv(c, keep_default_na=False, na_values=[""])
        if "trial" not in r or "seed" not in r or not any(k.startswith("final_") for k in r.columns):
            raise InputError(str(c), "final_*", "not an EKF Monte Carlo runs.csv (mmg montecarlo, mmg log-filter)")
        parts.append(r)
    runs = pd.concat(parts, ignore_index=True)
    dup = runs[runs.duplicated(["trial", "seed"])]
    if len(dup):
        raise InputError(str(csvs[-1]), "seed", f"trial {dup.trial.iloc[0]!r} seed {dup.seed.iloc[0]} is in more than "
                                                f"one of the Monte Carlo folders")
    return runs, ", ".join(str(c) for c in csvs)


def _summary_lines(tab: pd.DataFrame, runs: pd.DataFrame, bounds: list[str]) -> list[str]:
    """Factor-2 counts and ranges of MC/CRB, the rebuilt rudder's timing error, and the design
    criteria (median and mean relative std of the nonlinear derivatives) from the Monte Carlo."""
    from .fisher import LINEAR, NONLINEAR

    lines = []
    for what, t in (("linear derivatives", tab[tab.derivative.isin(LINEAR)]), ("all derivatives", tab)):
        parts = []
        for b in bounds:
            r = t[f"mc_over_crb_{b}"].to_numpy(float)
            parts.append(f"{b} {int(np.sum((r >= 0.5) & (r <= 2.0)))}/{len(r)} (MC/CRB {r.min():.2f}-{r.max():.2f})")
        lines.append(f"{what} with MC std within a factor 2 of the bound: " + ", ".join(parts))
    if "rudder_timing_rms_s" in runs and runs["rudder_timing_n"].fillna(0).sum() > 0:
        ok = runs[runs["rudder_timing_n"].fillna(0) > 0]
        n = ok["rudder_timing_n"].to_numpy(float)
        rms = float(np.sqrt(np.sum(n * ok["rudder_timing_rms_s"].to_numpy(float) ** 2) / n.sum()))
        lines.append(f"rebuilt rudder's reversal times against the truth file's: rms {rms:.3f} s, max "
                     f"{ok['rudder_timing_max_s'].max():.3f} s over {int(n.sum())} reversals "
                     f"({', '.join(f'{t} {np.sqrt(np.average(g.rudder_timing_rms_s ** 2, weights=g.rudder_timing_n)):.3f} s' for t, g in ok.groupby('trial', sort=False))})")
    nl = tab[tab.derivative.isin(NONLINEAR)].assign(rel_mc=lambda d: 100 * d.mc_std / d.value.abs())
    b = bounds[-1]
    nl = nl.assign(rel_crb=100 * nl[f"crb_std_{b}"] / nl.value.abs())
    lines.append(f"nonlinear derivatives, std / |value| [%] (the design criteria of mmg sensitivity --design, "
                 f"bound {b}): " + "; ".join(
                     f"{t}: MC median {g.rel_mc.median():.3g} mean {g.rel_mc.mean():.3g}, CRB median "
                     f"{g.rel_crb.median():.3g} mean {g.rel_crb.mean():.3g}" for t, g in nl.groupby("trial", sort=False)))
    return lines


def crb_table(mc_dir, out, n_seeds: int = 20, verbose: bool = True, rudder_timing: float | None = 0.15) -> pd.DataFrame:
    """CRB vs the EKF Monte Carlo: runs.csv of one folder ``mc_dir`` (run there with ``n_seeds``
    seeds per trial when missing) or of several folders (a list; e.g. more seeds run later with
    ``--first-seed``), pooled per trial.

    rudder_timing: prior std [s] of the per-movement rudder-timing nuisances of the second "log"
    bound (:func:`trials.planning.fisher.fisher`); None for the rudder-known bounds only.
    """
    from .fisher import LINEAR, crb_vs_montecarlo
    from .sensitivity_plots import plot_crb_vs_mc

    P = out.path if hasattr(out, "path") else (lambda n: Path(out) / n)
    runs, src = _read_runs(mc_dir, n_seeds, verbose)
    files = {k: trial_path(v) for k, v in EKF_TRIALS.items()}
    if "trial_file" in runs:
        files.update({t: Path(f) for t, f in runs.dropna(subset=["trial_file"]).groupby("trial")["trial_file"]
                      .first().items()})
    unknown = set(runs["trial"]) - set(files)
    if unknown:
        raise InputError(src, "trial", f"unknown trial(s) {', '.join(sorted(unknown))} and no trial_file "
                                       f"column to find them")
    missing = sorted(str(f) for t, f in files.items() if t in set(runs["trial"]) and not Path(f).is_file())
    if missing:
        raise InputError(src, "trial_file", f"trial file(s) not found: {', '.join(missing)}")
    tab = crb_vs_montecarlo(runs, files, rudder_timing=rudder_timing)
    tab.to_csv(P("crb_vs_mc.csv"), index=False, float_format="%.6g")
    timing = rudder_timing is not None
    plot_crb_vs_mc(tab, P("crb_vs_mc.png"),
                   "Cramer-Rao bound (log noise) vs Monte Carlo std of the EKF estimates, per trial")
    lin = tab[tab.derivative.isin(LINEAR)]
    cols = ["trial", "derivative", "value", "runs", "mc_std", "crb_std_log", "mc_over_crb_log"]
    cols += ["crb_std_log_timing", "mc_over_crb_log_timing"] if timing else []
    cols += ["crb_std_filter", "mc_over_crb_filter"]
    summary = _summary_lines(tab, runs, ["log", "log_timing"] if timing else ["log"])
    text = ("CRB standard deviation vs the Monte Carlo standard deviation of the EKF's final estimates\n"
            f"(runs: {src}; log: the information of the 5 s log actually recorded, rudder known; "
            + (f"log_timing: the same with the timing of each rudder movement a nuisance of prior std "
               f"{rudder_timing:g} s, as the log has no rudder channel; " if timing else "")
            + "filter: Table 8 R on independent 0.1 s samples, what the paper's filter assumes)\n\n"
            + "\n".join(summary) + "\n\nLinear derivatives:\n\n"
            + lin[cols].to_string(index=False, float_format=lambda v: f"{v:.3g}")
            + "\n\nAll derivatives:\n\n" + tab[cols].to_string(index=False, float_format=lambda v: f"{v:.3g}") + "\n")
    P("crb_vs_mc.txt").write_text(text)
    if verbose:
        print(text)
    return tab


# --------------------------------------------------------------------------- design search

def design(out, backend: str = "loky", n_jobs=None, verbose: bool = True, grid=None,
           rudder_timing: float | None = 0.15) -> pd.DataFrame:
    """The trial-design search (:mod:`trials.planning.design`): design.csv, design.txt and two plots in ``out``."""
    from .design import CRITERION, TIMING, best, search
    from .sensitivity_plots import plot_design

    P = out.path if hasattr(out, "path") else (lambda n: Path(out) / n)
    base, *refs = _load([trial_path(s) for s in ("stype120", "st35", "zz10", "zz20", "sine", "sawtooth")])
    df = search(base, grid, references=[base] + refs, rudder_timing=rudder_timing, backend=backend, n_jobs=n_jobs,
                progress=verbose)
    df.to_csv(P("design.csv"), index=False, float_format="%.6g")
    timing = rudder_timing is not None
    crit_cols = [c for c in df.columns if "nonlinear_pct" in c]
    refs_df = df[df.family == "reference"]
    ref = {row["trial"]: row[crit_cols] for _, row in refs_df.iterrows() if row["trial"] in ("S-type 120", "ST35", "ZZ20")}
    sweep = df[df.family != "reference"].copy()
    sweep["x"] = sweep["value_deg"]
    which = "solid: rudder known" + (f"; dashed: rudder timing unknown ({rudder_timing:g} s prior)" if timing else "")
    stype = sweep[sweep.family.isin(["S-type psi_S"])].rename(columns={"x": "psi_S_deg"})
    plot_design(stype, P("design_stype_psiS.png"), "psi_S_deg",
                "S-type (35 deg rudder), 3000 s: CRB of the nonlinear derivatives vs switching heading psi_S "
                f"(lower is better)\n{which}", ref, alt_prefix=TIMING if timing else None)
    zz = sweep[sweep.family.isin(["zigzag a/a", "zigzag 35/a", "S-type 120, rudder"])].rename(columns={"x": "angle_deg"})
    plot_design(zz, P("design_zigzag.png"), "angle_deg",
                "Zigzag a/a and 35/a, S-type 120 with rudder a, 3000 s: CRB of the nonlinear derivatives vs angle a "
                f"(lower is better)\n{which}", ref, alt_prefix=TIMING if timing else None)
    s120 = refs_df[refs_df.trial == "S-type 120"].iloc[0]
    lines = []
    for prefix, what in [("", "rudder known")] + ([(TIMING, f"rudder timing unknown, prior std {rudder_timing:g} s "
                                                             f"per movement")] if timing else []):
        crit, dopt, med = prefix + CRITERION, prefix + "d_opt_nonlinear_pct", prefix + "median_rel_crb_nonlinear_pct"
        cols = ["family", "value_deg", "trial"] + (["rudder_movements"] if timing else []) + [
            crit, med, dopt, prefix + "mean_rel_crb_linear_pct"]
        b = best(df, crit)
        bd = df.loc[df[dopt].idxmin()]
        bm = df.loc[df[med].idxmin()]
        better = df[(df[crit] < s120[crit]) & (df.trial != "S-type 120")]
        lines += [f"Trial design, 3000 s each, log noise model, {what}; criterion = mean over the 8 nonlinear "
                  "derivatives of CRB std / |value| [%] (lower is better); D = det(relative CRB covariance)^(1/16) "
                  "[%]\n",
                  df.sort_values(crit)[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"), "",
                  f"best ({what}): {b.trial} ({b.family}) {crit} = {b[crit]:.4g} % vs S-type 120: "
                  f"{s120[crit]:.4g} % (ratio {s120[crit] / b[crit]:.2f}); "
                  f"D: {b[dopt]:.4g} % vs {s120[dopt]:.4g} %",
                  f"best by the D-criterion: {bd.trial} ({bd[dopt]:.4g} % vs S-type 120: {s120[dopt]:.4g} %)",
                  f"best by the median relative CRB (not dominated by the near-zero N_bb): {bm.trial} "
                  f"({bm[med]:.4g} % vs S-type 120: {s120[med]:.4g} %)",
                  f"trials beating S-type 120 on {crit}: "
                  + (", ".join(better.sort_values(crit).trial) if len(better) else "none"), "", ""]
    text = "\n".join(lines)
    P("design.txt").write_text(text)
    if verbose:
        print(text)
    return df
