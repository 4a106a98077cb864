"""``wind``: force and moment from the log's measured relative wind.

The loads are the ship's wind-coefficient set (its config's ``wind`` section: Fujiwara, Ueno &
Nimura 1998 regression, :mod:`mmg.wind`) at the logged relative wind speed and direction
(``wind_speed_rel``, ``wind_dir_rel``: the apparent wind, so the loads need no ship state),
times ``scale`` (1 = as published).  A force effect: external (X, Y, N) about midship at the
samples, interpolated by the replay.  It needs the relative-wind channels and a ship with a wind
section; a record without them skips the effect with that reason.  Records whose wind columns
are all zero (:meth:`Wind.unavailable`) are skipped too: the scale is then not identifiable.

Only ``scale`` is fitted.  The published set is a regression over many hulls; a second
parameter (e.g. a separate scale on the yaw moment, the arm of the lateral load) would be
justified by a record with the wind from many directions and a strong wind; the pond records
have 1.5-2 m/s apparent wind and cannot separate it from the hull's own yaw moment.

A steady true wind (``true_speed_mps`` > 0, coming FROM ``true_from_deg``, clockwise from
north, the meteorological convention and that of the data set's ``wind_dir_true``) is the
further parameter pair: a simulation has no anemometer record, so the simulator (and a replay
of a record without wind channels) computes the apparent wind from the true one and the ship's
own motion at every step (:func:`mmg.model.wind_loads`, the same Fujiwara series).  With a true
wind given, the logged wind channels are not used (the wind is then what the config says).
Not fitted: the fit frees ``scale`` only.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .. import model as M
from ..errors import InputError
from .base import Context, Effect, Parameter

MAX_TRUE_WIND = 60.0
"""Largest steady true wind [m/s] a config may give (a hurricane; beyond it the value is in another unit)."""


_SCALE = Parameter("scale", "1", 1.0, 0.0, 10.0, 2.0, "factor on the published wind loads")
"""The wind scale: 1 (the published loads) when a config names the effect; range and prior width."""


class Wind(Effect):
    name = "wind"
    kind = "force"
    description = "wind loads from the measured relative wind"
    parameters = (_SCALE,
                  Parameter("true_speed_mps", "m/s", 0.0, 0.0, MAX_TRUE_WIND, 5.0,
                            "steady true wind speed (0: the record's measured wind)"),
                  Parameter("true_from_deg", "deg", 0.0, -360.0, 360.0, 180.0,
                            "direction the steady true wind comes from, clockwise from north"))
    channels = ("wind_speed_rel", "wind_dir_rel")
    affects = ("r", "heading", "v", "position")

    @classmethod
    def fit_parameters(cls):
        # the same parameter, its prior centred on no wind (0, as every effect's on its neutral value),
        # wide; the fit starts from the published loads (1).  mmg identify's --free wind_scale is this one
        return (replace(_SCALE, default=0.0, start=1.0),)

    @classmethod
    def from_fit(cls, theta):
        return {"scale": float(theta[0])}

    @classmethod
    def unavailable(cls, ctx: Context):
        if ctx.ship is None or getattr(ctx.ship, "wind", None) is None:
            return "the ship config has no wind section (wind geometry)"
        why = super().unavailable(ctx)
        if why:
            return why
        if not np.any(np.asarray(ctx.channels["wind_speed_rel"]) > 0):
            return "the relative-wind columns are all zero"
        return None

    @classmethod
    def needs(cls, values=None):
        """The relative-wind channels, unless ``values`` give a steady true wind (the model's own then)."""
        return () if values is not None and cls.steady(values) else cls.channels

    @classmethod
    def steady(cls, values) -> bool:
        """Whether the values give a steady true wind (else: the record's measured wind)."""
        return float(values.get("true_speed_mps", 0.0)) > 0.0

    @classmethod
    def pack(cls, packed, values, ship=None):
        """A steady true wind into the parameter-vector slots :func:`mmg.model.wind_loads` reads."""
        if not cls.steady(values):
            return packed
        if ship is None or getattr(ship, "wind", None) is None:
            raise InputError("wind", "true_speed_mps", "a steady wind needs the ship's wind section (its geometry)")

        from ..wind import RHO_AIR, amplitude_vector

        g = ship.wind.particulars()
        p = packed.p.copy()
        p[M.P_WIND_V] = float(values["true_speed_mps"])
        p[M.P_WIND_FROM] = math.radians(float(values["true_from_deg"]))
        p[M.P_WIND_Q] = 0.5 * RHO_AIR * float(values["scale"])
        p[M.P_WIND_AT], p[M.P_WIND_AL], p[M.P_WIND_ALL] = g.A_T, g.A_L, g.A_L * g.L
        p[M.P_WIND_AMP:M.P_WIND_AMP + M.N_WIND_AMP] = amplitude_vector(g)
        return replace(packed, p=p)

    @classmethod
    def external(cls, values, ctx: Context):
        if cls.steady(values):
            return None                   # in the model (pack), from the state
        from ..wind import angle_from_dataset, wind_forces

        X, Y, N = wind_forces(np.asarray(ctx.channels["wind_speed_rel"], float),
                              angle_from_dataset(ctx.channels["wind_dir_rel"]), ctx.ship.wind.particulars(),
                              scale=float(values["scale"]))
        return np.column_stack([X, Y, N])
