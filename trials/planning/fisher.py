"""Fisher information of the 12 sway/yaw derivatives in a trial, and the Cramer-Rao bound.

Unlike the sensitivities of eqs. (21)-(22) (:mod:`trials.planning.sensitivity`), which are shares of a
total over the trials being compared, the Fisher information of a trial depends only on that
trial, its duration and the measurement noise.

Output sensitivities (exact, from the model)
    The EKF's own model (:mod:`ekf.filter`: RK4 on :func:`mmg.model.rhs` over the 0.1 s
    filter step, states u, v, r, n, rudder angle an input interpolated linearly over the
    step) is run from the trial's start state with the rudder angle of the simulated trial.
    The 16-state augmented transition Jacobian F_k (:func:`ekf.filter.propagate_step`,
    complex step, exact to rounding) propagates the tangent
        S_{k+1} = F_k[:4, :] [S_k; 0 I],   S_0 = [I_4 0],
    S_k = d(u, v, r, n)(t_k) / d(u0, v0, r0, n0, c_1..c_12).  The rudder angle is treated as
    a known input, as the EKF treats it (in a closed-loop trial a changed derivative would
    also move the switching times; that is not information the filter uses).  The start
    state enters as four nuisance parameters.

Noise models (``noise=``)
    ``"filter"``  what the EKF assumes: R of Rhee & Kim Table 8 for the trial
        (``configs/estimation``), every 0.1 s sample independent:
        I = sum_k S_k^T R^-1 S_k.  The 0.1 s "measurements" are in fact interpolated from a
        5 s log (3-point parabolas, :mod:`ekf.preprocess`) and their errors are strongly
        correlated (lag-1 correlation ~0.9, sign change near 5 s), and Table 8's R is 10^2 to
        10^6 times the variance of the recovered errors, so this is the information the
        filter *believes* it has (its P without the prior), not what the data hold.
    ``"log"`` (default)  the information of the data actually recorded: the 5 s log's
        latitude, longitude, heading and rpm, each sample independent with uniform noise of
        the trial's half-widths a (variance a^2 / 3); the speed channel (noise-free in the
        paper's logs) is not used, as the estimator does not use it.  Position and heading
        sensitivities are integrated from those of u, v, r along the track
        (psi' = r, x' = u cos psi - v sin psi, y' = u sin psi + v cos psi, trapezoid on the
        0.1 s grid); the start position and heading are three more nuisance parameters.
        This is the exact way to count the correlated interpolated samples: go back to the
        independent samples they were interpolated from.
    ``"thinned"``  the recovered 0.1 s u, v, r, n with the *empirical* variance of their
        errors (given by ``recovered_var``), counting one independent sample per log
        interval (information x dt / interval): the usual rule of thumb, for comparison.

Rudder timing (``rudder_timing=``)
    The log has no rudder channel: the estimators rebuild the rudder from the trial's logic
    on the *logged* heading (:mod:`trials.files.rudder`), so each rudder movement of a zigzag or
    S-type trial starts a fraction of a 0.1 s step early or late.  ``rudder_timing=None``
    (default) takes the rudder as known exactly (the bound of an estimator given the true
    rudder).  ``rudder_timing=sigma`` [s] adds one nuisance per rudder movement, tau_j, the
    time shift of movement j: the rudder is delta(t) + tau_j g(t) over that movement
    (g = -d(delta)/dt; movements start 1 s before each order change, and at the start),
    each tau_j with a Gaussian prior of std sigma (``np.inf``: no prior).  This is exactly the
    nuisance the raw-log EKF (:mod:`ekf.log_filter`) estimates and marginalises, so with its
    ``sigma_tau`` it is the bound for the information that filter is given.  The output
    sensitivities to tau_j are exact (one complex-step run of the EKF model per movement).

CRB
    cov >= I^-1; the bound on a derivative's standard deviation is sqrt of its diagonal
    element of the inverse of the full matrix (nuisances marginalised).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mmg._jit import njit

from ekf.filter import NS, propagate_step, workspace
from ekf.kernels import CSTEP, make_workspace, rk4_step
from ekf.log_filter import ND as LOG_ND, NS as LOG_NS, SLOTS as LOG_SLOTS
from mmg.integrate import integrate
from mmg.model import DELTA_, N_, PSI_, R_, U_, V_
from mmg.simulation import prepare

from mmg.rudder import REBUILT_KINDS, movements
from .sensitivity import DERIVATIVES, LINEAR, NONLINEAR

NZ = NS + len(DERIVATIVES)              # the paper filter's state: u, v, r, n and the 12 derivatives
LOG_NZ = LOG_ND + len(DERIVATIVES)      # the raw-log filter's

NOISE_MODELS = ("log", "filter", "thinned")


@njit(cache=True)
def _tangent_kernel(z0, delta, dt, ship, hull_coef, idx, Y, S):
    """Fill Y (N, 4) with the model's u, v, r, n and S (N, 4, 16) with their sensitivities to z0; ship =
    (p, poly, hull_axis, hull_term), hull_coef and idx the packed ship's coefficients and the derivatives' slots."""
    nz = z0.shape[0]
    N = delta.shape[0]
    z = z0.copy()
    ws = workspace(nz, hull_coef)
    zn, F = ws[8], ws[9]
    for i in range(NS):
        Y[0, i] = z[i]
        for j in range(nz):
            S[0, i, j] = 1.0 if i == j else 0.0
    for k in range(1, N):
        propagate_step(z, delta[k - 1], delta[k], dt, ship, idx, ws)
        for i in range(nz):
            z[i] = zn[i]
        for i in range(NS):
            Y[k, i] = z[i]
            for j in range(nz):
                acc = F[i, j] if j >= NS else 0.0
                for m in range(NS):
                    acc += F[i, m] * S[k - 1, m, j]
                S[k, i, j] = acc
    return N


@njit(cache=True)
def _timing_kernel(z0, rudder, dt, ship, hull_coef, idx, out):
    """out (N, 4, n_seg): d(u, v, r, n)(t_k) / d tau_j, the rudder being delta + tau_j g over the
    steps with seg == j (seg non-decreasing); one complex-step run of the raw-log EKF's RK4 step
    per movement, started where the movement starts from a stored unperturbed run.

    z0 (20,) the raw-log filter's state layout (x, y, psi, n, u, v, r, tau, derivatives); rudder =
    (delta, g, seg, n_seg); ship = (p, poly, hull_axis, hull_term), hull_coef and idx the packed
    ship's coefficients and the derivatives' slots."""
    delta, g, seg, n_seg = rudder
    N = delta.shape[0]
    h = CSTEP
    ws = make_workspace(np.int64(LOG_NZ), np.int64(LOG_NS), hull_coef)
    nxt = ws[7]
    layout = (LOG_SLOTS, np.int64(LOG_ND), idx, np.int64(-1))
    z = np.empty(z0.shape[0], dtype=np.complex128)
    for i in range(z0.shape[0]):
        z[i] = z0[i]
    # the unperturbed run, in complex arithmetic like the perturbed ones (same rounding)
    zh = np.empty((N, LOG_NS), dtype=np.complex128)
    for i in range(LOG_NS):           # element-wise (a slice assignment compiles numba's shape-mismatch message)
        zh[0, i] = z[i]
    for k in range(1, N):
        rk4_step(z, delta[k - 1] + 0.0j, delta[k] + 0.0j, dt, layout, ship, ws)
        for i in range(LOG_NS):
            z[i] = nxt[i]
            zh[k, i] = nxt[i]
    k0 = 0
    for j in range(n_seg):
        while seg[k0] < j:
            k0 += 1
        for k in range(k0 + 1):
            for i in range(4):
                out[k, i, j] = 0.0
        for i in range(LOG_NS):
            z[i] = zh[k0, i]
        for k in range(k0 + 1, N):
            a0 = 1j * h * g[k - 1] if seg[k - 1] == j else 0.0j
            a1 = 1j * h * g[k] if seg[k - 1] == j else 0.0j
            rk4_step(z, delta[k - 1] + a0, delta[k] + a1, dt, layout, ship, ws)
            for i in range(LOG_NS):
                z[i] = nxt[i]
            out[k, 0, j] = z[4].imag / h
            out[k, 1, j] = z[5].imag / h
            out[k, 2, j] = z[6].imag / h
            out[k, 3, j] = z[3].imag / h
    return n_seg


@dataclass
class Tangent:
    """A trial's model outputs and their exact sensitivities.

    t (N,) [s]; y (N, 4) u, v, r, n of the EKF model; S (N, 4, 16) d y / d(u0, v0, r0, n0, c);
    delta (N,) rudder angle used [rad]; sim (N, 8) the simulator's states; values (12,) the
    derivatives; psi0 start heading.
    """

    trial: str
    t: np.ndarray
    y: np.ndarray
    S: np.ndarray
    delta: np.ndarray
    sim: np.ndarray
    values: np.ndarray
    log_interval: float
    noise: dict
    S_tau: np.ndarray | None = None
    """(N, 4, M) d(u, v, r, n) / d tau_j for the M rudder movements (``tangent(..., rudder_timing=True)``)."""

    def track_sensitivities(self, S=None):
        """psi, x, y of the model and their sensitivities (N, 3, ncol) by integrating along the track.

        S (N, 4, ncol) the u, v, r, n sensitivities to integrate (default ``self.S``)."""
        t, y = self.t, self.y
        S = self.S if S is None else S
        dt = np.diff(t)
        psi = np.concatenate([[self.sim[0, PSI_]], self.sim[0, PSI_] + np.cumsum(0.5 * dt * (y[1:, 2] + y[:-1, 2]))])
        Spsi = np.concatenate([np.zeros((1, S.shape[2])),
                               np.cumsum(0.5 * dt[:, None] * (S[1:, 2] + S[:-1, 2]), axis=0)])
        c, s = np.cos(psi), np.sin(psi)
        xd = y[:, 0] * c - y[:, 1] * s
        yd = y[:, 0] * s + y[:, 1] * c
        Sxd = c[:, None] * S[:, 0] - s[:, None] * S[:, 1] - yd[:, None] * Spsi
        Syd = s[:, None] * S[:, 0] + c[:, None] * S[:, 1] + xd[:, None] * Spsi

        def cumtrap(f):
            return np.concatenate([np.zeros((1,) + f.shape[1:]),
                                   np.cumsum(0.5 * dt.reshape((-1,) + (1,) * (f.ndim - 1)) * (f[1:] + f[:-1]), axis=0)])

        return psi, cumtrap(xd), cumtrap(yd), np.stack([Spsi, cumtrap(Sxd), cumtrap(Syd)], axis=1)


def tangent(trial, dt: float | None = None, rudder_timing: bool = False) -> Tangent:
    """Simulate ``trial`` and propagate the exact output sensitivities along it (EKF model, rudder as input).

    rudder_timing: also the sensitivities to the timing of each rudder movement (``Tangent.S_tau``);
        only trials whose rudder the estimators rebuild from the trial logic (``REBUILT_KINDS``:
        turning, zigzag, S-type) have such nuisances; a time-scheduled rudder (sine, sawtooth,
        schedule) has none.
    """
    pk, eq = prepare(trial.ship, trial.u0, trial.n0, trial.trim, trial.effects)
    law = trial.command_law(trim_rudder=eq.delta, psi0=0.0)
    x0 = eq.state()
    step = float(dt or trial.dt)
    _, sim, orders, _ = integrate(pk, x0, law, trial.duration, step)
    idx = np.array([trial.ship.hull.index(n) for n in DERIVATIVES], dtype=np.int64)
    values = pk.hull_coef[idx].copy()
    z0 = np.r_[x0[U_], x0[V_], x0[R_], x0[N_], values]
    delta = np.ascontiguousarray(sim[:, DELTA_])
    N = len(delta)
    Y = np.empty((N, NS))
    S = np.empty((N, NS, NZ))
    _tangent_kernel(z0, delta, step, pk.args()[:4], pk.hull_coef, idx, Y, S)
    S_tau = None
    if rudder_timing and trial.kind not in REBUILT_KINDS:
        S_tau = np.empty((N, NS, 0))          # a time schedule: the rudder's timing is known
    elif rudder_timing:
        seg = movements(np.asarray(orders, float), step)
        n_seg = int(seg[-1]) + 1
        g = -np.gradient(delta, step)
        zl = np.r_[0.0, 0.0, x0[PSI_], x0[N_], x0[U_], x0[V_], x0[R_], 0.0, values]
        S_tau = np.empty((N, NS, n_seg))
        _timing_kernel(zl, (delta, g, seg, n_seg), step, pk.args()[:4], pk.hull_coef, idx, S_tau)
    lg = trial.log
    from ..files.logio import M_PER_DEG_LAT, M_PER_DEG_LON

    noise = {"x_m": np.degrees(lg.noise_lat) * M_PER_DEG_LAT, "y_m": np.degrees(lg.noise_lon) * M_PER_DEG_LON,
             "psi_rad": lg.noise_heading, "n_rps": lg.noise_rpm}
    return Tangent(trial.name, np.arange(N) * step, Y, S, delta, sim, values, float(lg.interval), noise, S_tau)


def R_table(trial_name: str, config=None) -> np.ndarray:
    """The EKF's measurement noise variances (u, v, r, n) for a trial (Rhee & Kim Table 8)."""
    from ekf.estimate import R_for, load_config

    return np.diag(R_for(load_config(config), trial_name))


def fisher(tan: Tangent, noise: str = "log", R=None, recovered_var=None,
           rudder_timing: float | None = None) -> tuple[np.ndarray, list[str]]:
    """Fisher information (all parameters: nuisances first, then the 12 derivatives) and the parameter names.

    tan: the trial's :func:`tangent` (with ``rudder_timing=True`` when ``rudder_timing`` is given).
    noise: "log" (default), "filter" or "thinned" (module docstring).
    R: the "filter" model's variances of u, v, r, n (default Rhee & Kim Table 8 for the trial).
    recovered_var: the "thinned" model's variances of u, v, r, n.
    rudder_timing: None (rudder known) or the prior std [s] of each rudder movement's timing
        nuisance tau_j (``np.inf``: no prior), named ``tau_1``.. among the nuisances.
    """
    S = tan.S
    names = ["u0", "v0", "r0", "n0"] + list(DERIVATIVES)
    n_tau = 0
    if rudder_timing is not None:
        if tan.S_tau is None:
            raise ValueError("rudder_timing needs tangent(..., rudder_timing=True)")
        if not float(rudder_timing) > 0:
            raise ValueError(f"rudder_timing must be a prior std > 0 [s] (or np.inf), got {rudder_timing!r}")
        S_tau = tan.S_tau
        n_tau = S_tau.shape[2]
        S = np.concatenate([S_tau, S], axis=2)
        names = [f"tau_{j + 1}" for j in range(n_tau)] + names
    if noise == "filter":
        var = np.asarray(R if R is not None else R_table(tan.trial), float)
        W = 1.0 / var
        I = np.einsum("kij,i,kil->jl", S, W, S)
    elif noise == "thinned":
        var = np.asarray(recovered_var, float)
        dt = tan.t[1] - tan.t[0]
        I = (dt / tan.log_interval) * np.einsum("kij,i,kil->jl", S, 1.0 / var, S)
    elif noise == "log":
        dt = tan.t[1] - tan.t[0]
        stride = int(round(tan.log_interval / dt))
        sel = np.arange(0, len(tan.t), stride)
        _, _, _, T = tan.track_sensitivities(S)
        # channels: heading, x (lat), y (lon), rpm; nuisances psi0, x0, y0 add unit sensitivities
        nz = S.shape[2]
        G = np.zeros((len(sel), 4, nz + 3))
        G[:, 0, :nz] = T[sel, 0]
        G[:, 1, :nz] = T[sel, 1]
        G[:, 2, :nz] = T[sel, 2]
        G[:, 3, :nz] = S[sel, 3]
        G[:, 0, nz] = 1.0
        G[:, 1, nz + 1] = 1.0
        G[:, 2, nz + 2] = 1.0
        a = np.array([tan.noise["psi_rad"], tan.noise["x_m"], tan.noise["y_m"], tan.noise["n_rps"]])
        W = 3.0 / a ** 2                         # uniform on [-a, a]: variance a^2 / 3
        I = np.einsum("kij,i,kil->jl", G, W, G)
        # put the three extra nuisances first
        order = [nz, nz + 1, nz + 2] + list(range(nz))
        I = I[np.ix_(order, order)]
        names = ["psi0", "x0", "y0"] + names
    else:
        raise ValueError(f"noise model must be one of {NOISE_MODELS}, got {noise!r}")
    if n_tau and np.isfinite(rudder_timing):
        for j in range(n_tau):
            k = names.index(f"tau_{j + 1}")
            I[k, k] += 1.0 / float(rudder_timing) ** 2
    elif n_tau:
        # without a prior, a movement the record saw nothing of (one starting after the last
        # sample) has zero information and would make I singular: it is simply not there
        keep = [k for k, n in enumerate(names) if not (n.startswith("tau_") and I[k, k] == 0.0)]
        I, names = I[np.ix_(keep, keep)], [names[k] for k in keep]
    return 0.5 * (I + I.T), names


def crb(I: np.ndarray, names: list[str]) -> dict:
    """Cramer-Rao bound on each derivative's standard deviation (nuisances marginalised)."""
    # scale to unit diagonal before inverting (the parameters differ by orders of magnitude)
    d = np.sqrt(np.diag(I))
    C = np.linalg.inv(I / np.outer(d, d)) / np.outer(d, d)
    return {n: float(np.sqrt(C[i, i])) for i, n in enumerate(names) if n in DERIVATIVES}


def derivative_covariance(I: np.ndarray, names: list[str], subset=DERIVATIVES) -> np.ndarray:
    """CRB covariance block of ``subset`` (the other parameters marginalised)."""
    d = np.sqrt(np.diag(I))
    C = np.linalg.inv(I / np.outer(d, d)) / np.outer(d, d)
    ix = [names.index(n) for n in subset]
    return C[np.ix_(ix, ix)]


def criteria(I: np.ndarray, names: list[str], values: np.ndarray) -> dict:
    """Design criteria on the nonlinear derivatives (relative to their values; lower is better).

    ``mean_rel_crb_nonlinear_pct``: mean over the 8 nonlinear derivatives of CRB std / |value| (%);
    ``median_rel_crb_nonlinear_pct``: their median - N_bb is nearly zero (-0.0005 for the Esso
    Osaka), its relative std is ~100 % in every trial and makes up ~90 % of the mean, so the
    mean ranks trials almost by N_bb alone; the median is not held hostage by one derivative;
    ``d_opt_nonlinear_pct``: (det of the relative CRB covariance of the 8)^(1/16) in % - the
    geometric-mean standard deviation of D-optimal design (minimising it = maximising det I);
    the same three for the 4 linear derivatives.
    """
    val = dict(zip(DERIVATIVES, values))
    out = {}
    for tag, grp in (("nonlinear", NONLINEAR), ("linear", LINEAR)):
        C = derivative_covariance(I, names, grp)
        sc = np.array([abs(val[n]) for n in grp])
        Cr = C / np.outer(sc, sc)
        sign, logdet = np.linalg.slogdet(Cr)
        out[f"mean_rel_crb_{tag}_pct"] = float(100.0 * np.mean(np.sqrt(np.diag(Cr))))
        out[f"median_rel_crb_{tag}_pct"] = float(100.0 * np.median(np.sqrt(np.diag(Cr))))
        out[f"d_opt_{tag}_pct"] = float(100.0 * np.exp(logdet / (2 * len(grp)))) if sign > 0 else np.inf
    return out


def trial_crb(trial, noise: str = "log", **kw) -> dict:
    """Convenience: CRB std of each derivative and the design criteria for one trial
    (``kw``: :func:`fisher`'s R, recovered_var, rudder_timing)."""
    tan = tangent(trial, rudder_timing=kw.get("rudder_timing") is not None)
    I, names = fisher(tan, noise, **kw)
    return {"trial": trial.name, "crb": crb(I, names), **criteria(I, names, tan.values)}


def crb_vs_montecarlo(runs: "pd.DataFrame", trial_files: dict, noises=("log", "filter"),
                      rudder_timing: float | None = 0.15) -> "pd.DataFrame":
    """CRB std beside the Monte Carlo std of the EKF's final estimates, per trial and derivative.

    runs: the EKF Monte Carlo's runs.csv (:func:`trials.estimates.montecarlo.monte_carlo` or
        :func:`trials.estimates.montecarlo.log_filter_monte_carlo`: one row per trial and seed with ``final_<derivative>``,
        diverged runs flagged).
    trial_files: maps the trial names in it to trial YAML paths.
    noises: noise models of the bounds with the rudder known (columns ``crb_std_<noise>``).
    rudder_timing: also the "log" bound with a timing nuisance per rudder movement of this prior
        std [s] (columns ``crb_std_log_timing``, ``mc_over_crb_log_timing``; 0.15 s is the raw-log
        EKF's ``sigma_tau``); None to leave it out.
    """
    import pandas as pd

    from ..runs.trial import load_trial

    rows = []
    for trial, g in runs.groupby("trial", sort=False):
        ok = g[g["diverged"].isna() | (g["diverged"].astype(str) == "")] if "diverged" in g else g
        tr = load_trial(trial_files[trial])
        tan = tangent(tr, rudder_timing=rudder_timing is not None)
        bounds = {nm: crb(*fisher(tan, nm)) for nm in noises}
        if rudder_timing is not None:
            bounds["log_timing"] = crb(*fisher(tan, "log", rudder_timing=rudder_timing))
        for i, n in enumerate(DERIVATIVES):
            vals = ok[f"final_{n}"].to_numpy(float)
            row = {"trial": trial, "derivative": n, "value": tan.values[i], "runs": len(vals),
                   "mc_mean": float(np.mean(vals)), "mc_std": float(np.std(vals, ddof=1))}
            for nm, b in bounds.items():
                row[f"crb_std_{nm}"] = b[n]
                row[f"mc_over_crb_{nm}"] = row["mc_std"] / b[n]
            rows.append(row)
    return pd.DataFrame(rows)
