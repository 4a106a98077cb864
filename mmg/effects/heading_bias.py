"""``heading_bias``: the logged heading is the true one plus ``bias_deg`` [deg].

A measurement effect.  The over-ground velocity a record logs in ship axes (FRT-DS-ESSO u, v) is
resolved in the *logged* heading, so with the true heading psi and bias b::

    psi_logged = psi + b
    (u, v)_logged = R(-b) (u, v)_true        R(a) the rotation by a

(the earth-frame velocity is the same either way; the positions are unaffected).  The replay
starts from the true heading and velocities (:meth:`HeadingBias.to_model`) and its states are
mapped back before they are compared (:meth:`HeadingBias.to_logged`).  With the heading reset at
each segment a bias does not show in the heading residual itself: it shows as a sway velocity
-u sin b in the logged v that the hull cannot produce in a straight run.
"""
from __future__ import annotations

import numpy as np

from .base import Effect, Parameter


class HeadingBias(Effect):
    name = "heading_bias"
    kind = "measurement"
    description = "constant bias of the logged heading (velocities resolved in it)"
    parameters = (Parameter("bias_deg", "deg", 0.0, -30.0, 30.0, 10.0, "logged minus true heading", 0.0),)
    affects = ("v", "u")
    magnitude_unit = "deg"
    detection_size = (1.0, "deg")
    """1 deg of logged against true heading."""

    @classmethod
    def magnitude(cls, values, L):
        """|bias| [deg]."""
        return abs(float(values["bias_deg"]))

    @staticmethod
    def logged_heading(psi, bias):
        """The heading a compass with the bias ``bias`` [rad] logs for the true heading ``psi`` [rad]."""
        return psi + bias

    @staticmethod
    def _rot(u, v, a):
        c, s = np.cos(a), np.sin(a)
        return u * c - v * s, u * s + v * c

    @classmethod
    def to_model(cls, values, states):
        b = np.radians(values["bias_deg"])
        out = np.array(states, float)
        out[:, 0], out[:, 1] = cls._rot(out[:, 0], out[:, 1], b)
        out[:, 5] -= b
        return out

    @classmethod
    def to_logged(cls, values, states):
        b = np.radians(values["bias_deg"])
        out = np.array(states, float)
        out[:, 0], out[:, 1] = cls._rot(out[:, 0], out[:, 1], -b)
        out[:, 5] = cls.logged_heading(out[:, 5], b)
        return out
