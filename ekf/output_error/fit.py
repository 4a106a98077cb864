"""The joint output-error fit: the scaled least-squares problem, its Jacobian and the EKF start."""
from __future__ import annotations

import os
import time
from dataclasses import dataclass

import numpy as np

from ..filter import FilterDivergence
from .switches import search_switches
from .trial import FD_STEP, NNUIS, OETrial, trial_from_data


def _sim_task(tr: OETrial, theta, nuis, restart=None):
    return tr.residuals(theta, nuis, restart)


_POOLS: dict = {}
if hasattr(os, "register_at_fork"):
    # a forked child (the main job's background section) inherits the pools but not their threads:
    # a map on one would wait for ever, so the child starts with none and makes its own
    os.register_at_fork(after_in_child=_POOLS.clear)


def _workers(n_jobs) -> int:
    """Threads for ``n_jobs`` (joblib's convention: None or 1 one, -1 every core, -2 all but one)."""
    if n_jobs is None:
        return 1
    n = int(n_jobs)
    if n < 0:
        n = max(1, (os.cpu_count() or 1) + 1 + n)
    return max(1, n)


def _pool(workers: int):
    """One thread pool per size, kept for the process (a fit calls it some 50 times)."""
    from concurrent.futures import ThreadPoolExecutor

    pool = _POOLS.get(workers)
    if pool is None:
        pool = _POOLS[workers] = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="oe-jacobian")
    return pool


TSW_FD = 0.01  # forward-difference step of a reversal time, in steps (stays inside one ramp cell)


@dataclass
class OEResult:
    """Output-error fit: estimates, standard errors (from (J^T W J)^-1), cost and bookkeeping."""

    names: tuple
    theta: np.ndarray
    se: np.ndarray
    cov: np.ndarray
    nuisance: list                # per trial: v0, psi0, x0, y0 [, reversal times t_k]
    cost: float                   # 0.5 * sum of squared whitened residuals
    nres: int
    nfev: int
    njev: int
    trials: tuple
    start: np.ndarray
    seconds: float
    status: str = ""

    @property
    def final(self) -> dict:
        return dict(zip(self.names, map(float, self.theta)))

    @property
    def std_errors(self) -> dict:
        return dict(zip(self.names, map(float, self.se)))

    @property
    def nparams(self) -> int:
        return len(self.theta) + sum(len(n) for n in self.nuisance)

    @property
    def chi2_per_dof(self) -> float:
        return 2.0 * self.cost / max(self.nres - self.nparams, 1)


class _Problem:
    """Scaled least-squares problem: q = [theta / scale, nuisance_1 / nscale_1, ...].

    Nuisances per trial: v0 (scale 0.01 m/s), psi0 (1e-3 rad), x0, y0 (1 m) and, for open-loop
    ramp rudders, the reversal times t_k (0.1 s). Jacobian: forward differences for the derivatives
    and v0 (full runs), for t_k a run restarted just before the reversal (each t_k touches one trial
    and only the samples after it), analytic for psi0, x0, y0 (rotation about / shift of the start).
    """

    def __init__(self, trials: list[OETrial], theta0, scale, n_jobs: int = 1, verbose: bool = False):
        self.trials = trials
        self.scale = np.asarray(scale, float)
        self.nt = len(trials)
        self.nd = len(theta0)
        self.nn = [tr.nnuis for tr in trials]
        self.noff = self.nd + np.cumsum([0] + self.nn)  # column of each trial's first nuisance
        self.nscale = np.concatenate([np.r_[1e-2, 1e-3, 1.0, 1.0, np.full(n - NNUIS, 0.1)] for n in self.nn])
        nus = np.concatenate([tr.nuisance0() for tr in trials])
        self.q0 = np.r_[np.asarray(theta0, float) / self.scale, nus / self.nscale]
        self.offsets = np.cumsum([0] + [tr.nres for tr in trials])
        self.n_jobs = n_jobs
        self.verbose = verbose
        self._cache = None
        self._states = None
        self.t0 = time.perf_counter()
        self.nsim = 0
        self.free_theta = True

    def split(self, q):
        theta = q[: self.nd] * self.scale
        flat = q[self.nd:] * self.nscale
        nuis = [flat[a - self.nd: b - self.nd] for a, b in zip(self.noff[:-1], self.noff[1:])]
        return theta, nuis

    def join_nuisance(self, nuis) -> np.ndarray:
        return np.concatenate(nuis) / self.nscale

    def _run(self, tasks):
        self.nsim += len(tasks)
        workers = _workers(self.n_jobs)
        if workers == 1 or len(tasks) < 2:
            return [_sim_task(*a) for a in tasks]
        # threads: the compiled integration releases the GIL, so the columns run on every core without
        # pickling the trials to worker processes; results come back in task order (the same numbers)
        return list(_pool(workers).map(lambda a: _sim_task(*a), tasks))

    def fun(self, q):
        theta, nuis = self.split(q)
        key = q.tobytes()
        if self._cache is not None and self._cache[0] == key:
            return self._cache[1]
        res = np.concatenate(self._run([(tr, theta, nuis[i]) for i, tr in enumerate(self.trials)]))
        self._cache = (key, res)
        return res

    def jac(self, q):
        theta, nuis = self.split(q)
        f0 = self.fun(q)
        J = np.zeros((len(f0), len(q)))
        tasks, where = [], []
        for j in (range(self.nd) if self.free_theta else ()):
            th = theta.copy()
            h = FD_STEP * max(abs(theta[j]), 1e-3 * self.scale[j])
            th[j] += h
            for i, tr in enumerate(self.trials):
                tasks.append((tr, th, nuis[i]))
                where.append((i, j, h / self.scale[j]))
        for i, tr in enumerate(self.trials):  # v0: forward difference
            nu = nuis[i].copy()
            h = 1e-6
            nu[0] += h
            tasks.append((tr, theta, nu))
            c = self.noff[i]
            where.append((i, c, h / self.nscale[c - self.nd]))
        for i, tr in enumerate(self.trials):  # reversal times: restart a step before the ramp
            if tr.tsw is None or len(tr.tsw) == 0:
                continue
            S0 = tr.states(theta, nuis[i])
            if S0 is None:
                continue
            for k in range(len(tr.tsw)):
                nu = nuis[i].copy()
                h = TSW_FD * tr.dt
                tk = nu[NNUIS + k]
                if np.floor(tk / tr.dt + 0.5 + TSW_FD) != np.floor(tk / tr.dt + 0.5):
                    h = -h  # stay inside the ramp cell (the simulation is linear in t_k there)
                nu[NNUIS + k] += h
                i0 = int(max(0, min(len(S0) - 2, np.floor((min(tk, tk + h) - 0.5 * tr.dt) / tr.dt) - 1)))
                tasks.append((tr, theta, nu, (i0, S0)))
                c = self.noff[i] + NNUIS + k
                where.append((i, c, h / self.nscale[c - self.nd]))
        outs = self._run(tasks)
        for (i, col, hq), r in zip(where, outs):
            a, b = self.offsets[i], self.offsets[i + 1]
            J[a:b, col] = (r - f0[a:b]) / hq
        for i, tr in enumerate(self.trials):  # psi0, x0, y0: analytic (rotation about / shift of the start)
            a, b = self.offsets[i], self.offsets[i + 1]
            r = f0[a:b].reshape(-1, 4) * tr.sigma + tr.obs  # simulated psi, x, y, n
            x0, y0 = nuis[i][2], nuis[i][3]
            c = self.noff[i]
            blk = np.zeros((r.shape[0], 4, 3))
            blk[:, 0, 0] = 1.0
            blk[:, 1, 0] = -(r[:, 2] - y0)
            blk[:, 2, 0] = r[:, 1] - x0
            blk[:, 1, 1] = 1.0
            blk[:, 2, 2] = 1.0
            blk /= tr.sigma[None, :, None]
            blk *= self.nscale[c - self.nd + 1: c - self.nd + 4][None, None, :]
            J[a:b, c + 1: c + 4] = blk.reshape(-1, 3)
        if self.verbose:
            print(f"    jacobian {self.nsim} simulations, cost {0.5 * f0 @ f0:.6g} "
                  f"({time.perf_counter() - self.t0:.0f} s)", flush=True)
        return J


def fit_nuisance(trials: list[OETrial], theta, nuis=None, max_nfev: int = 30,
                 only_switching: bool = True) -> list[np.ndarray]:
    """Per trial, the nuisances (start sway/heading/position, reversal times) at fixed derivatives ``theta``.

    Cheap (no derivative columns; trials are independent) and it takes the start heading and the
    reversal times, which the positions see as hundreds of sigma over 3000 s, to their optimum
    before the derivatives move, so the joint fit starts near its valley floor. Trials without
    reversal times keep their start values unless ``only_switching`` is False (their v0 fitted at
    a wrong theta can take the joint fit away, e.g. ST35 from a 120 % start).
    """
    from scipy.optimize import least_squares

    out = []
    for i, tr in enumerate(trials):
        if only_switching and tr.tsw is None:
            out.append(tr.nuisance0() if nuis is None else np.asarray(nuis[i], float).copy())
            continue
        prob = _Problem([tr], theta, np.abs(theta))
        prob.free_theta = False
        if nuis is not None:
            prob.q0[prob.nd:] = prob.join_nuisance([nuis[i]])
        qt = prob.q0[: prob.nd]
        sol = least_squares(lambda z: prob.fun(np.r_[qt, z]), prob.q0[prob.nd:],
                            jac=lambda z: prob.jac(np.r_[qt, z])[:, prob.nd:], method="trf", max_nfev=max_nfev,
                            xtol=1e-8, ftol=1e-9, gtol=1e-10)
        out.append(prob.split(np.r_[qt, sol.x])[1][0].copy())
    return out


def fit(trials: list[OETrial], theta0, names, n_jobs: int = 1, verbose: bool = False,
        max_nfev: int = 60, stages=None, max_rounds: int = 6, prefit_nuisance: bool = True, xtol: float = 1e-8,
        ftol: float = 1e-9) -> OEResult:
    """Joint output-error fit of the coefficients ``names`` (start ``theta0``, in the trials' slot order) over ``trials``.

    ``stages``: optional record lengths [s] fitted in turn (continuation: a short record first,
    each stage starting from the previous), then the full records.
    """
    from dataclasses import replace

    from scipy.optimize import least_squares

    t0 = time.perf_counter()
    theta0 = np.asarray(theta0, float)
    theta = theta0.copy()
    nuis0 = None
    nfev = njev = 0
    for L in list(stages or []) + [None]:
        trs = trials if L is None else [replace(tr, duration=min(L, tr.duration), t_log=tr.t_log[tr.t_log <= L],
                                                obs=tr.obs[tr.t_log <= L], idx=None) for tr in trials]
        prob = _Problem(trs, theta, np.abs(theta0), n_jobs=n_jobs, verbose=verbose)
        if nuis0 is None and prefit_nuisance:
            nuis0 = fit_nuisance(trs, theta)
            if verbose:
                print(f"    nuisance pre-fit: cost {0.5 * np.sum(prob.fun(np.r_[prob.q0[:prob.nd], prob.join_nuisance(nuis0)]) ** 2):.6g}", flush=True)
        if nuis0 is not None:
            prob.q0[prob.nd:] = prob.join_nuisance(nuis0)
        if verbose:
            print(f"  stage {'full' if L is None else f'{L:g} s'}: {len(trs)} trials, "
                  f"{sum(t.nres for t in trs)} residuals", flush=True)
        for rnd in range(max_rounds):
            sol = least_squares(prob.fun, prob.q0, jac=prob.jac, method="trf", x_scale=1.0, max_nfev=max_nfev,
                                xtol=xtol, ftol=ftol, gtol=1e-10)
            theta, nuis = prob.split(sol.x)
            nuis0 = [n.copy() for n in nuis]
            nfev += sol.nfev
            njev += sol.njev or 0
            if not any(tr.order is not None for tr in trs):
                break
            moves = search_switches(trs, theta, nuis, verbose=verbose)
            if verbose:
                print(f"  round {rnd + 1}: cost {sol.cost:.6g}, {moves} switch moves", flush=True)
            if moves == 0:
                break
            prob._cache = None
            prob.q0 = sol.x.copy()
    J = sol.jac
    JtJ = J.T @ J
    try:
        covq = np.linalg.inv(JtJ)
    except np.linalg.LinAlgError:
        covq = np.linalg.pinv(JtJ)
    sc = np.r_[prob.scale, prob.nscale]
    cov = covq * np.outer(sc, sc)
    nd = len(theta)
    return OEResult(tuple(names), theta, np.sqrt(np.diag(cov)[:nd]), cov[:nd, :nd], [n.copy() for n in nuis], float(sol.cost),
                    len(sol.fun), nfev, njev, tuple(tr.name for tr in trials), theta0, time.perf_counter() - t0,
                    sol.message)


def information(trials: list[OETrial], theta) -> tuple[np.ndarray, np.ndarray]:
    """Fisher information J^T W J (derivatives and nuisances) at ``theta`` and the derivative standard errors."""
    prob = _Problem(trials, theta, np.abs(theta))
    J = prob.jac(prob.q0)
    cov = np.linalg.inv(J.T @ J)
    sc = np.r_[prob.scale, prob.nscale]
    cov = cov * np.outer(sc, sc)
    return J.T @ J, np.sqrt(np.diag(cov)[: len(theta)])


# --------------------------------------------------------------------------- EKF start + refinement


def refine(datas, cfg, rudder: str = "ramp", n_jobs: int = 1, verbose: bool = False, start: str = "ekf",
           stages=None, ekf_start: dict | None = None):
    """EKF (joint over ``datas``) then the joint output-error fit. Returns (ekf_final dict, OEResult).

    ``ekf_start``: the EKF's final values when the caller already has them (the joint estimate of
    the same data), so the filter is not run twice; ``n_jobs``: workers for the Jacobian's simulations.
    """
    from ..estimate import estimate, initial_state, joint_estimate

    names = tuple(datas[0].names)
    theta_start = initial_state(datas[0], cfg)[4:]
    ekf = None
    if ekf_start is not None:
        ekf = {n: float(ekf_start[n]) for n in names}
        theta_start = np.array([ekf[n] for n in names])
    elif start == "ekf":
        try:
            e = joint_estimate(datas, cfg) if len(datas) > 1 else estimate(datas[0], cfg)
            ekf = e.final
            theta_start = np.array([ekf[n] for n in names])
        except FilterDivergence as exc:
            if verbose:
                print(f"  EKF diverged ({exc}); output error starts from the initial guess", flush=True)
    trials = [trial_from_data(d, rudder=rudder) for d in datas]
    res = fit(trials, theta_start, names, n_jobs=n_jobs, verbose=verbose, stages=stages)
    return ekf, res


class OEEstimate:
    """An output-error estimate with the interface of :class:`ekf.estimate.Estimate` for the reports
    (``final``, ``errors_pct()``, ``to_pandas()``, ``data``, ``name``)."""

    def __init__(self, data, res: OEResult, name: str):
        self.data = data
        self.res = res
        self._name = name

    @property
    def name(self):
        return self._name

    @property
    def final(self):
        return self.res.final

    def errors_pct(self):
        tv = self.data.true_values
        if tv is None:
            return None
        return {n: 100.0 * abs(self.final[n] - tv[n]) / abs(tv[n]) for n in self.final}

    def to_pandas(self):
        """One row per coefficient: ``estimate``, ``std_error`` and, where known, ``true`` and ``error_pct``."""
        import pandas as pd

        err = self.errors_pct()
        rows = []
        for n, v in self.final.items():
            row = {"coefficient": n, "estimate": v, "std_error": self.res.std_errors[n]}
            if err is not None:
                row.update(true=self.data.true_values[n], error_pct=err[n])
            rows.append(row)
        return pd.DataFrame(rows).set_index("coefficient")


