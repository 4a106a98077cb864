"""Quantities with units at the edges (configs, logs, reports); SI inside.

A dimensional config value is written ``"<number> <unit>"`` (e.g. ``"10 kn"``,
``"35 deg"``, ``"2.34 deg/s"``).  :func:`to_si` converts it to SI for the
dimension the field expects and rejects a unit of the wrong dimension, so
``rudder: "35 m"`` is an error, not 35 radians.
"""
from __future__ import annotations

import math
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

_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z/^*0-9]+)\s*$")


def to_si(value: str, dimension: str) -> float:
    """Parse ``"<number> <unit>"`` and return the number in SI for ``dimension``.

    Raises ValueError with a message naming the accepted units when the string
    is malformed or its unit is not of this dimension.
    """
    table = UNITS[dimension]
    if not isinstance(value, str):
        raise ValueError(
            f"expected a {dimension} with a unit, e.g. '1.0 {next(iter(table))}' (units: {', '.join(table)}); got {value!r}"
        )
    m = _QUANTITY.match(value)
    if not m:
        raise ValueError(f"cannot read {value!r} as '<number> <unit>'")
    number, unit = float(m.group(1)), m.group(2)
    if unit not in table:
        raise ValueError(f"unit {unit!r} is not a {dimension} (use one of: {', '.join(table)})")
    return number * table[unit]
