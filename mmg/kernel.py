"""The simulator's compiled loop: fixed-step RK4 with the rudder / rpm command law evaluated inside.

:func:`simulate_kernel` is what :func:`mmg.integrate.integrate` runs (through :mod:`mmg._aot`,
which compiles this same function ahead of time).  Its own module so that the ahead-of-time
build (:mod:`mmg._aot`) can import it without importing :mod:`mmg.integrate`, which calls the build.
"""
from __future__ import annotations

import numpy as np

from ._inlining import source_stamp
from ._jit import njit
from .model import N_, P_ENGINE, PSI_, U_, ENGINE_CONSTANT_RPM, rhs
from .rudder import switch_side

__all__ = ["simulate_kernel", "SCHEDULE", "HEADING_SWITCH"]

SCHEDULE, HEADING_SWITCH = 0, 1

# HEADING_SWITCH parameters
HS_AMP, HS_HI, HS_LO, HS_FIRST, HS_PSI0, HS_TSTART, HS_TRIM = range(7)


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


