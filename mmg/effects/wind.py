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
"""
from __future__ import annotations

import numpy as np

from .base import Context, Effect, Parameter


class Wind(Effect):
    name = "wind"
    kind = "force"
    description = "wind loads from the measured relative wind"
    parameters = (Parameter("scale", "1", 1.0, 0.0, 10.0, 2.0, "factor on the published wind loads"),)
    channels = ("wind_speed_rel", "wind_dir_rel")
    affects = ("r", "heading", "v", "position")

    @classmethod
    def fit_parameters(cls):
        # prior centred on no wind (0), wide; the fit starts from the published loads (1)
        return (Parameter("scale", "1", 0.0, 0.0, 10.0, 2.0, "factor on the published wind loads", 1.0),)

    @classmethod
    def unavailable(cls, ctx: Context):
        why = super().unavailable(ctx)
        if why:
            return why
        if ctx.ship is None or getattr(ctx.ship, "wind", None) is None:
            return "the ship config has no wind section (wind geometry)"
        if not np.any(np.asarray(ctx.channels["wind_speed_rel"]) > 0):
            return "the relative-wind columns are all zero"
        return None

    @classmethod
    def external(cls, values, ctx: Context):
        from ..wind import angle_from_dataset, wind_forces

        X, Y, N = wind_forces(np.asarray(ctx.channels["wind_speed_rel"], float),
                              angle_from_dataset(ctx.channels["wind_dir_rel"]), ctx.ship.wind.particulars(),
                              scale=float(values["scale"]))
        return np.column_stack([X, Y, N])
