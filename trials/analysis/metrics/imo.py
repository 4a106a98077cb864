"""The IMO standard's manoeuvrability criteria (MSC.137(76)): the limits on the advance, the tactical
diameter, the initial turning ability, the 10/10 and 20/20 zigzag overshoots and the stopping track reach, and
:func:`imo_criteria`, which judges the turning and zigzag metrics against them.
"""
from __future__ import annotations



# --------------------------------------------------------------------------- criteria

IMO_STANDARD = ("IMO Resolution MSC.137(76) (2002), Standards for Ship Manoeuvrability, Annex section 5 "
                "(criteria), with the explanatory notes MSC/Circ.1053 (2002)")
"""Where the manoeuvring criteria below come from (the one definition of each limit in the project)."""

ADVANCE_LIMIT_L = 4.5
"""Largest advance of the turning circle at maximum rudder [L] (MSC.137(76) 5.3.1)."""
TACTICAL_DIAMETER_LIMIT_L = 5.0
"""Largest tactical diameter of the turning circle at maximum rudder [L] (MSC.137(76) 5.3.1)."""
INITIAL_TURNING_LIMIT_L = 2.5
"""Largest track reach [L] with 10 deg rudder by the time the heading has changed by 10 deg (MSC.137(76) 5.3.2)."""
ZZ20_FIRST_OVERSHOOT_LIMIT_DEG = 25.0
"""Largest first overshoot of the 20/20 zigzag [deg] (MSC.137(76) 5.3.3)."""
STOPPING_LIMIT_L = 15.0
"""Largest track reach of the full-astern stopping test [L] (MSC.137(76) 5.3.4; the Administration may
allow more for ships of large displacement, never more than :data:`STOPPING_LIMIT_LARGE_L`)."""
STOPPING_LIMIT_LARGE_L = 20.0
"""The most the Administration may allow for the stopping track reach of a large-displacement ship [L]."""


def zz10_overshoot_limits(L_over_V: float) -> tuple[float, float]:
    """The 10/10 zigzag's first and second overshoot limits [deg] for L/V [s] (MSC.137(76) 5.3.3).

    First: 10 deg if L/V < 10 s, 20 deg if L/V >= 30 s, else 5 + L/V / 2 deg.  Second: 25 deg,
    40 deg, else 17.5 + 0.75 L/V deg.  L is the ship length [m], V the test speed [m/s].
    """
    LV = float(L_over_V)
    if LV < 10.0:
        return 10.0, 25.0
    if LV >= 30.0:
        return 20.0, 40.0
    return 5.0 + 0.5 * LV, 17.5 + 0.75 * LV


def imo_criteria(L: float, U0: float, turning: dict | None = None, zz10: dict | None = None,
                 zz20: dict | None = None) -> list[dict]:
    """IMO MSC.137(76) manoeuvring criteria checked against the metrics given (:data:`IMO_STANDARD`).

    L [m], U0 approach speed [m/s]; L/V sets the 10/10 overshoot limits (:func:`zz10_overshoot_limits`).
    The limits are the module constants (``ADVANCE_LIMIT_L``, ...); :mod:`trials.imo` checks them on
    both sides with their uncertainty.
    """
    rows = []

    def add(name, value, limit):
        rows.append({"criterion": name, "value": value, "limit": limit,
                     "pass": None if value is None else bool(value <= limit)})

    if turning:
        add("advance (L)", turning.get("advance_L"), ADVANCE_LIMIT_L)
        add("tactical diameter (L)", turning.get("tactical_diameter_L"), TACTICAL_DIAMETER_LIMIT_L)
    if zz10:
        lim1, lim2 = zz10_overshoot_limits(L / U0)
        ov = zz10.get("overshoots_deg", [])
        add("10/10 first overshoot (deg)", ov[0] if len(ov) > 0 else None, lim1)
        add("10/10 second overshoot (deg)", ov[1] if len(ov) > 1 else None, lim2)
        add("initial turning: distance to 2nd execute (L)", zz10.get("distance_to_second_execute_L"),
            INITIAL_TURNING_LIMIT_L)
    if zz20:
        ov = zz20.get("overshoots_deg", [])
        add("20/20 first overshoot (deg)", ov[0] if len(ov) > 0 else None, ZZ20_FIRST_OVERSHOOT_LIMIT_DEG)
    return rows
