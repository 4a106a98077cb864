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
from numba import njit

from ._inlining import source_stamp
from .model import N_, P_ENGINE, PSI_, U_, ENGINE_CONSTANT_RPM, PackedShip, rhs
from .rudder import switch_side

SCHEDULE, HEADING_SWITCH = 0, 1

# HEADING_SWITCH parameters
HS_AMP, HS_HI, HS_LO, HS_FIRST, HS_PSI0, HS_TSTART, HS_TRIM = range(7)


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


@njit(cache=True, error_model="numpy")
def _interp(tq, ts, vs, k):
    """Linear interpolation with a moving pointer k (ts increasing); holds the ends."""
    nt = ts.shape[0]
    while k < nt - 2 and ts[k + 1] <= tq:
        k += 1
    if tq <= ts[0]:
        return vs[0], k
    if tq >= ts[nt - 1]:
        return vs[nt - 1], k
    w = (tq - ts[k]) / (ts[k + 1] - ts[k])
    return vs[k] + w * (vs[k + 1] - vs[k]), k


def _compile_simulate_kernel(stamp: int):
    """Compile the kernel below as a closure over ``stamp`` (:func:`mmg._inlining.source_stamp`, a hash of
    the sources it inlines): numba keys its on-disk cache by the function's own file and its closure,
    so an edit of the inlined model (another file) then recompiles it instead of loading stale code."""

    @njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
    def simulate_kernel(x0, dt, nsteps, p, poly, hull_axis, hull_term, hull_coef,
                        kind, cpar, st, sd, sn, states, orders, work):
        """Integrate ``nsteps`` RK4 steps from ``x0``; fill ``states`` (nsteps+1, 8) and ``orders``.

        ``work``: real (6, 8) scratch (the state and the four RK4 stages).  The kernel allocates
        nothing, so it is compiled without reference counting (``_nrt=False``: no atomic
        increment / decrement of the arrays' counts in the right-hand side, several per
        evaluation otherwise).  Releases the GIL (it touches no Python object): runs of different
        threads go on in parallel.  Returns the number of valid rows (< nsteps+1 when the run
        stopped because the surge speed fell below 1 % of its initial value or a value became NaN).
        """
        if stamp < 0:                     # never true: ties the cache entry to the inlined sources
            return 0
        nx = x0.shape[0]
        x = work[0]
        k1 = work[1]
        k2 = work[2]
        k3 = work[3]
        k4 = work[4]
        tmp = work[5]
        for j in range(nx):
            x[j] = x0[j]
        side = cpar[HS_FIRST]
        ptr = 0
        ptrn = 0
        u_min = 0.01 * abs(x0[U_])
        constant_rpm = p[P_ENGINE] == ENGINE_CONSTANT_RPM
        for i in range(nsteps + 1):
            t = i * dt
            if kind == SCHEDULE:
                dcmd, ptr = _interp(t, st, sd, ptr)
                ncmd, ptrn = _interp(t, st, sn, ptrn)
                if constant_rpm and not np.isnan(ncmd):
                    x[N_] = ncmd
            else:
                if t < cpar[HS_TSTART]:
                    dcmd = cpar[HS_TRIM]
                else:
                    side = switch_side(side, x[PSI_] - cpar[HS_PSI0], cpar[HS_HI], cpar[HS_LO])
                    dcmd = side * cpar[HS_AMP]
            for j in range(nx):
                states[i, j] = x[j]
            orders[i] = dcmd
            if not (x[U_] > u_min) or np.isnan(x[PSI_]):
                return i
            if i == nsteps:
                break
            for s in range(4):                       # one inlined copy of the right-hand side
                if s == 0:
                    for j in range(nx):
                        tmp[j] = x[j]
                else:
                    c = 0.5 * dt if s < 3 else dt
                    for j in range(nx):
                        tmp[j] = x[j] + c * work[s, j]
                rhs(tmp, dcmd, p, poly, hull_axis, hull_term, hull_coef, work[s + 1])
            for j in range(nx):
                x[j] += dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
        return nsteps + 1

    return simulate_kernel


simulate_kernel = _compile_simulate_kernel(source_stamp())


def integrate(packed: PackedShip, x0: np.ndarray, law: CommandLaw, duration: float, dt: float):
    """Run the compiled loop; returns (t [s], states (N, 8), rudder orders [rad], completed flag)."""
    nsteps = int(round(duration / dt))
    states = np.empty((nsteps + 1, 8))
    orders = np.empty(nsteps + 1)
    nvalid = simulate_kernel(
        np.asarray(x0, dtype=float), float(dt), nsteps, *packed.args(),
        law.kind, law.params, law.t, law.delta, law.n, states, orders, np.empty((6, 8)),
    )
    t = np.arange(nvalid) * dt
    return t, states[:nvalid], orders[:nvalid], nvalid == nsteps + 1
