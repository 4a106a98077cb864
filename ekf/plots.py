"""Figures of the estimator: recovered measurements vs truth (Rhee & Kim Figs 4-5) and
convergence of each coefficient (Figs 15-26). The numerics in :mod:`ekf.preprocess` and
:mod:`ekf.estimate` import no plotting; this module does (matplotlib imported on first use,
the backend left to the user: PNGs are written with the figure's own canvas).
"""
from __future__ import annotations

from pathlib import Path

from mmg.terms import latex_label
from mmg.units import DEG

from .filter import NS
from .preprocess import CHANNELS, Measurements, compare_with_truth


def _plt():
    import matplotlib.pyplot as plt

    return plt


def plot_comparison(meas: Measurements, truth, path, title: str = "") -> dict:
    """Rhee & Kim Figs 4-5 for all channels: recovered vs true, with RMS in each panel. Returns the RMS."""
    plt = _plt()
    rms = compare_with_truth(meas, truth)
    scale = {"u": (1.0, "m/s"), "v": (1.0, "m/s"), "r": (1 / DEG, "deg/s"), "delta": (1 / DEG, "deg"),
             "n": (60.0, "rpm")}
    fig, axs = plt.subplots(len(CHANNELS), 1, figsize=(9, 11), sharex=True)
    for ax, ch in zip(axs, CHANNELS):
        k, unit = scale[ch]
        ax.plot(truth.t, getattr(truth, ch) * k, "k-", lw=1.0, label="true (simulation)")
        ax.plot(meas.t, getattr(meas, ch) * k, "r-", lw=0.6, alpha=0.8, label="recovered from log")
        ax.set_ylabel(f"{ch} [{unit}]")
        ax.set_title(f"{ch}: RMS difference {rms[ch] * k:.3g} {unit}", fontsize=9)
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=8)
    axs[-1].set_xlabel("time [s]")
    fig.suptitle(title or f"Recovered measurements vs truth: {meas.name} (Rhee & Kim Figs 4-5)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return rms


def convergence_figure(ests: list, names=None, stride: int = 10, show: bool = False):
    """One figure, a panel per coefficient, every estimate's history (true value dashed where known)."""
    import numpy as np

    plt = _plt()
    names = list(names or ests[0].result.names)
    nc = 3 if len(names) > 4 else len(names)
    nr = int(np.ceil(len(names) / nc))
    fig, axs = plt.subplots(nr, nc, figsize=(4.2 * nc, 2.6 * nr), sharex=True, squeeze=False)
    for ax, n in zip(axs.flat, names):
        for e in ests:
            r = e.result
            i = list(r.names).index(n)
            ax.plot(r.t[::stride], r.z[::stride, NS + i], lw=1.0, label=e.name)
        tv = next((e.data.true_values for e in ests if e.data.true_values), None)
        if tv:
            ax.axhline(tv[n], color="k", ls="--", lw=1.0, label="true")
        ax.set_title(latex_label(n), fontsize=10)
        ax.grid(alpha=0.3)
    for ax in axs.flat[len(names):]:
        ax.set_visible(False)
    for ax in axs[-1]:
        ax.set_xlabel("time [s]")
    axs.flat[0].legend(fontsize=7)
    fig.suptitle(f"Convergence of the hull coefficients (augmented EKF): {', '.join(e.name for e in ests)}")
    fig.tight_layout()
    if show:
        plt.show()
    return fig


def plot_convergence(ests: list, out_dir: str | Path, stride: int = 10) -> list[Path]:
    """One PNG per coefficient with every trial's estimate history (Rhee & Kim Figs 15-26)."""
    plt = _plt()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    for n in ests[0].result.names:
        fig, ax = plt.subplots(figsize=(7, 4))
        for e in ests:
            r = e.result
            i = list(r.names).index(n)
            ax.plot(r.t[::stride], r.z[::stride, NS + i], lw=1.0, label=e.name)
        tv = next((e.data.true_values for e in ests if e.data.true_values), None)
        if tv:
            ax.axhline(tv[n], color="k", ls="--", lw=1.0, label="true")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"{latex_label(n)} [-] (non-dimensional)")
        ax.set_title(f"Convergence of {n} (augmented EKF, cf. Rhee & Kim Figs 15-26)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        p = out_dir / f"convergence_{n}.png"
        fig.savefig(p, dpi=100)
        plt.close(fig)
        paths.append(p)
    return paths
