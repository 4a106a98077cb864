"""Augmented EKF on the raw 5 s sea-trial log (issue 5, item 2: a near-efficient filter).

The paper-style filter (:mod:`ekf.filter`) measures u, v, r, n *recovered* at 0.1 s from
the 5 s log by 3-point parabolas, with Table 8's R (10^2-10^5 x the real error variance,
and blind to the strong correlation of the interpolated samples); its Monte Carlo spread is
up to 12 x the Cramer-Rao bound of :mod:`trials.fisher` (noise model "log").  This filter
measures what the log actually holds, so its information matches the CRB's:

State (20), ordered so that the measured states come first (H = [I_4 0], so the Joseph
update of :func:`ekf.filter.joseph_update` is reused as is):
    z = [x, y, psi, n, u, v, r, tau, Y_beta .. N_brr]
    the 19 of issue 5 plus tau, the timing offset [s] of the current rudder movement (below).
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
    (:func:`trials.fisher.fisher`, ``rudder_timing=0.15``) is 2.2 x the rudder-known one for
    ZZ20 Y_beta, 1.1-1.4 x for the N derivatives - the price of a log without a rudder
    channel.  ``rudder="true"`` runs the filter on the truth file's rudder instead, to check
    it against the rudder-known bound.
Measurement update (only at the log samples, every 5 s)
    z = [x, y, psi, n]: x, y from lat/lon with the paper's metres per degree
    (:func:`trials.logio.read_record`), psi the unwrapped logged heading, n = rpm / 60;
    R = diag(a^2 / 3) with a the uniform noise half-widths of the log header
    (:func:`ekf.output_error._noise_half_widths`).  Joseph form, P symmetrised.
Start
    Derivatives at 120 % of the ship file's values (config ``initial``), P0 from Table 7
    (``configs/estimation/rhee_kim.yaml``); x, y, psi, n the first log sample with variance
    R; u, v, r the first recovered 0.1 s values with Table 7's variances (wide: the start
    state is a nuisance, as in the CRB).  By default a second pass reruns the filter over the
    same data, the derivatives starting at the first pass's estimates with 100 x its final
    covariance as prior (relinearisation; see :func:`run_log_filter`).

Monte Carlo::

    python -m ekf.log_filter OUT --seeds 20 [--jobs 2]

writes ``OUT/runs.csv`` in the format of :mod:`ekf.montecarlo` (``mmg sensitivity
--crb-vs-mc OUT --out DIR`` compares it with the CRB).
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit

from mmg.errors import InputError
from mmg.model import N_, PSI_, R_, U_, V_, X_, Y_
from mmg.units import DEG

from .filter import DERIVATIVES, NEG_SPEED, NONFINITE, NOT_PD, OK, FilterDivergence, is_pd, joseph_update
from .kernels import fpft, jacobian_step, make_workspace, symmetrise

STATES = ("x", "y", "psi", "n", "u", "v", "r", "tau")
NS = 7                      # dynamic states (propagated by RK4)
TAU = 7                     # rudder-timing offset of the current rudder movement [s]
ND = 8                      # first derivative slot
NM = 4                      # measured: x, y, psi, n (the first four states)
NZ = ND + len(DERIVATIVES)  # 20
# mmg state slot of each dynamic filter state
SLOTS = np.array([X_, Y_, PSI_, N_, U_, V_, R_], dtype=np.int64)
_IU = 4                     # index of u in z

_REASON = {NONFINITE: "a state or covariance became non-finite",
           NEG_SPEED: "the surge speed estimate fell to zero or below",
           NOT_PD: "the error covariance P is no longer positive definite"}


# --------------------------------------------------------------------------- compiled kernels


@njit(cache=True)
def propagate_log(z, d0, d1, g0, g1, dt, p, poly, hull_axis, hull_term, idx, ws):
    """One RK4 step of z (20,) and its exact (complex-step) Jacobian: z_next = ws[8], F = ws[9].

    The rudder [rad] over the step (dt [s]) is d + tau g (d0 -> d1, g0 -> g1 [rad/s]): the
    rebuilt rudder moved by -tau in time, g = -d(delta)/dt, so the timing offset tau [s] is
    estimated like the rest.  ws from :func:`ekf.kernels.make_workspace` (NZ, NS, hull_coef).
    """
    jacobian_step(z, d0, d1, g0, g1, TAU, SLOTS, ND, dt, p, poly, hull_axis, hull_term, idx, ws)


@njit(cache=True)
def _check_log(z, P):
    for i in range(NZ):
        if not np.isfinite(z[i]):
            return NONFINITE
        for j in range(NZ):
            if not np.isfinite(P[i, j]):
                return NONFINITE
    if not (z[_IU] > 0.0):
        return NEG_SPEED
    if not is_pd(P):
        return NOT_PD
    return OK


@njit(cache=True)
def log_filter_kernel(z0, P0, meas, meas_k, delta, g, reset_k, var_tau, dt, R, q, p, poly, hull_axis, hull_term,
                      hull_coef, idx, zs, pdiag, nis):
    """The whole pass on the 0.1 s grid of ``delta`` (N,): predict every step, update at steps ``meas_k``.

    meas (M, 4) x, y, psi, n at grid steps meas_k (M,) (increasing; a sample at step 0 is taken
    to be in z0, P0); g (N,) = -d(delta)/dt; at the steps reset_k (before each rudder movement)
    tau is marginalised out (its effect already lives in the other states) and restarted at 0
    with variance var_tau; q (20,) diagonal of Q per step; zs, pdiag (N, 20) filled; nis (M,).
    Returns (status, step index, final P).
    """
    N = delta.shape[0]
    M = meas_k.shape[0]
    z = z0.copy()
    P = P0.copy()
    FP = np.empty((NZ, NZ))
    ws = make_workspace(NZ, NS, hull_coef)
    zn, F = ws[8], ws[9]
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
        propagate_log(z, delta[k - 1], delta[k], g[k - 1], g[k], dt, p, poly, hull_axis, hull_term, idx, ws)
        for i in range(NZ):
            z[i] = zn[i]
        fpft(F, P, NS, FP, P)
        symmetrise(P, P)
        for i in range(NZ):
            P[i, i] += q[i]
        st = _check_log(z, P)
        if st != OK:
            return st, k, P
        while j < M and meas_k[j] == k:
            nis[j] = joseph_update(z, P, meas[j], R)
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
    """A pass: t (N,) the 0.1 s grid, z (N, 20) estimates, pdiag (N, 20) variances, P final, nis (M,)."""

    t: np.ndarray
    z: np.ndarray
    pdiag: np.ndarray
    P: np.ndarray
    nis: np.ndarray
    names: tuple = STATES + DERIVATIVES

    @property
    def final(self) -> dict:
        return {n: float(self.z[-1, ND + i]) for i, n in enumerate(DERIVATIVES)}


def log_measurements(record):
    """(t_log, obs (K, 4) x, y, psi, n, R (4, 4)) of a project log's TrialRecord."""
    from trials.logio import M_PER_DEG_LAT, M_PER_DEG_LON

    from .output_error import _noise_half_widths

    meta = record.meta
    hw = _noise_half_widths(meta)
    mlat = float(meta.get("m_per_deg_lat", M_PER_DEG_LAT))
    mlon = float(meta.get("m_per_deg_lon", M_PER_DEG_LON))
    a = np.array([hw["lat_deg"] * mlat, hw["lon_deg"] * mlon, hw["heading_deg"] * DEG, hw["rpm"] / 60.0])
    obs = np.column_stack([record.x, record.y, record.psi, record.n]).astype(float)
    return np.asarray(record.t, float), obs, np.diag(a * a / 3.0)


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
    res = _run_once(data, record, cfg, q, duration, None, sigma_tau, uvr_std, rudder=rudder)
    for _ in range(passes - 1):
        res = _run_once(data, record, cfg, q, duration, res.z[-1, ND:], sigma_tau, uvr_std,
                        P_der=inflate * res.P[ND:, ND:], rudder=rudder)
    return res


def _true_rudder(data, t: np.ndarray) -> np.ndarray:
    if data.truth is None or getattr(data.truth, "delta", None) is None:
        raise InputError(data.source, "delta", "rudder='true' needs a truth file with the rudder angle")
    return np.interp(t, np.asarray(data.truth.t, float), np.asarray(data.truth.delta, float))


def _run_once(data, record, cfg, q, duration, start_derivs, sigma_tau, uvr_std=None, P_der=None,
              rudder: str = "rebuilt") -> LogFilterResult:
    from trials.rudder import manoeuvre_from_meta, movement_starts, reconstruct_rudder

    from .estimate import P0_for, initial_state

    m = data.meas
    t = np.asarray(m.t, float)
    dt = float(t[1] - t[0])
    keep = np.ones(len(t), bool) if duration is None else (t - t[0] <= duration + 1e-9)
    t = t[keep]
    N = len(t)
    if rudder not in ("rebuilt", "true"):
        raise ValueError(f"rudder must be 'rebuilt' or 'true', got {rudder!r}")
    delta = np.asarray(m.delta, float)[:N] if rudder == "rebuilt" else _true_rudder(data, t)
    delta = np.ascontiguousarray(delta)
    g = -np.gradient(delta, dt)
    # rudder movements start where the rebuilt order changes (and at the start)
    meta = m.meta
    kind, man = manoeuvre_from_meta(meta, data.source)
    order, _ = reconstruct_rudder(t, np.asarray(m.psi, float)[:N], kind, man, data.packed.p,
                                  float(meta.get("trim_rudder_deg", 0.0)) * DEG)
    reset_k = np.ascontiguousarray(movement_starts(order, dt))
    t_log, obs, R = log_measurements(record)
    mk = np.rint((t_log - t[0]) / dt).astype(np.int64)
    sel = (mk >= 0) & (mk < N)
    mk, obs = np.ascontiguousarray(mk[sel]), np.ascontiguousarray(obs[sel])
    zp = initial_state(data, cfg)                     # u, v, r, n, derivatives (16, paper layout)
    der = zp[4:] if start_derivs is None else np.asarray(start_derivs, float)
    P0p = P0_for(cfg)
    z0 = np.r_[obs[0], zp[0:3], 0.0, der]
    P0 = np.zeros((NZ, NZ))
    P0[:NM, :NM] = R
    P0[NM:NS, NM:NS] = P0p[0:3, 0:3] if uvr_std is None else np.diag(np.asarray(uvr_std, float) ** 2)
    P0[TAU, TAU] = sigma_tau ** 2
    P0[ND:, ND:] = P0p[4:, 4:] if P_der is None else P_der
    qv = np.zeros(NZ)
    for k, v in (q or {}).items():
        qv[(STATES + DERIVATIVES).index(k)] = float(v)
    zs = np.full((N, NZ), np.nan)
    pd_ = np.full((N, NZ), np.nan)
    nis = np.full(len(mk), np.nan)
    st, k, P = log_filter_kernel(z0, P0, obs, mk, delta, g, reset_k, float(sigma_tau ** 2), dt, R, qv,
                                 *data.packed.args(), np.asarray(data.slots, np.int64), zs, pd_, nis)
    if st != OK:
        raise FilterDivergence(data.name, t[k], _REASON[st])
    return LogFilterResult(t, zs, pd_, P, nis)


# --------------------------------------------------------------------------- Monte Carlo


def _timing_error(data) -> dict:
    """How far the rebuilt rudder's reversals are from the truth file's (rms, max [s], count)."""
    from trials.rudder import reversal_timing_errors

    if data.truth is None or getattr(data.truth, "delta", None) is None:
        return {}
    e = reversal_timing_errors(data.meas.t, data.meas.delta, data.truth.t, data.truth.delta)
    if len(e) == 0:
        return {"rudder_timing_n": 0, "rudder_timing_rms_s": np.nan, "rudder_timing_max_s": np.nan}
    return {"rudder_timing_n": len(e), "rudder_timing_rms_s": float(np.sqrt(np.mean(e ** 2))),
            "rudder_timing_max_s": float(np.abs(e).max())}


def _one(trial_file: str, seed: int, cfg: dict, q, sigma_tau: float = 0.15, rudder: str = "rebuilt") -> dict:
    from trials.logio import read_record

    from .estimate import data_from_trial

    with tempfile.TemporaryDirectory(prefix="ekf-log-mc-") as td:
        data = data_from_trial(trial_file, cfg, seed=seed, workdir=td)
        rec = data.record if data.record is not None else read_record(data.source)
        try:
            res = run_log_filter(data, rec, cfg, q=q, sigma_tau=sigma_tau, rudder=rudder)
        except FilterDivergence as exc:
            return {"trial": data.name, "seed": seed, "diverged": str(exc), "rudder": rudder, "sigma_tau_s": sigma_tau}
    tv = data.true_values
    fin = res.final
    return {"trial": data.name, "seed": seed, "diverged": "", "rudder": rudder, "sigma_tau_s": sigma_tau,
            **_timing_error(data),
            **{n: 100.0 * abs(fin[n] - tv[n]) / abs(tv[n]) for n in DERIVATIVES},
            **{f"final_{n}": v for n, v in fin.items()},
            "mean_nis": float(np.nanmean(res.nis))}


def _task(task) -> dict:
    return _one(*task)


def monte_carlo(out_dir, n_seeds: int = 20, trials=None, n_jobs: int = 2, first_seed: int = 1000,
                config=None, q=None, sigma_tau: float = 0.15, verbose: bool = True, backend: str = "loky",
                rudder: str = "rebuilt"):
    """``n_seeds`` seeds per trial; writes OUT/runs.csv (one row per trial and seed, with the
    ``trial_file`` it came from); returns it.

    trials: names of the paper's trials (ST35, ZZ10, ZZ20, S-type 120: the default) or paths
    of turning / zigzag / S-type trial YAMLs; rudder: "rebuilt" (default) or "true"
    (:func:`run_log_filter`).
    """
    import pandas as pd
    from trials.sweep import run_sweep

    from .estimate import REPO, load_config
    from .reproduce import TRIALS

    from trials.rudder import REBUILT_KINDS
    from trials.trial import load_trial

    cfg = load_config(config)
    files = [str(REPO / "configs" / "trials" / TRIALS[t]) if t in TRIALS else str(Path(t).resolve())
             for t in (trials or TRIALS)]
    for f in files:                       # all inputs checked before any run or output
        if not Path(f).is_file():
            raise InputError(f, "trials", f"neither one of {', '.join(TRIALS)} nor a trial YAML")
        if (kind := load_trial(f).kind) not in REBUILT_KINDS:
            raise InputError(f, "manoeuvre.kind", f"the raw-log EKF rebuilds the rudder of turning, zigzag and "
                                                  f"S-type trials only, not {kind}")
    jobs = [(f, first_seed + s, cfg, q, sigma_tau, rudder) for f in files for s in range(n_seeds)]
    rows = run_sweep(_task, jobs, backend=backend, n_jobs=n_jobs, progress=verbose,
                     labels=[f"{Path(j[0]).stem} seed {j[1]}" for j in jobs])
    runs = pd.DataFrame(rows)
    runs.insert(2, "trial_file", [j[0] for j in jobs])
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    runs.to_csv(out / "runs.csv", index=False, float_format="%.8g")
    return runs


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m ekf.log_filter", description="Monte Carlo of the raw-log EKF")
    ap.add_argument("out")
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--trials", nargs="*", default=None,
                    help="trial names (default ST35 ZZ10 ZZ20 'S-type 120') or turning/zigzag/S-type trial YAMLs")
    ap.add_argument("--sigma-tau", type=float, default=None,
                    help="prior std [s] of each rudder movement's timing (default 0.15, or 1e-4 with --true-rudder)")
    ap.add_argument("--first-seed", type=int, default=1000, help="noise seed of the first run of each trial")
    ap.add_argument("--true-rudder", action="store_true",
                    help="give the filter the truth file's rudder instead of the rebuilt one (a check against the "
                         "CRB with the rudder known)")
    args = ap.parse_args(argv)
    if args.sigma_tau is None:
        args.sigma_tau = 1e-4 if args.true_rudder else 0.15
    if not args.sigma_tau > 0:
        ap.error(f"--sigma-tau must be > 0, got {args.sigma_tau}")
    try:
        monte_carlo(args.out, n_seeds=args.seeds, trials=args.trials, n_jobs=args.jobs, sigma_tau=args.sigma_tau,
                    first_seed=args.first_seed, rudder="true" if args.true_rudder else "rebuilt")
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
