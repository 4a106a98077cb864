"""One trial of the output-error fit: its start, its rudder command and its simulated residuals."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mmg.integrate import CommandLaw, integrate
from mmg.model import DELTA_, N_, P_RATE, P_TE, PSI_, R_, U_, V_, X_, Y_, PackedShip
from mmg.rudder import reconstruct_rudder, switch_levels

CH = ("psi", "x", "y", "n")
"""Residual channels, in the order of :data:`ekf.data.LOG_CHANNELS`."""
NNUIS = 4  # v0, psi0, x0, y0 per trial
FD_STEP = 1e-7  # forward-difference step, relative to each coefficient's magnitude


def switch_steps(order: np.ndarray) -> np.ndarray:
    """Steps at which a rudder order changes."""
    return np.nonzero(np.diff(order) != 0)[0] + 1


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
    """An :class:`OETrial` from a :class:`ekf.data.TrialData` (its raw log record and :class:`~ekf.data.RecordInfo`).

    rudder: "ramp" (default; zigzag/S-type reversal times as continuous nuisance parameters,
    started where the recovered heading reaches the switching heading), "law" (closed-loop heading
    switch on the simulated heading) or "reconstructed" (the rebuilt order, whole-step switches).
    Turning trials use their constant order in every mode.
    """
    rec = data.record
    if rec is None:
        raise ValueError(f"{data.name}: the output-error fit needs the raw log record")
    info = data.info
    sigma = info.sigma()
    dt = float(data.meas.t[1] - data.meas.t[0])
    t = np.asarray(rec.t, float) - float(rec.t[0])
    dur = float(t[-1]) if duration is None else min(float(duration), float(t[-1]))
    keep = t <= dur + 1e-9
    obs = np.column_stack([rec.psi, rec.x, rec.y, rec.n])[keep]
    trim = float(info.trim_rudder)
    u0 = float(info.approach_speed) if info.approach_speed is not None else float(rec.U[0])
    n0 = float(info.approach_rpm) if info.approach_rpm is not None else float(rec.n[0])
    x0 = np.zeros(8)
    x0[U_], x0[V_], x0[R_], x0[DELTA_], x0[N_] = u0, 0.0, 0.0, trim, n0
    x0[PSI_], x0[X_], x0[Y_] = obs[0, 0], obs[0, 1], obs[0, 2]
    kind, man = info.kind, info.manoeuvre
    if rudder == "ramp" and kind != "turning":
        order, _ = reconstruct_rudder(data.meas.t, data.meas.psi, kind, man, data.packed.p, trim)
        sw = switch_steps(order)
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
        if kind == "turning":
            te = float(info.execute)
            if te > 0:
                law = CommandLaw.schedule([0.0, te, te + 1e-9, dur + 1.0], [trim, trim, man["rudder"], man["rudder"]])
            else:
                law = CommandLaw.schedule([0.0, dur + 1.0], [man["rudder"], man["rudder"]])
        else:
            side, hi, lo = switch_levels(kind, man)
            law = CommandLaw.heading_switch(man["rudder"], hi, lo, side, psi0=x0[PSI_])
    else:
        raise ValueError(f"rudder must be 'ramp', 'law' or 'reconstructed', not {rudder!r}")
    return OETrial(data.name, data.packed, np.asarray(data.slots), t[keep], obs, sigma, x0, law, dur, dt)


