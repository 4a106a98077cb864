"""State-augmented extended Kalman filter (Rhee & Kim 1999 section 4).

State (4 + m): z = [u, v, r, n, c_1 .. c_m] with c the estimated hull coefficients, named
from the ship's table (:func:`ekf.data.estimable_names`: for the Esso Osaka Rhee & Kim's 12
``Y_beta, Y_r, Y_bb, Y_rr, Y_bbr, Y_brr, N_beta, N_r, N_bb, N_rr, N_bbr, N_brr``); measurements
u, v, r, n (H = [I_4 0]); input the rudder angle delta (recovered, see :mod:`ekf.preprocess`).

Time update
    z is propagated over the 0.1 s step with RK4 on :func:`mmg.model.rhs` (the
    simulator's own right-hand side: the derivatives are written into the packed
    ship's ``hull_coef`` slots, heading/position are not needed, delta is the
    input interpolated linearly over the step, dc/dt = 0).  P <- F P F^T with F the
    exact Jacobian of that RK4 map: the tangent-linear RK4 of
    :func:`ekf.kernels.jacobian_step` (state columns by complex step of each stage, step
    1e-30, coefficient columns analytic as the hull force is linear in them), exact to
    rounding.  Q = 0 as in the paper.
Measurement update
    Joseph form P = (I-KH) P (I-KH)^T + K R K^T (filterpy's
    ``ExtendedKalmanFilter.update`` uses exactly this form; checked in
    ``tests/test_ekf.py``).  P is symmetrised after each step and checked
    for positive definiteness (Cholesky); a non-PD P, a non-finite state or u <= 0
    raises :class:`FilterDivergence` naming the trial and the time.

The RK4 step, its exact Jacobian and F P F^T are the kernels of :mod:`ekf.kernels`,
shared with the raw-log filter (:mod:`ekf.log_filter`); this filter's time update built on them
(:func:`propagate_step`, :func:`propagate_jacobian`) is :mod:`ekf.propagate`, re-exported here.
Two drivers share them:

* :class:`AugmentedEKF` (in :mod:`ekf.filterpy_ekf`, loaded on first use of the name so that
  this module does not import filterpy and scipy.stats), a subclass of filterpy's
  ``ExtendedKalmanFilter`` whose ``predict`` is the compiled propagation above and whose
  ``update`` is filterpy's; convenient step by step but ~100 us/step of Python in filterpy's update.
* :func:`run_filter`, the hot loop: the same predict kernel and the same Joseph-form
  update written in numba, so a 3000 s pass (30 000 steps) takes about half a second.
  filterpy's update is too slow for the 2 s budget (numpy calls on 16x16 arrays
  dominate), hence this; the two drivers agree to rounding (tested).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mmg._jit import carray, interpreted, njit

from mmg.model import PackedShip

from .kernels import (CSTEP, fpft, jacobian_step_reference, joseph_update_ws,  # noqa: F401 (CSTEP re-exported)
                      make_update_workspace, symmetrise)
from .propagate import NS, SLOTS, propagate_jacobian, propagate_step, workspace  # noqa: F401 (re-exported)

STATES = ("u", "v", "r", "n")
PD_TOL = 1e-9

OK, NONFINITE, NEG_SPEED, NOT_PD, NIS_HIGH = 0, 1, 2, 3, 4
_REASON = {NONFINITE: "a state or covariance became non-finite",
           NEG_SPEED: "the surge speed estimate fell to zero or below",
           NOT_PD: "the error covariance P is no longer positive definite",
           NIS_HIGH: "the innovations are far larger than their covariance predicts (mean NIS over the window "
                     "above the limit): the model no longer follows the measurements"}


class FilterDivergence(RuntimeError):
    """The filter diverged; carries the trial name, time [s] and reason."""

    def __init__(self, trial: str, time: float, reason: str):
        self.trial, self.time, self.reason = trial, float(time), reason
        super().__init__(f"EKF diverged on trial {trial!r} at t = {time:.1f} s: {reason} "
                         f"(check the initial derivatives, P0 and R)")


# --------------------------------------------------------------------------- compiled kernels


@njit(cache=True)
def is_pd(P, tol=PD_TOL):
    """True when P is positive (semi)definite to working precision.

    The diagonal must be positive and the correlation matrix D^-1/2 P D^-1/2 (+ tol I) must
    have a Cholesky factor.  The tolerance is needed because with Q = 0 P becomes genuinely
    singular: the shaft equation is stiff (dn/dt relaxes in ~0.2 s), so the model ties n to
    u, v, r and the filter's uncertainty in that combination decays geometrically to zero.
    """
    n = P.shape[0]
    d = np.empty(n)
    for i in range(n):
        if not (P[i, i] > 0.0):
            return False
        d[i] = np.sqrt(P[i, i])
    L = np.zeros((n, n))
    for j in range(n):
        s = 1.0 + tol
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not (s > 0.0):
            return False
        L[j, j] = np.sqrt(s)
        for i in range(j + 1, n):
            s = P[i, j] / (d[i] * d[j])
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / L[j, j]
    return True


@njit(cache=True)
def joseph_update(z, P, meas, R):
    """Measurement update with H = [I_4 0], Joseph form; symmetrises P. In place; returns the NIS y^T S^-1 y."""
    nz = z.shape[0]
    m = meas.shape[0]
    S = np.empty((m, m))
    for i in range(m):
        for j in range(m):
            S[i, j] = P[i, j] + R[i, j]
    SI = np.linalg.inv(S)
    K = np.zeros((nz, m))
    for i in range(nz):
        for j in range(m):
            acc = 0.0
            for k in range(m):
                acc += P[i, k] * SI[k, j]
            K[i, j] = acc
    y = np.empty(m)
    for i in range(m):
        y[i] = meas[i] - z[i]
    nis = 0.0
    for i in range(m):
        for j in range(m):
            nis += y[i] * SI[i, j] * y[j]
    for i in range(nz):
        acc = 0.0
        for j in range(m):
            acc += K[i, j] * y[j]
        z[i] += acc
    A = np.eye(nz)
    for i in range(nz):
        for j in range(m):
            A[i, j] -= K[i, j]
    KR = K @ R
    symmetrise(A @ P @ A.T + KR @ K.T, P)
    return nis


@njit(cache=True)
def _check(z, P):
    for i in range(z.shape[0]):
        if not np.isfinite(z[i]):
            return NONFINITE
    for i in range(P.shape[0]):
        for j in range(P.shape[1]):
            if not np.isfinite(P[i, j]):
                return NONFINITE
    if not (z[0] > 0.0):
        return NEG_SPEED
    if not is_pd(P):
        return NOT_PD
    return OK


@njit(cache=True)
def filter_kernel(prior, record, noise, ship, idx, out, work, reference=None):
    """The whole pass: predict (RK4 + exact F), P = F P F^T, Joseph update, checks.

    prior = (z0, P0) the initial state and covariance; record = (meas, delta, dt): meas (N, 4)
    u, v, r, n at times k*dt, delta (N,) the rudder [rad]; noise = (R, q, nis_window, nis_max):
    R (4, 4), Q = q I (0 in the paper), divergence when the NIS averaged over nis_window steps
    exceeds nis_max (nis_window 0: never); ship = (p, poly, hull_axis, hull_term) of the packed
    ship, idx the estimated coefficients' slots in its hull_coef; out = (zs, pdiag), both (N, nz),
    filled (row 0 the initial values); work = (ws, uw) the work arrays of :func:`propagate_step`
    (:func:`workspace`) and of the update (:func:`make_update_workspace`), made by
    :func:`run_filter`.  Returns (status, step index, final P).
    reference: the previous implementation, for tests and ``bench/bench_ekf.py``: F by the
    brute-force complex step (:func:`ekf.kernels.jacobian_step_reference`, one complex RK4 step
    per column) instead of the tangent-linear RK4 of :func:`propagate_step`, and the update by
    :func:`joseph_update` instead of its allocation-free form :func:`ekf.kernels.joseph_update_ws`;
    the same numbers to rounding.  Left out (None), that path is not compiled at all.
    """
    z0, P0 = prior
    meas, delta, dt = record
    R, q, nis_window, nis_max = noise
    zs, pdiag = out
    ws, uw = work
    nz = z0.shape[0]
    N = meas.shape[0]
    z = z0.copy()
    P = P0.copy()
    FP = np.empty((nz, nz))
    zn, F = ws[8], ws[9]
    for i in range(nz):
        zs[0, i] = z[i]
        pdiag[0, i] = P[i, i]
    ring = np.zeros(max(nis_window, 1))
    nis_sum = 0.0
    for k in range(1, N):
        if reference is not None and reference:
            jacobian_step_reference(z, (delta[k - 1], delta[k], 0.0, 0.0), (SLOTS, np.int64(NS), idx, np.int64(-1)), dt,
                                    ship, ws)
        else:
            propagate_step(z, delta[k - 1], delta[k], dt, ship, idx, ws)
        for i in range(nz):             # element-wise: a slice assignment compiles numba's shape-mismatch message (~7 s cold)
            z[i] = zn[i]
        fpft(F, P, np.int64(NS), FP, P)
        if q > 0.0:
            for i in range(nz):
                P[i, i] += q
        st = _check(z, P)
        if st != OK:
            return st, k, P
        if reference is not None and reference:
            nis = joseph_update(z, P, meas[k], R)
        else:
            nis = joseph_update_ws(z, P, meas[k], R, uw)
        st = _check(z, P)
        if nis_window > 0:
            slot = k % nis_window
            nis_sum += nis - ring[slot]
            ring[slot] = nis
            if k >= nis_window and nis_sum / nis_window > nis_max:
                st = NIS_HIGH
        for i in range(nz):
            zs[k, i] = z[i]
            pdiag[k, i] = P[i, i]
        if st != OK:
            return st, k, P
    return OK, N - 1, P


# --------------------------------------------------------------------------- Python side


@dataclass
class FilterResult:
    """A filter pass.

    Attributes
    ----------
    t : ndarray (N,)
        Time [s].
    z, pdiag : ndarray (N, 4 + m)
        Estimates and their variances: u, v, r, n then the coefficients :attr:`names`.
    P : ndarray (4 + m, 4 + m)
        Final covariance.
    names : tuple of str
        The estimated coefficients.
    """

    t: np.ndarray
    z: np.ndarray
    pdiag: np.ndarray
    P: np.ndarray
    names: tuple = ()

    @property
    def final(self) -> dict:
        """Final coefficient estimates by name."""
        return {n: float(self.z[-1, NS + i]) for i, n in enumerate(self.names)}

    @property
    def std(self) -> dict:
        """Final standard deviations of the coefficients by name."""
        return {n: float(np.sqrt(max(self.P[NS + i, NS + i], 0.0))) for i, n in enumerate(self.names)}

    def to_pandas(self):
        """The estimate history as a DataFrame indexed by time [s] (states, then coefficients)."""
        import pandas as pd

        return pd.DataFrame(self.z, columns=list(STATES + tuple(self.names)), index=pd.Index(self.t, name="t"))


def run_filter(packed: PackedShip, slots, t, meas, delta, z0, P0, R, trial: str = "", q: float = 0.0,
               nis_window_s: float = 60.0, nis_max: float = 20.0, names=()) -> FilterResult:
    """Run the compiled EKF over a whole record; raises FilterDivergence on failure.

    t (N,) equally spaced [s]; meas (N, 4) u, v, r, n; delta (N,) rudder [rad];
    z0 (4 + m,), P0 (4 + m, 4 + m), R (4, 4); q: Q = q I per step (0 = the paper's Q = 0);
    names: the m estimated coefficients (for the result's labels).
    Divergence is also declared when the normalised innovation squared y^T S^-1 y averaged over
    ``nis_window_s`` exceeds ``nis_max`` (its expectation is 4 for a consistent filter; 0 disables).
    """
    t = np.asarray(t, float)
    dt = float(t[1] - t[0])
    meas = carray(meas)
    N = len(t)
    nz = len(z0)
    zs = np.full((N, nz), np.nan)
    pd_ = np.full((N, nz), np.nan)
    c = carray                                   # one specialisation for every caller
    hull_coef = c(packed.hull_coef)
    # the work arrays made here, by their makers run interpreted (the same arrays): compiled, the
    # makers cost a cold cache 1.5-2 s for a few allocations a pass
    ws = interpreted(workspace)(nz, hull_coef)
    uw = interpreted(make_update_workspace)(nz, meas.shape[1])
    noise = (c(R), float(q), int(round(nis_window_s / dt)) if nis_max > 0 else 0, float(nis_max))
    ship = (c(packed.p), c(packed.poly), c(packed.hull_axis, np.int64), c(packed.hull_term, np.int64))
    st, k, P = filter_kernel((c(z0), c(P0)), (meas, c(delta), dt), noise, ship, c(slots, np.int64), (zs, pd_),
                             (ws, uw))
    if st != OK:
        raise FilterDivergence(trial, t[k], _REASON[st])
    return FilterResult(t, zs, pd_, P, tuple(names))


def __getattr__(name: str):
    """``ekf.filter.AugmentedEKF`` (and ``from ekf.filter import AugmentedEKF``) from :mod:`ekf.filterpy_ekf`,
    imported only then: filterpy pulls scipy.stats (~0.4 s), which the compiled path never needs."""
    if name == "AugmentedEKF":
        from .filterpy_ekf import AugmentedEKF

        globals()[name] = AugmentedEKF
        return AugmentedEKF
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
