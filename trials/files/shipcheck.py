"""Records checked against the ship they are analysed with.

Every command that reads a record and analyses it with a ship (``predict``, ``identify``,
``diagnose``, ``estimate``) or a ship length (``metrics``, ``nomoto``) calls
:func:`check_record_ship` after reading it, so that a record of another ship (a full-scale
sea-trial log replayed as the 3 m model, a model record analysed as the 325 m ship) is refused
in one line naming the file and the ship, not computed with.

The checks are dimensionless, so one threshold serves every ship:

* the header's particulars (a project log or truth file says its ``length_m``): within
  :data:`LENGTH_TOLERANCE` of the ship's length;
* the Froude number ``U / sqrt(g L)`` of the record's speeds (99th percentile) at most
  :data:`FROUDE_MAX`: displacement ships and their models run below Fn 0.35; a full-scale
  record read as a 3 m model runs at Fn 0.5 to 1;
* the propeller's tip speed ``pi |n| D`` (99th percentile; ``D`` the ship's propeller diameter, or
  :data:`DIAMETER_PER_LENGTH` ``L`` for a ship given by its length) at most :data:`TIP_SPEED_MAX`:
  real propellers turn with tips below about 45 m/s (the 325 m Esso Osaka about 26 m/s, its
  3 m model about 2.6 m/s), so a full-scale record in rpm (52 "rps" for the 325 m ship: 1.5 km/s)
  or in rad/s, or a model record in rpm, is refused with the likely unit;
* the non-dimensional turning rate ``r' = |r| L / U`` (99th percentile over the samples at a
  meaningful speed: at least :data:`MOVING_FRACTION` of the record's 95th-percentile speed):
  at most :data:`TURN_RATE_MAX` (L / R: a ship turns on a circle of at least a fraction of its
  length; a 3 m model record read as a 325 m ship turns at r' 40 to 250) and, when the heading
  changes by more than :data:`TURNING_DEG`, at least :data:`TURN_RATE_MIN` (a record that
  turns does so on circles of fewer than 20 ship lengths; a full-scale record read as a 3 m
  model turns at r' below 0.01).

The thresholds are calibrated on records the project did not make (the FRT-DS-ESSO 3 m model
records, the full-scale diagnose-dev logs) and on its own simulated trials;
``bench/ship_check_margins.py`` prints the statistics and their margins.
"""
from __future__ import annotations

import math

import numpy as np

from mmg.errors import InputError

G = 9.80665
FROUDE_MAX = 0.45
"""Largest Froude number U / sqrt(g L) (99th percentile of the speeds) of a record of the ship."""
TURN_RATE_MAX = 8.0
"""Largest non-dimensional turning rate |r| L / U (99th percentile, moving samples) of a record of the ship."""
TURN_RATE_MIN = 0.05
"""Smallest 99th-percentile |r| L / U of a record whose heading changes by more than :data:`TURNING_DEG`."""
TURNING_DEG = 15.0
"""Heading change [deg] (range over the record) from which a record counts as turning."""
MOVING_FRACTION = 0.25
"""Samples at a meaningful speed: at least this fraction of the record's 95th-percentile speed."""
LENGTH_TOLERANCE = 0.05
"""Largest relative difference between a header's ``length_m`` and the ship's length."""
TIP_SPEED_MAX = 80.0
"""Largest propeller tip speed pi |n| D [m/s] (99th percentile) of a record of the ship: real ones stay below ~45."""
TIP_SPEED_PLAUSIBLE = 45.0
"""Tip speed [m/s] up to which a propeller speed read in another unit is named as the likely one."""
DIAMETER_PER_LENGTH = 0.02
"""Propeller diameter per ship length assumed for a ship given by its length only (real ships 0.025-0.035:
the smaller figure, so that a valid record is never refused for it)."""
HINT = "a record of another ship? give the record's own ship or length"


class ShipMismatch(InputError):
    """A record that is not of the ship it is analysed with (an :class:`~mmg.errors.InputError`:
    one line, exit 2); commands that skip unusable records still refuse this one."""


def _ship_label(ship_or_length, name: str | None = None) -> tuple[float, str]:
    """(length [m], words naming the ship) of a Ship or a length."""
    parts = getattr(ship_or_length, "particulars", None)
    if parts is not None:
        L = float(parts.L)
        return L, f"the {getattr(ship_or_length, 'name', '') or 'ship'} (L = {L:g} m)"
    L = float(ship_or_length)
    return L, f"the {name} (L = {L:g} m)" if name else f"a ship of L = {L:g} m"


def record_statistics(rec, L: float) -> dict:
    """The dimensionless statistics :func:`check_record_ship` judges, for a ship of length ``L`` [m].

    Returns
    -------
    dict
        ``rps`` (99th percentile of the propeller speed |n| [rps]; NaN without it),
        ``froude`` (99th percentile of U / sqrt(g L)), ``speed`` (that speed [m/s]),
        ``turn_rate`` (99th percentile of |r| L / U over the moving samples; NaN without
        speed or yaw rate), ``heading_range_deg`` (NaN without heading).  NaN samples are left out.
    """
    out = {"froude": math.nan, "speed": math.nan, "turn_rate": math.nan, "heading_range_deg": math.nan,
           "rps": math.nan}
    n = getattr(rec, "n", None)
    if n is not None:
        n = np.abs(np.asarray(n, dtype=float))
        if np.isfinite(n).any():
            out["rps"] = float(np.nanpercentile(n, 99))
    try:
        U = np.abs(np.asarray(rec.speed(), dtype=float))
    except ValueError:
        U = None
    if U is not None and np.isfinite(U).any():
        out["speed"] = float(np.nanpercentile(U, 99))
        out["froude"] = out["speed"] / math.sqrt(G * L)
    if rec.psi is not None and np.isfinite(rec.psi).any():
        out["heading_range_deg"] = float(np.degrees(np.nanmax(rec.psi) - np.nanmin(rec.psi)))
    try:
        r = np.abs(np.asarray(rec.yaw_rate(), dtype=float))
    except ValueError:
        r = None
    if U is not None and r is not None and len(r) == len(U) and np.isfinite(out["speed"]):
        top = float(np.nanpercentile(U, 95))
        m = np.isfinite(U) & np.isfinite(r) & (U >= MOVING_FRACTION * top) & (U > 0)
        if m.sum() >= 10:
            out["turn_rate"] = float(np.percentile(r[m] * L / U[m], 99))
    return out


def check_header(rec, ship_or_length, src: str | None = None, name: str | None = None) -> None:
    """Refuse a record whose header states a length (``length_m``) other than the ship's."""
    src = src or rec.source or rec.name or "record"
    L, who = _ship_label(ship_or_length, name)
    lm = rec.meta.get("length_m")
    if lm is None or rec.meta.get("format") not in ("log", "truth"):
        return
    lm = float(lm)
    if abs(lm / L - 1) > LENGTH_TOLERANCE:
        hdr = f" ({rec.ship})" if rec.ship else ""
        raise ShipMismatch(src, "length_m", f"the header says a {lm:g} m ship{hdr}, not {who}: {HINT}")


SPEED_CHANNELS = ("U", "u", "v", "x", "y")
"""Channels a record's speed is taken from (:meth:`trials.files.records.TrialRecord.speed`)."""


def _checks(channels) -> set:
    """The plausibility checks that judge only channels in ``channels`` (all of them for None)."""
    if channels is None:
        return {"tip_speed", "froude", "turn_rate"}
    used = set(channels)
    out = set()
    if "n" in used:
        out.add("tip_speed")
    if used & set(SPEED_CHANNELS):
        out.add("froude")
        if used & {"r", "psi"}:
            out.add("turn_rate")
    return out


def check_record_ship(rec, ship_or_length, src: str | None = None, name: str | None = None,
                      channels=None) -> dict:
    """Refuse a record that cannot be of the ship: header length, propeller tip speed, Froude number, turning rate.

    Each check judges channels of the record; one the command does not use (``channels``) is not judged:
    the tip speed needs ``n``, the Froude number a speed channel (:data:`SPEED_CHANNELS`), the turning
    rate a speed channel and ``r`` or ``psi``.

    Parameters
    ----------
    rec : TrialRecord
        The record as read (:func:`trials.files.logio.read_record`).
    ship_or_length : Ship or float
        The ship the record is analysed with, or its length [m].
    src : str, optional
        The file named in the message (default ``rec.source``).
    name : str, optional
        Words naming a ship given by its length (e.g. "model the FRT-DS-ESSO layout assumes").
    channels : iterable of str, optional
        The channels the command uses (names of :data:`trials.files.records.CHANNELS`); None: all.

    Returns
    -------
    dict
        :func:`record_statistics` of the record for the ship.

    Raises
    ------
    ShipMismatch
        One line naming the file and the ship.
    """
    src = src or rec.source or rec.name or "record"
    L, who = _ship_label(ship_or_length, name)
    check_header(rec, ship_or_length, src, name)
    s = record_statistics(rec, L)
    checks = _checks(channels)
    if "tip_speed" in checks:
        from .logio import channel_column

        check_tip_speed(s["rps"], propeller_diameter(ship_or_length), src, who, channel_column(rec, "n") or "n")
    if "froude" in checks and s["froude"] > FROUDE_MAX:
        raise ShipMismatch(src, "speed", f"speeds up to {s['speed']:.3g} m/s (99th percentile) are Froude number "
                                         f"{s['froude']:.3g} for {who} (at most {FROUDE_MAX:g}): {HINT}")
    if "turn_rate" not in checks:
        return s
    if s["turn_rate"] > TURN_RATE_MAX:
        raise ShipMismatch(src, "yaw rate", f"the record turns at r L / U = {s['turn_rate']:.3g} (99th percentile) for "
                                            f"{who}, on circles of {1 / s['turn_rate']:.2g} ship lengths (at most "
                                            f"{TURN_RATE_MAX:g}): {HINT}")
    if s["heading_range_deg"] > TURNING_DEG and s["turn_rate"] < TURN_RATE_MIN:
        raise ShipMismatch(src, "yaw rate", f"the heading changes by {s['heading_range_deg']:.0f} deg but at r L / U = "
                                            f"{s['turn_rate']:.3g} (99th percentile) for {who}, on circles of "
                                            f"{1 / s['turn_rate']:.3g} ship lengths (at least {TURN_RATE_MIN:g}): {HINT}")
    return s


def check_same_ship(ship, other, option: str = "--initial", ship_option: str = "--ship") -> None:
    """Refuse a second ship (``--initial``, any other ship option) whose particulars are not ``ship``'s:
    length, beam and draught within :data:`LENGTH_TOLERANCE` (a model and its full-scale ship, or two
    hulls, are not two forms of one ship's model).  One :class:`ShipMismatch` naming both."""
    a, b = ship.particulars, other.particulars
    for key, words in (("L", "length"), ("B", "beam"), ("T", "draught")):
        x, y = float(getattr(a, key)), float(getattr(b, key))
        if not (x > 0 and y > 0) or abs(y / x - 1) > LENGTH_TOLERANCE:
            raise ShipMismatch(option, f"particulars.{key}",
                               f"{other.name or 'the ship'} has {words} {key} = {y:g} m, {ship_option} "
                               f"{ship.name or 'ship'} {x:g} m: not a model of the same ship; give one of "
                               f"{ship.name or ship_option}'s particulars")


def propeller_diameter(ship_or_length) -> float:
    """The ship's propeller diameter [m]; :data:`DIAMETER_PER_LENGTH` times a length given instead of a ship."""
    prop = getattr(ship_or_length, "propeller", None)
    if prop is not None and getattr(prop, "D", None):
        return float(prop.D)
    return DIAMETER_PER_LENGTH * _ship_label(ship_or_length)[0]


def tip_speed(rps: float, D: float) -> float:
    """The propeller's tip speed pi |n| D [m/s] at ``rps`` [rev/s] for a diameter ``D`` [m]."""
    return math.pi * abs(rps) * D


def check_tip_speed(rps: float, D: float, src: str, who: str, field: str = "n_prop") -> None:
    """Refuse a propeller speed ``rps`` [rev/s] whose tip speed with diameter ``D`` exceeds
    :data:`TIP_SPEED_MAX`, naming the unit it is likely in (rpm, rad/s)."""
    if not (math.isfinite(rps) and D > 0):
        return
    v = tip_speed(rps, D)
    if v <= TIP_SPEED_MAX:
        return
    likely = [f"{u}? ({rps:.3g} {u} = {rps / f:.3g} rps, tip speed {v / f:.3g} m/s)"
              for u, f in (("rpm", 60.0), ("rad/s", 2 * math.pi)) if v / f <= TIP_SPEED_PLAUSIBLE]
    raise ShipMismatch(src, field, f"{rps:.3g} rps (99th percentile) is a propeller tip speed pi n D = {v:.3g} m/s "
                                   f"with D = {D:.3g} m of {who}, beyond any real propeller (at most "
                                   f"{TIP_SPEED_MAX:g} m/s): " + ("; ".join(likely) or HINT))


def check_speed_option(rec, speed: float, L: float, src: str | None = None, option: str = "--speed") -> None:
    """Refuse a given speed [m/s] beyond :data:`FROUDE_MAX` for the length ``L`` or more than twice off the
    record's own speed (median over the moving samples)."""
    src = src or rec.source or rec.name or "record"
    fn = speed / math.sqrt(G * L)
    if fn > FROUDE_MAX:
        raise InputError(option, f"{speed:.4g} m/s", f"is Froude number {fn:.3g} for a {L:g} m ship (at most {FROUDE_MAX:g})")
    try:
        U = np.abs(np.asarray(rec.speed(), dtype=float))
    except ValueError:
        return
    U = U[np.isfinite(U)]
    if U.size < 10:
        return
    mid = float(np.median(U[U >= MOVING_FRACTION * np.percentile(U, 95)]))
    if mid > 0 and not 0.5 <= speed / mid <= 2.0:
        raise InputError(option, f"{speed:.4g} m/s", f"the record {src} runs at {mid:.3g} m/s (median): the speed given is "
                                               f"{speed / mid:.3g} times that")


def read_for_ship(path, ship_or_length, name: str | None = None, channels=None):
    """:func:`trials.files.logio.read_record` with the ship's length (for a layout that does not state one), then
    :func:`check_record_ship` of the ``channels`` the command uses (None: all): the one way a command reads
    a record it analyses with a ship.

    A reader's refusal of speeds beyond Froude number 1 for this length (a full-scale record read
    as a model) is raised as a :class:`ShipMismatch` that also names the ship.
    """
    from .logio import read_record

    L, who = _ship_label(ship_or_length, name)
    try:
        rec = read_record(path, length_m=L)
    except InputError as e:
        if "Froude number" in e.message and f"{L:g} m ship" in e.message:
            raise ShipMismatch(e.source, e.field, f"{e.message}; or a record of another ship than {who}? give the "
                                                  f"record's own ship or length") from None
        raise
    check_record_ship(rec, ship_or_length, name=name, channels=channels)
    return rec
