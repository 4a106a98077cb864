"""Figures of ``mmg diagnose``: per record, residual time series before and after the named
effects (u, v, r, heading, distance) and the tracks measured / before / after."""
from __future__ import annotations

import numpy as np

from .predict_plots import replay_layout


def diagnose_figure(diag, i: int):
    """Figure for record ``i`` of a :class:`trials.measured.diagnose.Diagnosis` (not pyplot-managed).

    The track is to scale, its start marked, its legend off the data; a long track runs across the bottom,
    turned so its long side is horizontal (:func:`trials.measured.predict_plots.replay_layout`)."""
    from matplotlib.figure import Figure

    rec = diag.records[i]
    t = rec.seg.inputs.t
    m, b, a = rec.seg.meas, diag.pred_before[i], diag.pred_after[i]
    # the track as drawn (no outlines: no padding): a long one across the bottom
    shown = np.vstack([q[np.all(np.isfinite(q[:, 3:5]), axis=1)] for q in (m, b, a)])
    view, wide, track_h = replay_layout(shown[:, 3], shown[:, 4], pad=0.0)
    view.unit = "m"
    fig = Figure(figsize=(11, 8 + (track_h if wide else 0)), layout="constrained")
    if wide:
        gs = fig.add_gridspec(6, 1, height_ratios=[1.0] * 5 + [track_h / 1.3])
        cell, track_cell = (lambda k: gs[k, 0]), gs[5, 0]                  # noqa: E731
    else:
        gs = fig.add_gridspec(5, 2)
        cell, track_cell = (lambda k: gs[k, 0]), gs[:, 1]                  # noqa: E731
    rows = [("u [m/s]", lambda p: p[:, 0] - m[:, 0]), ("v [m/s]", lambda p: p[:, 1] - m[:, 1]),
            ("r [deg/s]", lambda p: np.degrees(p[:, 2] - m[:, 2])),
            ("heading [deg]", lambda p: np.degrees(p[:, 5] - m[:, 5])),
            ("distance [m]", lambda p: np.hypot(p[:, 3] - m[:, 3], p[:, 4] - m[:, 4]))]
    for k, (lab, f) in enumerate(rows):
        ax = fig.add_subplot(cell(k))
        ax.plot(t, f(b), lw=0.8, label="before (ship fitted, no effect)")
        ax.plot(t, f(a), lw=0.8, label="after (" + (", ".join(diag.named) or "nothing named") + ")")
        ax.set_ylabel(lab, fontsize=8)
        ax.tick_params(labelsize=7)
        if k == 0:
            ax.legend(fontsize=7)
            ax.set_title(f"{rec.name}: residual (replay - log), segments restart from the log", fontsize=9)
    ax.set_xlabel("t [s]")
    ax = fig.add_subplot(track_cell)
    ax.plot(*view.hv(m[:, 3], m[:, 4]), "k", lw=1.2, label="logged")
    ax.plot(*view.hv(b[:, 3], b[:, 4]), lw=0.8, label="before")
    ax.plot(*view.hv(a[:, 3], a[:, 4]), lw=0.8, label="after")
    ax.plot(*view.hv(m[:1, 3], m[:1, 4]), "o", color="g", ms=5, zorder=3, label="start")
    view.finish(ax)
    ax.tick_params(labelsize=7)
    if wide:                 # the legend beside the track, off the data
        ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    else:                    # ... or below it
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=4, frameon=False)
    ax.set_title("track (segment-wise replay)", fontsize=9)
    return fig

