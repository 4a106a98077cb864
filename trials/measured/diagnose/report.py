"""What ``mmg diagnose`` tells a user: each named effect's value with a 95 % interval and the evidence
behind it, and the console lines (units, three significant figures, a legend for the statistics).

* :func:`effect_intervals`: the 95 % interval of each named parameter from the fitted parameters and
  their covariance.  A current is fitted in north/east components; its speed and direction intervals
  come from the confidence ellipse of (north, east) at the one-parameter level (1.96 standard
  deviations: the ellipse's projection on any line is that line's 95 % interval): speed from the
  nearest and farthest points of the ellipse from the origin (0 when the origin is inside), direction
  from the two tangents from the origin (``"any"`` when the origin is inside: the speed interval
  includes 0).  Other parameters: the fitted value +- 1.96 standard errors in the fitted parameter,
  mapped to the named one (a monotone map, e.g. T/H -> H/T), clipped to the parameter's bounds.
* :func:`effect_evidence`: dBIC and z of the round in which the effect was named, and
  the calibrated :func:`~trials.measured.diagnose.decision.false_alarm_probability` at its magnitude.
* :func:`summary_lines`: the console text of a :class:`trials.measured.diagnose.Diagnosis`.
"""
from __future__ import annotations

import math

import numpy as np

from mmg.model import G

from .decision import SPEED_UNIT
from .decision import false_alarm_probability  # noqa: F401  (re-exported: the report's evidence)

__all__ = ["Z95", "effect_estimate", "effect_intervals", "polar_interval", "effect_evidence",
           "summary_lines", "not_identifiable_line", "fmt3", "format_rms", "format_values", "channel_text",
           "straight_run_line", "size_in_si", "size_with_unit", "round_header", "IDENTIFIABILITY_LEGEND", "form_line"]

Z95 = 1.959963984540054
"""The two-sided 95 % point of the standard normal."""

CHANNEL_UNITS = {"u": "m/s", "v": "m/s", "r": "deg/s", "heading": "deg", "position": "m"}
"""Units of the ``rms_*`` channels (:data:`trials.measured.diagnose.CHANNELS`)."""


# --------------------------------------------------------------------------- numbers

GRAVITY = G
"""g [m/s^2] of a size in sqrt(g L)."""

IDENTIFIABILITY_LEGEND = ("(identifiability: R, the multiple correlation of the effect with the other fitted "
                          "parameters, 0 to 1, near 1 when they can stand in for it; sd, its standard error in the "
                          "effect's unit with them fitted too (alone: with them held); detection size, the smallest "
                          "size of it the diagnosis sets out to find)")
"""The one-line legend printed before the first identifiability line of a diagnosis."""


def size_in_si(value: float, unit: str, L: float, T: float, U: float | None = None) -> str:
    """A size in a ship-relative unit said in SI, to print beside it: ``"0.140 m/s"`` for ``value``
    sqrt(g L) (speed = value * sqrt(g L), ``L`` [m]) and ``"0.116 m/s at U = 7.72 m/s"`` for ``value`` U
    (a fraction of the records' speed ``U`` [m/s]: :data:`~trials.measured.diagnose.decision.SPEED_UNIT`),
    ``"H = 33.6 m"`` for a ratio T/H (depth H = T / value, ``T`` the draft [m]; ``"H infinite"`` at 0);
    ``""`` for any other unit (already SI-like: m/s, deg), and for U without a speed."""
    if unit == "sqrt(gL)":
        return f"{fmt3(abs(value) * math.sqrt(GRAVITY * L))} m/s"
    if unit == SPEED_UNIT:
        return f"{fmt3(abs(value) * U)} m/s at U = {fmt3(U)} m/s" if U else ""
    if unit == "T/H":
        return "H infinite" if value == 0 else f"H = {fmt3(T / abs(value))} m"
    return ""


def size_with_unit(value: float, unit: str, L: float, T: float, U: float | None = None) -> str:
    """``value`` with its ``unit`` and, for a ship-relative one, its SI value beside it
    (:func:`size_in_si`; ``U`` [m/s] the records' speed, for a size in U): ``"0.0259 sqrt(gL) = 0.140 m/s"``,
    ``"0.0150 U = 0.116 m/s at U = 7.72 m/s"``, ``"0.0893 T/H, H = 33.6 m"``, ``"0.738 deg"``."""
    text = f"{fmt3(value)} {unit}".rstrip()
    si = size_in_si(value, unit, L, T, U)
    return text if not si else f"{text} = {si}" if unit in ("sqrt(gL)", SPEED_UNIT) else f"{text}, {si}"


def round_header(number: int, named) -> str:
    """The console line before a search round's candidates: ``"round 1: candidates against the ship alone"``,
    ``"round 2: after naming current"``."""
    if not named:
        return f"round {number}: candidates against the ship alone"
    return f"round {number}: after naming {', '.join(named)}"



def fmt3(x) -> str:
    """``x`` to three significant figures, without exponent between 1e-3 and 1e6 (412, 18.3, 0.251,
    0.00123); ``inf`` and ``n/a`` (not a number) spelled out."""
    if x is None:
        return "n/a"
    x = float(x)
    if math.isnan(x):
        return "n/a"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    if x == 0.0:
        return "0"
    r = float(f"{x:.2e}")                       # rounded to 3 s.f. (may carry to the next decade)
    e = math.floor(math.log10(abs(r)))
    if e >= 6 or e < -3:
        return f"{r:.2e}"
    if e >= 2:
        return f"{r:.0f}"
    return f"{r:.{2 - e}f}"


def _strip_unit(name: str, unit: str) -> str:
    for suf in ("_mps", "_deg", "_m", "_s"):
        if name.endswith(suf) and unit != "1":
            return name[: -len(suf)]
    return name


def parameter_label(effect: str, name: str, unit: str = "1") -> str:
    """An effect parameter's name in words: the effect's name, then the parameter's without its unit when it
    adds to it (``heading bias`` for heading_bias bias_deg, ``current speed`` for current speed_mps)."""
    words = effect.replace("_", " ")
    p = _strip_unit(name, unit).replace("_", " ")
    return words if words.split()[-1] == p else f"{words} {p}"


def _unit(u: str) -> str:
    return "" if u in ("1", "") else f" {u}"


# --------------------------------------------------------------------------- intervals


def effect_estimate(model, cls, inflate: float):
    """(fitted parameters, their covariance) of effect ``cls`` in a fitted model of
    :mod:`trials.measured.diagnose` (standard errors inflated by ``inflate``, as the report's)."""
    idx = [i for i, f in enumerate(model.free) if f.kind == "effect" and f.name.split(".")[0] == cls.name]
    th = np.asarray(model.fit.theta, float)[idx]
    std = np.asarray(model.fit.std, float)[idx] * inflate
    corr = np.nan_to_num(np.asarray(model.fit.corr, float)[np.ix_(idx, idx)], nan=0.0)
    np.fill_diagonal(corr, 1.0)
    return th, corr * np.outer(std, std)


def polar_interval(north: float, east: float, cov, level_z: float = Z95, n_points: int = 8192):
    """95 % intervals of the speed and the direction (towards, clockwise from north) of a vector
    fitted as (north, east) with covariance ``cov``: from the ellipse ``(p - p0)' C^-1 (p - p0) <=
    level_z^2`` (module docstring).

    Returns
    -------
    (speed_lo, speed_hi), direction
        ``direction`` is ``(lo, hi)`` in [0, 360) degrees, the arc clockwise from ``lo`` to ``hi``
        (``lo > hi`` when it crosses north), or ``"any"`` when the origin is inside the ellipse.
    """
    p0 = np.array([north, east], float)
    C = np.asarray(cov, float).reshape(2, 2)
    if not (np.isfinite(p0).all() and np.isfinite(C).all()):
        return (math.nan, math.nan), (math.nan, math.nan)
    C = 0.5 * (C + C.T)
    w, V = np.linalg.eigh(C)
    A = V * np.sqrt(np.clip(w, 0.0, None))            # C = A A'
    a = np.linspace(0.0, 2 * np.pi, n_points, endpoint=False)
    ring = p0[:, None] + level_z * A @ np.vstack([np.cos(a), np.sin(a)])
    dist = np.hypot(ring[0], ring[1])
    # origin inside the ellipse: its whitened distance within level_z
    inside = bool(w.min() > 0 and float(p0 @ np.linalg.solve(C, p0)) <= level_z ** 2) or \
        (w.min() <= 0 and dist.min() <= 1e-12)
    hi = float(dist.max())
    if inside:
        return (0.0, hi), "any"
    lo = float(dist.min())
    b0 = math.atan2(p0[1], p0[0])
    rel = (np.arctan2(ring[1], ring[0]) - b0 + np.pi) % (2 * np.pi) - np.pi     # about the fitted bearing
    d_lo, d_hi = math.degrees(b0 + rel.min()) % 360.0, math.degrees(b0 + rel.max()) % 360.0
    return (lo, hi), (d_lo, d_hi)


def _bounds(params, name):
    for p in params:
        if p.name == name:
            return p.lower, p.upper
    return -math.inf, math.inf


def _clip(lo, hi, bounds):
    return float(np.clip(lo, *bounds)), float(np.clip(hi, *bounds))


def effect_intervals(cls, theta, cov, level_z: float = Z95) -> dict:
    """{named parameter: [lo, hi] or ``"any"``}: the 95 % intervals of effect ``cls`` from its fitted
    parameters ``theta`` and their covariance (module docstring); bounds from ``cls.parameters``."""
    theta = np.asarray(theta, float)
    cov = np.atleast_2d(np.asarray(cov, float))
    fitp, named = cls.fit_parameters(), cls.parameters
    vals = cls.from_fit(theta)
    fnames = [p.name for p in fitp]
    if len(fitp) == 2 and fnames[0].startswith("north") and fnames[1].startswith("east") and \
            [p.unit for p in named].count("deg") == 1 and len(named) == 2:
        ang = next(p for p in named if p.unit == "deg")
        spd = next(p for p in named if p.unit != "deg")
        (s_lo, s_hi), d = polar_interval(theta[0], theta[1], cov, level_z)
        # the named direction's convention (towards or from) relative to the bearing of (north, east)
        off = (vals[ang.name] - math.degrees(math.atan2(theta[1], theta[0]))) % 360.0 if np.any(theta) else 0.0
        out = {spd.name: list(_clip(s_lo, s_hi, (max(spd.lower, 0.0), spd.upper)))}
        out[ang.name] = "any" if d == "any" else [(d[0] + off) % 360.0, (d[1] + off) % 360.0]
        return out
    sd = np.sqrt(np.abs(np.diag(cov)))
    out = {}
    for j, (fp, v) in enumerate(zip(fitp, theta)):
        lo, hi = _clip(v - level_z * sd[j], v + level_z * sd[j], (fp.lower, fp.upper))
        ends = []
        for e in (lo, hi):
            th = theta.copy()
            th[j] = e
            ends.append(cls.from_fit(th))
        moved = [k for k in vals if any(not _same(ends[i][k], vals[k]) for i in range(2))]
        if len(moved) == 1:                 # a monotone map of this one parameter
            k = moved[0]
            a, b = sorted((ends[0][k], ends[1][k]))
            out[k] = list(_clip(a, b, _bounds(named, k)))
        elif not moved and fp.name in vals:
            out[fp.name] = list(_clip(lo, hi, _bounds(named, fp.name)))
    if set(out) != set(vals):               # any other map: the delta method's value +- z se
        _, se = cls.report(theta, cov)
        for k, v in vals.items():
            if k not in out:
                out[k] = list(_clip(v - level_z * se[k], v + level_z * se[k], _bounds(named, k)))
    return out


def _same(a, b) -> bool:
    return (math.isinf(a) and a == b) or (math.isfinite(a) and math.isfinite(b) and abs(a - b) <= 1e-12 * max(1, abs(b)))


# --------------------------------------------------------------------------- evidence


def effect_evidence(named, rounds) -> dict:
    """{effect: {"delta_bic", "z", "false_alarm_probability"}} of each named effect, from the search
    round in which it was named (round k names the k-th effect; else its last round that cleared)."""
    out = {}
    for k, e in enumerate(named):
        hits = [(i, c) for i, rd in enumerate(rounds) for c in rd.get("candidates", []) if c.get("effect") == e]
        in_k = [c for i, c in hits if i == k and c.get("clears_threshold", True)]
        cleared = [c for _, c in hits if c.get("clears_threshold")]
        pick = in_k or cleared or [c for _, c in hits]
        if not pick:
            out[e] = {"delta_bic": None, "z": None, "magnitude": None, "floor": None, "false_alarm_probability": None}
            continue
        c = pick[0] if in_k else pick[-1]
        dbic, z, mag = c.get("delta_bic"), c.get("z"), c.get("magnitude")
        kind = rounds[min(k, len(rounds) - 1)].get("kind")
        out[e] = {"delta_bic": dbic, "z": z, "magnitude": mag, "floor": c.get("floor"),
                  "false_alarm_probability": None if mag is None or kind is None else
                  false_alarm_probability(e, kind, mag)}
    return out


# --------------------------------------------------------------------------- text


def format_rms(rms: dict) -> str:
    """``u 0.0403 m/s, v 0.0739 m/s, ...``: residual RMS per channel with units."""
    return ", ".join(f"{c} {fmt3(v)}{_unit(CHANNEL_UNITS.get(c, ''))}" for c, v in rms.items())


def format_values(effect: str, values: dict) -> str:
    """An effect's named values with units, three significant figures (``speed 0.293 m/s, direction 241 deg``)."""
    import mmg.effects as E

    try:
        units = {p.name: p.unit for p in E.get(effect).parameters}
    except Exception:                        # an unknown name: no units known
        units = {}
    return ", ".join(f"{_strip_unit(k, units.get(k, '1'))} {fmt3(v)}{_unit(units.get(k, ''))}" for k, v in values.items())


def _range(iv, unit: str) -> str:
    if iv == "any":
        return "any direction"
    if iv is None or iv[0] is None or iv[1] is None:
        return "n/a"
    sep = " to " if iv[0] < 0 or iv[1] < 0 else "-"          # -1.62 to -1.43 deg, not -1.62--1.43
    return f"{fmt3(iv[0])}{sep}{fmt3(iv[1])}{_unit(unit)}"


def effect_line(effect: str, values: dict, intervals: dict, evidence: dict) -> str:
    """One console line: value with units (3 s.f.), its 95 % interval, dBIC, z and the false-alarm p."""
    import mmg.effects as E

    params = {p.name: p for p in E.get(effect).parameters}
    if effect == "current":
        v = (f"{fmt3(values['speed_mps'])} m/s towards {fmt3(values['direction_deg'])} deg")
        ivs = f"{_range(intervals.get('speed_mps'), 'm/s')}, {_range(intervals.get('direction_deg'), 'deg')}"
    else:
        v = format_values(effect, values)
        ivs = ", ".join(_range(intervals.get(k), params[k].unit if k in params else "") for k in values)
    ev = evidence or {}
    p = ev.get("false_alarm_probability")
    return (f"{effect:<13} {v}  (95 %: {ivs})   dBIC {fmt3(ev.get('delta_bic'))}, z {fmt3(ev.get('z'))}, "
            f"false-alarm p {fmt3(p) if p is not None else 'n/a'}")


def _plain(x) -> str:
    """Any JSON-like value as text with numbers to 3 s.f. (no raw dict, no 16 digits)."""
    if isinstance(x, dict):
        return ", ".join(f"{k} {_plain(v)}" for k, v in x.items())
    if isinstance(x, (list, tuple)):
        return ", ".join(_plain(v) for v in x)
    if isinstance(x, (bool, np.bool_)) or x is None:
        return str(x).lower()
    if isinstance(x, (int, float, np.floating, np.integer)):
        return fmt3(x)
    return str(x)


def not_identifiable_line(ni: dict) -> str:
    """The console line of one ``not_identifiable`` entry: the effect, what it is confused with (the
    correlation where there is one), why it is reported (its standard error could not have shown the
    size to detect, its calibrated floor, or its evidence short of a name) and what would separate it.

    Parameters
    ----------
    ni : dict
        An entry of :attr:`trials.measured.diagnose.Diagnosis.not_identifiable` (``effect``,
        ``confused_with``, ``correlation`` or None, ``what_would_separate``; optionally ``reason``,
        ``reason_kind`` (not printed: the reason says it), ``std``, ``detection_size``, ``unit``).

    Returns
    -------
    str
        One line, units with every figure.
    """
    from .decision import STATISTICAL_REASON

    conf = ", ".join(map(str, ni.get("confused_with") or []))
    corr = ni.get("correlation")
    why = f"correlation {fmt3(corr)} with {conf}" if corr is not None else f"confused with {conf}"
    reason = ni.get("reason")
    if reason and reason != STATISTICAL_REASON:
        why = f"{why}: {reason}"
    elif ni.get("std") is not None and ni.get("detection_size") is not None:
        unit = _unit(ni.get("unit") or "")
        why = f"{why}; sd {fmt3(ni['std'])}{unit}: could not have shown {fmt3(ni['detection_size'])}{unit}"
    return f"{ni.get('effect')}: not identifiable from these records ({why}): {ni.get('what_would_separate', '')}" \
        .rstrip(": ")


def summary_lines(diag) -> list[str]:
    """The console text of a :class:`trials.measured.diagnose.Diagnosis`: a line per named effect
    (:func:`effect_line`), one per effect reported ``model_form_mismatch``
    (:func:`form_line`), the statistics' legend, a line per effect that cannot be told apart, the
    residual RMS per channel (config, ship fitted, with the named effects), ``unexplained`` when set."""
    from .rules import rule

    bic, z_min = rule("bic_threshold"), rule("z_threshold")
    lines = []
    for e in diag.named:
        lines.append(effect_line(e, diag.parameters.get(e, {}), (diag.intervals_95 or {}).get(e, {}),
                                 (diag.evidence or {}).get(e, {})))
    if not diag.named:
        lines.append("nothing named")
    lines += [form_line(x) for x in getattr(diag, "model_form_effects", None) or []]
    lines.append(f"  (dBIC: information gain with the effect, named above {bic:g}; z: the fit's distance from "
                 f"no effect in standard errors, named above {z_min:g}; false-alarm p: chance of naming it at "
                 "this dBIC on records without it, n/a: not calibrated)")
    lines += [not_identifiable_line(ni) for ni in diag.not_identifiable or []]
    for k, v in (diag.model_form_mismatch or {}).items():
        lines.append(f"model-form mismatch: {k} fitted {fmt3(v['fitted'])} against the config's {fmt3(v['config'])} "
                     f"({fmt3(v['z'])} prior std away): not written to --out-ship")
    for st in getattr(diag, "straight_runs", None) or []:
        lines.append(straight_run_line(st))
    from ...files.tables import text_table

    rows = [[f"  {c} [{CHANNEL_UNITS.get(c, '')}]", fmt3(diag.rms_config.get(c)), fmt3(diag.rms_before.get(c)),
             fmt3(diag.rms_after.get(c))] for c in diag.rms_after]
    lines += text_table(["residual RMS (replay - log)", "config", "ship fitted", "+ named"], rows)
    lines += absent_lines(getattr(diag, "absent_channels", None) or [])
    if diag.unexplained:
        lines.append(f"unexplained: {diag.unexplained_description}")
    for r in diag.runs or []:
        lines.append(f"  record {r.records[0].name}: " + ("; ".join(
            f"{e} {format_values(e, r.parameters.get(e, {}))}" for e in r.named) or "nothing named"))
    return lines


def absent_lines(table) -> list:
    """A line per channel some record does not log (``  r not logged by a, b (column r_angvelo [rad/s]): its
    residual compares ...``), from :func:`trials.measured.diagnose.absent_table`."""
    by = {}
    for e in table:
        by.setdefault((e["channel"], e["column"], e["compared_instead"]), []).append(e["record"])
    lines = []
    for (c, col, what), names in by.items():
        where = f"column {col}" if col else "no column for it in the layout"
        then = f"its residual compares {what}" if what else "left out of the fit; no residual reported from it"
        lines.append(f"  {c} not logged by {', '.join(names)} ({where}): {then}")
    return lines


def straight_run_line(st: dict) -> str:
    """``straight run of dev_09 (10 samples, 9 s): drift over ground -0.95 deg (sd 0.107), 8.9 sd -> 0.2 sd with
    the named effects``: one entry of :func:`trials.measured.diagnose.straight_run_table`."""
    return (f"straight run of {st['record']} ({st['samples']} samples, {fmt3(st['seconds'])} s): drift over ground "
            f"{fmt3(st['logged_drift_deg'])} deg (sd {fmt3(st['sd_deg'])}), {fmt3(abs(st['z_before']))} sd -> "
            f"{fmt3(abs(st['z_after']))} sd with the named effects")


def channel_text(channel: str, rms_si: float, noise_si: float, mean_si: float | None = None) -> str:
    """``v residual 0.0830 m/s RMS (noise 0.0120 m/s)``: a residual channel in its unit (r and heading in
    degrees), never as a ratio to a noise level that may be near zero."""
    deg = channel in ("r", "heading")
    f = math.degrees if deg else float
    unit = {"u": "m/s", "v": "m/s", "r": "deg/s", "heading": "deg"}.get(channel, "m")
    noise = f(noise_si)
    nz = f"noise {fmt3(noise)} {unit}" if noise >= 1e-9 * max(abs(f(rms_si)), 1e-30) and noise > 0 \
        else "no measurable noise"
    mean = "" if mean_si is None else f", mean {fmt3(f(mean_si))} {unit}"
    return f"{channel} residual {fmt3(f(rms_si))} {unit} RMS ({nz}{mean})"


def form_line(ent: dict) -> str:
    """The one console line of a ``model_form_mismatch`` entry: ``wind: model_form_mismatch, not named
    (scale 5.4 outside the plausible 0.333-3; ...): ...``."""
    ship = ent.get("ship_coefficients") or []
    beside = f"; ship coefficients beyond their priors in the same fit: {', '.join(ship)}" if ship else ""
    return (f"{ent['effect']}: {ent['status']}, not named (fitted {format_values(ent['effect'], ent.get('parameters') or {})}; "
            f"{ent['reason']}{beside})")
