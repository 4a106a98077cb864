"""Output-error (maximum-likelihood) refinement of the 12 sway/yaw hull derivatives.

The augmented EKF (:mod:`ekf.filter`) gives a first estimate; this module refines it by
simulating every trial with the simulator's own compiled model (:func:`mmg.integrate.integrate`
on a copy of the packed ship whose ``hull_coef`` slots hold the candidate derivatives, no
second physics copy) and minimising the weighted residuals against the *raw* 5 s log samples
(no interpolation, no differentiation):

    J(theta) = sum_trials sum_k  sum_{c in psi, x, y, n} ((c_sim(t_k; theta) - c_log(t_k)) / sigma_c)^2

jointly over several trials, with :func:`scipy.optimize.least_squares` (trust-region).
``sigma_c`` is the log's noise standard deviation (uniform noise of half-width a has
sigma = a / sqrt(3); the half-widths are read from the log header, Rhee & Kim Table 4
otherwise), so the weights are the inverse noise variances and (J^T W J)^-1 at the optimum
is the (Gaussian-approximation) Cramér-Rao covariance of the estimate: the standard errors
reported beside each derivative.

Per trial the unknown start is estimated too (nuisance parameters): the sway speed v0 and
the start heading/position psi0, x0, y0 (their Jacobian columns are analytic: a shift, and
a rotation of the track about the start point).  u0, n0 and the trim rudder come from the
log header (the steady approach).  The rudder is driven by

* ``rudder="ramp"`` (default): turning trials their constant order; zigzag / S-type trials an
  open-loop order whose reversal times t_k are continuous nuisance parameters too, started where
  the recovered heading reaches the switching heading (:meth:`OETrial.ramp_law`: the step holding
  t_k gets the order that moves the rate-limited rudder by the matching fraction of a full-rate
  step, so the cost is continuous in t_k and the derivatives no longer have to make up for
  whole-step switch errors). A per-trial pre-fit of the nuisances at the start derivatives
  (:func:`fit_nuisance`) precedes the joint fit;
* ``rudder="law"``: the trial's own closed-loop law (heading switch on the *simulated* heading);
  the cost jumps whenever a simulated switch moves a step (the fit stops in a wrong cell), or
* ``rudder="reconstructed"``: the order rebuilt from the recovered heading as an open-loop
  schedule with whole-step switches (searched greedily; some stay one step off).

Derivative Jacobian columns are forward differences (one simulation per derivative and trial);
simulations of one Jacobian can go to joblib workers (``n_jobs``).

    python -m ekf.output_error OUT --seeds 20          # Monte Carlo, EKF vs output error
    python -m ekf.output_error OUT --seeds 1 --trials ZZ20
    python -m ekf.output_error OUT --summarise-only --ekf-summary EKF_MC/summary.csv
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mmg.integrate import CommandLaw, integrate
from mmg.model import DELTA_, N_, P_RATE, P_TE, PSI_, R_, U_, V_, X_, Y_, PackedShip
from mmg.units import DEG, KNOT

from .filter import DERIVATIVES, FilterDivergence
from .preprocess import M_PER_DEG_LAT, M_PER_DEG_LON, manoeuvre_from_meta, reconstruct_rudder

CH = ("psi", "x", "y", "n")
# Rhee & Kim Table 4 log noise (uniform half-widths): lat 8e-7 deg, lon 4e-7 deg, heading 0.012 deg, rpm 0.2
DEFAULT_HALF_WIDTH = {"lat_deg": 8.0e-7, "lon_deg": 4.0e-7, "heading_deg": 1.2e-2, "rpm": 0.2}
NNUIS = 4  # v0, psi0, x0, y0 per trial
FD_STEP = 1e-7  # forward-difference step, relative to each derivative's magnitude


# --------------------------------------------------------------------------- one trial


def _noise_half_widths(meta: dict) -> dict:
    """Uniform half-widths from a header line 'uniform: lat 8e-07 deg, lon 4e-07 deg, heading ..., rpm 0.2 rpm'."""
    out = dict(DEFAULT_HALF_WIDTH)
    s = str(meta.get("noise", ""))
    if s.startswith("uniform:"):
        for part in s.split(":", 1)[1].split(","):
            w = part.split()
            if len(w) >= 2:
                try:
                    val = float(w[1])
                except ValueError:
                    continue
                key = {"lat": "lat_deg", "lon": "lon_deg", "heading": "heading_deg", "rpm": "rpm"}.get(w[0])
                if key and val > 0:  # a noise-free log keeps the default weights
                    out[key] = val
    return out


@dataclass
class OETrial:
    """What the output-error fit needs of one trial (SI).

    t_log (K,) log times; obs (K, 4) psi, x, y, n at those times; sigma (4,) noise std of
    psi [rad], x, y [m], n [rps]; x0 (8,) start state; law the rudder command; duration, dt
    the simulation; packed/slots the ship and the derivative slots in ``hull_coef``.
    """

    name: str
    packed: PackedShip
    slots: np.ndarray
    t_log: np.ndarray
    obs: np.ndarray
    sigma: np.ndarray
    x0: np.ndarray
    law: CommandLaw
    duration: float
    dt: float
    idx: np.ndarray = field(default=None)
    order: np.ndarray | None = None   # open-loop rudder order on the 0.1 s grid (rudder="reconstructed")
    tsw: np.ndarray | None = None     # start values of the rudder reversal times [s] (rudder="ramp")
    levels: np.ndarray | None = None  # rudder order before the first reversal and after each one [rad]

    def __post_init__(self):
        if self.idx is None:
            self.idx = np.round(self.t_log / self.dt).astype(np.int64)

    @property
    def nres(self) -> int:
        return self.obs.size

    @property
    def nnuis(self) -> int:
        return NNUIS + (0 if self.tsw is None else len(self.tsw))

    def nuisance0(self) -> np.ndarray:
        nu = np.array([self.x0[V_], self.obs[0, 0], self.obs[0, 1], self.obs[0, 2]])
        return nu if self.tsw is None else np.r_[nu, self.tsw]

    def ramp_law(self, tsw, t_shift: float = 0.0) -> CommandLaw:
        """Open-loop order: ``levels`` with reversals at the continuous times ``tsw``.

        The loop samples the order at each step start (zero-order hold) and the steering gear is
        rate-limited, so a plain order ramp would act only through the sign of the order error
        (the cost stays flat over most of a step). Instead the one step i whose start lies in
        (t_k - dt/2, t_k + dt/2] gets the order that moves the rudder, over that step, by the
        fraction f = (i dt - t_k + dt/2) / dt of a full-rate step (exact in the steering gear's
        linear zone, f < ~0.98; beyond, a continuous blend up to an order saturated over the whole
        step, which moves the rudder like the full reversal). The rudder then
        leaves its old angle at t_k + dt/2 whatever the step grid: the simulation is continuous
        in every t_k, and t_k = (i - 1/2) dt is the heading-switch law's reversal at step i exactly.
        """
        dt = self.dt
        te, rate = float(self.packed.p[P_TE]), float(self.packed.p[P_RATE])
        lam = te * rate
        g = 1.0 - np.exp(-dt / te)
        dfull = rate * dt
        flin = min(lam * g / dfull, 1.0)
        tk = np.sort(np.asarray(tsw, float))
        ik = np.floor(tk / dt - 0.5) + 1.0   # the step whose start lies in (t_k - dt/2, t_k + dt/2]
        ik = np.maximum(ik, 1.0)
        ik = np.maximum.accumulate(ik + 2.0 * np.arange(len(ik))) - 2.0 * np.arange(len(ik))
        f = np.clip((ik * dt - tk + 0.5 * dt) / dt, 0.0, 1.0)
        e = 1e-6 * dt
        ts, vs = [-1e9], [self.levels[0]]
        for k in range(len(tk)):
            a, b = self.levels[k], self.levels[k + 1]
            sgn, span = np.sign(b - a), abs(b - a)
            if f[k] <= flin:
                c = a + sgn * f[k] * dfull / g
            else:
                c = a + sgn * min(lam + (f[k] - flin) / (1.0 - flin) * dfull, span)  # saturated all step at f = 1
            t0 = (ik[k] - 0.5) * dt
            ts += [t0 - e, t0 + e, t0 + dt - e, t0 + dt + e]
            vs += [a, c, c, b]
        ts.append(max(self.duration + 1.0, ts[-1] + 1.0))
        vs.append(self.levels[-1])
        return CommandLaw.schedule(np.array(ts) - t_shift, vs)

    def _pk(self, theta) -> PackedShip:
        coef = self.packed.hull_coef.copy()
        coef[self.slots] = theta
        return PackedShip(self.packed.p, self.packed.poly, self.packed.hull_axis, self.packed.hull_term, coef)

    def states(self, theta, nuis, restart=None) -> np.ndarray | None:
        """(steps+1, 8) simulated states, or None when the run stopped early.

        ``restart=(i0, states)``: continue from row i0 of an earlier run (rows before i0 are copied);
        used for the switch-time Jacobian columns, where nothing changes before the reversal.
        """
        pk = self._pk(theta)
        if restart is not None and self.tsw is not None:
            i0, S0 = restart
            law = self.ramp_law(nuis[NNUIS:], t_shift=i0 * self.dt)
            _, S, _, done = integrate(pk, S0[i0], law, self.duration - i0 * self.dt, self.dt)
            if not done or not np.all(np.isfinite(S)):
                return None
            return np.concatenate([S0[:i0], S])
        x0 = self.x0.copy()
        x0[V_], x0[PSI_], x0[X_], x0[Y_] = nuis[:NNUIS]
        law = self.law
        if self.tsw is not None:
            law = self.ramp_law(nuis[NNUIS:])
        elif self.order is not None:
            law = CommandLaw.schedule(np.arange(len(self.order)) * self.dt, self.order)
        elif law.kind == 1:  # heading switch relative to the start heading
            par = law.params.copy()
            par[4] = nuis[1]
            law = CommandLaw(law.kind, par, law.t, law.delta, law.n)
        t, S, _, done = integrate(pk, x0, law, self.duration, self.dt)
        if not done or not np.all(np.isfinite(S)):
            return None
        return S

    def simulate(self, theta, nuis, restart=None) -> np.ndarray | None:
        """(K, 4) simulated psi, x, y, n at the log times, or None when the run stopped early."""
        S = self.states(theta, nuis, restart)
        return None if S is None else S[self.idx][:, [PSI_, X_, Y_, N_]]

    def residuals(self, theta, nuis, restart=None) -> np.ndarray:
        sim = self.simulate(theta, nuis, restart)
        if sim is None:
            return np.full(self.nres, 1e6)
        return ((sim - self.obs) / self.sigma).ravel()


def trial_from_data(data, rudder: str = "ramp", duration: float | None = None) -> OETrial:
    """An :class:`OETrial` from a :class:`ekf.estimate.TrialData` (re-reads its raw log).

    rudder: "ramp" (default; zigzag/S-type reversal times as continuous nuisance parameters,
    started where the recovered heading reaches the switching heading), "law" (closed-loop heading
    switch on the simulated heading) or "reconstructed" (the rebuilt order, whole-step switches).
    Turning trials use their constant order in every mode.
    """
    from trials.logio import read_record

    rec = data.record if data.record is not None else read_record(data.source)
    meta = rec.meta
    hw = _noise_half_widths(meta)
    mlat = float(meta.get("m_per_deg_lat", M_PER_DEG_LAT))
    mlon = float(meta.get("m_per_deg_lon", M_PER_DEG_LON))
    sigma = np.array([hw["heading_deg"] * DEG, hw["lat_deg"] * mlat, hw["lon_deg"] * mlon, hw["rpm"] / 60.0]) / np.sqrt(3)
    dt = float(data.meas.t[1] - data.meas.t[0])
    t = np.asarray(rec.t, float) - float(rec.t[0])
    dur = float(t[-1]) if duration is None else min(float(duration), float(t[-1]))
    keep = t <= dur + 1e-9
    obs = np.column_stack([rec.psi, rec.x, rec.y, rec.n])[keep]
    trim = float(meta.get("trim_rudder_deg", 0.0)) * DEG
    u0 = float(meta.get("approach_speed_kn", rec.U[0] / KNOT)) * KNOT
    n0 = float(meta["approach_rpm"]) / 60.0 if "approach_rpm" in meta else float(rec.n[0])
    x0 = np.zeros(8)
    x0[U_], x0[V_], x0[R_], x0[DELTA_], x0[N_] = u0, 0.0, 0.0, trim, n0
    x0[PSI_], x0[X_], x0[Y_] = obs[0, 0], obs[0, 1], obs[0, 2]
    kind, man = manoeuvre_from_meta(meta, data.source)
    if rudder == "ramp" and kind != "turning":
        order, _ = reconstruct_rudder(data.meas.t, data.meas.psi, kind, man, data.packed.p, trim)
        sw = switches(order)
        tm = data.meas.t - data.meas.t[0]
        keep_sw = sw[tm[sw] < dur]
        tsw = (tm[keep_sw] - 0.5 * dt).astype(float)
        levels = np.asarray(order, float)[np.r_[0, keep_sw]].copy()
        law = CommandLaw.schedule([0.0, 1.0], [levels[0], levels[0]])
        return OETrial(data.name, data.packed, np.asarray(data.slots), t[keep], obs, sigma, x0, law, dur, dt,
                       tsw=tsw, levels=levels)
    if rudder == "reconstructed":
        order, _ = reconstruct_rudder(data.meas.t, data.meas.psi, kind, man, data.packed.p, trim)
        law = CommandLaw.schedule(data.meas.t - data.meas.t[0], order)
        return OETrial(data.name, data.packed, np.asarray(data.slots), t[keep], obs, sigma, x0, law, dur, dt,
                       order=np.asarray(order, float).copy())
    elif rudder in ("law", "ramp"):
        side = 1.0 if man.get("first", "starboard") == "starboard" else -1.0
        if kind == "turning":
            te = float(meta.get("execute_s", 0.0))
            if te > 0:
                law = CommandLaw.schedule([0.0, te, te + 1e-9, dur + 1.0], [trim, trim, man["rudder"], man["rudder"]])
            else:
                law = CommandLaw.schedule([0.0, dur + 1.0], [man["rudder"], man["rudder"]])
        elif kind == "zigzag":
            law = CommandLaw.heading_switch(man["rudder"], man["heading"], -man["heading"], side, psi0=x0[PSI_])
        else:
            h = man["switch_heading"]
            hi, lo = (h, 0.0) if side > 0 else (0.0, -h)
            law = CommandLaw.heading_switch(man["rudder"], hi, lo, side, psi0=x0[PSI_])
    else:
        raise ValueError(f"rudder must be 'ramp', 'law' or 'reconstructed', not {rudder!r}")
    return OETrial(data.name, data.packed, np.asarray(data.slots), t[keep], obs, sigma, x0, law, dur, dt)


# --------------------------------------------------------------------------- the joint fit


def _sim_task(tr: OETrial, theta, nuis, restart=None):
    return tr.residuals(theta, nuis, restart)


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
        if self.n_jobs == 1 or len(tasks) < 4:
            return [_sim_task(*a) for a in tasks]
        from joblib import Parallel, delayed
        return Parallel(n_jobs=self.n_jobs)(delayed(_sim_task)(*a) for a in tasks)

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


def switches(order: np.ndarray) -> np.ndarray:
    """Steps k at which the order changes (order[k] != order[k-1])."""
    return np.flatnonzero(np.diff(order) != 0.0) + 1


def _shifted(order: np.ndarray, k: int, d: int) -> np.ndarray | None:
    """The order with its switch at step k moved by d = +-1 step, or None if it would meet another switch."""
    o = order.copy()
    if d < 0:
        if k - 1 < 1 or o[k - 2] != o[k - 1]:
            return None
        o[k - 1] = o[k]
    else:
        if k + 1 >= len(o) or o[k + 1] != o[k]:
            return None
        o[k] = o[k - 1]
    return o


def search_switches(trials: list[OETrial], theta, nuis, verbose: bool = False) -> int:
    """Move each rudder switch of the open-loop orders by whole steps while that lowers the trial's cost.

    The orders rebuilt from the recovered heading switch up to a step (0.1 s) away from the true
    ones, which the positions (noise ~0.05 m) see as hundreds of sigma; the switch steps are
    integer unknowns, found here switch by switch in time order with theta fixed. Returns the
    number of moves (in place on ``trials[i].order``).
    """
    moves = 0
    for i, tr in enumerate(trials):
        if tr.order is None:
            continue
        r = tr.residuals(theta, nuis[i])
        best = r @ r
        for k in switches(tr.order):
            kk = k
            for d in (-1, +1):
                while True:
                    o = _shifted(tr.order, kk, d)
                    if o is None:
                        break
                    old = tr.order
                    tr.order = o
                    r = tr.residuals(theta, nuis[i])
                    c = r @ r
                    if c < best:
                        best = c
                        kk += d
                        moves += 1
                    else:
                        tr.order = old
                        break
        if verbose:
            print(f"    switches of {tr.name}: cost {0.5 * best:.6g}", flush=True)
    return moves


def fit(trials: list[OETrial], theta0, names=DERIVATIVES, n_jobs: int = 1, verbose: bool = False,
        max_nfev: int = 60, stages=None, max_rounds: int = 6, prefit_nuisance: bool = True, xtol: float = 1e-8,
        ftol: float = 1e-9) -> OEResult:
    """Joint output-error fit of the derivatives ``names`` (start ``theta0``) over ``trials``.

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
           stages=None):
    """EKF (joint over ``datas``) then the joint output-error fit. Returns (ekf_final dict, OEResult)."""
    from .estimate import initial_state, joint_estimate

    theta_start = initial_state(datas[0], cfg)[4:]
    ekf = None
    if start == "ekf":
        try:
            e = joint_estimate(datas, cfg) if len(datas) > 1 else __import__("ekf.estimate", fromlist=["estimate"]).estimate(datas[0], cfg)
            ekf = e.final
            theta_start = np.array([ekf[n] for n in DERIVATIVES])
        except FilterDivergence as exc:
            if verbose:
                print(f"  EKF diverged ({exc}); output error starts from the initial guess", flush=True)
    trials = [trial_from_data(d, rudder=rudder) for d in datas]
    res = fit(trials, theta_start, n_jobs=n_jobs, verbose=verbose, stages=stages)
    return ekf, res


class OEEstimate:
    """Duck-typed :class:`ekf.estimate.Estimate` for the reports (final, errors_pct, data, name)."""

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
        return {n: 100.0 * abs(self.final[n] - tv[n]) / abs(tv[n]) for n in DERIVATIVES}


# --------------------------------------------------------------------------- Monte Carlo


PAPER_TRIALS = ("ST35", "ZZ10", "ZZ20", "S-type 120")


def _mc_one(seed: int, trials, cfg, rudder: str) -> dict:
    from .estimate import data_from_trial
    from .reproduce import TRIALS
    from .estimate import REPO

    with tempfile.TemporaryDirectory(prefix="ekf-oe-") as td:
        datas = [data_from_trial(REPO / "configs" / "trials" / TRIALS[t], cfg, seed=seed,
                                 workdir=Path(td) / TRIALS[t].removesuffix(".yaml")) for t in trials]
        tv = datas[0].true_values
        try:
            ekf, res = refine(datas, cfg, rudder=rudder)
        except FilterDivergence as exc:
            return {"seed": seed, "diverged": str(exc)}
    row = {"seed": seed, "diverged": "", "seconds": res.seconds, "chi2_dof": res.chi2_per_dof, "nfev": res.nfev}
    for n in DERIVATIVES:
        row[f"ekf_{n}"] = 100.0 * abs(ekf[n] - tv[n]) / abs(tv[n]) if ekf else np.nan
        row[f"oe_{n}"] = 100.0 * abs(res.final[n] - tv[n]) / abs(tv[n])
        row[f"oe_signed_{n}"] = 100.0 * (res.final[n] - tv[n]) / abs(tv[n])
        row[f"se_{n}"] = 100.0 * res.std_errors[n] / abs(tv[n])
        row[f"final_{n}"] = res.final[n]
    return row


def _mc_task(task) -> dict:
    return _mc_one(*task)


def monte_carlo(out_dir, n_seeds: int = 20, trials=PAPER_TRIALS, n_jobs: int = 2, first_seed: int = 1000,
                config=None, rudder: str = "ramp", verbose: bool = True, ekf_summary=None, backend: str = "loky"):
    """Seeds x (joint EKF, then joint output error); writes runs.csv, summary.csv/.md; returns the summary."""
    import pandas as pd
    from trials.sweep import run_sweep

    from .estimate import load_config

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg = load_config(config)
    seeds = [first_seed + s for s in range(n_seeds)]
    t0 = time.perf_counter()
    rows = run_sweep(_mc_task, [(s, tuple(trials), cfg, rudder) for s in seeds], backend=backend,
                     n_jobs=n_jobs, progress=verbose, labels=[f"seed {s}" for s in seeds])
    runs = pd.DataFrame(rows)
    runs.to_csv(out / "runs.csv", index=False, float_format="%.6g")
    if verbose:
        print(f"  {len(seeds)} seeds in {time.perf_counter() - t0:.0f} s on {n_jobs} workers", flush=True)
    return summarise(out, trials, rudder, ekf_summary, verbose)


def summarise(out_dir, trials=PAPER_TRIALS, rudder: str = "ramp", ekf_summary=None, verbose: bool = True):
    """summary.csv/.md from ``OUT/runs.csv``: per derivative the joint EKF and output-error % errors
    (mean +- std over seeds), the OE signed bias and spread, the OE standard error from (J^T W J)^-1
    and the spread / standard-error ratio (about 1 when the fit is noise-limited), and, when an
    ``ekf.montecarlo`` summary.csv is given, the per-trial EKF's best trial beside them."""
    import pandas as pd

    out = Path(out_dir)
    runs = pd.read_csv(out / "runs.csv", dtype={"diverged": str})
    runs["diverged"] = runs["diverged"].fillna("")
    ok = runs[runs["diverged"] == ""]
    per_trial = None
    if ekf_summary is not None and Path(ekf_summary).exists():
        per_trial = pd.read_csv(ekf_summary)
    summ = []
    for n in DERIVATIVES:
        row = {"coeff": n}
        if per_trial is not None:
            g = per_trial[per_trial.coeff == n].sort_values("mean_err_pct")
            b = g.iloc[0]
            row.update(ekf1_trial=b.trial, ekf1_mean=b.mean_err_pct, ekf1_std=b.std_err_pct)
        row.update({"ekf_mean": ok[f"ekf_{n}"].mean(), "ekf_std": ok[f"ekf_{n}"].std(ddof=1),
                    "oe_mean": ok[f"oe_{n}"].mean(), "oe_std": ok[f"oe_{n}"].std(ddof=1),
                    "oe_bias": ok[f"oe_signed_{n}"].mean(), "oe_spread": ok[f"oe_signed_{n}"].std(ddof=1),
                    "crb_se": ok[f"se_{n}"].mean()})
        row["spread_over_se"] = row["oe_spread"] / row["crb_se"]
        row["within_5pct"] = bool(row["oe_mean"] < 5.0)
        summ.append(row)
    summary = pd.DataFrame(summ)
    summary.to_csv(out / "summary.csv", index=False, float_format="%.4g")
    label = " + ".join(trials)
    seeds = ok["seed"].astype(int)
    chi = ok["chi2_dof"].astype(float)
    lines = [f"Joint estimate over {label}; {len(ok)} of {len(runs)} seeds ({seeds.min()}-{seeds.max()}) at the "
             f"paper's log noise, full 3000 s trials, rudder: {rudder}. % error of the final value: mean +- std over seeds.",
             f"Output-error chi2/dof over seeds: {chi.min():.3f}-{chi.max():.3f} (median {chi.median():.3f}); "
             f"mean {ok['seconds'].astype(float).mean():.0f} s per OE fit.",
             "OE signed = mean +- std of the signed % error; OE std err = standard error from (J^T W J)^-1 "
             "(mean over seeds); spread/SE = std of the signed error over the standard error.",
             ""]
    head = "| coeff | "
    sep = "|---|"
    if per_trial is not None:
        head += "best single-trial EKF % | "
        sep += "---|"
    head += "joint EKF % | output error % | OE signed % | OE std err % | spread/SE | < 5 % |"
    sep += "---|---|---|---|---|---|"
    lines += [head, sep]
    for _, r in summary.iterrows():
        cell = f"| {r.coeff} | "
        if per_trial is not None:
            cell += f"{r.ekf1_mean:.2f} +- {r.ekf1_std:.2f} ({r.ekf1_trial}) | "
        cell += (f"{r.ekf_mean:.2f} +- {r.ekf_std:.2f} | {r.oe_mean:.3f} +- {r.oe_std:.3f} | "
                 f"{r.oe_bias:+.3f} +- {r.oe_spread:.3f} | {r.crb_se:.3f} | {r.spread_over_se:.2f} | "
                 f"{'yes' if r.within_5pct else 'no'} |")
        lines.append(cell)
    (out / "summary.md").write_text("\n".join(lines) + "\n")
    if verbose:
        print("\n".join(lines))
    return summary


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m ekf.output_error", description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="output folder")
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--first-seed", type=int, default=1000)
    ap.add_argument("--trials", nargs="+", default=list(PAPER_TRIALS), help="trial names (ST35 ZZ10 ZZ20 'S-type 120')")
    ap.add_argument("--rudder", choices=("ramp", "law", "reconstructed"), default="ramp")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--ekf-summary", default=None,
                    help="summary.csv of 'python -m ekf.montecarlo' (per-trial EKF) to show beside the table")
    ap.add_argument("--summarise-only", action="store_true", help="rewrite the table from OUT/runs.csv, no runs")
    a = ap.parse_args(argv)
    if a.summarise_only:
        summarise(a.out, tuple(a.trials), a.rudder, a.ekf_summary)
    else:
        monte_carlo(a.out, a.seeds, tuple(a.trials), n_jobs=a.jobs, first_seed=a.first_seed, rudder=a.rudder,
                    ekf_summary=a.ekf_summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
