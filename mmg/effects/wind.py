"""``wind``: force and moment from the log's measured relative wind.

The loads are the ship's wind-coefficient set (its config's ``wind`` section: Fujiwara, Ueno &
Nimura 1998 regression, :mod:`mmg.wind`) at the logged relative wind speed and direction
(``wind_speed_rel``, ``wind_dir_rel``: the apparent wind, so the loads need no ship state),
times ``scale`` (1 = as published).  A force effect: external (X, Y, N) about midship at the
samples, interpolated by the replay.  It needs the relative-wind channels and a ship with a wind
section; a record without them skips the effect with that reason.  Records whose wind columns
are all zero (:meth:`Wind.unavailable`) are skipped too: the scale is then not identifiable.

Fitted: ``scale`` and three shape terms, ``sway_factor``, ``yaw_factor`` and ``yaw_sin``: the loads are
X = scale X_F, Y = scale sway_factor Y_F, N = scale (yaw_factor N_F + yaw_sin sin(gamma) q A_L L_oa) with
X_F, Y_F, N_F the published regression's (:func:`mmg.wind.amplitude_vector`, the one place the shape
terms act, for the replay's measured-wind loads and the simulator's steady wind alike).  The effect stands for *a* wind load,
not for one regression's numbers: a real ship's side force and, above all, its yaw moment (the arm
of the lateral load, a small difference of large terms) stray from any regression, so one scale
cannot stand for them and the misfit would be named as other effects.  Only ``scale`` says whether
the wind is there (:meth:`Wind.presence_parameters`): with it at 0 the factors do nothing; the test
that it is there is on the three loads together (:meth:`Wind.presence_z`).

``yaw_sin`` (prior :data:`YAW_SIN_SIGMA` = 0.08 about 0, bounds -0.3 to 0.3) lets the yaw moment
change its shape, not only its size: a factor keeps the regression's moment's sign at every angle, and
where a real ship's moment has another sign (the regression on the Esso Osaka geometry turns the bow
away from a wind forward of 73 deg, a loaded VLCC with its accommodation aft turns it into the wind at
every angle) no factor follows it.  On the loaded VLCC's curve of OCIMF (1994)
(:mod:`trials.measured.wind_curves`), over all angles, the best yaw factor alone (1.99) leaves 46 % of
the moment's rms; with ``yaw_sin`` 0.082 (factor 1.15) 10 %; the prior's std is that departure.

The factors' prior (:data:`SHAPE_SIGMA` = 0.35 about 1, bounds 0.2-3): how far a real ship's
coefficients stray from a regression's.  Owens & Palo (1982), *Wind-induced steady loads on ships*,
NAVFAC technical report, DTIC ADA119984 (abstract read; the report itself not), fitting 31 ships from
six independent wind-tunnel series, give the head-wind drag coefficient to 12 % and the peak
lateral-force coefficient to 10 % within their own data, and the yaw moment only "by inspection"
of the data (no regression of useful accuracy): the moment, a lateral load times an arm that is a
small difference of large terms, is the least predictable part.  A factor here also takes up the
curve's shape over the angles a record sees and the geometry a config guesses (no full-scale
geometry is published for the bundled ships), so its prior is wider than a regression's fit
accuracy: 0.35 puts 0.3 and 1.7 at 2 sigma.  The project's own evidence agrees: on the independent
simulator's logs (``../shared/data/diagnose-dev``) one scale fitted 0.36-0.82 for one and the same wind.  Further reading
(not checked here): Haddara & Guedes Soares (1999), Marine Structures 12:199-209, four methods
compared on one tanker; Ueno, Kitamura, Sogihara & Fujiwara (2012), ACEM'12, the 76 ships behind
Fujiwara's regression; Blendermann (1994), J. Wind Eng. Ind. Aerodyn. 51:339-351.

A steady true wind (``true_speed_mps`` > 0, coming FROM ``true_from_deg``, clockwise from
north, the meteorological convention and that of the data set's ``wind_dir_true``) is the
further parameter pair: a simulation has no anemometer record, so the simulator (and a replay
of a record without wind channels) computes the apparent wind from the true one and the ship's
own motion at every step (:func:`mmg.model.wind_loads`, the same Fujiwara series).  With a true
wind given, the logged wind channels are not used (the wind is then what the config says).
Not fitted: the fit frees ``scale`` and the shape factors only.
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

SHAPE_SIGMA = 0.35
"""Prior standard deviation of the shape factors about 1 (module docstring: how far real ships stray)."""

SHAPE_FACTORS = ("sway_factor", "yaw_factor")
"""The shape factors' names: optional in a ship's ``wind:`` section and an ``effects: wind`` section."""

_SWAY = Parameter("sway_factor", "1", 1.0, 0.2, 3.0, SHAPE_SIGMA, "further factor on the published sway force")
_YAW = Parameter("yaw_factor", "1", 1.0, 0.2, 3.0, SHAPE_SIGMA, "further factor on the published yaw moment")

YAW_SIN_SIGMA = 0.08
"""Prior standard deviation of ``yaw_sin`` about 0 (module docstring: a measured tanker curve's departure)."""

_YAW_SIN = Parameter("yaw_sin", "1", 0.0, -0.3, 0.3, YAW_SIN_SIGMA, "yaw-moment coefficient added times sin(gamma)")


class Wind(Effect):
    name = "wind"
    kind = "force"
    description = "wind loads from the measured relative wind"
    parameters = (_SCALE, _SWAY, _YAW, _YAW_SIN,
                  Parameter("true_speed_mps", "m/s", 0.0, 0.0, MAX_TRUE_WIND, 5.0,
                            "steady true wind speed (0: the record's measured wind)"),
                  Parameter("true_from_deg", "deg", 0.0, -360.0, 360.0, 180.0,
                            "direction the steady true wind comes from, clockwise from north"))
    channels = ("wind_speed_rel", "wind_dir_rel")
    affects = ("r", "heading", "v", "position")
    magnitude_unit = "1"
    detection_size = (0.5, "1")
    """0.5 on the scale of the published loads."""

    @classmethod
    def magnitude(cls, values, L):
        """|scale| of the loads."""
        return abs(float(values["scale"]))

    @classmethod
    def fit_parameters(cls):
        # the same parameter, its prior centred on no wind (0, as every effect's on its neutral value),
        # wide; the fit starts from the published loads (1).  mmg identify's --free wind_scale is this one
        # the shape factors: prior and start on the published curves (1)
        return (replace(_SCALE, default=0.0, start=1.0), _SWAY, _YAW, _YAW_SIN)

    @classmethod
    def from_fit(cls, theta):
        return {"scale": float(theta[0]), "sway_factor": float(theta[1]), "yaw_factor": float(theta[2]),
                "yaw_sin": float(theta[3])}

    @classmethod
    def load_factors(cls, scale, sway_factor=1.0, yaw_factor=1.0) -> np.ndarray:
        """The factors (3,) on the surge force, sway force and yaw moment that take the loads :meth:`external`
        gives at some values to those at the values times ``scale``, ``sway_factor`` and ``yaw_factor``:
        scale * (1, sway_factor, yaw_factor), the loads being linear in the scale and in each shape factor
        (:func:`mmg.wind.wind_forces`, :func:`mmg.wind.amplitude_vector`).  How a fit that computes a
        record's loads once (``mmg identify --free wind_scale wind_sway_factor wind_yaw_factor``: factors on
        the loads of the ship's own values) applies its fitted values.

        Parameters
        ----------
        scale : float
            Factor on all three loads [-].
        sway_factor, yaw_factor : float
            Further factors on the sway force and the yaw moment [-].

        Returns
        -------
        ndarray, shape (3,)
            The factors on X, Y and N [-].
        """
        return scale * np.array([1.0, sway_factor, yaw_factor])

    @classmethod
    def presence_parameters(cls):
        """Only the scale: at 0 there is no wind whatever the shape factors say."""
        return ("scale",)

    @classmethod
    def presence_z(cls, theta, cov):
        """The Wald test that the three loads, surge ``scale``, sway ``scale * sway_factor`` and yaw
        ``scale * yaw_factor`` (delta-method covariance), are all zero, as the normal deviate of the
        same two-sided tail probability (chi-square with the covariance's rank as its degrees of
        freedom).  The scale alone (the surge load) can trade with the ship's resistance and thrust,
        which the diagnosis fits too, while the sway and yaw loads, which turn with the relative wind,
        show the wind plainly: on a 10/10 zigzag in a 10 m/s quartering wind (family seed 7000) the
        scale stood 1.6 standard errors from 0 at dBIC 246."""
        from scipy.stats import chi2, norm

        s, a, b = (float(x) for x in np.asarray(theta, float)[:3])
        G = np.array([[1.0, 0.0, 0.0], [a, s, 0.0], [b, 0.0, s]])
        C = G @ np.asarray(cov, float)[:3, :3] @ G.T
        g = np.array([s, s * a, s * b])
        if not (np.all(np.isfinite(C)) and np.all(np.isfinite(g))):
            return super().presence_z(theta, cov)
        w, V = np.linalg.eigh(0.5 * (C + C.T))
        keep = w > 1e-12 * max(float(w.max()), 1e-300)
        if not np.any(keep):
            return super().presence_z(theta, cov)
        x = float(np.sum((V[:, keep].T @ g) ** 2 / w[keep]))
        return float(norm.isf(0.5 * chi2.sf(x, int(np.sum(keep)))))

    @classmethod
    def amplitudes(cls, values, particulars):
        """The Fujiwara amplitudes with the values' shape terms (:func:`mmg.wind.amplitude_vector`)."""
        from ..wind import amplitude_vector

        s = _shape(values)
        return amplitude_vector(particulars, s.sway_factor, s.yaw_factor, s.yaw_sin)

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

        from ..wind import RHO_AIR

        g = ship.wind.particulars()
        p = packed.p.copy()
        p[M.P_WIND_V] = float(values["true_speed_mps"])
        p[M.P_WIND_FROM] = math.radians(float(values["true_from_deg"]))
        p[M.P_WIND_Q] = 0.5 * RHO_AIR * float(values["scale"])
        p[M.P_WIND_AT], p[M.P_WIND_AL], p[M.P_WIND_ALL] = g.A_T, g.A_L, g.A_L * g.L
        p[M.P_WIND_AMP:M.P_WIND_AMP + M.N_WIND_AMP] = cls.amplitudes(values, g)
        return replace(packed, p=p)

    @classmethod
    def external(cls, values, ctx: Context):
        if cls.steady(values):
            return None                   # in the model (pack), from the state
        from ..wind import angle_from_dataset, wind_forces

        X, Y, N = wind_forces(np.asarray(ctx.channels["wind_speed_rel"], float),
                              angle_from_dataset(ctx.channels["wind_dir_rel"]), ctx.ship.wind.particulars(),
                              scale=float(values["scale"]), shape=_shape(values))
        return np.column_stack([X, Y, N])


def _shape(values):
    """The shape terms of the wind effect's ``values`` (:class:`mmg.wind.WindShape`; a term not given: neutral)."""
    from ..wind import WindShape

    return WindShape(float(values.get("sway_factor", 1.0)), float(values.get("yaw_factor", 1.0)),
                     float(values.get("yaw_sin", 0.0)))
