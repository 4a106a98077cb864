"""Figures of a replay: measured against predicted track (ship outlines) and time histories."""
from __future__ import annotations

import numpy as np

from .plots import _figure, ship_outline

__all__ = ["replay_figure"]


def replay_figure(rep, title: str | None = None, pyplot: bool = True):
    """Track with ship outlines (left) and heading, yaw rate, speed, rudder and revolutions
    (right) of a :class:`trials.predict.Replayed`, measured (black) against predicted (red).

    A replay that diverged (:attr:`~trials.predict.Replayed.diverged_at`) is marked by a dotted
    line at that time and in the titles, and every panel keeps the measured record's range (its span
    again on each side), so the run-away prediction leaves the axes instead of squashing the record
    to a flat line.

    Returns
    -------
    matplotlib.figure.Figure
    """
    run, p, L, B = rep.run, rep.pred, rep.L, rep.B
    m, t = run.meas, run.t
    title = title or run.name
    t_div = rep.diverged_at
    div = "" if t_div is None else f"\nreplay diverged at t = {t_div:.1f} s"

    def keep_measured_range(x):
        lo, hi = float(np.nanmin(x)), float(np.nanmax(x))
        pad = max(hi - lo, 1e-6 * max(abs(lo), abs(hi), 1.0))
        return lo - pad, hi + pad

    fig = _figure((14, 8), pyplot)
    gs = fig.add_gridspec(5, 2, width_ratios=[1.0, 1.2])
    ax = fig.add_subplot(gs[:, 0])
    ax.plot(m[:, 4] / L, m[:, 3] / L, "k-", lw=1.2, label="measured")
    ax.plot(p[:, 4] / L, p[:, 3] / L, "r--", lw=1.2, label="predicted")
    every = max((t[-1] - t[0]) / 12, 1e-9)
    first = True
    for tk in np.arange(t[0], t[-1] + 1e-9, every):
        i = min(int(np.searchsorted(t, tk)), len(t) - 1)
        for s, ec, lab in ((m, "k", "outline, measured"), (p, "r", "outline, predicted")):
            if np.all(np.isfinite(s[i])):
                px, py = ship_outline(s[i, 3], s[i, 4], s[i, 5], L, B)
                ax.fill(py / L, px / L, fc="none", ec=ec, lw=0.6, label=lab if first else None)
        first = False
    if t_div is not None:
        ax.set_xlim(*keep_measured_range(m[:, 4] / L))
        ax.set_ylim(*keep_measured_range(m[:, 3] / L))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("y, east (L)")
    ax.set_ylabel("x, north (L)")
    ax.set_title(f"{title}: track (L = {L:g} m, wind {run.wind}){div}")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    rows = [("heading (deg)", np.degrees(m[:, 5]), np.degrees(p[:, 5])),
            ("yaw rate (deg/s)", np.degrees(m[:, 2]), np.degrees(p[:, 2])),
            ("speed (m/s)", np.hypot(m[:, 0], m[:, 1]), np.hypot(p[:, 0], p[:, 1])),
            ("sway v (m/s)", m[:, 1], p[:, 1])]
    axs = []
    for k, (lab, a, b) in enumerate(rows):
        a_ = fig.add_subplot(gs[k, 1], sharex=axs[0] if axs else None)
        a_.plot(t, a, "k-", lw=1, label="measured")
        a_.plot(t, b, "r--", lw=1, label="predicted")
        if t_div is not None:
            a_.axvline(t_div, color="r", ls=":", lw=1.2, label=f"replay diverged (t = {t_div:.1f} s)")
            a_.set_ylim(*keep_measured_range(a))
        a_.set_ylabel(lab)
        a_.grid(True, alpha=0.3)
        axs.append(a_)
    axs[0].legend(loc="best", fontsize=8)
    axs[0].set_title(f"{title}: time histories{div}")
    a_ = fig.add_subplot(gs[4, 1], sharex=axs[0])
    a_.plot(t, np.degrees(run.inputs.delta), "b-", lw=1, label="rudder (deg)")
    a_.plot(t, run.inputs.n, "g-", lw=1, label="revolutions (rps)")
    a_.set_ylabel("inputs")
    a_.set_xlabel("t (s)")
    a_.grid(True, alpha=0.3)
    a_.legend(loc="best", fontsize=8)
    for a in axs:
        a.tick_params(labelbottom=False)
    fig.tight_layout()
    return fig
