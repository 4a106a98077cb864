"""The trial-config disturbances (``disturbances.current``, ``disturbances.rudder_offset``,
``log.bias``) as thin SI adapters over the effects of :mod:`mmg.effects`: a documented alias.

``simulate(..., disturbances=[...])`` builds the same :class:`mmg.effects.EffectSet` as
``effects=`` (:func:`as_effects`); new code states effects as effects.

The physics of each is defined once, in its effect (:class:`mmg.effects.Current`,
:class:`mmg.effects.RudderOffset`); the classes here keep the simulator's SI interface (speed in
m/s, angles in rad) and write the effect's parameter-vector slots (:mod:`mmg.model`) through
:meth:`Disturbance.slots`, so the compiled right-hand side (simulator and estimators) sees them
without a second copy.  :meth:`Disturbance.effect` gives the named effect and values (the
form the replay, :mod:`ekf.identify` and ``mmg diagnose`` use).  Sensor biases act on logs
(:class:`SensorBias`, read by :func:`trials.files.logio.log_frame`); the heading part is the
``heading_bias`` effect of a logged heading.

Conventions: directions are the direction a flow goes *towards*, clockwise from
north [rad]; forces in N and moments in N m about midship.

Every component checks its values when it is built: they must be finite, a current's speed
0 to 20 kn (:data:`mmg.units.MAX_CURRENT`) and a rudder offset within +-10 deg
(:data:`mmg.units.MAX_RUDDER_OFFSET`); anything else raises :class:`mmg.errors.InputError`
naming the component and the field, so a NaN never reaches the solver.
"""
from __future__ import annotations

import abc
import math
from dataclasses import dataclass, fields

from . import model as M
from . import effects as E
from .errors import InputError
from .units import MAX_CURRENT, MAX_RUDDER_OFFSET, is_finite_number


def _check(obj, bounds: dict | None = None) -> None:
    """InputError unless every field of ``obj`` is a finite number within ``bounds`` (name -> (lo, hi), SI)."""
    for f in fields(obj):
        v = getattr(obj, f.name)
        if not is_finite_number(v):
            raise InputError(type(obj).__name__, f.name, f"must be a finite number, got {v!r:.40}")
        lo, hi = (bounds or {}).get(f.name, (-math.inf, math.inf))
        if not lo <= v <= hi:
            raise InputError(type(obj).__name__, f.name, f"{v!r} is outside {lo:g} to {hi:g} (SI)")


class Disturbance(abc.ABC):
    """A disturbance: maps to parameter-vector slots of the compiled model."""

    @abc.abstractmethod
    def effect(self):
        """(effect class, named values) of :mod:`mmg.effects`."""

    def slots(self) -> dict[int, float]:
        """Parameter index -> value (the effect's slots)."""
        cls, values = self.effect()
        return cls.slots(values)


@dataclass(frozen=True)
class UniformCurrent(Disturbance):
    """Uniform steady current: speed [m/s] towards ``direction`` [rad from north].

    The hydrodynamic forces use the velocity through the water (the state's u, v);
    the track over ground adds the current.
    """

    speed: float
    direction: float

    def __post_init__(self):
        _check(self, {"speed": (0.0, MAX_CURRENT)})

    def effect(self):
        return E.Current, {"speed_mps": self.speed, "direction_deg": math.degrees(self.direction)}

    def slots(self):          # exact radians, no round trip through degrees
        return {M.P_CUR_SPEED: self.speed, M.P_CUR_DIR: self.direction}


@dataclass(frozen=True)
class RudderOffset(Disturbance):
    """A rudder indicator zero error [rad]: the effective angle is delta + offset."""

    offset: float

    def __post_init__(self):
        _check(self, {"offset": (-MAX_RUDDER_OFFSET, MAX_RUDDER_OFFSET)})

    def effect(self):
        return E.RudderOffset, {"offset_deg": math.degrees(self.offset)}

    def slots(self):
        return {M.P_RUDDER_OFFSET: self.offset}


@dataclass(frozen=True)
class ConstantForce(Disturbance):
    """Constant body-fixed force and moment (e.g. a steady wind load): X, Y [N], N [N m]."""

    X: float = 0.0
    Y: float = 0.0
    N: float = 0.0

    def __post_init__(self):
        _check(self)

    def effect(self):
        raise NotImplementedError("a constant force is not a named effect; use its slots")

    def slots(self):
        return {M.P_EXT_X: self.X, M.P_EXT_Y: self.Y, M.P_EXT_N: self.N}


@dataclass(frozen=True)
class SensorBias:
    """Constant bias of logged channels (heading [rad], speed [m/s], rpm [rps])."""

    heading: float = 0.0
    speed: float = 0.0
    rpm: float = 0.0

    def __post_init__(self):
        _check(self)

    def effect(self):
        """The heading part as the ``heading_bias`` effect (speed and rpm biases have no effect module)."""
        return E.HeadingBias, {"bias_deg": math.degrees(self.heading)}


def as_effects(disturbances) -> tuple:
    """(:class:`mmg.effects.EffectSet` of the components' effects, slots of those that are no named
    effect (:class:`ConstantForce`)): how ``simulate(disturbances=...)`` builds the same effects as
    ``effects=`` (the documented alias; the physics is the effects')."""
    items, slots = [], {}
    for d in disturbances or ():
        if isinstance(d, E.EffectSet):
            items += list(d.items)
        elif isinstance(d, ConstantForce):
            slots.update(d.slots())
        else:
            items.append(d.effect())
    return E.EffectSet(tuple(items)), slots


def combine(disturbances) -> dict[int, float]:
    """Merge the slots of several disturbances (later ones win on the same slot)."""
    out: dict[int, float] = {}
    for d in disturbances:
        out.update(d.slots())
    return out
