"""Run the simulator: a ship, a command law, a start condition -> a time history."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .equilibrium import Equilibrium, straight_run, with_kq_scale
from .integrate import CommandLaw, integrate
from .model import STATE_NAMES, pack
from .ship import Ship


@dataclass(frozen=True)
class SimulationResult:
    """Time history of a simulation at the integration step.

    t : (N,) time [s]; states : (N, 8) [u, v, r, x, y, psi, delta, n] in SI
    (see :mod:`mmg.model`); orders : (N,) rudder order [rad];
    equilibrium : the start condition; completed : False when the run stopped early.
    """

    t: np.ndarray
    states: np.ndarray
    orders: np.ndarray
    equilibrium: Equilibrium
    completed: bool
    ship: str = ""
    meta: dict = field(default_factory=dict)

    def __getattr__(self, name):
        if name in STATE_NAMES:
            return self.states[:, STATE_NAMES.index(name)]
        raise AttributeError(name)

    @property
    def U(self) -> np.ndarray:
        """Speed through the water [m/s]."""
        return np.hypot(self.states[:, 0], self.states[:, 1])

    def to_pandas(self):
        """States and rudder order as a DataFrame indexed by time [s]."""
        import pandas as pd

        df = pd.DataFrame(self.states, columns=list(STATE_NAMES), index=pd.Index(self.t, name="t"))
        df["delta_order"] = self.orders
        return df


def prepare(ship: Ship, u0: float, n0: float | None = None, trim: bool = True, effects=None):
    """Solve the straight run and pack the (K_Q-calibrated) ship; returns (packed, equilibrium).

    ``effects``: an :class:`mmg.effects.EffectSet` added to the ship's own (:attr:`mmg.ship.Ship.effects`;
    a trial's effects).  Measurement effects (a heading bias) act on logs, not here."""
    es = ship.effect_set().merged(effects)
    es = es if es.items else None
    eq = straight_run(ship, u0, n=n0, trim=trim, effects=es)
    sh = with_kq_scale(ship, eq.K_Q_scale)
    pk = pack(sh, eq.power_W)
    if es is not None:
        pk = es.pack(pk, sh)
    return pk, eq


def simulate(ship: Ship, law: CommandLaw, duration: float, dt: float, u0: float,
             n0: float | None = None, trim: bool = True, effects=None) -> SimulationResult:
    """Simulate from a steady straight run.

    Parameters
    ----------
    ship : Ship
    law : CommandLaw
        Rudder (and rpm) orders, see :mod:`mmg.integrate`.
    duration, dt : float
        Length of the run and fixed RK4 step [s].
    u0 : float
        Approach speed [m/s].
    n0 : float, optional
        Approach rpm [rps]; solved when None.
    trim : bool
        Start from the trimmed straight run (rudder and drift that cancel Y_0, N_0).
    effects : mmg.effects.EffectSet, optional
        Effects besides the ship's own (:func:`prepare`), e.g.
        ``mmg.effects.effect_set({"current": {"speed_mps": 0.5, "direction_deg": 90}})``.
    """
    pk, eq = prepare(ship, u0, n0, trim, effects)
    t, states, orders, done = integrate(pk, eq.state(), law, duration, dt)
    return SimulationResult(t, states, orders, eq, done, ship.name)
