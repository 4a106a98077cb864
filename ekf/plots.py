"""Figures of the estimator: recovered measurements vs truth (Rhee & Kim Figs 4-5) and
convergence of each derivative (Figs 15-26). The numerics in :mod:`ekf.preprocess` and
:mod:`ekf.estimate` import no plotting; this module does.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from mmg.units import DEG  # noqa: E402
from trials.sensitivity_plots import LABELS  # noqa: E402  (LaTeX names of the derivatives)

from typing import TYPE_CHECKING  # noqa: E402

from .filter import DERIVATIVES, NS  # noqa: E402
from .preprocess import CHANNELS, Measurements, compare_with_truth  # noqa: E402

if TYPE_CHECKING:
    from .estimate import Estimate



def plot_comparison(meas: Measurements, truth, path, title: str = "") -> dict:
    """Rhee & Kim Figs 4-5 for all channels: recovered vs true, with RMS in each panel. Returns the RMS."""
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


def plot_convergence(ests: list[Estimate], out_dir: str | Path, stride: int = 10) -> list[Path]:
    """One PNG per derivative with every trial's estimate history (Rhee & Kim Figs 15-26)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    for i, n in enumerate(DERIVATIVES):
        fig, ax = plt.subplots(figsize=(7, 4))
        for e in ests:
            r = e.result
            ax.plot(r.t[::stride], r.z[::stride, NS + i], lw=1.0, label=e.name)
        tv = next((e.data.true_values for e in ests if e.data.true_values), None)
        if tv:
            ax.axhline(tv[n], color="k", ls="--", lw=1.0, label="real")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"{LABELS[n]} [-] (non-dimensional)")
        ax.set_title(f"Convergence of {n} (augmented EKF, cf. Rhee & Kim Figs 15-26)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        p = out_dir / f"convergence_{n}.png"
        fig.savefig(p, dpi=100)
        plt.close(fig)
        paths.append(p)
    return paths
