"""``rudder_offset``: the blade sits ``offset_deg`` [deg] from what the rudder indicator logs.

A force effect through the rudder model: the effective blade angle is the logged one plus the
offset (the parameter-vector slot ``P_RUDDER_OFFSET`` read by :func:`mmg.model.rudder`), in the
simulator, the replay and the estimators alike.  Positive: the blade is to starboard of the
indicator (the ship turns to starboard with the indicator at zero).
"""
from __future__ import annotations

import numpy as np

from .. import model as M
from ..units import MAX_RUDDER_OFFSET
from .base import Effect, Parameter

_LIM = float(np.degrees(MAX_RUDDER_OFFSET))


class RudderOffset(Effect):
    name = "rudder_offset"
    kind = "force"
    description = "rudder blade offset from the indicator"
    parameters = (Parameter("offset_deg", "deg", 0.0, -_LIM, _LIM, 5.0, "blade minus indicated angle", 0.0),)
    affects = ("r", "heading", "position")
    magnitude_unit = "deg"
    detection_size = (1.0, "deg")
    """1 deg of blade against indicated angle."""

    @classmethod
    def magnitude(cls, values, L):
        """|offset| [deg]."""
        return abs(float(values["offset_deg"]))

    @classmethod
    def slots(cls, values):
        return {M.P_RUDDER_OFFSET: float(np.radians(values["offset_deg"]))}
