"""Fixed-step RK4 integration with the rudder/rpm command evaluated in the loop.

Two kinds of command law run inside the compiled loop, so closed-loop trials
(zigzag, S-type) cost no Python per step:

* ``SCHEDULE``: rudder order delta*(t) and, optionally, rpm order n*(t), linear
  interpolation in a table (turning, sine, sawtooth, any table).
* ``HEADING_SWITCH``: the rudder order is +/- delta_a; it reverses to port when
  the heading change reaches psi_hi and to starboard when it falls to psi_lo
  (zigzag: psi_hi = -psi_lo = psi_a; S-type: psi_hi = psi_S, psi_lo = 0); the law is
  :func:`mmg.rudder.switch_side`, the same one that rebuilds the rudder of a log.

The command is held over a step (zero-order hold); the steering gear and shaft
dynamics are part of the integrated state.  Deterministic: same inputs, same
bits.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kernel import (HEADING_SWITCH, HS_AMP, HS_FIRST, HS_HI, HS_LO, HS_PSI0, HS_TRIM,  # noqa: F401 (re-exported)
                     HS_TSTART, SCHEDULE, _interp, simulate_kernel)
from .model import PackedShip


@dataclass(frozen=True)
class CommandLaw:
    """Rudder (and rpm) order for the compiled loop.

    kind : SCHEDULE or HEADING_SWITCH
    params : HEADING_SWITCH parameters [amp rad, psi_hi rad, psi_lo rad, first side +1/-1,
             psi_0 rad, t_start s, trim rudder rad before t_start]
    t, delta, n : schedule table: time [s], rudder order [rad], rpm order [rps] (NaN: keep current)
    """

    kind: int
    params: np.ndarray
    t: np.ndarray
    delta: np.ndarray
    n: np.ndarray

    @staticmethod
    def schedule(t, delta, n=None) -> "CommandLaw":
        t = np.asarray(t, dtype=float)
        d = np.asarray(delta, dtype=float)
        nn = np.full_like(t, np.nan) if n is None else np.asarray(n, dtype=float)
        return CommandLaw(SCHEDULE, np.zeros(7), t, d, nn)

    @staticmethod
    def heading_switch(amp, psi_hi, psi_lo, first_side, psi0=0.0, t_start=0.0, trim=0.0) -> "CommandLaw":
        par = np.array([amp, psi_hi, psi_lo, float(np.sign(first_side)), psi0, t_start, trim])
        z = np.zeros(1)
        return CommandLaw(HEADING_SWITCH, par, z, z, z)


def integrate(packed: PackedShip, x0: np.ndarray, law: CommandLaw, duration: float, dt: float):
    """Run the compiled loop; returns (t [s], states (N, 8), rudder orders [rad], completed flag)."""
    nsteps = int(round(duration / dt))
    states = np.empty((nsteps + 1, 8))
    orders = np.empty(nsteps + 1)
    from ._aot import simulate_kernel as the_kernel     # ahead-of-time compiled, or the JIT's (mmg._aot)

    f8 = lambda a: np.ascontiguousarray(a, dtype=np.float64)           # noqa: E731 (the compiled types)
    nvalid = the_kernel()(
        f8(x0), float(dt), nsteps, f8(packed.p), f8(packed.poly), np.ascontiguousarray(packed.hull_axis, dtype=np.int64),
        np.ascontiguousarray(packed.hull_term, dtype=np.int64), f8(packed.hull_coef),
        int(law.kind), f8(law.params), f8(law.t), f8(law.delta), f8(law.n), states, orders,
    )
    t = np.arange(nvalid) * dt
    return t, states[:nvalid], orders[:nvalid], nvalid == nsteps + 1
