"""Simulated zigzag of a Nomoto model with a trapezoidal rudder (Artyszuk's test set-up).

:func:`trapezoid_rudder` gives the piecewise-linear zigzag rudder and its exact
integral Delta(s') (eqs. 19-22); :func:`simulate_zigzag` integrates the model
adaptively piece by piece between the rudder's knots, locating the
counter-rudder and overshoot events exactly, and returns a
:class:`ZigzagSimulation` (which can also give the exact states at the four
points and convert itself to a :class:`~trials.files.records.TrialRecord`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np
from scipy.integrate import solve_ivp

from trials.analysis.nomoto.models import NomotoModel
from trials.analysis.nomoto.points import ZigzagPoints
from trials.files.records import TrialRecord

__all__ = ["trapezoid_knots", "trapezoid_rudder", "ZigzagSimulation", "simulate_zigzag"]


# ------------------------------------------------------------------ trapezoidal rudder
def trapezoid_knots(delta0: float, s_R: float, s_cr: Sequence[float]):
    """Knots (s', delta) of the piecewise-linear zigzag rudder.

    The rudder leaves midships at s' = 0 and reaches +delta0 at s'_R (eq. 19);
    at each counter-rudder s'_CRk it starts to move to the opposite side at the
    same rate, taking 2 s'_R.

    Parameters
    ----------
    delta0 : float
        Nominal rudder angle [rad] of the first execute (sign = side).
    s_R : float
        Rudder steering distance s'_R = delta0 / (ddelta/ds') [-], eq. (19).
    s_cr : sequence of float
        Counter-rudder abscissas s'_CR1, s'_CR2, ... [-], increasing.

    Returns
    -------
    ks, kd : ndarray
        Knot abscissas s' [-] and rudder angles [rad] there.
    """
    ks, kd = [0.0, s_R], [0.0, delta0]
    side = 1.0
    for s in s_cr:
        ks += [float(s), float(s) + 2.0 * s_R]
        kd += [side * delta0, -side * delta0]
        side = -side
    return np.asarray(ks), np.asarray(kd)


def trapezoid_rudder(s, delta0: float, s_R: float, s_cr: Sequence[float]):
    """Rudder angle and its integral Delta(s') for the trapezoidal zigzag rudder.

    Delta is integrated exactly over the piecewise-linear rudder; on the constant
    parts this reduces to Artyszuk's eqs. (20)-(22), e.g. for a 10 deg zigzag
    Delta(s'_R < s' <= s'_CR1) = pi/18 (s' - 0.5 s'_R).

    Parameters
    ----------
    s : array_like
        Dimensionless distances s' >= 0 [-].
    delta0, s_R, s_cr
        See :func:`trapezoid_knots`.

    Returns
    -------
    delta, Delta : ndarray
        Rudder [rad] and its integral [rad] at ``s``.
    """
    s = np.asarray(s, dtype=float)
    ks, kd = trapezoid_knots(delta0, s_R, s_cr)
    # extend the last value flat to infinity
    ks = np.append(ks, max(ks[-1], np.max(s, initial=0.0)) + 1.0)
    kd = np.append(kd, kd[-1])
    delta = np.interp(s, ks, kd)
    area = np.concatenate([[0.0], np.cumsum(0.5 * (kd[1:] + kd[:-1]) * np.diff(ks))])
    i = np.clip(np.searchsorted(ks, s, side="right") - 1, 0, len(ks) - 2)
    Delta = area[i] + 0.5 * (kd[i] + delta) * (s - ks[i])
    return delta, Delta


# ------------------------------------------------------------------ simulation
@dataclass(frozen=True)
class ZigzagSimulation:
    """A simulated zigzag in dimensionless distance.

    Attributes
    ----------
    model : NomotoModel
        The model simulated.
    s, psi, omega, eps, delta, Delta : ndarray
        s' [-], heading [rad], omega' [-], eps' [-], rudder [rad], rudder integral [rad].
    s_cr : tuple of float
        Counter-rudder abscissas (heading reached the check angle) [-].
    s_os : tuple of float
        Overshoot abscissas (omega' = 0 after each counter-rudder) [-].
    delta0, psi0, s_R : float
        Rudder angle [rad], check heading [rad], rudder steering distance [-].

    Notes
    -----
    :func:`simulate_zigzag` also attaches the integrator's pieces (dense
    output between rudder knots) as the private attribute ``_pieces``, from
    which :meth:`state_at` and :meth:`points` take exact states at any
    abscissa rather than values interpolated on the ``ds`` grid.
    """

    model: NomotoModel
    s: np.ndarray
    psi: np.ndarray
    omega: np.ndarray
    eps: np.ndarray
    delta: np.ndarray
    Delta: np.ndarray
    s_cr: tuple
    s_os: tuple
    delta0: float
    psi0: float
    s_R: float

    def state_at(self, s: float) -> dict:
        """State at one abscissa from the integrator's dense output (not the ``ds`` grid).

        Parameters
        ----------
        s : float
            Abscissa s' [-] inside the simulation.

        Returns
        -------
        dict
            Keys s, eps, omega, Delta, delta, psi.
        """
        return _exact_states(self, [s])[0]

    def points(self, n: int = 2) -> "ZigzagPoints":
        """The four-point abscissas CR1, OS1, CR2, OS2, ... (exact states), as :class:`ZigzagPoints`.

        Parameters
        ----------
        n : int
            Number of (counter-rudder, overshoot) pairs.
        """
        names, ss = [], []
        for k in range(n):
            names += [f"CR{k + 1}", f"OS{k + 1}"]
            ss += [self.s_cr[k], self.s_os[k]]
        rows = _exact_states(self, ss)
        return ZigzagPoints.from_rows(names, rows)

    def to_record(self, L: float = 100.0, U: float = 5.0, name: str = "nomoto-sim") -> TrialRecord:
        """The simulation as a :class:`TrialRecord` for a ship of length L [m] at speed U [m/s].

        Parameters
        ----------
        L : float
            Ship length [m]; t = s' L / U, r = omega' U / L.
        U : float
            Constant speed [m/s].
        name : str
            Record name.
        """
        t = self.s * L / U
        return TrialRecord(
            t=t, name=name, ship=self.model.name or "nomoto", source="simulation",
            psi=self.psi.copy(), r=self.omega * U / L, delta=self.delta.copy(),
            U=np.full_like(t, U), meta={"L": L, "model": self.model.to_dict()},
        )

    def to_pandas(self):
        """Time series as a DataFrame indexed by s'."""
        import pandas as pd

        return pd.DataFrame(
            {"psi": self.psi, "omega": self.omega, "eps": self.eps, "delta": self.delta, "Delta": self.Delta},
            index=pd.Index(self.s, name="s"),
        )

    def to_dict(self) -> dict:
        """Summary: model, zigzag settings and the characteristic abscissas."""
        return {"model": self.model.to_dict(), "delta0": self.delta0, "psi0": self.psi0, "s_R": self.s_R,
                "s_cr": list(self.s_cr), "s_os": list(self.s_os)}


def _rhs(model: NomotoModel):
    """Right-hand side f(s, y, delta, ddelta) with y = (psi, omega[, eps])."""
    K, T1, T2, T3 = model.K, model.T1, model.T2, model.T3
    if model.order == 1:
        return lambda s, y, d, dd: [y[1], (K * d - y[1]) / T1]
    a, b = T1 * T2, T1 + T2
    return lambda s, y, d, dd: [y[1], y[2], (K * (d + T3 * dd) - y[1] - b * y[2]) / a]


def _eps_of(model: NomotoModel, y, d):
    """eps' from the state (1st order: (K delta - omega')/T)."""
    if model.order == 1:
        return (model.K * d - y[1]) / model.T1
    return y[2]


def simulate_zigzag(model: NomotoModel, delta0_deg: float = 10.0, psi0_deg: Optional[float] = None,
                    rudder_rate_deg_per_L: float = 23.0, s_max: float = 14.0, ds: float = 0.001,
                    n_cr: int = 8, rtol: float = 1e-11, atol: float = 1e-13) -> ZigzagSimulation:
    """Simulate a delta0/psi0 zigzag with a trapezoidal rudder.

    At s' = 0 the ship runs straight (psi = omega' = eps' = 0) and the rudder
    starts to move to +delta0 at the given rate; whenever the heading reaches the
    check angle on the side the rudder points to, the rudder is reversed at the
    same rate (counter-rudder).  Integration is adaptive (``solve_ivp``, DOP853)
    piece by piece between the rudder's knots, with the heading events located
    exactly; the output is then sampled every ``ds``.

    Parameters
    ----------
    model : NomotoModel
        Model to simulate (first or second order).
    delta0_deg : float
        Rudder angle [deg], e.g. 10 for a 10/10 zigzag.
    psi0_deg : float, optional
        Check heading [deg]; defaults to ``delta0_deg``.
    rudder_rate_deg_per_L : float
        Rudder rate [deg per ship length travelled]; Artyszuk uses 23 deg/L.
    s_max : float
        Length of the run [-] (ship lengths).
    ds : float
        Output sampling step in s' [-]; the paper interpolates to 0.001.
    n_cr : int
        Maximum number of counter-rudders.
    rtol, atol : float
        Integrator tolerances.

    Returns
    -------
    ZigzagSimulation
        Sampled every ``ds`` up to ``s_max`` (or up to the counter-rudder after
        the ``n_cr``-th one), with the counter-rudder and overshoot abscissas.
    """
    if psi0_deg is None:
        psi0_deg = delta0_deg
    d0, p0 = np.radians(delta0_deg), np.radians(psi0_deg)
    s_R = delta0_deg / rudder_rate_deg_per_L
    rate = d0 / s_R
    run = _Pieces(_rhs(model), s_max, {"rtol": rtol, "atol": atol})
    y = np.zeros(2 if model.order == 1 else 3)
    s0, dstart, side = 0.0, 0.0, 1.0
    s_cr, s_os = [], []
    ramp_to = d0                 # ramp 0 -> +delta0 then hold; the loop alternates (ramp, hold)
    while s0 < s_max:
        y, s0, os_at = run.ramp(y, s0, dstart, ramp_to, rate, side)
        if s_cr and len(s_os) < len(s_cr) and os_at is not None:
            s_os.append(os_at)
        if s0 >= s_max:
            break
        y, s0, cr_at, os_at = run.hold(y, s0, ramp_to, side * p0, side)
        if s_cr and len(s_os) < len(s_cr) and os_at is not None:
            s_os.append(os_at)
        if cr_at is None or len(s_cr) >= n_cr:
            break
        s_cr.append(cr_at)
        dstart, ramp_to, side = ramp_to, -ramp_to, -side
    pieces = run.pieces
    s, out, dl = _sampled(pieces, s0, ds, len(y))
    eps = _eps_of(model, out, dl)
    delta, Delta = trapezoid_rudder(s, d0, s_R, s_cr)
    sim = ZigzagSimulation(model=model, s=s, psi=out[0], omega=out[1], eps=eps, delta=delta, Delta=Delta,
                           s_cr=tuple(s_cr), s_os=tuple(s_os), delta0=d0, psi0=p0, s_R=s_R)
    object.__setattr__(sim, "_pieces", pieces)
    return sim


def _overshoot_event(side: float):
    """The overshoot event of a zigzag piece: omega' changes sign towards the new ``side``."""
    ev = lambda s, yy: yy[1]                                              # noqa: E731
    ev.terminal, ev.direction = False, side
    return ev


class _Pieces:
    """The pieces of a zigzag integrated so far (``pieces``: (start, end, dense output, rudder at the start,
    rudder rate)), each by ``solve_ivp`` (DOP853, tolerances ``tol``) of the right-hand side ``f`` up to ``s_max``."""

    def __init__(self, f, s_max: float, tol: dict):
        self.f, self.s_max, self.tol, self.pieces = f, s_max, tol, []

    def ramp(self, y, s0: float, dstart: float, ramp_to: float, rate: float, side: float):
        """The rudder's ramp from ``dstart`` to ``ramp_to`` at ``rate``: (state, end abscissa, the overshoot's
        abscissa in it or None)."""
        f, dd = self.f, np.sign(ramp_to - dstart) * rate
        fun = (lambda dst, ddd, st: (lambda s, yy: f(s, yy, dst + ddd * (s - st), ddd)))(dstart, dd, s0)
        s1 = min(s0 + abs(ramp_to - dstart) / rate, self.s_max)
        sol = solve_ivp(fun, (s0, s1), y, method="DOP853", dense_output=True, events=_overshoot_event(side),
                        **self.tol)
        self.pieces.append((s0, s1, sol.sol, dstart, dd))
        return sol.y[:, -1], s1, float(sol.t_events[0][0]) if len(sol.t_events[0]) else None

    def hold(self, y, s0: float, hold: float, target: float, side: float):
        """The rudder held at ``hold`` until the heading reaches ``target`` (the counter-rudder; the overshoot
        is omega' = 0 on the way): (state, end abscissa, the counter-rudder's abscissa or None, the
        overshoot's or None)."""
        f = self.f
        ev_cr = (lambda tg: (lambda s, yy: yy[0] - tg))(target)
        ev_cr.terminal, ev_cr.direction = True, side
        fun = (lambda dh: (lambda s, yy: f(s, yy, dh, 0.0)))(hold)
        sol = solve_ivp(fun, (s0, self.s_max), y, method="DOP853", dense_output=True,
                        events=(ev_cr, _overshoot_event(side)), **self.tol)
        self.pieces.append((s0, sol.t[-1], sol.sol, hold, 0.0))
        first = lambda k: float(sol.t_events[k][0]) if len(sol.t_events[k]) else None     # noqa: E731
        return sol.y[:, -1], sol.t[-1], first(0), first(1)


def _sampled(pieces, s_end: float, ds: float, n_states: int):
    """(s every ``ds`` up to ``s_end``, the states there from the pieces' dense output, the rudder there)."""
    s = np.arange(0.0, s_end + 0.5 * ds, ds)
    s = s[s <= s_end + 1e-12]
    out = np.zeros((n_states, len(s)))
    dl = np.zeros(len(s))
    for (a, b, sol, dst, ddd) in pieces:
        m = (s >= a) & (s <= b)
        if m.any():
            out[:, m] = sol(s[m])
            dl[m] = dst + ddd * (s[m] - a)
    return s, out, dl


def _exact_states(sim: ZigzagSimulation, ss) -> list:
    """States at arbitrary abscissas from the simulation's dense output."""
    rows = []
    for s in ss:
        for (a, b, sol, dst, ddd) in sim._pieces:  # noqa: SLF001 - set by simulate_zigzag
            if a <= s <= b:
                y = sol(s)
                d = dst + ddd * (s - a)
                break
        else:
            raise ValueError(f"s'={s} outside the simulation")
        _, Delta = trapezoid_rudder([s], sim.delta0, sim.s_R, sim.s_cr)
        rows.append({"s": float(s), "eps": float(_eps_of(sim.model, y, d)), "omega": float(y[1]),
                     "Delta": float(Delta[0]), "delta": float(d), "psi": float(y[0])})
    return rows


