"""Augmented EKF on the raw 5 s sea-trial log (a near-efficient filter).

The paper-style filter (:mod:`ekf.filter`) measures u, v, r, n *recovered* at 0.1 s from
the 5 s log by 3-point parabolas, with Table 8's R (10^2-10^5 x the real error variance,
and blind to the strong correlation of the interpolated samples); its Monte Carlo spread is
up to 12 x the Cramer-Rao bound of :mod:`trials.planning.fisher` (noise model "log").  This filter
measures what the log actually holds, so its information matches the CRB's:

State (8 + m), ordered so that the measured states come first (H = [I_4 0], so the Joseph
update of :func:`ekf.filter.joseph_update` is reused as is):
    z = [x, y, psi, n, u, v, r, tau, c_1 .. c_m]
    with tau the timing offset [s] of the current rudder movement (below) and c the estimated
    hull coefficients (``data.names``; the Esso Osaka's 12 Y_beta .. N_brr by default).
Time update (every 0.1 s)
    RK4 on :func:`mmg.model.rhs` (the only physics; the derivatives written into the
    ``hull_coef`` slots of a complex copy), rudder angle a known input rebuilt from the trial
    logic on the interpolated heading (:func:`ekf.preprocess.recover`), linear over the step;
    dc/dt = 0, dtau/dt = 0.  F is the exact Jacobian of that RK4 map by complex step (one
    complex RK4 step per column); P <- F P F^T + Q with Q = 0 by default (none was needed:
    the model is the simulator's to rounding, and with the timing state the mean NIS is ~4).
Rudder timing
    The rebuilt rudder switches where the *interpolated* heading crosses the switch level;
    that heading is off by ~1.5e-4 rad while the true heading moves ~4e-4 rad per 0.1 s step
    near a switch, so switches land a step early or late.  One step leaves a heading offset
    of ~1.3e-3 rad (10 x the log's heading noise) and, with the true R, biased the
    derivatives by 5-10 standard deviations (ZZ20 seed 1000: Y_beta +1.8 %, 9 sd).  The
    filter therefore uses delta(t) + tau g(t), g = -d(delta)/dt (the rebuilt rudder moved by
    tau in time) and estimates tau; before each rudder movement (order change of the
    rebuilt logic, and at the start) tau is marginalised out (its effect already lives in
    u, v, r, x, y, psi) and restarted at 0 with std ``sigma_tau`` (0.15 s; the rebuilt
    movements are off by 0.05-0.07 s rms).  Marginalising these nuisances costs information
    on the sway derivatives: the CRB with the same per-movement nuisances
    (:func:`trials.planning.fisher.fisher`, ``rudder_timing=0.15``) is 2.2 x the rudder-known one for
    ZZ20 Y_beta, 1.1-1.4 x for the N derivatives - the price of a log without a rudder
    channel.  ``rudder="true"`` runs the filter on the truth file's rudder instead, to check
    it against the rudder-known bound.
Measurement update (only at the log samples, every 5 s)
    z = [x, y, psi, n] of the raw record (positions in metres, unwrapped heading, rpm / 60);
    R = diag(sigma^2) with sigma the log's noise std (``data.info.noise_std``: for a uniform
    noise of half-width a, a / sqrt(3)).  Joseph form, P symmetrised.
Start
    Derivatives at 120 % of the ship file's values (config ``initial``), P0 from Table 7
    (``configs/estimation/rhee_kim.yaml``); x, y, psi, n the first log sample with variance
    R; u, v, r the first recovered 0.1 s values with Table 7's variances (wide: the start
    state is a nuisance, as in the CRB).  By default a second pass reruns the filter over the
    same data, the derivatives starting at the first pass's estimates with 100 x its final
    covariance as prior (relinearisation; see :func:`run_log_filter`).

Monte Carlo: ``mmg log-filter OUT --seeds 20`` (:func:`trials.estimates.montecarlo.log_filter_monte_carlo`)
writes ``OUT/runs.csv``; ``mmg sensitivity --crb-vs-mc OUT --out DIR`` compares it with the CRB.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from mmg._jit import carray, njit, readonly

from mmg.errors import InputError
from mmg.model import N_, PSI_, R_, U_, V_, X_, Y_

from .filter import NEG_SPEED, NONFINITE, NOT_PD, OK, FilterDivergence, is_pd, joseph_update
from .kernels import (fpft, jacobian_step, jacobian_step_reference, joseph_update_ws, make_update_workspace,
                      make_workspace, symmetrise)

STATES = ("x", "y", "psi", "n", "u", "v", "r", "tau")
NS = 7                      # dynamic states (propagated by RK4)
TAU = 7                     # rudder-timing offset of the current rudder movement [s]
ND = 8                      # first derivative slot
NM = 4                      # measured: x, y, psi, n (the first four states)
# mmg state slot of each dynamic filter state
SLOTS = readonly(np.array([X_, Y_, PSI_, N_, U_, V_, R_], dtype=np.int64))
_IU = 4                     # index of u in z

_REASON = {NONFINITE: "a state or covariance became non-finite",
           NEG_SPEED: "the surge speed estimate fell to zero or below",
           NOT_PD: "the error covariance P is no longer positive definite"}


# --------------------------------------------------------------------------- compiled kernels


@njit(cache=True, inline="always")
def propagate_log(z, rudder, dt, ship, idx, ws):
    """One RK4 step of z (nz,) and its exact Jacobian: z_next = ws[8], F = ws[9] (the tangent-linear
    RK4 of :func:`ekf.kernels.jacobian_step`: 20 complex evaluations of the dynamics and 16 of the
    track a step, not 80 of the whole model).

    The rudder [rad] over the step (dt [s]) is d + tau g, rudder = (d0, d1, g0, g1) (d0 -> d1,
    g0 -> g1 [rad/s]): the rebuilt rudder moved by -tau in time, g = -d(delta)/dt, so the timing
    offset tau [s] is estimated like the rest.  ship = (p, poly, hull_axis, hull_term); idx the
    derivatives' slots in hull_coef; ws from :func:`ekf.kernels.make_workspace` (nz, NS, hull_coef).
    """
    jacobian_step(z, rudder, (SLOTS, np.int64(ND), idx, np.int64(TAU)), dt, ship, ws)


@njit(cache=True)
def _check_log(z, P):
    nz = z.shape[0]
    for i in range(nz):
        if not np.isfinite(z[i]):
            return NONFINITE
        for j in range(nz):
            if not np.isfinite(P[i, j]):
                return NONFINITE
    if not (z[_IU] > 0.0):
        return NEG_SPEED
    if not is_pd(P):
        return NOT_PD
    return OK


@njit(cache=True)
def log_filter_kernel(prior, record, noise, ship, hull_coef, idx, out, reference=None):
    """The whole pass on the 0.1 s grid of ``delta`` (N,): predict every step, update at steps ``meas_k``.

    prior = (z0, P0); record = (delta, g, dt, meas, meas_k, reset_k): the rudder [rad] on the grid
    of step dt [s], g (N,) = -d(delta)/dt, meas (M, 4) x, y, psi, n at grid steps meas_k (M,)
    (increasing; a sample at step 0 is taken to be in z0, P0); at the steps reset_k (before each
    rudder movement) tau is marginalised out (its effect already lives in the other states) and
    restarted at 0 with variance var_tau; noise = (R, q, var_tau): R (4, 4), q (nz,) diagonal of Q
    per step; ship = (p, poly, hull_axis, hull_term), hull_coef and idx the packed ship's
    coefficients and the estimated ones' slots; out = (zs, pdiag, nis): zs, pdiag (N, nz), nis (M,)
    filled.
    reference: the previous implementation (tests): F by the brute-force complex step
    (:func:`ekf.kernels.jacobian_step_reference`) instead of the tangent-linear RK4 of
    :func:`propagate_log`, the update by :func:`ekf.filter.joseph_update` instead of
    :func:`ekf.kernels.joseph_update_ws`; the same numbers to rounding.  Left out (None), that path
    is not compiled at all.
    Returns (status, step index, final P).
    """
    z0, P0 = prior
    delta, g, dt, meas, meas_k, reset_k = record
    R, q, var_tau = noise
    zs, pdiag, nis = out
    N = delta.shape[0]
    M = meas_k.shape[0]
    NZ = z0.shape[0]
    z = z0.copy()
    P = P0.copy()
    FP = np.empty((NZ, NZ))
    ws = make_workspace(NZ, np.int64(NS), hull_coef)
    zn, F = ws[8], ws[9]
    uw = make_update_workspace(NZ, meas.shape[1])
    j = 0
    while j < M and meas_k[j] < 1:
        j += 1
    r = 0
    for i in range(NZ):
        zs[0, i] = z[i]
        pdiag[0, i] = P[i, i]
    for k in range(1, N):
        while r < reset_k.shape[0] and reset_k[r] <= k - 1:
            z[TAU] = 0.0
            for i in range(NZ):
                P[TAU, i] = 0.0
                P[i, TAU] = 0.0
            P[TAU, TAU] = var_tau
            r += 1
        rudder = (delta[k - 1], delta[k], g[k - 1], g[k])
        if reference is not None and reference:
            jacobian_step_reference(z, rudder, (SLOTS, np.int64(ND), idx, np.int64(TAU)), dt, ship, ws)
        else:
            propagate_log(z, rudder, dt, ship, idx, ws)
        for i in range(NZ):
            z[i] = zn[i]
        fpft(F, P, np.int64(NS), FP, P)
        symmetrise(P, P)
        for i in range(NZ):
            P[i, i] += q[i]
        st = _check_log(z, P)
        if st != OK:
            return st, k, P
        while j < M and meas_k[j] == k:
            if reference is not None and reference:
                nis[j] = joseph_update(z, P, meas[j], R)
            else:
                nis[j] = joseph_update_ws(z, P, meas[j], R, uw)
            j += 1
            st = _check_log(z, P)
            if st != OK:
                return st, k, P
        for i in range(NZ):
            zs[k, i] = z[i]
            pdiag[k, i] = P[i, i]
    return OK, N - 1, P


# --------------------------------------------------------------------------- Python side


@dataclass
class LogFilterResult:
    """A pass: t (N,) the 0.1 s grid, z (N, 8 + m) estimates, pdiag (N, 8 + m) variances, P final,
    nis (M,) the normalised innovations at the log samples, names the m estimated coefficients."""

    t: np.ndarray
    z: np.ndarray
    pdiag: np.ndarray
    P: np.ndarray
    nis: np.ndarray
    names: tuple = ()

    @property
    def final(self) -> dict:
        """Final coefficient estimates by name."""
        return {n: float(self.z[-1, ND + i]) for i, n in enumerate(self.names)}

    @property
    def std(self) -> dict:
        """Final standard deviations of the coefficients by name."""
        return {n: float(np.sqrt(max(self.P[ND + i, ND + i], 0.0))) for i, n in enumerate(self.names)}


def log_measurements(record, info):
    """(t_log, obs (K, 4) x, y, psi, n, R (4, 4)) of a raw record (t, x, y, psi, n arrays) and its
    :class:`ekf.data.RecordInfo` (noise std)."""
    sd = info.noise_std
    a = np.array([sd["x"], sd["y"], sd["psi"], sd["n"]], float)
    obs = np.column_stack([record.x, record.y, record.psi, record.n]).astype(float)
    return np.asarray(record.t, float), obs, np.diag(a * a)


def run_log_filter(data, record, cfg: dict, q=None, duration: float | None = None,
                   passes: int = 2, sigma_tau: float = 0.15, uvr_std=None,
                   inflate: float = 100.0, rudder: str = "rebuilt") -> LogFilterResult:
    """Run the filter on a TrialData (``data.meas``: the rebuilt rudder at 0.1 s) and its raw log record.

    q: per-step process noise variances, a dict by state name (default none: Q = 0).
    duration: use only the first ``duration`` seconds.
    passes: pass 1 starts the derivatives at the config's initial values (120 % of truth)
    with Table 7's P0.  That pass is not efficient on its own: in the first minutes, with the
    wide P0 and the start state still uncertain, the linearisation is poor while P collapses,
    and with Q = 0 the errors made then are never undone (ST35 seed 1001: N_rr off by 11
    standard deviations, mean NIS 4.4, the same after restarting from the pass's estimates
    with Table 7's P0 again).  Each further pass therefore restarts the filter (same data)
    from the previous pass's estimates with the previous pass's final derivative covariance
    times ``inflate`` (100) as their prior: linearised about a good point from the start,
    while a prior of 1 % of the data's information pulls the result by ~1 % of the (small)
    pass-to-pass change -- an iterated EKF / Gauss-Newton step (ST35 seed 1001: all
    derivatives within 1 sd, NIS 4.1).
    uvr_std: start std of u, v, r (default Table 7's variances).
    sigma_tau: prior std [s] of the timing offset of each rudder movement.
    rudder: "rebuilt" (from the trial logic on the logged heading, what a real log allows) or
        "true" (the truth file's rudder angle: a check of the filter against the CRB with the
        rudder known; use a tiny ``sigma_tau`` with it).
    Raises FilterDivergence.
    """
    opts = _PassOptions(q, duration, sigma_tau, uvr_std, rudder)
    res = _run_once(data, record, cfg, opts)
    for _ in range(passes - 1):
        res = _run_once(data, record, cfg, opts, (res.z[-1, ND:], inflate * res.P[ND:, ND:]))
    return res


class _PassOptions(NamedTuple):
    """:func:`run_log_filter`'s options of every pass (its parameters of the same names)."""

    q: dict | None
    duration: float | None
    sigma_tau: float
    uvr_std: object
    rudder: str


def _true_rudder(data, t: np.ndarray) -> np.ndarray:
    if data.truth is None or getattr(data.truth, "delta", None) is None:
        raise InputError(data.source, "delta", "rudder='true' needs a truth file with the rudder angle")
    return np.interp(t, np.asarray(data.truth.t, float), np.asarray(data.truth.delta, float))


def _run_once(data, record, cfg, opts: _PassOptions, start=None) -> LogFilterResult:
    """One pass; start = (the derivatives' start values, their covariance), the config's and Table 7's
    when None."""
    from mmg.rudder import movement_starts, reconstruct_rudder

    from .estimate import P0_for, initial_state

    q, duration, sigma_tau, uvr_std, rudder = opts
    start_derivs, P_der = (None, None) if start is None else start
    m = data.meas
    t = np.asarray(m.t, float)
    dt = float(t[1] - t[0])
    keep = np.ones(len(t), bool) if duration is None else (t - t[0] <= duration + 1e-9)
    t = t[keep]
    N = len(t)
    if rudder not in ("rebuilt", "true"):
        raise ValueError(f"rudder must be 'rebuilt' or 'true', got {rudder!r}")
    delta = np.asarray(m.delta, float)[:N] if rudder == "rebuilt" else _true_rudder(data, t)
    delta = carray(delta)
    g = -np.gradient(delta, dt)
    # rudder movements start where the rebuilt order changes (and at the start)
    info = data.info
    order, _ = reconstruct_rudder(t, np.asarray(m.psi, float)[:N], info.kind, info.manoeuvre, data.packed.p,
                                  info.trim_rudder)
    reset_k = carray(movement_starts(order, dt), np.int64)
    t_log, obs, R = log_measurements(record, info)
    mk = np.rint((t_log - t[0]) / dt).astype(np.int64)
    sel = (mk >= 0) & (mk < N)
    mk, obs = carray(mk[sel], np.int64), carray(obs[sel])
    zp = initial_state(data, cfg)                     # u, v, r, n, coefficients (paper-filter layout)
    der = zp[4:] if start_derivs is None else np.asarray(start_derivs, float)
    P0p = P0_for(cfg, data.names)
    NZ = ND + len(data.names)
    z0 = np.r_[obs[0], zp[0:3], 0.0, der]
    P0 = np.zeros((NZ, NZ))
    P0[:NM, :NM] = R
    P0[NM:NS, NM:NS] = P0p[0:3, 0:3] if uvr_std is None else np.diag(np.asarray(uvr_std, float) ** 2)
    P0[TAU, TAU] = sigma_tau ** 2
    P0[ND:, ND:] = P0p[4:, 4:] if P_der is None else P_der
    qv = np.zeros(NZ)
    for k, v in (q or {}).items():
        qv[(STATES + tuple(data.names)).index(k)] = float(v)
    zs = np.full((N, NZ), np.nan)
    pd_ = np.full((N, NZ), np.nan)
    nis = np.full(len(mk), np.nan)
    p, poly, hull_axis, hull_term, hull_coef = (carray(a, a.dtype) for a in data.packed.args())
    st, k, P = log_filter_kernel((carray(z0), carray(P0)), (delta, carray(g), dt, obs, mk, reset_k),
                                 (carray(R), qv, float(sigma_tau ** 2)), (p, poly, hull_axis, hull_term), hull_coef,
                                 carray(data.slots, np.int64), (zs, pd_, nis))
    if st != OK:
        raise FilterDivergence(data.name, t[k], _REASON[st])
    return LogFilterResult(t, zs, pd_, P, nis, tuple(data.names))
