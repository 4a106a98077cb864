"""Compiled kernels shared by the paper EKF (:mod:`ekf.filter`), the raw-log EKF
(:mod:`ekf.log_filter`) and the Fisher information (:mod:`trials.fisher`).

The filters differ only in which :mod:`mmg.model` state slots they propagate and where the
estimated hull derivatives sit in their state z:

* paper filter: z = [u, v, r, n, c_1 .. c_12], slots ``[U_, V_, R_, N_]``, derivatives from z[4];
* raw-log filter: z = [x, y, psi, n, u, v, r, tau, c_1 .. c_12], slots
  ``[X_, Y_, PSI_, N_, U_, V_, R_]``, derivatives from z[8] (tau, the rudder-timing offset, is
  held like the derivatives and enters through the rudder angle, see :func:`jacobian_step`).

So one RK4 step (:func:`rk4_step`), one complex-step Jacobian (:func:`jacobian_step`) and one
covariance propagation (:func:`fpft`) serve both; the only physics is :func:`mmg.model.rhs`.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from mmg.model import DELTA_, rhs

CSTEP = 1e-30               # complex-step size: F = Im(step(z + i h e_j)) / h, exact to rounding


@njit(cache=True)
def rk4_step(z, slots, c0, d0, d1, dt, p, poly, hull_axis, hull_term, coef, idx, xs, k1, k2, k3, k4, out):
    """One RK4 step of the dynamic states of z over ``dt`` [s]; real or complex z.

    z[i] (i < len(slots)) is the mmg state ``slots[i]`` (SI units: m/s, rad/s, m, rad, rps);
    z[c0 + j] is the hull derivative written into ``coef[idx[j]]`` (``coef`` a complex copy of
    the packed ship's ``hull_coef``), held over the step; other mmg states are 0.
    d0, d1: rudder angle [rad] at the start and end of the step (real, or complex to carry a
    complex-step perturbation), linear over the step: it enters as the DELTA_ state (d0 for
    stage 1, the mid value for stages 2-3, d1 for stage 4) and its real part as the command.
    xs, k1..k4: complex work arrays (8,); out[:len(slots)] <- z_next of the dynamic states.
    """
    ns = slots.shape[0]
    for j in range(idx.shape[0]):
        coef[idx[j]] = z[c0 + j]
    zero = 0.0 * z[0]
    for j in range(xs.shape[0]):
        xs[j] = zero
    dm = 0.5 * (d0 + d1)
    for i in range(ns):
        xs[slots[i]] = z[i]
    xs[DELTA_] = d0 + zero
    rhs(xs, d0.real, p, poly, hull_axis, hull_term, coef, k1)
    for i in range(ns):
        xs[slots[i]] = z[i] + 0.5 * dt * k1[slots[i]]
    xs[DELTA_] = dm + zero
    rhs(xs, dm.real, p, poly, hull_axis, hull_term, coef, k2)
    for i in range(ns):
        xs[slots[i]] = z[i] + 0.5 * dt * k2[slots[i]]
    rhs(xs, dm.real, p, poly, hull_axis, hull_term, coef, k3)
    for i in range(ns):
        xs[slots[i]] = z[i] + dt * k3[slots[i]]
    xs[DELTA_] = d1 + zero
    rhs(xs, d1.real, p, poly, hull_axis, hull_term, coef, k4)
    c6 = dt / 6.0
    for i in range(ns):
        s = slots[i]
        out[i] = z[i] + c6 * (k1[s] + 2.0 * k2[s] + 2.0 * k3[s] + k4[s])


@njit(cache=True)
def make_workspace(nz, ns, hull_coef):
    """Work arrays of :func:`jacobian_step` for nz states of which ns are propagated:
    (zc, coef, xs, k1, k2, k3, k4, out, z_next, F); coef is a complex copy of ``hull_coef``."""
    coef = np.empty(hull_coef.shape[0], dtype=np.complex128)
    for i in range(hull_coef.shape[0]):
        coef[i] = hull_coef[i]
    return (np.empty(nz, dtype=np.complex128), coef, np.zeros(8, dtype=np.complex128),
            np.empty(8, dtype=np.complex128), np.empty(8, dtype=np.complex128), np.empty(8, dtype=np.complex128),
            np.empty(8, dtype=np.complex128), np.empty(ns, dtype=np.complex128), np.empty(nz), np.empty((nz, nz)))


@njit(cache=True)
def jacobian_step(z, d0, d1, g0, g1, itau, slots, c0, dt, p, poly, hull_axis, hull_term, idx, ws):
    """One RK4 step of the real state z (:func:`rk4_step`) and its exact Jacobian F = d z_next / d z.

    Column j of F is Im(step(z + i h e_j)) / h with h = 1e-30 (complex step: exact to rounding).
    The states from len(slots) on are held (their rows of F are the identity).
    Rudder [rad] d0 -> d1 over the step; with itau >= 0 it is d + z[itau] g (g0 -> g1 [rad/s]),
    z[itau] a timing offset [s] (g = -d(delta)/dt: the rudder moved by -tau in time); itau < 0:
    the rudder is d alone (g ignored).  ws from :func:`make_workspace`: z_next = ws[8], F = ws[9].
    """
    zc, coef, xs, k1, k2, k3, k4, out, z_next, F = ws
    nz = z.shape[0]
    ns = slots.shape[0]
    for j in range(nz):
        for i in range(nz):
            zc[i] = z[i]
        zc[j] += 1j * CSTEP
        if itau >= 0:
            e0 = d0 + zc[itau] * g0
            e1 = d1 + zc[itau] * g1
        else:
            e0 = d0 + 0j
            e1 = d1 + 0j
        rk4_step(zc, slots, c0, e0, e1, dt, p, poly, hull_axis, hull_term, coef, idx, xs, k1, k2, k3, k4, out)
        for i in range(ns):
            F[i, j] = out[i].imag / CSTEP
        if j == 0:
            for i in range(ns):
                z_next[i] = out[i].real
    for i in range(ns, nz):
        z_next[i] = z[i]
        for j in range(nz):
            F[i, j] = 1.0 if i == j else 0.0


@njit(cache=True)
def _dot(a, b):
    """sum_k a[k] b[k], k ascending (the summation order every caller relies on)."""
    acc = 0.0
    for k in range(a.shape[0]):
        acc += a[k] * b[k]
    return acc


@njit(cache=True)
def fpft(F, P, ns, FP, out):
    """out = F P F^T for F = [[A], [0 I]] with A = F[:ns] (the held states' rows the identity).

    FP (nz, nz) is work space; out may be P itself.  Not symmetrised (see :func:`symmetrise`).
    """
    nz = P.shape[0]
    for i in range(ns):
        for j in range(nz):
            FP[i, j] = _dot(F[i], P[:, j])
    for i in range(ns, nz):
        for j in range(nz):
            FP[i, j] = P[i, j]
    for i in range(nz):
        for j in range(ns):
            out[i, j] = _dot(FP[i], F[j])
        for j in range(ns, nz):
            out[i, j] = FP[i, j]


@njit(cache=True)
def symmetrise(A, out):
    """out = (A + A^T) / 2 (out may be A itself)."""
    n = A.shape[0]
    for i in range(n):
        for j in range(i, n):
            s = 0.5 * (A[i, j] + A[j, i])
            out[i, j] = s
            out[j, i] = s
