"""Sea-trial logs: writing them as a real trial records them, and reading any supported log.

Formats
-------
* **Project log** (``log.csv``): what Rhee & Kim's simulation prints (section 2.2): every
  ``interval`` seconds ``time_s, lat_deg, lon_deg, heading_deg, speed_kn, rpm``, with
  uniform noise of the Table 4 levels from a seeded generator.  Heading is printed as a
  gyro does, in [0, 360).  Positions use the paper's metres per degree (1852 x 60 for
  latitude, 1526.16 x 60 for longitude).  A ``# key: value`` header carries the ship, the
  trial, its parameters, the start position and the seed.
* **Project truth** (``truth.csv``): the states at every integration step, in SI:
  ``time_s, u_mps, v_mps, r_radps, delta_rad, delta_order_rad, x_m, y_m, psi_rad, n_rps``.
* **FRT-DS-ESSO** (Osaka University free-running model tests): 10 Hz CSV with columns
  ``t [s], x_position_mid [m], u_velo [m/s], y_position_mid [m], vm_velo [m/s], psi_hat [rad]
  (wrapped), r_angvelo [rad/s], n_prop [rps], delta_rudder [rad], wind...``.

:func:`read_record` recognises the format from the header and returns a
:class:`~trials.files.records.TrialRecord`.  Anything else raises :class:`~mmg.errors.InputError`
(one line naming the file and the field; the CLI exits 2), never another exception and never a
silently wrong record:

* the file: missing, a directory, binary (NUL bytes), not UTF-8, larger than
  ``256 * mmg.limits.MAX_SAMPLES`` bytes;
* the table: rows with more or fewer cells than the header, a column twice, missing columns,
  cells that are not finite numbers (named by file line);
* time: not strictly increasing, a gap (a step over 1.5 sampling steps), a sampling step that is
  not the format's (the header's ``interval_s`` for a log, ``dt_s`` for a truth file, 10 Hz for
  FRT-DS-ESSO, or a resampled copy of it at 0.02 to 1 s; "time in milliseconds?" when it is 1000
  times), a step other than the header's (logs, truth files), a record spanning more than
  ``mmg.limits.MAX_STEPS`` steps of 0.1 s (what the estimators would integrate); any number
  beyond 1e12;
* units (plausibility): a rudder beyond 45 deg in a radian column ("degrees?"), a yaw rate
  beyond 1 rad/s ("deg/s?") or disagreeing with the heading's change (one of them in degrees), a
  heading jumping more than 1 rad/s sample after sample, speeds or the track beyond Froude number 1
  for the ship's length, a logged speed that is not the speed along the track (a log with
  ``interval_s``), positions far from the header's start, propeller speeds beyond 100 rps ("rpm?");
* channels against each other: surge and sway against the track's derivative rotated
  into the body frame (:func:`velocity_track_fit`; "in kn, not m/s?"), both wind speeds against
  the ship's velocity (:func:`wind_scale_fit`: one common factor), relative against true wind,
  a heading that does not point along the track.  ``bench/channel_margins.py`` prints what the
  real records fit.

A heading is not refused for its range: wrapped, cumulative (a gyro's count of turns) or offset
by whole turns, it is unwrapped to the same record; degrees are told by its rate against the
sampling step, the yaw rate and the track.  (A log without the project header's ``interval_s``
is not checked against its track, as for its speed: its heading_deg keeps the gyro's range.)

Empty or NaN cells in a column the format does not need (FRT-DS-ESSO: all but time, positions and
heading; a log's rudder and wind; a truth file's wind) do not refuse the record: they are kept as
NaN and noted (``rec.meta["nan_channels"]``, the column and its first file line, and a warning); a
command refuses them only in the channels it uses (:func:`require_finite`).

Rows whose cells are all empty (e.g. the ~300 rows after the end of a real zigzag) carry no
sample: they are ignored and said so (``rec.meta["notes"]`` and a warning on the
``trials.files.logio`` logger); a gap they leave in time is refused as a gap.
"""
from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from mmg.errors import InputError
from mmg.limits import MAX_SAMPLES, MAX_STEPS
from mmg.units import DEG, KNOT

from ..records import TrialRecord
from .layout import MAX_WIND_MPS


# --------------------------------------------------------------------------- reading

_log = logging.getLogger("trials.files.logio")

MAX_SPAN_S = MAX_STEPS * 0.1
"""Longest record [s] a reader accepts: :data:`mmg.limits.MAX_STEPS` steps of 0.1 s (the analysis step)."""
FRT_INTERVAL_S = 0.1
"""FRT-DS-ESSO sampling step [s] (10 Hz)."""
FRT_STEP_RANGE = (0.02, 1.0, FRT_INTERVAL_S)
"""Sampling steps [s] accepted in the FRT-DS-ESSO layout (copies resampled between 50 Hz and 1 Hz)."""
STEP_RTOL = 1e-6
"""Relative tolerance of every comparison of a sampling step with a bound: a step read from a
file's times (0.02 s resampled: a median of 0.0199999999999996 s) is that step, not beyond it."""
DENSE_STEP_S = 1.0
"""Largest sampling step [s] of a dense record (the sample-to-sample heading checks)."""


def _step_within(step: float, lo: float | None = None, hi: float | None = None) -> bool:
    """``lo <= step <= hi`` (either bound optional) within the relative tolerance :data:`STEP_RTOL`."""
    return ((lo is None or step >= lo * (1 - STEP_RTOL)) and (hi is None or step <= hi * (1 + STEP_RTOL)))


FRT_LENGTH_M = 3.0
MAX_RUDDER = 45.0 * DEG
"""Largest plausible rudder angle [rad]; a larger value in a radian column is a unit error."""
MAX_YAW_RATE = 1.0
"""Largest plausible yaw rate [rad/s] (57 deg/s) for any ship or model."""
MAX_FROUDE = 1.0
"""Largest plausible Froude number U / sqrt(g L) of a displacement ship or model."""
MAX_RPS = 100.0
"""Largest plausible propeller speed [rps]."""
MAX_MAGNITUDE = 1e12
"""Largest magnitude of any number in a record (seconds, metres, ...): beyond it arithmetic on the
channels overflows and no unit makes sense."""
G = 9.80665


_MISSING = ("", "nan", "na", "n/a", "null", "none")
"""Cells that say a value is missing (kept as NaN in an optional column)."""


def require_finite(rec: TrialRecord, channels, command: str) -> None:
    """Refuse a record whose ``channels`` (names of :data:`trials.files.records.CHANNELS` and
    :data:`~trials.files.records.WIND_CHANNELS`) a command uses hold missing values.

    The readers keep empty and NaN cells of a column the format does not need as NaN and note
    where (``rec.meta["nan_channels"]``: channel -> (column, first such cell)), so that a command
    that does not use the column reads the record; one that does calls this first.

    Raises
    ------
    InputError
        Naming the file, the column and the file line of its first missing value.
    """
    holes = rec.meta.get("nan_channels") or {}
    for c in channels:
        if c in holes and getattr(rec, c, None) is not None:
            col, where = holes[c]
            raise InputError(rec.source or rec.name, col, f"{where}: {command} uses this channel")


class _Table:
    """A table being checked: numeric columns with messages that point at the file line."""

    def __init__(self, df: pd.DataFrame, src: str, lines=None):
        self.df, self.src, self.lines = df, src, lines
        self.holes: dict[str, str] = {}     # optional column -> where its first missing value is
        self.empty: set[str] = set()        # optional columns with no value at all: no data, as if absent

    def where(self, i: int) -> str:
        return f"line {int(self.lines[i])}" if self.lines is not None else f"data row {i + 1}"

    def require(self, cols) -> None:
        for c in cols:
            if c not in self.df.columns:
                raise InputError(self.src, c, "missing column")

    def numeric(self, c: str, optional: bool = False) -> np.ndarray:
        """Column ``c`` as floats; a cell that is not a finite number is refused, except that in an
        ``optional`` column (one the format does not need) empty and NaN cells are kept as NaN and
        noted in :attr:`holes`: only a command that uses the channel refuses them
        (:func:`require_finite`)."""
        col = self.df[c]
        if col.dtype.kind in "fiu":
            vals = col.to_numpy(dtype=float)
        else:
            vals = pd.to_numeric(col.astype(str).str.strip(), errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(vals))
        if bad.size:
            i = int(bad[0])
            raw = str(col.iloc[i]).strip()
            what = "empty cell" if raw == "" else (f"value {raw[:20]!r} is not a finite number")
            where = f"{what} at {self.where(i)}" + (f" ({bad.size} such cells)" if bad.size > 1 else "")
            if optional and all(str(col.iloc[j]).strip().lower() in _MISSING for j in bad):
                if bad.size == len(vals):      # missing throughout: no data, the channel is absent
                    self.empty.add(c)
                    _log.info("note: %s: %s: no value in any row: treated as absent", self.src, c)
                else:
                    self.holes[c] = where
                return vals
            raise InputError(self.src, c, where)
        huge = np.flatnonzero(np.abs(vals) > MAX_MAGNITUDE)
        if huge.size:
            i = int(huge[0])
            raise InputError(self.src, c, f"value {vals[i]:.4g} at {self.where(i)} is beyond any plausible value of a "
                                          f"channel (|v| > {MAX_MAGNITUDE:g})")
        return vals


_TIME_UNITS = ((1e3, "time in milliseconds?"), (1e6, "time in microseconds?"), (1 / 60, "time in minutes?"),
               (1 / 3600, "time in hours?"))


def _time_hint(ratio: float, step: float, nominal: float) -> str:
    for factor, text in _TIME_UNITS:
        if abs(ratio / factor - 1) < 0.05:
            return f" ({text})"
    if abs(step - 1.0) < 1e-9 and abs(nominal - 1.0) > 1e-6:
        return " (sample numbers rather than seconds?)"
    return ""


def _check_time(tab: _Table, col: str, t: np.ndarray, nominal: float | None, what: str, tol: float,
                step_range: tuple | None = None) -> None:
    """Time strictly increasing, sampled at ``nominal`` (within relative ``tol``; else a gap or a wrong
    step) or, with ``step_range`` (lo, hi, format step), at a uniform step within it, spanning no more
    than :data:`MAX_SPAN_S`."""
    src = tab.src
    if len(t) < 2:
        raise InputError(src, col, "fewer than two samples")
    if len(t) > MAX_SAMPLES:
        raise InputError(src, col, f"{len(t):,} samples; a record may have at most {MAX_SAMPLES:,} (mmg.limits.MAX_SAMPLES)")
    dt = np.diff(t)
    bad = np.flatnonzero(~(dt > 0))
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(src, col, f"time is not strictly increasing at {tab.where(i)} (t = {t[i]:g} s after {t[i - 1]:g} s)")
    med = float(np.median(dt))
    if nominal is not None:
        ratio = med / nominal
        if abs(ratio - 1.0) > tol:
            raise InputError(src, col, f"sampling step {med:g} s, but {what} is {nominal:g} s{_time_hint(ratio, med, nominal)}")
    if step_range is not None:
        lo, hi, fmt = step_range
        if not _step_within(med, lo, hi):
            raise InputError(src, col, f"sampling step {med:g} s, but {what} is {fmt:g} s (resampled copies "
                                       f"{lo:g} to {hi:g} s){_time_hint(med / fmt, med, fmt)}")
    span = float(t[-1] - t[0])
    if span > MAX_SPAN_S:
        ref = nominal or (step_range[2] if step_range else None)
        hint = _time_hint(med / ref, med, ref) if ref else ""
        raise InputError(src, col, f"the record spans {span:.4g} s ({t[0]:g} to {t[-1]:g} s, step {med:g} s); a record may span "
                                   f"at most {MAX_SPAN_S:,.0f} s (mmg.limits.MAX_STEPS steps of 0.1 s){hint}")
    step = nominal if nominal is not None else med
    gap_limit = 1.5 * step if (nominal is not None or step_range is not None) else 3.0 * med
    gap = np.flatnonzero(dt > gap_limit * (1 + 1e-9))
    if gap.size:
        i = int(gap[0])
        missing = int(round(dt[i] / step)) - 1
        raise InputError(src, col, f"gap of {dt[i]:g} s after t = {t[i]:g} s ({tab.where(i + 1)}; about {max(missing, 1)} "
                                   f"sample{'s' if missing > 1 else ''} missing at the sampling step of {step:g} s)")
    if nominal is not None:
        odd = np.flatnonzero(np.abs(dt - nominal) > tol * nominal)
        if odd.size:
            i = int(odd[0])
            raise InputError(src, col, f"step of {dt[i]:g} s after t = {t[i]:g} s ({tab.where(i + 1)}) differs from {what} "
                                       f"({nominal:g} s)")


def _angle_hint(vmax_abs: float, limit_deg: float) -> str:
    return " (degrees?)" if vmax_abs <= 1.01 * max(limit_deg, 360.0) else ""


def _check_rudder(tab: _Table, col: str, d: np.ndarray) -> None:
    m = float(np.max(np.abs(d)))
    if m > MAX_RUDDER:
        i = int(np.argmax(np.abs(d)))
        raise InputError(tab.src, col, f"rudder angle {d[i]:.4g} rad ({float(d[i]) / DEG:.4g} deg) at {tab.where(i)} is beyond the "
                                       f"+/-45 deg of any rudder{_angle_hint(m, 45)}")


def _check_rudder_deg(tab: _Table, col: str, d: np.ndarray) -> None:
    ad = np.where(np.isfinite(d), np.abs(d), 0.0)       # missing values: refused by a command that uses them
    m = float(np.max(ad))
    if m > MAX_RUDDER / DEG:
        i = int(np.argmax(ad))
        raise InputError(tab.src, col, f"rudder angle {d[i]:.4g} deg at {tab.where(i)} is beyond the +/-45 deg of any rudder")


def _check_yaw_rate(tab: _Table, col: str, r: np.ndarray) -> None:
    m = float(np.max(np.abs(r)))
    if m > MAX_YAW_RATE:
        i = int(np.argmax(np.abs(r)))
        hint = " (deg/s?)" if m <= 60 else ""
        raise InputError(tab.src, col, f"yaw rate {r[i]:.4g} rad/s ({float(r[i]) / DEG:.4g} deg/s) at {tab.where(i)} is impossible for a "
                                       f"ship (at most {MAX_YAW_RATE:g} rad/s){hint}")


def _check_heading_rate(tab: _Table, col: str, t: np.ndarray, psi: np.ndarray, unit: str = "radians") -> None:
    """On a dense record (step <= 1 s) the heading [rad, from a column in ``unit``] cannot change faster
    than MAX_YAW_RATE sample after sample."""
    dt = np.diff(t)
    if len(dt) < 10 or not _step_within(float(np.median(dt)), hi=DENSE_STEP_S):
        return
    rate = np.abs(np.diff(psi)) / dt
    p99 = float(np.percentile(rate, 99))
    if p99 > MAX_YAW_RATE:
        hint = " (degrees?)" if unit == "radians" and p99 * DEG <= MAX_YAW_RATE else ""
        raise InputError(tab.src, col, f"the heading changes by up to {p99 / DEG * np.median(dt):.3g} deg from sample to sample "
                                       f"({p99:.3g} rad/s in 1 % of the samples): the heading is "
                                       f"not {unit}{hint}")


def _check_heading_vs_track(tab: _Table, col: str, cols: str, t, x, y, psi, unit: str = "radians") -> None:
    """A project log (a ship going ahead, no body-frame velocities): its heading must point along its
    track (x north, y east) within 45 deg (median over ~2 s blocks that move; a turn's drift angle is
    less).  A heading in another unit points anywhere."""
    i = _block_starts(t, 2.0)
    if len(i) < 6:
        return
    d = np.diff(x[i]) + 1j * np.diff(y[i])
    moving = np.abs(d) > 0.25 * np.median(np.abs(d))
    if moving.sum() < 5 or not np.any(np.abs(d) > 0):
        return
    h = 0.5 * (psi[i][1:] + psi[i][:-1])
    miss = float(np.degrees(np.median(np.abs(np.angle(d[moving] * np.exp(-1j * h[moving]))))))
    if miss > 45.0:
        hint = " (degrees?)" if unit == "radians" else ""
        raise InputError(tab.src, col, f"the heading points {miss:.3g} deg (median) away from the track {cols}: "
                                       f"not a heading in {unit}{hint}")


def _check_heading_vs_yaw_rate(tab: _Table, psi_col: str, r_col: str, t: np.ndarray, psi: np.ndarray, r: np.ndarray) -> None:
    """Heading and yaw rate of a dense record must agree: the least-squares slope of the heading change
    over ~1 s blocks against the integrated yaw rate is 1 (57 when one of them is in degrees)."""
    dt = np.diff(t)
    if len(dt) < 10:
        return
    med = float(np.median(dt))
    if not _step_within(med, hi=DENSE_STEP_S):
        return
    k = max(1, int(round(1.0 / med)))
    idx = np.arange(0, len(t), k)
    if len(idx) < 3:
        return
    rint = np.concatenate([[0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * dt)])
    a, b = np.diff(psi[idx]), np.diff(rint[idx])
    sb = float(np.dot(b, b))
    if not np.isfinite(sb) or np.sqrt(sb) < 5 * DEG:       # too little turning to compare
        return
    slope = float(np.dot(a, b) / sb)
    if 0.5 <= slope <= 2.0:
        return
    r2d = 180 / np.pi
    if abs(slope / r2d - 1) < 0.3:
        raise InputError(tab.src, psi_col, f"the heading changes {slope:.3g} times as fast as the yaw rate {r_col} integrates "
                                           f"(heading in degrees?)")
    if abs(slope * r2d - 1) < 0.3:
        raise InputError(tab.src, r_col, f"the yaw rate integrates to {1 / slope:.3g} times the change of {psi_col} "
                                         f"(yaw rate in deg/s?)")
    if -2.0 <= slope <= -0.5:
        raise InputError(tab.src, r_col, f"the yaw rate has the opposite sign of the change of {psi_col}")
    raise InputError(tab.src, psi_col, f"the heading and the yaw rate {r_col} disagree: the heading changes {slope:.3g} times "
                                       f"what the yaw rate integrates to")


def _check_speed(tab: _Table, col: str, U: np.ndarray, L: float | None, unit: str = "m/s", factor: float = 1.0) -> None:
    """Speed against the ship: at most Froude number MAX_FROUDE (50 m/s without a length)."""
    limit = MAX_FROUDE * np.sqrt(G * L) if L else 50.0
    m = float(np.max(np.abs(U))) * factor
    if m > limit:
        i = int(np.argmax(np.abs(U)))
        what = f"Froude number {m / np.sqrt(G * L):.3g} for a {L:g} m ship" if L else "beyond any ship"
        raise InputError(tab.src, col, f"speed {U[i]:.4g} {unit} at {tab.where(i)} is {what} (not {unit}?)")


def _check_track(tab: _Table, cols: str, t, x, y, L: float | None, U=None, ratio_range=None, ucol: str = "") -> None:
    """Positions against the ship: the median speed along the track at most Froude MAX_FROUDE for a ship of
    known length ``L`` and, with ``U`` and ``ratio_range``, within that range of the median logged speed."""
    dt = np.diff(t)
    if len(dt) < 3:
        return
    trk = np.hypot(np.diff(x), np.diff(y)) / dt
    med = float(np.median(trk))
    if L and med > MAX_FROUDE * np.sqrt(G * L):
        raise InputError(tab.src, cols, f"the positions move {med:.4g} m/s along the track (median), Froude number "
                                        f"{med / np.sqrt(G * L):.3g} for the {L:g} m ship: not the unit the format says?")
    if U is not None and ratio_range is not None and len(dt) >= 5:
        mu = float(np.median(np.abs(U)))
        if mu > 0.5 and med > 0.25:
            q = med / mu
            if not ratio_range[0] <= q <= ratio_range[1]:
                raise InputError(tab.src, ucol, f"the logged speed is {1 / q:.3g} times the speed along the track "
                                                f"{cols} ({mu:.3g} vs {med:.3g} m/s, medians): wrong speed unit?")


def _apparent_wind(tab: _Table, cols, speed_col: str, dir_col: str, speed_si: float, dir_si: float) -> dict:
    """The optional apparent-wind columns of a project log or truth file (both or neither) as
    ``wind_speed_rel`` [m/s] and ``wind_dir_rel`` [rad, 0 to 2 pi; comes from, from the bow,
    clockwise]; refused when only one is there, the speed is negative or beyond
    :data:`MAX_WIND_MPS`, or the direction is outside one turn of its unit."""
    have = [c for c in (speed_col, dir_col) if c in cols]
    if not have:
        return {}
    if len(have) == 1:
        other = dir_col if have[0] == speed_col else speed_col
        raise InputError(tab.src, other, f"missing: {have[0]} needs {other} (the apparent wind is a speed and a direction)")
    V, d = tab.numeric(speed_col, optional=True), tab.numeric(dir_col, optional=True)
    if speed_col in tab.empty or dir_col in tab.empty:       # a wind with no values: no wind channels
        for c in (speed_col, dir_col):
            tab.holes.pop(c, None)
        return {}
    V = V * speed_si
    Vf, df_ = V[np.isfinite(V)], d[np.isfinite(d)]          # missing values: refused by a command that uses them
    if Vf.size and (Vf.min() < 0 or Vf.max() > MAX_WIND_MPS):
        bad = np.max(np.abs(Vf)) / speed_si
        raise InputError(tab.src, speed_col, f"{bad:.4g} is not an apparent wind speed in its column's unit "
                                             f"(0 to {MAX_WIND_MPS / speed_si:.4g})")
    turn = 2 * np.pi / dir_si
    if df_.size and (df_.min() < -1e-9 or df_.max() > turn * (1 + 1e-9)):
        raise InputError(tab.src, dir_col, f"must lie in 0 to {turn:.6g} (one turn in its column's unit), "
                                           f"got {df_.min():.4g} to {df_.max():.4g}")
    return {"wind_speed_rel": V, "wind_dir_rel": np.mod(d * dir_si, 2 * np.pi)}


def _holes(tab: _Table, channels: dict) -> dict:
    """``rec.meta["nan_channels"]`` of a table: channel -> (column, first missing value) for the
    optional columns (``channels``: column -> channel) that hold missing values, said on the logger."""
    out = {}
    for c, where in tab.holes.items():
        out[channels[c]] = (c, where)
        _log.warning("note: %s: %s: %s (kept as NaN: only a command that uses the channel refuses it)", tab.src, c, where)
    return {"nan_channels": out} if out else {}


def _check_range(tab: _Table, col: str, v: np.ndarray, lo: float, hi: float, what: str) -> None:
    bad = np.flatnonzero((v < lo) | (v > hi))
    if bad.size:
        i = int(bad[0])
        raise InputError(tab.src, col, f"{v[i]:.6g} at {tab.where(i)} is not {what} (range {lo:g} to {hi:g})")


def _check_rps(tab: _Table, col: str, n: np.ndarray, unit: str = "rps", factor: float = 1.0) -> None:
    m = float(np.max(np.abs(n)))
    if m > MAX_RPS:
        i = int(np.argmax(np.abs(n)))
        hint = " (rpm where rps is expected?)" if unit == "rps" else ""
        raise InputError(tab.src, col, f"propeller speed {n[i] * factor:.4g} {unit} at {tab.where(i)} is beyond any ship "
                                       f"(at most {MAX_RPS * factor:g} {unit}){hint}")


WIND_KMH = 3.6
"""km/h per m/s: the wrong unit a wind-speed column is most likely in."""


def _check_wind_consistency(tab: _Table, a: dict, psi: np.ndarray) -> None:
    """Relative and true wind against each other: the true wind follows from the relative wind, the
    ship's u, v and heading (:func:`mmg.wind.true_wind_from_relative`; 3e-4 m/s RMS in the dataset).
    A speed column off by the factor 3.6 (km/h) or 1.944 (knots) is named; all-zero wind columns pass."""
    need = ("wind_speed_rel", "wind_dir_rel", "wind_speed_true", "u", "v")
    if not all(k in a for k in need):
        return
    Vr, Vt = a["wind_speed_rel"], a["wind_speed_true"]
    if not (np.any(Vr > 0) and np.any(Vt > 0)):
        return
    from mmg.wind import true_wind_from_relative

    def miss(scale_rel, scale_true):
        calc, _ = true_wind_from_relative(Vr / scale_rel, a["wind_dir_rel"], a["u"], a["v"], psi)
        return float(np.median(np.abs(calc - Vt / scale_true)))

    tol = 0.1 + 0.1 * float(np.median(Vt))
    if "wind_dir_true" in a:
        s, se, rms = wind_scale_fit(a["t"], Vr, a["wind_dir_rel"], Vt, a["wind_dir_true"], a["u"], a["v"], psi)
        lo, hi = SCALE_OK["wind"]
        good = np.isfinite(s) and rms <= 0.1 * abs(s) * float(np.sqrt(np.mean(a["u"] ** 2 + a["v"] ** 2)))
        if good and (s + 3 * se < lo or s - 3 * se > hi):
            raise InputError(tab.src, "wind_velo_relative_mid [m/s], wind_velo_true [m/s]",
                             f"both wind speeds are {s:.3g} times what the ship's own velocity u, v implies "
                             f"(the true wind minus the relative wind is the ship's velocity){_speed_unit_hint(s)}")
    if miss(1.0, 1.0) <= tol:
        return
    for f, unit in ((WIND_KMH, "km/h"), (1.0 / KNOT, "kn")):
        if miss(f, 1.0) <= tol:
            raise InputError(tab.src, "wind_velo_relative_mid [m/s]", f"the relative wind does not give the logged true "
                                      f"wind unless divided by {f:.4g}: in {unit}, not m/s?")
        if miss(1.0, f) <= tol:
            raise InputError(tab.src, "wind_velo_true [m/s]", f"the true wind does not follow from the relative wind, "
                                      f"speed and heading unless divided by {f:.4g}: in {unit}, not m/s?")
    raise InputError(tab.src, "wind_velo_relative_mid [m/s]", f"relative and true wind disagree (median "
                              f"{miss(1.0, 1.0):.3g} m/s): not the dataset's conventions or units")


# --------------------------------------------------------------------------- channels against each other

SPEED_UNITS = ((1.0 / KNOT, "kn"), (3.6, "km/h"), (100.0, "cm/s"), (1000.0, "mm/s"), (1.0 / 0.3048, "ft/s"),
               (3600.0 / 1609.344, "mph"))
"""Wrong units a column in m/s is most likely in: (value in that unit per m/s, unit)."""
SCALE_OK = {"u": (0.8, 1.25), "v": (0.55, 1.8), "wind": (0.8, 1.25)}
"""Range of a fitted factor (implied over logged for u, v; logged over implied for the wind) within which a
channel is taken to be in its unit.  The real records (bench/channel_margins.py) fit u to 0.997-1.015, the
wind to 0.997-1.002 and v, whose track is the least sure, to 0.76-1.00: the sway of a real zigzag in knots
would fit 0.39.  A factor is judged only when its 3-sigma interval lies wholly outside the range."""


SPEED_TOL = {"u": 0.1, "v": 0.3}
"""How far (relative) a fitted factor may be from a unit's to name the unit: v's track is the least sure."""


def _speed_unit_hint(f: float, tol: float = 0.1) -> str:
    """': in km/h, not m/s?' when ``f`` (logged over implied) is within ``tol`` (relative) of a known
    speed unit's factor; every such unit, nearest first (': in kn or mph, not m/s?')."""
    near = sorted((abs(np.log(f / k)), unit) for k, unit in SPEED_UNITS if f > 0 and abs(np.log(f / k)) < np.log1p(tol))
    if near:
        return f": in {' or '.join(unit for _, unit in near)}, not m/s?"
    if -1.8 <= f <= -0.55:
        return ": the opposite sign of the format's axis?"
    return ": not m/s?"


def _block_starts(t: np.ndarray, seconds: float) -> np.ndarray:
    """Indices of the samples starting consecutive blocks of about ``seconds`` (at least one step each)."""
    med = float(np.median(np.diff(t)))
    k = max(1, int(round(seconds / med)))
    return np.arange(0, len(t), k)


def _integral(t: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Cumulative trapezoidal integral of ``f`` over ``t``, starting at 0."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(t))])


def velocity_track_fit(t, x, y, psi, u, v=None, block_s: float = 2.0):
    """Factors by which the logged body-frame velocities must be multiplied to move the ship along its track.

    Over blocks of about ``block_s`` seconds the track's displacement (x north, y east) is fitted by
    least squares as ``k_u * integral(u (cos psi, sin psi)) + k_v * integral(v (-sin psi, cos psi))``.

    Returns
    -------
    dict
        ``k_u``, ``se_u`` and (with ``v``) ``k_v``, ``se_v``: the factors (1 when the channels are in
        their units) and their standard errors; ``heading_miss_deg``: the median angle between the track's
        displacement and the displacement the velocities and heading imply over the blocks that move,
        with the fitted factors (NaN when none moves); ``blocks``: the number of blocks.
    """
    i = _block_starts(t, block_s)
    c, s = np.cos(psi), np.sin(psi)
    cols = [(_integral(t, u * c), _integral(t, u * s))]
    if v is not None:
        cols.append((_integral(t, -v * s), _integral(t, v * c)))
    A = np.column_stack([np.concatenate([np.diff(ax[i]), np.diff(ay[i])]) for ax, ay in cols])
    b = np.concatenate([np.diff(x[i]), np.diff(y[i])])
    m = len(i) - 1
    out = {"blocks": m, "k_u": np.nan, "se_u": np.inf, "k_v": np.nan, "se_v": np.inf, "heading_miss_deg": np.nan}
    if m < 5:
        return out
    N = A.T @ A
    k = np.linalg.lstsq(A, b, rcond=None)[0]
    pred = A @ k if np.all(np.isfinite(k)) and np.all(k != 0) else A.sum(axis=1)   # any unit or sign of u, v
    dp, dt_ = pred[:m] + 1j * pred[m:], b[:m] + 1j * b[m:]
    moving = (np.abs(dp) > 0.05 * np.median(np.abs(dp))) & (np.abs(dt_) > 0) if np.any(dp) else np.zeros(m, bool)
    if moving.sum() >= 5:
        out["heading_miss_deg"] = float(np.degrees(np.median(np.abs(np.angle(dt_[moving] / dp[moving])))))
    if np.linalg.cond(N) > 1e12:
        return out
    res = b - A @ k
    dof = max(len(b) - len(k), 1)
    cov = float(res @ res) / dof * np.linalg.inv(N)
    out["k_u"], out["se_u"] = float(k[0]), float(np.sqrt(cov[0, 0]))
    if v is not None:
        out["k_v"], out["se_v"] = float(k[1]), float(np.sqrt(cov[1, 1]))
    return out


def _check_velocities_vs_track(tab: _Table, cols: dict, t, x, y, psi, u, v=None) -> None:
    """The logged surge and sway against the track's own derivative rotated into the body frame
    (:func:`velocity_track_fit`): a factor whose 3-sigma interval lies outside :data:`SCALE_OK` is a
    wrong unit (named when it is a known one) or sign.
    ``cols`` names the columns: ``{"u": ..., "v": ..., "psi": ..., "track": ...}``."""
    fit = velocity_track_fit(t, x, y, psi, u, v)
    miss = fit["heading_miss_deg"]
    if np.isfinite(miss) and miss > 45.0:
        raise InputError(tab.src, cols["psi"], f"the heading and the velocities point {miss:.3g} deg (median) away from "
                                               f"the track {cols['track']}: not a heading in radians (degrees?)")
    for key in ("u", "v"):
        k, se = fit[f"k_{key}"], fit[f"se_{key}"]
        lo, hi = SCALE_OK[key]
        if key not in cols or not np.isfinite(k) or not (k + 3 * se < lo or k - 3 * se > hi):
            continue
        f = 1.0 / k if k != 0 else np.inf
        raise InputError(tab.src, cols[key], f"the logged velocity is {f:.3g} times what the track {cols['track']} "
                                             f"implies in the body frame (fit {k:.3g} +/- {se:.2g})"
                                             f"{_speed_unit_hint(f, SPEED_TOL[key])} (or the positions are not in metres)")


def wind_scale_fit(t, Vr, dir_rel, Vt, dir_true, u, v, psi):
    """Common factor ``s`` by which both logged wind speeds exceed the m/s the ship's velocity implies.

    The true air velocity is the apparent one plus the ship's (:func:`mmg.wind.true_wind_from_relative`);
    both wind speeds in one wrong unit (``s`` times m/s) leave the directions alone and scale the
    difference of the two wind vectors to ``s`` times the ship's velocity (u, v), which no wind unit
    touches.  ``s`` is its least-squares factor in the ship's axes.

    Returns
    -------
    (float, float, float)
        ``s``, its standard error (over ~2 s blocks of samples) and the RMS residual [logged unit].
    """
    d = Vr * np.exp(1j * dir_rel) - Vt * np.exp(1j * (dir_true - psi))
    B = u + 1j * v
    bb = float(np.sum(np.abs(B) ** 2))
    if bb <= 0:
        return np.nan, np.inf, np.nan
    s = float(np.real(np.sum(d * np.conj(B)))) / bb
    res = d - s * B
    rms = float(np.sqrt(np.mean(np.abs(res) ** 2)))
    per_block = max(1, int(round(2.0 / float(np.median(np.diff(t))))))   # samples of one ~2 s block
    return s, rms / np.sqrt(bb / per_block), rms
