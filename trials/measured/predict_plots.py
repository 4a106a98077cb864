"""Figures of a replay: measured against predicted track (ship outlines) and time histories."""
from __future__ import annotations

import numpy as np

from ..files.plots import TURN_RATIO, TrackView, _figure, ship_outline

__all__ = ["replay_figure", "replay_layout"]

WIDE_RATIO = 2.5
"""A track longer than this many times its width goes across the top of a replay figure."""


def replay_layout(north, east, pad: float = 0.6) -> tuple:
    """Where a replay figure puts a track (in L): (view, across the top?, track height [in]).

    A track within ``WIDE_RATIO`` of square goes in the tall left column, turned a quarter when it is long
    east-west (its long side along the column); a longer one across the top of the figure, turned when
    long north-south, its box as tall as its shape asks (2.8-5 in; the data limits fill the box, to scale).
    """
    n_span = float(np.nanmax(north) - np.nanmin(north)) + 2 * pad + 1e-12
    e_span = float(np.nanmax(east) - np.nanmin(east)) + 2 * pad + 1e-12
    ratio = max(n_span, e_span) / min(n_span, e_span)
    if ratio <= WIDE_RATIO:
        return TrackView(e_span > TURN_RATIO * n_span), False, 0.0
    view = TrackView(n_span > e_span)
    return view, True, float(np.clip(13.0 / ratio, 2.8, 5.0))


def replay_figure(rep, title: str | None = None, pyplot: bool = True, bands=None):
    """Track with ship outlines (left, or across the top for a long track: :func:`replay_layout`) and
    heading, yaw rate, speed, rudder and revolutions of a :class:`trials.measured.predict.Replayed`, measured
    (black) against predicted (red).  The track is to scale, its start marked, the legend below it; the
    panels are packed by matplotlib's constrained layout, every legend on the canvas.

    A replay that diverged (:attr:`~trials.measured.predict.Replayed.diverged_at`) is marked by a dotted
    line at that time and in the titles, and every panel keeps the measured record's range (its span
    again on each side), so the run-away prediction leaves the axes instead of squashing the record
    to a flat line.

    With ``bands`` (:class:`trials.measured.bands.Bands`) the heading panel shows the record's unwrapped
    heading, the nominal prediction on its turn and the shaded 90 % band, and the track a few drawn tracks
    and the 90 % position band's circles about the median track at the outlines' times.

    Returns
    -------
    matplotlib.figure.Figure
    """
    m, p, L = rep.run.meas, rep.pred, rep.L
    title = title or rep.run.name
    t_div = rep.diverged_at
    div = "" if t_div is None else f"\nreplay diverged at t = {t_div:.1f} s"
    shown = m if t_div is not None else np.vstack([m, p[np.all(np.isfinite(p[:, 3:5]), axis=1)]])
    view, wide, track_h = replay_layout(shown[:, 3] / L, shown[:, 4] / L)      # the track as drawn
    if wide:                     # a long track across the top, turned so its long side runs across
        fig = _figure((14, 8 + track_h), pyplot)
        gs = fig.add_gridspec(6, 1, height_ratios=[track_h / 1.4] + [1.0] * 5)
        ax = fig.add_subplot(gs[0, 0])
        cell = lambda k: gs[k + 1, 0]                                     # noqa: E731
    else:
        fig = _figure((14, 8), pyplot)
        gs = fig.add_gridspec(5, 2, width_ratios=[1.0, 1.2])
        ax = fig.add_subplot(gs[:, 0])
        cell = lambda k: gs[k, 1]                                         # noqa: E731
    _replay_track(ax, view, rep, bands, shown, wide, f"{title}: track (L = {L:g} m, wind {rep.run.wind}){div}")
    _replay_histories(fig, cell, rep, bands, f"{title}: time histories{div}")
    fig.set_layout_engine("constrained", h_pad=0.02, hspace=0.0)
    return fig


def _measured_range(x) -> tuple:
    """The range of ``x`` with its span again on each side (a panel's limits where the replay diverged)."""
    lo, hi = float(np.nanmin(x)), float(np.nanmax(x))
    pad = max(hi - lo, 1e-6 * max(abs(lo), abs(hi), 1.0))
    return lo - pad, hi + pad


def _replay_track(ax, view, rep, bands, shown, wide: bool, title: str) -> None:
    """:func:`replay_figure`'s track: measured and predicted, the start, outlines to scale, the bands."""
    m, p, t, L, B = rep.run.meas, rep.pred, rep.run.t, rep.L, rep.B
    ax.plot(*view.hv(m[:, 3] / L, m[:, 4] / L), "k-", lw=1.2, label="measured")
    ax.plot(*view.hv(p[:, 3] / L, p[:, 4] / L), "r--", lw=1.2, label="predicted")
    ax.plot(*view.hv(m[:1, 3] / L, m[:1, 4] / L), "o", color="g", ms=6, zorder=3, label="start")
    every = max((t[-1] - t[0]) / 12, 1e-9)
    first = True
    for tk in np.arange(t[0], t[-1] + 1e-9, every):
        i = min(int(np.searchsorted(t, tk)), len(t) - 1)
        for s, ec, lab in ((m, "k", "outline, measured"), (p, "r", "outline, predicted")):
            if np.all(np.isfinite(s[i])):
                px, py = ship_outline(s[i, 3], s[i, 4], s[i, 5], L, B)
                ax.fill(*view.hv(px / L, py / L), fc="none", ec=ec, lw=0.6,
                        label=f"{lab} (to scale), every {every:.0f} s" if first else None)
        first = False
    if bands is not None:
        _track_bands(ax, view, bands, L, t, every, shown[:, 3:5])
    if rep.diverged_at is not None:
        hlim, vlim = view.hv(_measured_range(m[:, 3] / L), _measured_range(m[:, 4] / L))
        ax.set_xlim(*hlim)
        ax.set_ylim(*vlim)
    view.finish(ax)
    ax.set_title(title)
    # the legend below the track, 4.5 font sizes under it: clear of the ticks and the axis label
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), borderaxespad=4.5, ncol=3 if wide else 2, fontsize=8,
              frameon=False)


def _replay_histories(fig, cell, rep, bands, title: str) -> None:
    """:func:`replay_figure`'s time histories in the cells ``cell(0..4)``: heading (with the band), yaw rate,
    speed, sway, and the inputs."""
    m, p, t, t_div = rep.run.meas, rep.pred, rep.run.t, rep.diverged_at
    rows = [("heading (deg)", np.degrees(m[:, 5]), np.degrees(p[:, 5])) if bands is None else
            ("heading (deg)\nunwrapped", bands.heading_deg, bands.nominal_deg),
            ("yaw rate (deg/s)", np.degrees(m[:, 2]), np.degrees(p[:, 2])),
            ("speed (m/s)", np.hypot(m[:, 0], m[:, 1]), np.hypot(p[:, 0], p[:, 1])),
            ("sway v (m/s)", m[:, 1], p[:, 1])]
    axs = []
    for k, (lab, a, b) in enumerate(rows):
        a_ = fig.add_subplot(cell(k), sharex=axs[0] if axs else None)
        if k == 0 and bands is not None:
            _heading_band(a_, t, bands)
        a_.plot(t, a, "k-", lw=1, label="measured")
        a_.plot(t, b, "r--", lw=1, label="predicted" if bands is None else "predicted, nominal ship and start")
        if t_div is not None:
            a_.axvline(t_div, color="r", ls=":", lw=1.2, label=f"replay diverged (t = {t_div:.1f} s)")
            a_.set_ylim(*_measured_range(a))
        a_.set_ylabel(lab)
        a_.grid(True, alpha=0.3)
        axs.append(a_)
    if bands is not None:        # room above the data for the legend
        lo, hi = axs[0].get_ylim()
        axs[0].set_ylim(lo, hi + 0.7 * (hi - lo))
        axs[0].legend(loc="upper left", fontsize=7, ncol=2)
    else:
        axs[0].legend(loc="best", fontsize=8)
    axs[0].set_title(title)
    a_ = fig.add_subplot(cell(4), sharex=axs[0])
    a_.plot(t, np.degrees(rep.run.inputs.delta), "b-", lw=1, label="rudder (deg)")
    a_.plot(t, rep.run.inputs.n, "g-", lw=1, label="revolutions (rps)")
    a_.set_ylabel("inputs")
    a_.set_xlabel("t (s)")
    a_.grid(True, alpha=0.3)
    a_.legend(loc="best", fontsize=8)
    for a in axs:
        a.tick_params(labelbottom=False)


def _track_bands(ax, view, bands, L: float, t, every: float, shown) -> None:
    """A few drawn tracks and the 90 % position band (circles of its radius about the median track) on the track,
    both cut where they leave the box of the ``shown`` positions [m] widened by its span on each side (a
    diverging draw runs off to 1e14 m: it would squash the record to a point)."""
    lo, hi = np.nanmin(shown, axis=0), np.nanmax(shown, axis=0)
    pad = np.maximum(hi - lo, L)

    def cut(x, y):
        out = (x < lo[0] - pad[0]) | (x > hi[0] + pad[0]) | (y < lo[1] - pad[1]) | (y > hi[1] + pad[1])
        return np.where(out, np.nan, x) / L, np.where(out, np.nan, y) / L

    for k, tr in enumerate(bands.tracks):
        ax.plot(*view.hv(*cut(tr[:, 0], tr[:, 1])), "-", color="tab:blue", lw=0.5, alpha=0.5,
                label=f"drawn tracks ({len(bands.tracks)} of {bands.draws}; cut at the box of the record)" if k == 0
                else None)
    ang = np.linspace(0.0, 2 * np.pi, 49)
    first = True
    for tk in np.arange(t[0] + every, t[-1] + 1e-9, every):
        i = min(int(np.searchsorted(t, tk)), len(t) - 1)
        r, xm, ym = bands.radius[i], bands.x_median[i], bands.y_median[i]
        if np.isfinite(r) and np.isfinite(xm) and np.isfinite(ym):
            ax.plot(*view.hv(*cut(xm + r * np.cos(ang), ym + r * np.sin(ang))), "-", color="tab:purple",
                    lw=0.9, label="90 % position band about the median track" if first else None)
            first = False


def _heading_band(ax, t, bands) -> None:
    """The shaded 90 % heading band, and where diverged draws leave it unbounded, hatched over the panel's height."""
    ok = np.isfinite(bands.lo) & np.isfinite(bands.hi)
    ax.fill_between(t, np.where(ok, bands.lo, np.nan), np.where(ok, bands.hi, np.nan), color="tab:blue", alpha=0.25,
                    lw=0, label=f"90 % band, {bands.draws} draws ({bands.diverged} diverged); "
                                f"record inside {100 * bands.coverage90:.0f} % of samples")
    if not ok.all():
        ax.fill_between(t, 0, 1, where=~ok, transform=ax.get_xaxis_transform(), facecolor="none",
                        edgecolor="tab:blue", hatch="//", lw=0, alpha=0.5,
                        label="band unbounded there (over 5 % of the draws diverged)")
