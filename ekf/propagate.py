"""The time update of the paper EKF (:mod:`ekf.filter`): one RK4 step of the augmented state and its
exact Jacobian, compiled.

Its own module so that both drivers, the numba loop :func:`ekf.filter.run_filter` and the filterpy
class :class:`ekf.filterpy_ekf.AugmentedEKF`, import it without importing each other
(:mod:`ekf.filter` re-exports every name here).
"""
from __future__ import annotations

import numpy as np
from mmg._jit import njit, readonly

from mmg.model import N_, R_, U_, V_

from .kernels import jacobian_step, make_workspace

NS = 4
SLOTS = readonly(np.array([U_, V_, R_, N_], dtype=np.int64))   # mmg state slot of each dynamic state


@njit(cache=True)
def workspace(nz, hull_coef):
    """Work arrays of :func:`propagate_step` (:func:`ekf.kernels.make_workspace`): z_next = ws[8], F = ws[9]."""
    return make_workspace(nz, np.int64(NS), hull_coef)


@njit(cache=True, inline="always")
def propagate_step(z, d0, d1, dt, ship, idx, ws):
    """One RK4 step of the augmented state z (nz,) and its exact Jacobian into ``ws`` (z_next = ws[8], F = ws[9]).

    F by the tangent-linear RK4 of :func:`ekf.kernels.jacobian_step` (state columns by complex
    step of each stage, derivative columns analytic: 16 complex evaluations of the dynamics a
    step, not 64 of the whole model).

    d0, d1 rudder angle [rad] at the start and end of the step (an input, linear over it), dt [s];
    ship = (p, poly, hull_axis, hull_term) of the packed ship; idx the derivatives' slots in
    ``hull_coef``; ws from :func:`workspace`."""
    # np.int64(): a literal constant would compile a specialisation of its own (Literal[int](4)),
    # beside the int64 one every other caller (the raw-log filter, Python) shares
    jacobian_step(z, (d0, d1, 0.0, 0.0), (SLOTS, np.int64(NS), idx, np.int64(-1)), dt, ship, ws)


@njit(cache=True)
def propagate_jacobian(z, d0, d1, dt, p, poly, hull_axis, hull_term, hull_coef, idx, z_next, F):
    """Propagate z over one step (RK4 on mmg.model.rhs) and fill F = d z_next / d z (complex step).

    z (nz,) real; d0, d1 rudder angle [rad] at the start and end of the step; dt [s];
    hull_coef the packed ship's coefficients (the derivative slots ``idx`` are overwritten
    by z[4:] in a complex copy); z_next (nz,) and F (nz, nz) are written.  F is exact to
    rounding (:func:`propagate_step`; no truncation error).
    """
    ws = workspace(z.shape[0], hull_coef)
    propagate_step(z, d0, d1, dt, (p, poly, hull_axis, hull_term), idx, ws)
    zn, Fw = ws[8], ws[9]
    for i in range(zn.shape[0]):      # element-wise (a slice assignment compiles numba's shape-mismatch message)
        z_next[i] = zn[i]
        for j in range(Fw.shape[1]):
            F[i, j] = Fw[i, j]
