"""The figures of an :class:`~trials.imo.result.ImoResult`: turning-circle tracks with ship outlines,
zigzag heading and rudder histories, the sampled criteria's distributions with their limits."""
from __future__ import annotations

import numpy as np

from mmg.units import DEG

from ..files.plots import _figure, ship_outline
from .standard import SIDES, STOPPING_RUN

__all__ = ["tracks_figure", "zigzags_figure", "stopping_figure", "distributions_figure"]

COLOURS = {"starboard": "tab:green", "port": "tab:red"}
_STYLE = {"smallest": (0, (1, 1)), "median": "-.", "largest": (0, (5, 2))}


def tracks_figure(res, pyplot: bool = True):
    """Both turning circles of ``res`` in ship lengths (x north, y east from the execute point), hull
    outlines every quarter of the time to 180 deg, the advance and tactical diameter in the legend; with
    samples also the samples' smallest, median and largest turns (outlines at 180 deg)."""
    fig = _figure((9.0, 8.0) if res.sample_runs else (8.0, 7.0), pyplot)
    ax = fig.add_subplot(1, 1, 1)
    L, B = res.L, res.B
    for s in SIDES:
        run, m = res.runs[f"turning circle, {s}"]
        t, x, y, psi = run.t, run.x / L, run.y / L, run.psi
        t180 = m.get("time_to_180_s") or t[-1]
        keep = t <= min(t[-1], 1.6 * t180)
        adv, tac = m.get("advance_L"), m.get("tactical_diameter_L")
        label = (f"{s} turn ({abs(m.get('rudder_deg') or res.runs[f'turning circle, {s}'][0].trial.manoeuvre['rudder'] / DEG):g} "
                 f"deg): advance {adv:.2f} L, tactical diameter {tac:.2f} L" if adv is not None and tac is not None
                 else f"{s} turn")
        ax.plot(y[keep], x[keep], color=COLOURS[s], lw=1.5, label=label)
        for tk in np.linspace(0.0, min(t[-1], t180), 5):
            i = int(np.searchsorted(t, tk))
            i = min(i, len(t) - 1)
            px, py = ship_outline(x[i], y[i], psi[i], 1.0, B / L)
            ax.fill(py, px, facecolor="none", edgecolor=COLOURS[s], lw=0.8)
    for label, (run, m) in res.sample_runs.items():
        side = "starboard" if "starboard" in label else "port"
        t180 = m.get("time_to_180_s") or run.t[-1]
        keep = run.t <= min(run.t[-1], 1.6 * t180)
        which = label.split(": ")[1].split()[0]
        tac = m.get("tactical_diameter_L")
        ax.plot(run.y[keep] / L, run.x[keep] / L, color=COLOURS[side], lw=0.8, ls=_STYLE[which],
                label=f"{side}, {which} sampled tactical diameter ({tac:.2f} L)" if tac is not None else None)
        if which != "median":
            i = min(int(np.searchsorted(run.t, t180)), len(run.t) - 1)
            px, py = ship_outline(run.x[i] / L, run.y[i] / L, run.psi[i], 1.0, B / L)
            ax.fill(py, px, facecolor="none", edgecolor=COLOURS[side], lw=0.6, ls=_STYLE[which])
    ax.axhline(4.5, color="k", ls=":", lw=0.8, label="advance limit 4.5 L (MSC.137(76) 5.3.1)")
    for v in (-5.0, 5.0):
        ax.axvline(v, color="k", ls="--", lw=0.8)
    ax.plot([], [], color="k", ls="--", lw=0.8, label="tactical diameter limit 5 L")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("y, east (L)")
    ax.set_ylabel("x, north (L)")
    ax.set_title(f"{res.ship}: turning circles at {res.speed} (approach heading north)")
    ax.grid(True, alpha=0.3)
    n = len(ax.get_legend_handles_labels()[1])
    ax.legend(loc="upper center", fontsize=7, bbox_to_anchor=(0.5, -0.1), ncol=1 if n <= 5 else 2)
    fig.subplots_adjust(bottom=0.3 if n > 5 else 0.27)
    return fig


def zigzags_figure(res, pyplot: bool = True):
    """Heading change and rudder angle against time of the 10/10 and 20/20 zigzags to both sides."""
    fig = _figure((10.0, 9.0), pyplot)
    for k, kind in enumerate(("10/10", "20/20")):
        ax = fig.add_subplot(2, 1, k + 1)
        for s in SIDES:
            run, m = res.runs[f"{kind} zigzag, {s}"]
            t = run.t
            ov = m.get("overshoots_deg") or []
            ovs = ", ".join(f"{v:.1f}" for v in ov[:2])
            ax.plot(t, (run.psi - run.psi[0]) / DEG, color=COLOURS[s], lw=1.5,
                    label=f"heading change, first to {s} (overshoots {ovs} deg)")
            ax.plot(t, run.delta / DEG, color=COLOURS[s], lw=0.8, ls="--", label=f"rudder, first to {s}")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("angle (deg)")
        ax.set_title(f"{res.ship}: {kind} zigzags at {res.speed}")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.17), ncol=2)
    fig.subplots_adjust(hspace=0.75, bottom=0.14, top=0.95)
    return fig


def stopping_figure(res, pyplot: bool = True):
    """The full-astern stopping test of ``res``: the track in ship lengths (x north, y east from the point
    of the astern order) with hull outlines every minute-scale interval and the 15 L / 20 L track-reach
    limits; beside it the surge speed [kn] and the revolutions [rpm] against time.  The track's axes span
    the track and the 15 L line with a margin (:func:`_stopping_view`), to scale."""
    from mmg.units import KNOT

    run, m = res.runs[STOPPING_RUN]
    L, B = res.L, res.B
    t, x, y, psi = run.t, run.x / L, run.y / L, run.psi
    fig = _figure((10.0, 7.0), pyplot)
    gs = fig.add_gridspec(2, 2, width_ratios=[1.0, 1.4])
    ax = fig.add_subplot(gs[:, 0])
    tr = m.get("track_reach_L")
    label = ("track" if tr is None else f"track: track reach {tr:.2f} L, head reach {m['head_reach_L']:.2f} L, "
             f"lateral deviation {m['lateral_deviation_L']:+.2f} L")
    ax.plot(y, x, color="tab:blue", lw=1.5, label=label)
    for tk in np.linspace(0.0, t[-1], 7):
        i = min(int(np.searchsorted(t, tk)), len(t) - 1)
        px, py = ship_outline(x[i], y[i], psi[i], 1.0, B / L)
        ax.fill(py, px, facecolor="none", edgecolor="tab:blue", lw=0.8)
    ax.axhline(15.0, color="tab:red", ls="--", lw=0.8,
               label="15 L ahead of the order: the track-reach limit (MSC.137(76) 5.3.4)")
    (e0, e1), (n0, n1) = _stopping_view(x, y)
    if n1 >= 20.0:
        ax.axhline(20.0, color="tab:red", ls=":", lw=0.8,
                   label="20 L: the most the Administration may accept for large ships")
    ax.set_xlim(e0, e1)
    ax.set_ylim(n0, n1)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("y, east (L)")
    ax.set_ylabel("x, north (L)")
    fig.suptitle(f"{res.ship}: full astern from {res.speed}, rudder midships", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.1))
    a1 = fig.add_subplot(gs[0, 1])
    a1.plot(t / 60.0, run.u / KNOT, color="tab:blue")
    a1.set_ylabel("surge speed u (kn)")
    a1.set_title(f"stopped after {t[-1] / 60:.1f} min (u down to 1 % of V)", fontsize=9)
    a1.grid(True, alpha=0.3)
    a2 = fig.add_subplot(gs[1, 1], sharex=a1)
    a2.plot(t / 60.0, run.n * 60.0, color="tab:orange")
    a2.set_ylabel("revolutions (rpm)")
    a2.set_xlabel("time from the astern order (min)")
    a2.grid(True, alpha=0.3)
    fig.set_layout_engine("constrained")
    return fig


def _stopping_view(x, y, pad: float = 1.0, narrowest: float = 0.4) -> tuple:
    """The stopping track's view in L: ``(east limits, north limits)``, the track and the 15 L limit line
    with ``pad`` L about them, the east span widened about the track's middle to at least ``narrowest``
    times the north span (equal scales: the box is then no thin strip)."""
    n0, n1 = float(np.min(x)) - pad, max(float(np.max(x)), 15.0) + pad
    e0, e1 = float(np.min(y)) - pad, float(np.max(y)) + pad
    half = max(e1 - e0, narrowest * (n1 - n0)) / 2
    mid = (e0 + e1) / 2
    return (mid - half, mid + half), (n0, n1)


def distributions_figure(res, pyplot: bool = True):
    """A histogram per sampled criterion with its limit (red), the median and the 90 % interval, each panel
    with its own legend (its limit's value)."""
    if res.samples is None:
        raise ValueError("no samples: imo(ship, samples=N) gives the distributions")
    crit = list(res.criteria)
    cols = 4
    rows = int(np.ceil(len(crit) / cols))
    fig = _figure((4.0 * cols, 2.8 * rows), pyplot)
    by_name = {r["name"]: r for r in res.rows()}
    for k, c in enumerate(crit):
        ax = fig.add_subplot(rows, cols, k + 1)
        v = np.array([np.nan if x is None else x for x in res.samples[c.name]], dtype=float)
        v = v[np.isfinite(v)]
        r = by_name[c.name]
        if v.size:
            ax.hist(v, bins=min(40, max(10, v.size // 20)), color="tab:blue", alpha=0.6, label="samples")
        ax.axvline(c.limit, color="tab:red", lw=1.5, label=f"limit {c.limit:.3g} {c.unit}")
        if r["value"] is not None:
            ax.axvline(r["value"], color="k", lw=1.0, label="median")
        if r["interval"] and None not in r["interval"]:
            ax.axvspan(*r["interval"], color="grey", alpha=0.2, label="90 % interval")
        p = r["probability"]
        ax.set_title(f"{c.name}\nP(meet) = {p:.3f}: {r['verdict']}", fontsize=8)
        ax.set_xlabel(f"{c.name.split(',')[0]} ({c.unit})", fontsize=8)
        ax.set_ylabel("samples", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6, loc="best")
    fig.suptitle(f"{res.ship}: IMO criteria over {res.n_samples} parameter samples at {res.speed}")
    fig.set_layout_engine("constrained")
    return fig
