"""Disturbances as components shared by the simulator and the estimator.

Each component is a frozen dataclass that writes its values into the packed
parameter vector (:mod:`mmg.model`) through :meth:`Disturbance.slots`, so the
compiled right-hand side (used by both the simulator and the estimator's
propagation) sees it without a second copy of the physics.  Measurement-side
effects (sensor biases) act on logs instead, through :meth:`SensorBias.apply`.

Conventions: directions are the direction a flow goes *towards*, clockwise from
north [rad]; forces in N and moments in N m about midship.
"""
from __future__ import annotations

import abc
from dataclasses import dataclass

from . import model as M


class Disturbance(abc.ABC):
    """A disturbance: maps to parameter-vector slots of the compiled model."""

    @abc.abstractmethod
    def slots(self) -> dict[int, float]:
        """Parameter index -> value."""


@dataclass(frozen=True)
class UniformCurrent(Disturbance):
    """Uniform steady current: speed [m/s] towards ``direction`` [rad from north].

    The hydrodynamic forces use the velocity through the water (the state's u, v);
    the track over ground adds the current.
    """

    speed: float
    direction: float

    def slots(self):
        return {M.P_CUR_SPEED: self.speed, M.P_CUR_DIR: self.direction}


@dataclass(frozen=True)
class RudderOffset(Disturbance):
    """A rudder indicator zero error [rad]: the effective angle is delta + offset."""

    offset: float

    def slots(self):
        return {M.P_RUDDER_OFFSET: self.offset}


@dataclass(frozen=True)
class ConstantForce(Disturbance):
    """Constant body-fixed force and moment (e.g. a steady wind load): X, Y [N], N [N m]."""

    X: float = 0.0
    Y: float = 0.0
    N: float = 0.0

    def slots(self):
        return {M.P_EXT_X: self.X, M.P_EXT_Y: self.Y, M.P_EXT_N: self.N}


@dataclass(frozen=True)
class SensorBias:
    """Constant bias of logged channels (heading [rad], speed [m/s], rpm [rps])."""

    heading: float = 0.0
    speed: float = 0.0
    rpm: float = 0.0


def combine(disturbances) -> dict[int, float]:
    """Merge the slots of several disturbances (later ones win on the same slot)."""
    out: dict[int, float] = {}
    for d in disturbances:
        out.update(d.slots())
    return out
