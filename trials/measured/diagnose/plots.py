"""Figures of ``mmg diagnose``: per record (:func:`diagnose_figure`), residual time series before and
after the named effects (u, v, r, heading, distance) and the tracks measured / before / after; per
diagnosis (:func:`diagnose_summary_figure`), the manoeuvre, the residuals per channel and the fitted
values with their 95 % intervals."""
from __future__ import annotations

import math

import numpy as np

from ..predict_plots import replay_layout

_RESIDUALS = (("u [m/s]", "u", lambda p, m: p[:, 0] - m[:, 0]), ("v [m/s]", "v", lambda p, m: p[:, 1] - m[:, 1]),
              ("r [deg/s]", "r", lambda p, m: np.degrees(p[:, 2] - m[:, 2])),
              ("heading [deg]", "heading", lambda p, m: np.degrees(p[:, 5] - m[:, 5])),
              ("distance [m]", "position", lambda p, m: np.hypot(p[:, 3] - m[:, 3], p[:, 4] - m[:, 4])))
"""The residual panels: (axis label, ``rms_*`` channel, replayed minus logged in the label's unit)."""


def along_cross(north, east, ref_north, ref_east):
    """(along-track, cross-track to starboard) [m] of points (``north``, ``east``) relative to the mean
    course of the reference track (its principal axis, pointing from its start to its end), and the
    mean course [deg, clockwise from north]."""
    rn, re = np.asarray(ref_north, float), np.asarray(ref_east, float)
    ok = np.isfinite(rn) & np.isfinite(re)
    P = np.column_stack([rn[ok], re[ok]])
    c0 = P.mean(axis=0)
    _, _, vt = np.linalg.svd(P - c0, full_matrices=False)
    d = vt[0]
    if (P[-1] - P[0]) @ d < 0:
        d = -d
    side = np.array([-d[1], d[0]])                          # starboard of the course (east of north)
    Q = np.column_stack([np.asarray(north, float), np.asarray(east, float)]) - P[0]
    return Q @ d, Q @ side, math.degrees(math.atan2(d[1], d[0])) % 360.0


def _nice_factor(x: float) -> float:
    """The largest round factor (1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 times a power of ten) not above ``x``; at least 1."""
    if x <= 1.0:
        return 1.0
    e = 10.0 ** math.floor(math.log10(x))
    return max(f * e for f in (1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0) if f * e <= x)


def _along_track_panel(ax, tracks, box_ratio: float):
    """A long track (a zigzag) drawn as the cross-track deviation against the along-track distance, the
    cross-track scale enlarged by a round factor stated in the title (the track itself would be a strip:
    35 km by 1 km).  ``tracks``: [(states (N, 6), label, style kwargs)], the first the reference;
    ``box_ratio``: the axes' width / height, for the factor."""
    ref = tracks[0][0]
    a_ref, c_ref, course = along_cross(ref[:, 3], ref[:, 4], ref[:, 3], ref[:, 4])
    a_span = float(np.nanmax(a_ref) - np.nanmin(a_ref)) or 1.0
    c_span = float(np.nanmax(c_ref) - np.nanmin(c_ref)) or 1.0
    k = _nice_factor(a_span / c_span / box_ratio / 1.15)        # the data fills about the box's height
    for s, lab, kw in tracks:
        a, c, _ = along_cross(s[:, 3], s[:, 4], ref[:, 3], ref[:, 4])
        ax.plot(a, c, label=lab, **kw)
    ax.plot(a_ref[:1], c_ref[:1], "o", color="g", ms=5, zorder=3, label="start")
    ax.set_aspect(k, adjustable="datalim")
    if not ax.yaxis_inverted():
        ax.invert_yaxis()                                       # starboard down: the chart turned to the course
    ax.set_xlabel(f"along-track distance [m], along the mean course {round(course) % 360:03d} deg")
    ax.set_ylabel("cross-track [m], to starboard \u2193")
    ax.grid(True, alpha=0.3)
    return k, course


def diagnose_figure(diag, i: int):
    """Figure for record ``i`` of a :class:`trials.measured.diagnose.Diagnosis` (not pyplot-managed).

    A track close to square (a turning circle) is drawn to scale, its start marked, its legend off the
    data.  A long one (its sides more than ``WIDE_RATIO`` apart: a zigzag, 35 km by 1 km) would be a
    strip to scale: it runs across the bottom as the cross-track deviation against the along-track
    distance from the mean course, the cross-track scale enlarged by a stated round factor."""
    from matplotlib.figure import Figure

    rec = diag.records[i]
    t = rec.seg.inputs.t
    m, b, a = rec.seg.meas, diag.pred_before[i], diag.pred_after[i]
    shown = np.vstack([q[np.all(np.isfinite(q[:, 3:5]), axis=1)] for q in (m, b, a)])
    view, wide, _ = replay_layout(shown[:, 3], shown[:, 4], pad=0.0)
    view.unit = "m"
    track_h = 3.2
    fig = Figure(figsize=(11, 8 + (track_h if wide else 0)), layout="constrained")
    fig.get_layout_engine().set(w_pad=0.08)          # the y labels of the residual panels clear the canvas's edge
    if wide:
        gs = fig.add_gridspec(6, 1, height_ratios=[1.0] * 5 + [track_h / 1.3])
        cell, track_cell = (lambda k: gs[k, 0]), gs[5, 0]                  # noqa: E731
    else:
        gs = fig.add_gridspec(5, 2)
        cell, track_cell = (lambda k: gs[k, 0]), gs[:, 1]                  # noqa: E731
    after = "after (" + (", ".join(diag.named) or "nothing named") + ")"
    absent = getattr(rec, "absent", None) or {}
    for k, (lab, ch, f) in enumerate(_RESIDUALS):
        ax = fig.add_subplot(cell(k))
        if ch in absent and not absent[ch].get("compared_instead"):       # nothing logged to compare with
            ax.text(0.5, 0.5, f"{ch} not logged: no residual", transform=ax.transAxes, ha="center", va="center",
                    fontsize=9, color="0.3")
            ax.set_xlim(float(t[0]), float(t[-1]))
            ax.set_yticks([])
        else:
            ax.plot(t, f(b, m), lw=0.8, label="before (ship fitted, no effect)")
            ax.plot(t, f(a, m), lw=0.8, label=after)
        ax.set_ylabel(lab, fontsize=8)
        ax.tick_params(labelsize=7)
        if k == 0:
            ax.legend(fontsize=7)
            ax.set_title(f"{rec.name}: residual (replay - log), segments restart from the log", fontsize=9)
    ax.set_xlabel("t [s]")
    ax = fig.add_subplot(track_cell)
    tracks = [(m, "logged", dict(color="k", lw=2.4, alpha=0.35)), (b, "before", dict(lw=0.9)),
              (a, "after", dict(lw=0.9, ls="--"))]
    if wide:
        k, _ = _along_track_panel(ax, tracks, box_ratio=3.2)        # the track axes' width / height in this layout
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
        ax.set_title(f"track against the mean course (segment-wise replay); cross-track scale x{k:g} "
                     "the along-track", fontsize=9)
        return fig
    for s, lab, kw in tracks:
        ax.plot(*view.hv(s[:, 3], s[:, 4]), label=lab, **kw)
    ax.plot(*view.hv(m[:1, 3], m[:1, 4]), "o", color="g", ms=5, zorder=3, label="start")
    view.finish(ax)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=4, frameon=False)
    ax.set_title("track (segment-wise replay)", fontsize=9)
    return fig


# --------------------------------------------------------------------------- the summary figure


def _end_to_end(diag):
    """Per record: (time on the common axis [s], its offset [s]); records end to end."""
    out, t0 = [], 0.0
    for r in diag.records:
        t = np.asarray(r.seg.inputs.t, float)
        out.append((t - t[0] + t0, t0))
        t0 += float(t[-1] - t[0]) + (float(np.median(np.diff(t))) if len(t) > 1 else 1.0)
    return out


def _mark_records(ax, diag, times, label: bool):
    if len(diag.records) < 2:
        return
    for (t, off), r in zip(times, diag.records):
        if off > 0:
            ax.axvline(off, color="0.5", lw=0.8, ls=":")
        if label:
            ax.text(off, 1.02, r.name, transform=ax.get_xaxis_transform(), fontsize=7, va="bottom")


def _text_panel(ax, lines, title):
    ax.axis("off")
    ax.text(0.0, 1.0, "\n".join(lines), va="top", ha="left", family="monospace", fontsize=8.5,
            transform=ax.transAxes)
    ax.set_title(title, fontsize=9, loc="left")


def _evidence_lines(diag) -> list:
    """The evidence panel: dBIC, z and the false-alarm p of each named effect (a table whose columns fit any
    value), the effects that cannot be told apart, the legend."""
    from ...files.tables import text_table
    from .report import fmt3

    ev = diag.evidence or {}
    rows = []
    for e in diag.named:
        d = ev.get(e, {})
        rows.append([e, fmt3(d.get("delta_bic")), fmt3(d.get("z")), fmt3(d.get("false_alarm_probability"))])
    out = text_table(["effect", "dBIC", "z", "p"], rows)
    for ni in diag.not_identifiable or []:
        out.append(f"{ni.get('effect')}: not identifiable")
        out.append(f"  (with {', '.join(map(str, ni.get('confused_with') or []))})")
    out += ["", "dBIC: information gain with the effect", "z: fit from no effect, standard errors",
            "p: false-alarm probability at this dBIC", "   (n/a: not calibrated)"]
    return out


def _interval_panels(fig, gs, col: int, diag):
    """An errorbar panel per named effect parameter (value, 95 % interval, the no-effect value dashed) and
    the evidence below them; a text panel (the candidates' evidence) when nothing is named."""
    import mmg.effects as E

    from ...files.tables import text_table
    from .report import fmt3, parameter_label

    n_rows = gs.get_geometry()[0]
    rows = [(e, k, v) for e in diag.named for k, v in diag.parameters.get(e, {}).items()]
    if not rows:
        last = (diag.rounds or [{}])[-1].get("candidates", [])
        text = ["nothing named", "", "last round's candidates:"]
        text += text_table(["effect", "dBIC", "z"], [[c["effect"], fmt3(c.get("delta_bic")), fmt3(c.get("z"))]
                                                     for c in last])
        text += ["", "named when dBIC and z clear", "their thresholds (console legend)"]
        if diag.unexplained:
            text += ["", "unexplained residual: see the console"]
        _text_panel(fig.add_subplot(gs[:, col]), text, "fitted effects")
        return
    cells = [gs[j, col] for j in range(len(rows))] if len(rows) < n_rows else \
        [c for c in gs[:n_rows - 1, col].subgridspec(len(rows), 1)]
    for cell, (e, k, v) in zip(cells, rows):
        ax = fig.add_subplot(cell)
        p = {q.name: q for q in E.get(e).parameters}.get(k)
        unit = "" if p is None or p.unit == "1" else p.unit
        iv = (diag.intervals_95 or {}).get(e, {}).get(k)
        name = parameter_label(e, k, p.unit if p is not None else "1")
        title = f"{name} = {fmt3(v)}{' ' + unit if unit else ''}"
        if iv == "any":
            ax.axvspan(0.0, 360.0, color="C0", alpha=0.15)
            ax.plot([v], [0], "o", color="C0")
            ax.set_xlim(0.0, 360.0)
            title += "\n95 %: any direction"
        elif iv is not None and None not in iv and all(np.isfinite(iv)) and np.isfinite(v):
            lo, hi = float(iv[0]), float(iv[1])
            if unit == "deg" and lo > hi:                     # an arc across north: unwrapped about v
                lo -= 360.0
            if unit == "deg" and v - lo > 180.0:
                lo, hi = lo + 360.0, hi + 360.0
            ax.errorbar([v], [0], xerr=[[max(v - lo, 0.0)], [max(hi - v, 0.0)]], fmt="o", capsize=6, color="C0")
            title += f"\n95 %: {fmt3(iv[0])} to {fmt3(iv[1])}{' ' + unit if unit else ''}"
        else:
            ax.plot([v], [0], "o", color="C0")
        if p is not None and np.isfinite(p.default) and unit != "deg":
            ax.axvline(p.default, color="0.4", ls="--", lw=0.8)
            ax.set_xlabel(f"{name} [{unit or '-'}]  (dashed: no effect)", fontsize=8)
        else:
            ax.set_xlabel(f"{name} [{unit or '-'}]", fontsize=8)
        ax.set_yticks([])
        ax.tick_params(labelsize=7)
        ax.set_title(title, fontsize=9)
    _text_panel(fig.add_subplot(gs[len(cells) if len(rows) < n_rows else n_rows - 1:, col]), _evidence_lines(diag),
                "evidence")


def diagnose_summary_figure(diag):
    """One figure for a whole :class:`trials.measured.diagnose.Diagnosis` (not pyplot-managed): on top the
    manoeuvre (rudder and heading against time, records end to end), below the residual of each channel
    before (ship fitted, no effect) and after the named effects, their RMS in the legend; on the right the
    named effects' fitted values with their 95 % intervals (a text panel of the candidates' evidence when
    nothing is named)."""
    from matplotlib.figure import Figure

    from .report import fmt3

    fig = Figure(figsize=(15, 12), layout="constrained")
    gs = fig.add_gridspec(7, 2, width_ratios=[2.6, 1.0])
    times = _end_to_end(diag)
    named = ", ".join(diag.named) or "nothing named"
    fig.suptitle(f"mmg diagnose: {named}   ({len(diag.records)} record(s): "
                 f"{', '.join(r.name for r in diag.records)})", fontsize=11)
    ax0 = None
    for k, (lab, f) in enumerate((("rudder [deg]", lambda r: np.degrees(r.seg.inputs.delta)),
                                  ("heading [deg]", lambda r: np.degrees(np.unwrap(r.seg.meas[:, 5]))))):
        ax = fig.add_subplot(gs[k, 0], sharex=ax0)
        ax0 = ax0 or ax
        for (t, _), r in zip(times, diag.records):
            ax.plot(t, f(r), lw=0.9, color="k")
        ax.set_ylabel(lab, fontsize=8)
        ax.tick_params(labelsize=7)
        _mark_records(ax, diag, times, label=k == 0)
        if k == 0:
            ax.set_title("manoeuvre as logged", fontsize=9, loc="right")
    for k, (lab, ch, f) in enumerate(_RESIDUALS):
        ax = fig.add_subplot(gs[k + 2, 0], sharex=ax0)
        unit = lab[lab.index("[") + 1:-1]
        for q, pred, rms, name, kw in (
                (0, diag.pred_before, diag.rms_before, "before (ship fitted, no effect)", dict(color="C0", lw=0.7)),
                (1, diag.pred_after, diag.rms_after, f"after ({named})", dict(color="C1", lw=0.7))):
            for j, ((t, _), r) in enumerate(zip(times, diag.records)):
                ax.plot(t, f(pred[j], r.seg.meas), label=f"{name}: RMS {fmt3(rms.get(ch))} {unit}" if j == 0 else None,
                        **kw)
        ax.set_ylabel(lab, fontsize=8)
        ax.tick_params(labelsize=7)
        _mark_records(ax, diag, times, label=False)
        ax.legend(fontsize=7, loc="lower right", bbox_to_anchor=(1.0, 1.0), ncol=2, frameon=False,
                  borderaxespad=0.1)
        if k == 0:
            ax.set_title("residual (replay - log) per channel", fontsize=9, loc="left")
    ax.set_xlabel("t [s]" + (" (records end to end)" if len(diag.records) > 1 else ""))
    _interval_panels(fig, gs, 1, diag)
    return fig
