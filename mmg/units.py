"""Quantities with units at the edges (configs, logs, reports); SI inside.

A dimensional config value is written ``"<number> <unit>"`` (e.g. ``"10 kn"``,
``"35 deg"``, ``"2.34 deg/s"``).  :func:`to_si` converts it to SI for the
dimension the field expects and rejects a unit of the wrong dimension, so
``rudder: "35 m"`` is an error, not 35 radians.  A number without a unit (``10``,
``"0.1"``) is refused, and so is a number that is not finite (``"nan kn"``,
``"1e400 kn"``).  A unit that starts with a digit (``1/s``) must be separated from the
number by a space (``"2 1/s"``); ``"10"`` is the number 10 without a unit, never 1 in
the unit "0".

:func:`to_si` also takes plausible bounds (``lo``, ``hi`` in SI): a value outside them is
refused as "implausible, probably the wrong unit", with the bounds in the unit the value
was written in.  The bounds used across the configs are the constants below; they are
wide enough for any displacement ship a naval architect would model with MMG, from a 1 m
free-running model to a 500 m tanker, and narrow enough to catch a unit slip (knots
written as m/s on a model, radians written as degrees, a length in mm).
"""
from __future__ import annotations

import math
import numbers
import re

KNOT = 1852.0 / 3600.0
"""One knot in m/s."""

DEG = math.pi / 180.0
"""One degree in rad."""

M_PER_DEG_LAT = 1852.0 * 60.0
"""Metres per degree of latitude used by Rhee & Kim's logs (one nautical mile per minute)."""

M_PER_DEG_LON = 1526.16 * 60.0
"""Metres per degree of longitude used by Rhee & Kim's logs (about 34.5 deg N)."""

UNITS: dict[str, dict[str, float]] = {
    "length": {"m": 1.0, "km": 1000.0, "nmi": 1852.0},
    "area": {"m^2": 1.0, "m2": 1.0},
    "speed": {"m/s": 1.0, "kn": KNOT, "knot": KNOT, "knots": KNOT},
    "angle": {"deg": DEG, "rad": 1.0},
    "angular_rate": {"deg/s": DEG, "rad/s": 1.0},
    "time": {"s": 1.0, "min": 60.0, "h": 3600.0},
    "revolutions": {"rps": 1.0, "rpm": 1.0 / 60.0, "1/s": 1.0},
    "density": {"kg/m^3": 1.0, "kg/m3": 1.0},
    "force": {"N": 1.0, "kN": 1e3, "MN": 1e6},
    "moment": {"N*m": 1.0, "kN*m": 1e3, "MN*m": 1e6},
}

# --------------------------------------------------------------------------- plausible bounds (SI)

MAX_SHIP_SPEED = 60.0 * KNOT
"""Approach speed: below 60 kn (30.9 m/s; the fastest displacement ships make about 40 kn)."""

MAX_FROUDE = 1.0
"""Approach Froude number U / sqrt(g L): at most 1 (MMG models displacement ships, Fn < 0.4 in practice)."""

MAX_RUDDER = 90.0 * DEG
"""Any rudder angle (order, amplitude, steering-gear limit): at most 90 deg (ships use 35-45 deg)."""

MAX_HEADING_CHANGE = 360.0 * DEG
"""Switching heading change of a zigzag or S-type trial: at most 360 deg."""

MAX_RUDDER_OFFSET = 10.0 * DEG
"""Rudder indicator zero error: at most 10 deg."""

MAX_LATITUDE = 90.0 * DEG
"""Latitude: within +-90 deg."""

LONGITUDE_RANGE = (-180.0 * DEG, 360.0 * DEG)
"""Longitude: -180 to 360 deg (east positive, either convention)."""

MAX_CURRENT = 20.0 * KNOT
"""Uniform current speed: at most 20 kn (the strongest tidal races run at about 16 kn)."""

MAX_RPM = 100.0
"""Propeller speed: at most 100 rps = 6000 rpm (full scale 50-200 rpm, free-running models to ~1800 rpm)."""

SHIP_LENGTH_RANGE = (0.5, 500.0)
"""Length between perpendiculars: 0.5 m (a small model) to 500 m (the largest ships are 460 m)."""

DENSITY_RANGE = (950.0, 1100.0)
"""Water density: 950-1100 kg/m^3 (fresh tank water 998, sea water 1020-1030)."""

MAX_STEERING_RATE = 60.0 * DEG
"""Steering-gear rate limit: at most 60 deg/s (full scale 2.3-7 deg/s, Froude-scaled models ~16 deg/s)."""

MAX_STEERING_TIME_CONSTANT = 60.0
"""Steering-gear time constant T_E: at most 60 s (Rhee & Kim: 2.5 s)."""

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?:infinity|inf|nan)"
# a unit starting with a letter may follow the number directly ("20deg"); one starting with a
# digit ("1/s") needs a space, so "10" is never read as 1 in the unit "0"
_QUANTITY = re.compile(rf"^\s*({_NUMBER})(?:\s+([A-Za-z0-9][A-Za-z0-9/^*]*)|([A-Za-z][A-Za-z0-9/^*]*))\s*$",
                       re.IGNORECASE)


def _examples(dimension: str) -> str:
    return ", ".join(UNITS[dimension])


def _is_plain_number(value) -> bool:
    if isinstance(value, bool):
        return False
    if isinstance(value, numbers.Real):
        return True
    if isinstance(value, str):
        try:
            float(value)
        except ValueError:
            return False
        return True
    return False


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def to_si(value: str, dimension: str, lo: float | None = None, hi: float | None = None, *,
          lo_open: bool = False, hi_open: bool = False, why: str = "") -> float:
    """Parse ``"<number> <unit>"`` and return the number in SI for ``dimension``.

    Parameters
    ----------
    value : str
        E.g. ``"10 kn"``.
    dimension : str
        A key of :data:`UNITS` (``"speed"``, ``"angle"``, ...).
    lo, hi : float, optional
        Bounds in SI; a value below ``lo`` (or at it when ``lo_open``) or above ``hi`` (or at
        it when ``hi_open``) is refused.  A lower bound of 0 is worded "must be positive" /
        "must be zero or more"; any other bound "outside the plausible range ... probably the
        wrong unit" (or ``why``, when given).

    Raises
    ------
    ValueError
        One line: the value has no unit, is not finite, cannot be read, has a unit of
        another dimension (naming the accepted units) or is outside the bounds.
    """
    table = UNITS[dimension]
    first = next(iter(table))
    if _is_plain_number(value):
        raise ValueError(f"{value!r} has no unit, so it is not a {dimension}: write it with one, "
                         f"e.g. '{str(value).strip()} {first}' (units: {_examples(dimension)})")
    if not isinstance(value, str):
        raise ValueError(
            f"expected a {dimension} with a unit, e.g. '1.0 {first}' (units: {_examples(dimension)}); "
            f"got {value!r}"
        )
    m = _QUANTITY.match(value)
    if not m:
        raise ValueError(f"cannot read {value!r} as '<number> <unit>' (a {dimension}, e.g. '1.0 {first}')")
    number, unit = float(m.group(1)), m.group(2) or m.group(3)
    if unit not in table:
        raise ValueError(f"unit {unit!r} is not a {dimension} (use one of: {_examples(dimension)})")
    if not math.isfinite(number):
        raise ValueError(f"{value!r} is not a finite number")
    x = number * table[unit]
    if not math.isfinite(x):
        raise ValueError(f"{value!r} is not a finite number in SI")
    check_range(x, lo, hi, lo_open=lo_open, hi_open=hi_open, shown=repr(value), unit=unit, scale=table[unit],
                why=why)
    return x


def is_finite_number(x) -> bool:
    """True for a real, finite number that fits a float (not a bool; an int of 400 digits is not)."""
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        return False
    try:
        return math.isfinite(float(x))
    except OverflowError:
        return False


def check_range(x: float, lo: float | None = None, hi: float | None = None, *, lo_open: bool = False,
                hi_open: bool = False, shown=None, unit: str = "", scale: float = 1.0, why: str = "") -> float:
    """``x`` when it is finite and within ``[lo, hi]`` (open ends as flagged); else ValueError.

    ``shown`` is how the value was written (default ``x / scale`` and ``unit``), ``unit`` and
    ``scale`` (SI per unit) express the bounds in the value's unit, ``why`` replaces "probably the
    wrong unit" in an out-of-range message.  The message is one line.
    """
    if not is_finite_number(x):
        raise ValueError(f"{x!r:.40} is not a finite number")
    shown = _fmt(x / scale) + (f" {unit}" if unit else "") if shown is None else shown
    below = lo is not None and (x < lo or (lo_open and x == lo))
    above = hi is not None and (x > hi or (hi_open and x == hi))
    if not (below or above):
        return x
    u = f" {unit}" if unit else ""
    if below and lo == 0:
        word = "positive" if lo_open else "zero or more"
        raise ValueError(f"must be {word}, got {shown}" + (f" ({why})" if why else ""))
    if lo is None:
        rng = f"at most {_fmt(hi / scale)}{u}"
    elif hi is None:
        rng = f"at least {_fmt(lo / scale)}{u}"
    else:
        rng = f"{_fmt(lo / scale)} to {_fmt(hi / scale)}{u}"
    if why:
        raise ValueError(f"{shown} is out of range ({rng}): {why}")
    raise ValueError(f"{shown} is outside the plausible range ({rng}): probably the wrong unit")
