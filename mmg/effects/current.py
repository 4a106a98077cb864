"""``current``: a uniform steady current over ground.

Parameters: ``speed_mps`` [m/s] and ``direction_deg`` [deg], the direction it sets *towards*,
from north, clockwise.  It is a kinematic effect: the hydrodynamic forces act on the velocity
through the water (the model's u, v), the track over ground adds the current (the
parameter-vector slots ``P_CUR_SPEED``, ``P_CUR_DIR`` of :mod:`mmg.model`, read by
:func:`mmg.model.track`), and the logged u, v of a record (FRT-DS-ESSO: GNSS velocity over
ground resolved in ship axes) are over ground: logged u, v = water-relative u, v + the current
resolved in ship axes (:meth:`Current.to_logged`).  A replay therefore starts (and a segment
restarts) from the water-relative velocity, logged minus current (:meth:`Current.to_model`),
and its residuals compare the replayed over-ground velocity with the logged one; positions
are over ground on both sides.

Fitted in north/east components (regular at zero speed; :meth:`Current.report` gives speed and
direction with standard errors by the delta method).
"""
from __future__ import annotations

import numpy as np

from .. import model as M
from ..units import MAX_CURRENT
from .base import Effect, Parameter


class Current(Effect):
    name = "current"
    kind = "kinematic"
    description = "uniform steady current over ground"
    parameters = (
        Parameter("speed_mps", "m/s", 0.0, 0.0, MAX_CURRENT, 1.0, "current speed"),
        Parameter("direction_deg", "deg", 0.0, -360.0, 360.0, 180.0,
                  "direction it sets towards, from north, clockwise"),
    )
    affects = ("u", "v", "position")
    magnitude_unit = "sqrt(gL)"
    detection_size = (0.0027, "sqrt(gL)")
    """0.0027 sqrt(g L) in its worst-determined direction: 3 % of a trial speed of Froude number 0.09
    (0.15 m/s at 325 m, 0.015 m/s for a 3 m model), a drift of 0.27 L per 100 s at full scale."""

    @classmethod
    def magnitude(cls, values, L):
        """The current's speed over sqrt(g L)."""
        return float(values["speed_mps"]) / float(np.sqrt(9.80665 * L))

    @classmethod
    def fit_parameters(cls):
        return (Parameter("north_mps", "m/s", 0.0, -MAX_CURRENT, MAX_CURRENT, 1.0, "current towards north", 0.0),
                Parameter("east_mps", "m/s", 0.0, -MAX_CURRENT, MAX_CURRENT, 1.0, "current towards east", 0.0))

    @classmethod
    def from_fit(cls, theta):
        cn, ce = float(theta[0]), float(theta[1])
        return {"speed_mps": float(np.hypot(cn, ce)), "direction_deg": float(np.degrees(np.arctan2(ce, cn)) % 360.0)}

    @staticmethod
    def _ne(values):
        s, d = values["speed_mps"], np.radians(values["direction_deg"])
        return s * np.cos(d), s * np.sin(d)

    @classmethod
    def slots(cls, values):
        return {M.P_CUR_SPEED: float(values["speed_mps"]), M.P_CUR_DIR: float(np.radians(values["direction_deg"]))}

    @classmethod
    def _body(cls, values, psi):
        cn, ce = cls._ne(values)
        c, s = np.cos(psi), np.sin(psi)
        return cn * c + ce * s, -cn * s + ce * c

    @classmethod
    def to_model(cls, values, states):
        out = np.array(states, float)
        cu, cv = cls._body(values, out[:, 5])
        out[:, 0] -= cu
        out[:, 1] -= cv
        return out

    @classmethod
    def to_logged(cls, values, states):
        out = np.array(states, float)
        cu, cv = cls._body(values, out[:, 5])
        out[:, 0] += cu
        out[:, 1] += cv
        return out
