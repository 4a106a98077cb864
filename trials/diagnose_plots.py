"""Figures of ``mmg diagnose``: per record, residual time series before and after the named
effects (u, v, r, heading, distance) and the tracks measured / before / after."""
from __future__ import annotations

import numpy as np


def diagnose_figure(diag, i: int):
    """Figure for record ``i`` of a :class:`trials.diagnose.Diagnosis` (not pyplot-managed)."""
    from matplotlib.figure import Figure

    rec = diag.records[i]
    t = rec.seg.inputs.t
    m, b, a = rec.seg.meas, diag.pred_before[i], diag.pred_after[i]
    fig = Figure(figsize=(11, 8), layout="constrained")
    gs = fig.add_gridspec(5, 2)
    rows = [("u [m/s]", lambda p: p[:, 0] - m[:, 0]), ("v [m/s]", lambda p: p[:, 1] - m[:, 1]),
            ("r [deg/s]", lambda p: np.degrees(p[:, 2] - m[:, 2])),
            ("heading [deg]", lambda p: np.degrees(p[:, 5] - m[:, 5])),
            ("distance [m]", lambda p: np.hypot(p[:, 3] - m[:, 3], p[:, 4] - m[:, 4]))]
    for k, (lab, f) in enumerate(rows):
        ax = fig.add_subplot(gs[k, 0])
        ax.plot(t, f(b), lw=0.8, label="before (ship fitted, no effect)")
        ax.plot(t, f(a), lw=0.8, label="after (" + (", ".join(diag.named) or "nothing named") + ")")
        ax.set_ylabel(lab, fontsize=8)
        ax.tick_params(labelsize=7)
        if k == 0:
            ax.legend(fontsize=7)
            ax.set_title(f"{rec.name}: residual (replay - log), segments restart from the log", fontsize=9)
    ax.set_xlabel("t [s]")
    ax = fig.add_subplot(gs[:, 1])
    ax.plot(m[:, 4], m[:, 3], "k", lw=1.2, label="logged")
    ax.plot(b[:, 4], b[:, 3], lw=0.8, label="before")
    ax.plot(a[:, 4], a[:, 3], lw=0.8, label="after")
    ax.set_aspect("equal", "datalim")
    ax.set_xlabel("y east [m]")
    ax.set_ylabel("x north [m]")
    ax.legend(fontsize=8)
    ax.set_title("track (segment-wise replay)", fontsize=9)
    return fig
