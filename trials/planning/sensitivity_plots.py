"""Bar charts of sensitivities (Rhee & Kim Figs 2, 8-9, 12-14), estimation efficiency (Fig. 28)
and the trial-design criterion curves.  PNG, Agg backend."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from mmg.terms import latex_label

from .sensitivity import DERIVATIVES

LABELS = {n: latex_label(n) for n in DERIVATIVES}


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _bars(ax, table: pd.DataFrame, xlabels):
    """Grouped bars: rows of ``table`` on the x axis, one bar per column."""
    n = len(table.columns)
    x = np.arange(len(table.index))
    w = 0.8 / max(n, 1)
    for j, c in enumerate(table.columns):
        ax.bar(x + (j - (n - 1) / 2) * w, table[c].to_numpy(float), w, label=str(c))
    ax.set_xticks(x)
    ax.set_xticklabels(xlabels)
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=8)


def plot_sensitivity(df: pd.DataFrame, path, title: str | None = None) -> Path:
    """Sensitivity [%] of each derivative, one bar per trial (the group of ``df`` sums to 100 %)."""
    plt = _plt()
    trials = list(dict.fromkeys(df["trial"]))
    tab = df.pivot(index="derivative", columns="trial", values="sensitivity_pct").reindex(DERIVATIVES)[trials]
    fig, ax = plt.subplots(figsize=(10, 4.5))
    _bars(ax, tab, [LABELS[n] for n in DERIVATIVES])
    ax.set_xlabel("hydrodynamic derivative (perturbed to 120 %)")
    ax.set_ylabel("sensitivity S [%] (eq. 22; group sums to 100 %)")
    ax.set_title(title or f"Sensitivity of the derivatives: {', '.join(trials)}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def plot_groups(tab: pd.DataFrame, path, title: str, ylabel: str) -> Path:
    """Fig. 14 / Fig. 28 layout: groups (linear, nonlinear, total/overall) on x, one bar per trial.

    ``tab`` index = trials, columns = groups.
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    _bars(ax, tab.T, list(tab.columns))
    ax.set_xlabel("derivative group")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def plot_design(df: pd.DataFrame, path, param: str, title: str, reference: dict | None = None,
                criterion: str = "mean_rel_crb_nonlinear_pct", alt_prefix: str | None = None) -> Path:
    """Criterion against the swept parameter, one line per trial family; optional reference lines.

    reference: trial name -> row (mapping of criterion columns) drawn as horizontal lines;
    alt_prefix: also draw the columns ``alt_prefix + criterion`` dashed in the family's colour
    (e.g. the criteria with the rudder timing unknown).
    """
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    crit2 = criterion.replace("mean_rel_crb", "d_opt")
    for ax, c, lab in ((axes[0], criterion, "mean CRB std / |value| of the 8 nonlinear derivatives [%]"),
                       (axes[1], crit2, "D-criterion: det(rel. CRB cov)^(1/16) [%]")):
        for fam, g in df.groupby("family", sort=False):
            g = g.sort_values(param)
            line, = ax.plot(g[param], g[c], "o-", label=fam)
            if alt_prefix and alt_prefix + c in g:
                ax.plot(g[param], g[alt_prefix + c], "o--", mfc="none", color=line.get_color())
        for (name, row), ls in zip((reference or {}).items(), ("--", ":", "-.", (0, (5, 1)))):
            ax.axhline(row[c], ls=ls, lw=1.2, color="k" if "120" in name else "0.45", label=name)
        ax.set_yscale("log")
        ax.set_xlabel(param.replace("_deg", " [deg]"))
        ax.set_ylabel(lab, fontsize=9)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def plot_crb_vs_mc(tab: pd.DataFrame, path, title: str) -> Path:
    """CRB std (``crb_std_log``, and ``crb_std_log_timing`` when present) and Monte Carlo std
    (``mc_std``) of the EKF estimates, per trial and derivative (log scale)."""
    plt = _plt()
    trials = list(dict.fromkeys(tab["trial"]))
    fig, axes = plt.subplots(1, len(trials), figsize=(3.4 * len(trials), 4.2), sharey=True, squeeze=False)
    for ax, tr in zip(axes[0], trials):
        g = tab[tab.trial == tr].set_index("derivative").reindex(DERIVATIVES)
        x = np.arange(len(DERIVATIVES))
        bars = [("crb_std_log", "CRB, rudder known"), ("crb_std_log_timing", "CRB, rudder timing unknown"),
                ("mc_std", "EKF Monte Carlo")]
        bars = [b for b in bars if b[0] in g]
        w = 0.8 / len(bars)
        for i, (col, lab) in enumerate(bars):
            ax.bar(x + (i - (len(bars) - 1) / 2) * w, g[col], w, label=lab)
        ax.set_xticks(x)
        ax.set_xticklabels([LABELS[n] for n in DERIVATIVES], rotation=90, fontsize=7)
        ax.set_yscale("log")
        ax.set_title(tr, fontsize=9)
        ax.grid(axis="y", alpha=0.3, which="both")
    axes[0][0].set_ylabel("standard deviation of the estimate [-] (non-dimensional)")
    axes[0][0].legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
