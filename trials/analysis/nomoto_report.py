"""Nomoto identification of a record file as a report: the text table and the JSON + plot files (``mmg nomoto``)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mmg.errors import InputError

CHANNELS = ("psi", "delta", "r", "U", "u", "v")
"""The channels the Nomoto identification reads: heading, rudder, yaw rate, speed (never ``n``)."""


def _f(v, fmt="{:.4g}"):
    return "n/a" if v is None or not np.isfinite(v) else fmt.format(v)


def report(ident) -> str:
    """Plain-text report of a :class:`trials.analysis.nomoto.NomotoIdentification`."""
    z = ident.zigzag
    d = ident.to_dict()
    lines = [f"record {z.name}: L = {z.L:g} m, U = {z.U:.4g} m/s, execute at t = {z.t_execute:.4g} s "
             f"to {d['first_execute_to']}, rudder {np.degrees(z.delta0):.3g} deg, yaw rate {z.yaw_rate_source}",
             "points (s' [-], eps' [-], omega' [-], Delta [rad], delta [rad], psi [deg]):"]
    for nm_, v in ident.points.to_dict().items():
        lines.append(f"  {nm_:4s} {v['s']:8.4f} {v['eps']:9.5f} {v['omega']:9.5f} {v['Delta']:9.5f} "
                     f"{v['delta']:9.5f} {v['psi_deg']:9.3f}")
    lines.append("")
    lines += _fit_table(ident)
    for key, fit in (("least_squares", ident.least_squares), ("output_error", ident.output_error)):
        if fit is None:
            continue
        ci = "  ".join(f"{k}' [{_f(lo)}, {_f(hi)}] [-]" for k, (lo, hi) in fit.ci95.items() if k != "delta_bias")
        if not ident.usable(key):          # an interval about a fit that identified nothing means nothing
            ci = f"none: the fit is UNUSABLE ({ident.problems[key]})"
        lines.append(f"95 % intervals, {fit.method.replace('_', ' ')}: {ci}")
    note = ident.four_point.note()
    if note:
        lines.append(f"four-point: {note}")
    for fit in (ident.least_squares, ident.output_error):
        if fit is not None and fit.note:
            lines.append(f"{fit.method}: {fit.note}")
    for key, (label, _, _) in ident.fits().items():
        if not ident.usable(key):
            lines.append(f"{label}: UNUSABLE, {ident.problems[key]}")
    return "\n".join(lines)


def _rms_text(v) -> str:
    return "n/a" if v is None or not np.isfinite(v) else ("{:.3f}" if abs(v) < 1e4 else "{:.3g}").format(v)


def _fit_table(ident) -> list:
    """The fits' parameters, dimensionless [-] and in seconds, with heading RMS [deg] and usability."""
    from trials.files.tables import text_table

    z = ident.zigzag
    head = ("method", "K' [-]", "T1' [-]", "T2' [-]", "T3' [-]", "K [1/s]", "T1 [s]", "T2 [s]", "T3 [s]",
            "psi RMS [deg]", "fit")
    rows = []
    for (key, _), (_, r) in zip(ident.fits().items(), ident.to_pandas().iterrows()):
        dim = ident.dimensional(key)
        rows.append([r["method"], *(_f(r[c]) for c in ("K", "T1", "T2", "T3")),
                     *(_f(np.nan if dim.get(c) is None else dim[c]) for c in ("K_per_s", "T1_s", "T2_s", "T3_s")),
                     _rms_text(r["rms_deg"]), "ok" if r["usable"] else "UNUSABLE"])
    return [f"fits (K' = K L/U, T' = T U/L; L = {z.L:g} m, U = {z.U:.4g} m/s):"] + text_table(head, rows, "<" + ">" * 9 + "<")


def identify_log(path, length: float, speed: float | None = None, output_error: bool = True):
    """Nomoto identification of a zigzag record file (:func:`trials.analysis.nomoto.identify`); a project log
    without rudder channel gets its rudder rebuilt from the trial logic of its header.

    Returns
    -------
    (NomotoIdentification, str or None)
        The identification and a note when the rudder was rebuilt.
    """
    from trials.analysis import nomoto as nm
    from trials.files.logio import require_finite

    if length is None or not np.isfinite(length) or length <= 0:
        raise InputError("--length", "", f"ship length must be a positive number of metres, got {length}")
    if speed is not None and (not np.isfinite(speed) or speed <= 0):
        raise InputError("--speed", "", f"speed must be a positive number of m/s, got {speed}")
    from trials.files.shipcheck import check_speed_option, read_for_ship

    rec = read_for_ship(path, length, channels=CHANNELS)        # a length the record contradicts is refused
    if speed is not None:
        check_speed_option(rec, speed, length)
    require_finite(rec, CHANNELS, "mmg nomoto")
    note = None
    if rec.delta is None and rec.meta.get("format") == "log":
        from trials.files.rudder import with_rebuilt_rudder

        rec = with_rebuilt_rudder(rec)
        note = f"{rec.name}: no rudder channel in the log; rudder rebuilt from the {rec.meta.get('kind')} logic in its header"
    return nm.identify(rec, length, speed, output_error=output_error), note


def write_identification(ident, json_path) -> None:
    """The identification's JSON and its plot (same stem, .png) written together or not at all."""
    from trials.analysis.nomoto_plot import plot_identification
    from trials.files.output import StagedOutput, dump_json

    out = Path(json_path)
    with StagedOutput(out.parent) as stage:
        dump_json(ident.to_dict(), stage.path(out.name))        # NaN / Infinity written as null
        plot_identification(ident, stage.path(out.with_suffix(".png").name))
