"""Engine orders that prescribe the propeller revolutions: the full-astern order of a stopping test.

The engine models of :mod:`mmg.model` hold the revolutions (``constant_rpm``) or integrate the shaft
against a constant power with the first-quadrant K_Q (``constant_power``, Rhee & Kim 1999 eqs. 15-19).
Neither can reverse a shaft: the model has no four-quadrant torque K_Q(beta_p) (:mod:`mmg.fourquadrant`
gives the thrust only) and no astern turbine or diesel.  A reversal is therefore *prescribed*: the
revolutions follow an order n*(t) and the shaft equation is not integrated (no torque needed), whatever
the ship's engine mode (:func:`prescribed_revolutions`).

:class:`AsternOrder` is that order: from the approach revolutions n_0 at the execute time, n falls
linearly through zero to ``-astern_ratio * n_0`` over ``ramp_s`` seconds, then is held.  Constants
and their sources:

* :data:`ASTERN_RPM_RATIO` = 0.7: full-astern revolutions as a fraction of the ahead ones.  A geared
  steam turbine (the Esso Osaka's plant) develops about 40 % of its ahead power astern, a diesel over
  80 % (Cockcroft & Lameijer, *A Guide to the Collision Avoidance Rules*, on the astern power of
  ships); with the propeller torque going as n^2 (power as n^3) 40 % of the power turns the
  propeller at 0.40^(1/3) = 0.74 of the ahead revolutions, fewer while the ship still has headway
  (the propeller then absorbs more torque than in free running astern).  0.7 is that figure rounded
  down; a diesel would give some 0.9 (0.8^(1/3) = 0.93).
* :data:`REVERSAL_TIME_S` = 120 s: from full ahead to full astern revolutions.  "Even if the engines
  can be made to go astern within one minute of the order 'stop' ..." (Cockcroft & Lameijer, same
  passage): a crash reversal of a large ship's engine takes minutes (1-3 min is the figure usually
  quoted for large diesels; no primary source for it was at hand); 120 s puts n = 0 at
  120 / 1.7 = 71 s after the order.  The reach depends on it weakly (60 s: 15.62 L, 180 s: 16.30 L for
  the Esso Osaka against 15.96 L), on the astern revolutions strongly (docs/imo.md).

Both are parameters of the order, not of the ship: a ship with its own engine data gives its own.
:data:`REVERSAL_TIME_S` is a full-scale time: on a Froude-scaled model of scale lambda (its config's
``full_scale:`` section, :attr:`mmg.ship.Ship.froude_scale`) the same reversal takes 120 / sqrt(lambda) s
(times scale as sqrt(lambda) at equal Froude number; :func:`reversal_time`).  The ratio is
non-dimensional and stays.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .model import ENGINE_CONSTANT_RPM, P_ENGINE, PackedShip

__all__ = ["AsternOrder", "ASTERN_RPM_RATIO", "REVERSAL_TIME_S", "prescribed_revolutions", "reversal_time"]

ASTERN_RPM_RATIO = 0.7
"""Full-astern revolutions over the approach (ahead) revolutions (module docstring: source)."""
REVERSAL_TIME_S = 120.0
"""Time [s] of the linear ramp from the approach revolutions to the full-astern ones at full scale
(module docstring; a model's: :func:`reversal_time`)."""


def reversal_time(scale: float = 1.0) -> float:
    """The ramp time [s] of the full-astern order on a ship of Froude scale ``scale`` (lambda = L of the
    full-scale ship / L of this one; 1 at full scale): :data:`REVERSAL_TIME_S` / sqrt(lambda)."""
    scale = float(scale)
    if not (math.isfinite(scale) and scale > 0.0):
        raise ValueError(f"scale: a positive finite number, got {scale!r}")
    return REVERSAL_TIME_S / math.sqrt(scale)


@dataclass(frozen=True)
class AsternOrder:
    """Full astern: the revolutions ramp linearly from n_0 to ``-astern_ratio * n_0``, then hold (SI).

    Attributes
    ----------
    astern_ratio : float
        Full-astern revolutions over the approach ones (> 0, at most 1.5), default :data:`ASTERN_RPM_RATIO`.
    ramp_s : float
        Duration [s] of the ramp from n_0 to the full-astern revolutions (>= 0; 0: a step),
        default :data:`REVERSAL_TIME_S`.
    execute_s : float
        Time [s] of the astern order (>= 0), default 0.
    """

    astern_ratio: float = ASTERN_RPM_RATIO
    ramp_s: float = REVERSAL_TIME_S
    execute_s: float = 0.0

    def __post_init__(self):
        ok = {"astern_ratio": lambda v: 0.0 < v <= 1.5, "ramp_s": lambda v: 0.0 <= v <= 3600.0,
              "execute_s": lambda v: 0.0 <= v < math.inf}
        for name, good in ok.items():
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not good(float(v)):
                raise ValueError(f"AsternOrder.{name}: {v!r} is not a finite number in its range "
                                 f"(astern_ratio (0, 1.5], ramp_s [0, 3600] s, execute_s >= 0 s)")

    def revolutions(self, t, n0: float) -> np.ndarray:
        """The ordered revolutions [rps] at times ``t`` [s] from the approach ones ``n0`` [rps]."""
        t = np.asarray(t, dtype=float)
        n_end = -self.astern_ratio * n0
        if self.ramp_s == 0.0:
            return np.where(t < self.execute_s, n0, n_end)
        w = np.clip((t - self.execute_s) / self.ramp_s, 0.0, 1.0)
        return n0 + w * (n_end - n0)

    def table(self, n0: float, duration: float) -> tuple[np.ndarray, np.ndarray]:
        """Breakpoints (t [s], n [rps]) of the order over [0, ``duration``] for linear interpolation
        (:meth:`mmg.integrate.CommandLaw.schedule`); a step (``ramp_s`` = 0) is a ramp of 1 ns."""
        t0 = self.execute_s
        t1 = t0 + max(self.ramp_s, 1e-9)
        n_end = -self.astern_ratio * n0
        t = [t0, t1, max(duration, t1) + 1.0]
        n = [n0, n_end, n_end]
        if t0 > 0.0:
            t, n = [0.0] + t, [n0] + n
        return np.asarray(t, dtype=float), np.asarray(n, dtype=float)


def prescribed_revolutions(packed: PackedShip) -> PackedShip:
    """``packed`` with its revolutions taken from the order (the shaft equation not integrated): the
    simulator's constant-rpm mode, whatever the ship's engine (a copy; the original is not changed)."""
    p = packed.p.copy()
    p[P_ENGINE] = ENGINE_CONSTANT_RPM
    return replace(packed, p=p)
