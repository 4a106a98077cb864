"""The simulator's compiled loop: fixed-step RK4 with the rudder / rpm command law evaluated inside.

:func:`simulate_kernel` is what :func:`mmg.integrate.integrate` runs (through :mod:`mmg._aot`,
which compiles this same function ahead of time).  Its own module so that the ahead-of-time
build (:mod:`mmg._aot`) can import it without importing :mod:`mmg.integrate`, which calls the build.
"""
from __future__ import annotations

import numpy as np

from ._jit import njit
from .model import DELTA_, ENGINE_CONSTANT_RPM, N_, P_ENGINE, PSI_, R_, U_, V_, rhs_of
from .rk4 import rk4_step
from .rudder import switch_side

__all__ = ["simulate_kernel", "rk4_step", "axpy8", "SCHEDULE", "HEADING_SWITCH"]

SCHEDULE, HEADING_SWITCH = 0, 1

ZERO8 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

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


@njit(cache=True, error_model="numpy", inline="always")
def axpy8(a, c, b):
    """a + c b of two 8-tuples (the state and a stage derivative) as a tuple: stays in registers."""
    return (a[0] + c * b[0], a[1] + c * b[1], a[2] + c * b[2], a[3] + c * b[3],
            a[4] + c * b[4], a[5] + c * b[5], a[6] + c * b[6], a[7] + c * b[7])


@njit(cache=True, error_model="numpy", inline="always")
def _simulator_rhs(y, tau, args):
    """The simulator's right-hand side for :func:`rk4_step`: :func:`mmg.model.rhs_of` with the
    rudder order held over the step (``args`` = (order, p, poly, hull_axis, hull_term, hull_coef))."""
    dcmd, p, poly, hull_axis, hull_term, hull_coef = args
    return rhs_of(y[U_], y[V_], y[R_], y[PSI_], y[DELTA_], y[N_], dcmd, p, poly, hull_axis, hull_term, hull_coef)


@njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
def simulate_kernel(x0, dt, nsteps, p, poly, hull_axis, hull_term, hull_coef,
                    kind, cpar, st, sd, sn, states, orders):
    """Integrate ``nsteps`` RK4 steps from ``x0``; fill ``states`` (nsteps+1, 8) and ``orders``.

    The state and the four RK4 stages are tuples of scalars (:func:`mmg.model.rhs_of`, inlined), which
    the compiler keeps in registers: an earlier version staged them through a (6, 8) work
    array, 1.27-1.33x the hand-specialised kernel against 1.20-1.23x now
    (``bench/bench_kernel.py``).  The kernel allocates nothing, so it is compiled without
    reference counting (``_nrt=False``: no atomic increment / decrement of the arrays' counts in the right-hand side, several per
    evaluation otherwise).  Releases the GIL (it touches no Python object): runs of different
    threads go on in parallel.  Returns the number of valid rows (< nsteps+1 when the run
    stopped because the surge speed fell below 1 % of its initial value or a value became NaN).
    """
    xs = (x0[0], x0[1], x0[2], x0[3], x0[4], x0[5], x0[6], x0[7])   # the state, as scalars
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
                xs = xs[:N_] + (ncmd,)
        else:
            if t < cpar[HS_TSTART]:
                dcmd = cpar[HS_TRIM]
            else:
                side = switch_side(side, xs[PSI_] - cpar[HS_PSI0], cpar[HS_HI], cpar[HS_LO])
                dcmd = side * cpar[HS_AMP]
        for j in range(8):
            states[i, j] = xs[j]
        orders[i] = dcmd
        if not (xs[U_] > u_min) or np.isnan(xs[PSI_]):
            return i
        if i == nsteps:
            break
        # the four RK4 stages through one inlined copy of the right-hand side (rk4_step)
        xs = rk4_step(_simulator_rhs, axpy8, ZERO8, xs, dt, (dcmd, p, poly, hull_axis, hull_term, hull_coef))
    return nsteps + 1




