"""A log's table to a :class:`~trials.files.records.TrialRecord`, one builder per format (project log,
project truth, FRT-DS-ESSO) running the checks of :mod:`.checks` on its channels, and :func:`read_record`
(a file of any supported format to its record).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from mmg.errors import InputError
from mmg.units import DEG, KNOT, M_PER_DEG_LAT, M_PER_DEG_LON

from ..logwrite import LOG_COLUMNS, TRUTH_COLUMNS
from ..records import TrialRecord
from .checks import (FRT_LENGTH_M, FRT_STEP_RANGE, _Table, _angle_hint, _apparent_wind, _check_heading_rate,
                     _check_heading_vs_track, _check_heading_vs_yaw_rate, _check_range, _check_rps, _check_rudder,
                     _check_rudder_deg, _check_speed, _check_time, _check_track, _check_velocities_vs_track,
                     _check_wind_consistency, _check_yaw_rate, _holes, _log)
from .layout import FRT_COLUMNS, FRT_REQUIRED, MAX_WIND_MPS
from .read import _load


_POSITIVE_META = ("interval_s", "dt_s", "length_m", "m_per_deg_lat", "m_per_deg_lon")
_FINITE_META = ("start_lat_deg", "start_lon_deg", "execute_s", "rudder_deg", "heading_deg", "switch_heading_deg",
                "trim_rudder_deg", "steering_T_E_s", "steering_rate_deg_s", "steering_delta_max_deg")


def _check_meta(meta: dict, src: str) -> None:
    """Header values the readers and analyses use must be numbers (positive where they are sizes)."""
    for k in _POSITIVE_META + _FINITE_META:
        if k not in meta:
            continue
        v = meta[k]
        ok = (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
              and (v > 0 or k not in _POSITIVE_META))
        if not ok:
            need = "a positive number" if k in _POSITIVE_META else "a finite number"
            raise InputError(src, k, f"header value {v!r} is not {need}")


def unwrap_heading(psi_wrapped: np.ndarray) -> np.ndarray:
    """Continuous heading [rad] from a wrapped one, starting on the branch (-pi, pi]."""
    psi = np.unwrap(psi_wrapped)
    return psi - 2 * np.pi * np.round(psi[0] / (2 * np.pi))


def read_record(path: str | Path, length_m: float | None = None) -> TrialRecord:
    """Read a project log, a project truth file or an FRT-DS-ESSO CSV into a TrialRecord.

    Anything that is not such a file, or is one with wrong-looking content, raises
    :class:`~mmg.errors.InputError` naming the file and the field (column, header key or line):
    a directory, a binary or non-UTF-8 file, rows with the wrong number of cells, cells that are
    not numbers, NaN, time that does not increase, gaps, a sampling step that is not the format's
    (the header's ``interval_s`` / ``dt_s``, 10 Hz for FRT-DS-ESSO), a record longer than
    ``mmg.limits.MAX_STEPS`` steps of 0.1 s, and channels in a wrong unit (see
    :func:`record_from_frame`).  Empty rows (all cells empty) are ignored and said so in
    ``rec.meta["notes"]`` and on the ``trials.files.logio`` logger; missing values in an optional column
    are kept as NaN (``rec.meta["nan_channels"]``; a command calls :func:`require_finite`).
    Peak memory is a few times the file's size (bench/bench_memory.py).

    ``length_m`` [m] is the ship's length where the file does not say it (FRT-DS-ESSO files):
    speeds and track are checked against it; the 3 m model's when omitted.
    """
    path = Path(path)
    src = str(path)
    meta, df, rows, notes = _load(path, src)
    return record_from_frame(df, meta, src, default_name=path.stem, notes=notes, lines=rows, length_m=length_m)


def record_from_frame(df: pd.DataFrame, meta: dict, source: str = "simulation", default_name: str = "",
                      notes=None, lines=None, length_m: float | None = None) -> TrialRecord:
    """A TrialRecord from a table in one of the supported column layouts and its header ``meta``.

    The one conversion behind :func:`read_record`; the estimators' in-memory path
    (:func:`trials.estimates.estimation.data_from_trial`) uses it on a simulated log and truth table
    directly, so a simulated record and the same record read back from its files agree.

    Besides the table's form (columns, numbers, time) it checks that the channels look like
    their units: a rudder within 45 deg, yaw rate within 1 rad/s and agreeing with the heading,
    the heading's rate and its direction against the track (degrees), the sampling step equal to
    the header's (``interval_s`` for logs, ``dt_s`` for truth files, 0.1 s for FRT-DS-ESSO),
    speeds and track below Froude number 1 for the ship, surge and sway against the track and
    the wind speeds against the ship's velocity.  Each refusal is an
    :class:`~mmg.errors.InputError` naming the channel and the likely unit.
    """
    src = source
    _check_meta(meta, src)
    df = df.copy(deep=False)                # the caller's frame keeps its columns (no copy of the data)
    df.columns = [str(c).strip() for c in df.columns]
    tab = _Table(df, src, lines)
    cols = set(df.columns)
    notes = list(notes or [])
    for nt in notes:
        _log.warning("note: %s: %s", src, nt)
    name = str(meta.get("trial", default_name))
    ship = str(meta.get("ship", ""))
    L = float(meta["length_m"]) if "length_m" in meta else None
    if "t [s]" in cols or "psi_hat [rad]" in cols:
        try:
            return _read_frt(tab, src, Path(src), notes, length_m or FRT_LENGTH_M)
        except InputError as e:       # the 3 m model assumed, not given: say how to give the record's length
            if length_m or "Froude" not in e.message:
                raise
            raise InputError(e.source, e.field, f"{e.message}; the FRT-DS-ESSO layout's usual {FRT_LENGTH_M:g} m model "
                                                f"was assumed: give the record's length (--length) or ship (--ship)") from None
    head = {"name": name, "ship": ship, "source": src}
    if "u_mps" in cols or "psi_rad" in cols:
        return _truth_record(tab, cols, meta, head, notes, L)
    if "lat_deg" in cols or "heading_deg" in cols or "time_s" in cols:
        return _log_record(tab, cols, meta, head, notes, L)
    missing = sorted(set(LOG_COLUMNS) - cols)
    raise InputError(src, missing[0] if missing else "", "missing column (not a project log, truth file or FRT-DS-ESSO CSV)")


def _truth_record(tab: _Table, cols, meta: dict, head: dict, notes: list, L) -> TrialRecord:
    """A truth file's record, its channels checked; head = the record's name, ship and source."""
    tab.require(TRUTH_COLUMNS)
    a = {c: tab.numeric(c) for c in TRUTH_COLUMNS}
    _check_time(tab, "time_s", a["time_s"], meta.get("dt_s"), "the header's dt_s", 1e-3)
    _check_rudder(tab, "delta_rad", a["delta_rad"])
    _check_rudder(tab, "delta_order_rad", a["delta_order_rad"])
    _check_yaw_rate(tab, "r_radps", a["r_radps"])
    _check_heading_rate(tab, "psi_rad", a["time_s"], a["psi_rad"])
    _check_heading_vs_yaw_rate(tab, "psi_rad", "r_radps", a["time_s"], a["psi_rad"], a["r_radps"])
    U = np.hypot(a["u_mps"], a["v_mps"])
    _check_track(tab, "x_m, y_m", a["time_s"], a["x_m"], a["y_m"], L)
    _check_velocities_vs_track(tab, {"u": "u_mps", "v": "v_mps", "psi": "psi_rad", "track": "x_m, y_m"},
                               a["time_s"], a["x_m"], a["y_m"], a["psi_rad"], a["u_mps"], a["v_mps"])
    _check_speed(tab, "u_mps", U, L)
    _check_track(tab, "x_m, y_m", a["time_s"], a["x_m"], a["y_m"], L, U, (0.2, 5.0), "u_mps")
    _check_rps(tab, "n_rps", a["n_rps"])
    wind = _apparent_wind(tab, cols, "wind_rel_mps", "wind_rel_rad", 1.0, 1.0)
    return TrialRecord(t=a["time_s"], **head, x=a["x_m"], y=a["y_m"],
                       psi=a["psi_rad"], U=U, u=a["u_mps"],
                       v=a["v_mps"], r=a["r_radps"], delta=a["delta_rad"], n=a["n_rps"],
                       meta={**meta, "format": "truth", "delta_order": a["delta_order_rad"], "notes": notes,
                             **_holes(tab, {"wind_rel_mps": "wind_speed_rel", "wind_rel_rad": "wind_dir_rel"})},
                       **wind)


def _log_record(tab: _Table, cols, meta: dict, head: dict, notes: list, L) -> TrialRecord:
    """A project log's record (positions in degrees, heading, speed in knots, rpm), its channels checked;
    head = the record's name, ship and source."""
    tab.require(LOG_COLUMNS)
    a = {c: tab.numeric(c) for c in LOG_COLUMNS}
    t = a["time_s"]
    _check_time(tab, "time_s", t, meta.get("interval_s"), "the header's interval_s", 1e-3)
    _check_range(tab, "lat_deg", a["lat_deg"], -90.0, 90.0, "a latitude in degrees")
    _check_range(tab, "lon_deg", a["lon_deg"], -180.0, 360.0, "a longitude in degrees")
    # a gyro's 0-360, +-180, a cumulative count of turns: the same heading; its unit is told by the track
    # in a log that says it is a project log (``interval_s``, as for the speed), else by the gyro's range
    if "interval_s" not in meta:
        _check_range(tab, "heading_deg", a["heading_deg"], -360.0, 360.0, "a heading in degrees (a gyro prints 0-360)")
    psi = unwrap_heading(np.radians(a["heading_deg"]))
    _check_heading_rate(tab, "heading_deg", t, psi, "degrees")
    _check_rps(tab, "rpm", a["rpm"] / 60.0, "rpm", 60.0)
    lat0 = float(meta.get("start_lat_deg", a["lat_deg"][0]))
    lon0 = float(meta.get("start_lon_deg", a["lon_deg"][0]))
    for col, key, v0 in (("lat_deg", "start_lat_deg", lat0), ("lon_deg", "start_lon_deg", lon0)):
        if key in meta and abs(a[col][0] - v0) > 1.0:
            raise InputError(head["source"], col, f"the first position {a[col][0]:.6g} is "
                                                  f"{abs(a[col][0] - v0):.3g} deg from the header's {key} {v0:g}: "
                                                  "not degrees?")
    mlat = float(meta.get("m_per_deg_lat", M_PER_DEG_LAT))
    mlon = float(meta.get("m_per_deg_lon", M_PER_DEG_LON))
    x, y, U = (a["lat_deg"] - lat0) * mlat, (a["lon_deg"] - lon0) * mlon, a["speed_kn"] * KNOT
    _check_speed(tab, "speed_kn", a["speed_kn"], L, "kn", KNOT)
    # the track against the logged speed over ground, for a log that says it is a project log
    _check_track(tab, "lat_deg, lon_deg", t, x, y, L, U, (0.7, 1.4) if "interval_s" in meta else None, "speed_kn")
    if "interval_s" in meta:
        _check_heading_vs_track(tab, "heading_deg", "lat_deg, lon_deg", t, x, y, psi, "degrees")
    extra = {}
    if "rudder_deg" in cols:
        d = tab.numeric("rudder_deg", optional=True)
        _check_rudder_deg(tab, "rudder_deg", d)
        extra["delta"] = d * DEG
    extra.update(_apparent_wind(tab, cols, "wind_rel_kn", "wind_rel_deg", KNOT, DEG))
    return TrialRecord(t=t, **head, x=x, y=y,
                       psi=psi, U=U,
                       n=a["rpm"] / 60.0, meta={**meta, "format": "log", "notes": notes, **_holes(
                           tab, {"rudder_deg": "delta", "wind_rel_kn": "wind_speed_rel", "wind_rel_deg": "wind_dir_rel"})},
                       **extra)


def _read_frt(tab: _Table, src: str, path: Path, notes: list, L: float) -> TrialRecord:
    df = tab.df
    tab.require(FRT_REQUIRED)
    present = [c for c in FRT_COLUMNS if c in df.columns]
    a = {FRT_COLUMNS[c]: tab.numeric(c, optional=c not in FRT_REQUIRED) for c in present}
    a = {k: v for k, v in a.items() if _frt_column(k) not in tab.empty}     # no values at all: absent
    t = a["t"]
    _check_time(tab, "t [s]", t, None, "the FRT-DS-ESSO sampling step (10 Hz)", 0.0, FRT_STEP_RANGE)
    # wrapped, cumulative (a gyro's count of turns) or offset by whole turns: all the same heading; degrees
    # are told by the heading's rate against the sampling step, the yaw rate and the track, not by the range
    psi = unwrap_heading(a.pop("psi"))
    holes = {FRT_COLUMNS[c]: (c, where) for c, where in tab.holes.items()}
    _check_frt_channels(tab, {k: w for k, w in a.items() if k not in holes}, t, psi, L)
    u, v = a.get("u"), a.get("v")
    U = np.hypot(u, v) if u is not None and v is not None else None
    if U is not None and ("u" in holes or "v" in holes):
        holes["U"] = holes.get("u") or holes["v"]
    meta = {"format": "frt-ds-esso", "ship": "Esso Osaka 3 m model" if L == FRT_LENGTH_M else "", "length_m": L,
            "interval_s": float(np.median(np.diff(t))), "notes": notes}
    if holes:
        meta["nan_channels"] = {**_holes(tab, FRT_COLUMNS)["nan_channels"], **holes}
    return TrialRecord(t=a.pop("t"), name=path.stem, ship=meta["ship"], source=src,
                       psi=psi, U=U, meta=meta, **a)


def _frt_column(channel: str) -> str:
    return next(c for c, k in FRT_COLUMNS.items() if k == channel)


def _check_frt_channels(tab: _Table, a: dict, t: np.ndarray, psi: np.ndarray, L: float) -> None:
    """The units of the FRT-DS-ESSO channels ``a`` (those without missing values; by their keys in
    :data:`FRT_COLUMNS`): each against its range and against the other channels."""
    src = tab.src
    _check_heading_rate(tab, "psi_hat [rad]", t, psi)
    if "delta" in a:
        _check_rudder(tab, "delta_rudder [rad]", a["delta"])
    if "r" in a:
        _check_yaw_rate(tab, "r_angvelo [rad/s]", a["r"])
        _check_heading_vs_yaw_rate(tab, "psi_hat [rad]", "r_angvelo [rad/s]", t, psi, a["r"])
    track = "x_position_mid [m], y_position_mid [m]"
    _check_track(tab, track, t, a["x"], a["y"], L)
    if "u" in a:                            # first: it names the unit
        names = {"u": "u_velo [m/s]", "psi": "psi_hat [rad]", "track": track}
        if "v" in a:
            names["v"] = "vm_velo [m/s]"
        _check_velocities_vs_track(tab, names, t, a["x"], a["y"], psi, a["u"], a.get("v"))
    for key, col in (("u", "u_velo [m/s]"), ("v", "vm_velo [m/s]")):
        if key in a:
            _check_speed(tab, col, a[key], L)
    if "n" in a:
        _check_rps(tab, "n_prop [rps]", a["n"])
    for key, col in (("wind_speed_rel", "wind_velo_relative_mid [m/s]"), ("wind_speed_true", "wind_velo_true [m/s]")):
        if key in a:
            w = a[key]
            if float(np.min(w)) < 0.0 or float(np.max(w)) > MAX_WIND_MPS:
                i = int(np.argmax(np.abs(w))) if float(np.max(w)) > MAX_WIND_MPS else int(np.argmin(w))
                raise InputError(src, col, f"wind speed {w[i]:.4g} m/s at {tab.where(i)} is not a wind speed in m/s "
                                           f"(0 to {MAX_WIND_MPS:g}; knots or km/h?)")
    for key, col in (("wind_dir_rel", "wind_dir_relative_mid [rad]"), ("wind_dir_true", "wind_dir_true [rad]")):
        if key in a:
            w = a[key]
            m = float(np.max(np.abs(w)))
            if m > 2 * np.pi + 0.01:
                raise InputError(src, col, f"wind direction {m:.4g} is not radians (|value| <= 2 pi){_angle_hint(m, 360)}")
    _check_wind_consistency(tab, a, psi)
