"""Does the model create energy?  The power balance of the ship with its propeller stopped.

With the propeller stopped (n = 0), the rudder amidships and no wind or other external load, the
water can only take energy from the ship: the rate of change of its kinetic energy (rigid body and
added mass, about midship)::

    T = 1/2 nu^T M nu,   nu = (u, v, r),
    M = [[m + m_x, 0, 0], [0, m + m_y, x_G m], [0, x_G m, I_zG + x_G^2 m + J_z]]
    dT/dt = nu^T M dnu/dt = u X + v Y + r N + (m_y - m_x) u v r

must not be positive at any state (X, Y, N the total forces of :func:`mmg.model.forces`; the last
term is the work of the added-mass (Munk) coupling, which the MMG equations of
:func:`mmg.model.rhs` carry on their left side).  A model whose hull polynomial gives dT/dt > 0
somewhere in the range a record visits can feed its own motion there, and an open-loop replay that
enters that region runs away: this is the check ``mmg identify`` makes of a fitted ship over the
states its training records visit (:func:`trials.measured.physical.physical_check`).

:func:`unpowered_power` computes dT/dt from the model's own right-hand side (the one definition of
the forces); :func:`hull_term_power` splits the hull's part by coefficient, so a failing state names
the coefficients that feed the motion there (:func:`power_check`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .model import (P_IZ, P_JZ, P_L, P_M, P_MX, P_MY, P_RHO, P_T, P_ULOW, P_XG, R_, U_, V_,
                    hull_regressors, pack, rhs)

__all__ = ["PowerCheck", "unpowered_power", "hull_term_power", "power_check", "power_scale", "state_box",
           "relative_power", "gains_no_energy"]

POWER_TOLERANCE = 1e-4
"""A state fails when dT/dt exceeds this fraction of :func:`power_scale` (rounding of the force
evaluation is some 1e-12 of it; the straight-run resistance of the Esso Osaka is -8e-3)."""


def _packed(ship_or_packed):
    return ship_or_packed if hasattr(ship_or_packed, "args") else pack(ship_or_packed)


def _states(u, v, r):
    u, v, r = np.broadcast_arrays(*(np.asarray(a, float) for a in (u, v, r)))
    return u.ravel(), v.ravel(), r.ravel(), u.shape


def mass_matrix(p: np.ndarray) -> np.ndarray:
    """The 3 x 3 mass matrix (rigid body plus added mass, about midship) [kg, kg m, kg m^2] of a
    packed parameter vector ``p``."""
    m, xg = p[P_M], p[P_XG]
    return np.array([[m + p[P_MX], 0.0, 0.0], [0.0, m + p[P_MY], xg * m],
                     [0.0, xg * m, p[P_IZ] + xg * xg * m + p[P_JZ]]])


def unpowered_power(ship_or_packed, u, v, r) -> np.ndarray:
    """dT/dt [W] with the propeller stopped and the rudder amidships at the states u, v [m/s],
    r [rad/s] (arrays broadcast together): nu^T M dnu/dt of :func:`mmg.model.rhs`."""
    pk = _packed(ship_or_packed)
    uu, vv, rr, shape = _states(u, v, r)
    x, out = np.zeros(8), np.zeros(8)
    acc = np.empty((uu.size, 3))
    for i in range(uu.size):             # propeller stopped, rudder amidships: x[DELTA_] = x[N_] = 0
        x[U_], x[V_], x[R_] = uu[i], vv[i], rr[i]
        rhs(x, 0.0, *pk.args(), out)
        acc[i] = out[:3]
    nu = np.column_stack([uu, vv, rr])
    P = np.einsum("ij,jk,ik->i", nu, mass_matrix(pk.p), acc)
    return P.reshape(shape)


def power_scale(ship_or_packed, u, v, r) -> np.ndarray:
    """1/2 rho L T U_t^3 [W], U_t^2 = u^2 + v^2 + (r L / 2)^2: the scale dT/dt is judged against
    (the hull's own force scale times a speed that does not vanish in a pure yaw)."""
    p = _packed(ship_or_packed).p
    ut2 = np.asarray(u, float) ** 2 + np.asarray(v, float) ** 2 + (np.asarray(r, float) * p[P_L] / 2.0) ** 2
    return 0.5 * p[P_RHO] * p[P_L] * p[P_T] * ut2 ** 1.5


def hull_term_power(ship, u: float, v: float, r: float, packed=None) -> dict:
    """{hull coefficient name: its share of dT/dt [W]} at one state: the coefficient's value times
    its regressor's power u dX + v dY + r dN (:func:`mmg.model.hull_regressors`); ``packed``: the
    ship already packed (:func:`mmg.model.pack`)."""
    pk = packed or pack(ship)
    names = list(ship.hull.names)
    idx = np.arange(len(names), dtype=np.int64)
    x = np.zeros(8)
    x[U_], x[V_], x[R_] = u, v, r
    reg = np.zeros((3, len(names)))
    hull_regressors(x, pk.p, pk.hull_axis, pk.hull_term, idx, reg)
    share = pk.hull_coef * (u * reg[0] + v * reg[1] + r * reg[2])
    return dict(zip(names, (float(s) for s in share)))


@dataclass(frozen=True)
class PowerCheck:
    """The power balance of a ship over a set of states (:func:`power_check`).

    Attributes
    ----------
    passes : bool
        No state where the unpowered ship gains energy (beyond :data:`POWER_TOLERANCE`).
    worst : float
        The largest dT/dt over :func:`power_scale` found (negative: every state dissipates).
    state : tuple of float
        (u [m/s], v [m/s], r [rad/s]) of that state.
    n_states, n_failing : int
        States checked, and those that gain energy.
    feeding : dict
        At the worst state of a failing check: the hull coefficients whose share of dT/dt is
        positive, largest first [W]; empty when it passes.
    """

    passes: bool
    worst: float
    state: tuple
    n_states: int
    n_failing: int
    feeding: dict

    def describe(self) -> str:
        """One line: passes, or where it fails and what feeds it."""
        u, v, r = self.state
        if self.passes:
            return f"dissipative at all {self.n_states} states (worst dT/dt {self.worst:.3g} of 1/2 rho L T U^3)"
        names = ", ".join(f"{k} ({w:+.3g} W)" for k, w in list(self.feeding.items())[:3])
        return (f"gains energy unpowered at {self.n_failing} of {self.n_states} states; worst dT/dt "
                f"{self.worst:+.3g} of 1/2 rho L T U^3 at u {u:.3g} m/s, v {v:.3g} m/s, r {np.degrees(r):.3g} deg/s; "
                f"fed by {names or 'no single hull term'}")

    def to_dict(self) -> dict:
        return {"passes": self.passes, "worst": self.worst, "state": {"u_mps": self.state[0], "v_mps": self.state[1],
                "r_radps": self.state[2]}, "n_states": self.n_states, "n_failing": self.n_failing,
                "feeding_W": self.feeding}


def relative_power(ship_or_packed, u, v, r) -> tuple[np.ndarray, np.ndarray]:
    """(dT/dt over :func:`power_scale` [-], judged) at the states u, v [m/s], r [rad/s] (flattened):
    the unpowered power relative to its scale at every state, and whether the state is judged (its scale
    above the hull's low-speed floor, :func:`power_check`; below it the ratio is that of vanishing forces).

    Parameters
    ----------
    ship_or_packed : Ship or PackedShip
    u, v, r : array_like
        States (broadcast together) [m/s, m/s, rad/s].

    Returns
    -------
    rel : ndarray
        dT/dt / (1/2 rho L T U_t^3) at each state (NaN at rest).
    judged : ndarray of bool
        True where the state's scale is above the low-speed floor.
    """
    pk = _packed(ship_or_packed)
    uu, vv, rr, _ = _states(u, v, r)
    sc = power_scale(pk, uu, vv, rr)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = unpowered_power(pk, uu, vv, rr) / sc
    return rel, sc > power_scale(pk, pk.p[P_ULOW], 0.0, 0.0)


def gains_no_energy(ship_or_packed, u, v, r, tol: float = POWER_TOLERANCE) -> bool:
    """Whether the ship gains no energy unpowered at any judged state of u, v [m/s], r [rad/s]:
    :attr:`PowerCheck.passes` of :func:`power_check` without its diagnosis of the worst state (for
    checking many ships over one grid)."""
    rel, judged = relative_power(ship_or_packed, u, v, r)
    return not bool(np.any(judged & (rel > tol)))


def power_check(ship, u, v, r, tol: float = POWER_TOLERANCE) -> PowerCheck:
    """:class:`PowerCheck` of ``ship`` at the states u, v [m/s], r [rad/s] (arrays broadcast
    together).  States whose U_t (:func:`power_scale`) is below the hull's low-speed floor
    (:data:`mmg.model.LOW_SPEED_FROUDE` sqrt(g L)) are skipped: there the forces are a few
    microwatts' worth, and a term such as Y_0 (a propeller-induced side force the model keeps at any
    speed) outweighs a vanishing scale without feeding any motion."""
    uu, vv, rr, _ = _states(u, v, r)
    pk = pack(ship)
    rel, ok = relative_power(pk, uu, vv, rr)
    uu, vv, rr, rel = uu[ok], vv[ok], rr[ok], rel[ok]
    i = int(np.argmax(rel))
    bad = int(np.sum(rel > tol))
    feeding = {}
    if bad:
        share = hull_term_power(ship, uu[i], vv[i], rr[i], pk)
        feeding = dict(sorted(((k, w) for k, w in share.items() if w > 0), key=lambda kv: -kv[1]))
    return PowerCheck(bad == 0, float(rel[i]), (float(uu[i]), float(vv[i]), float(rr[i])), int(rel.size), bad, feeding)


def state_box(u, v, r, n: int = 9) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An n x n x n grid (flattened) spanning the range of the states u, v [m/s], r [rad/s] given
    (e.g. every state a set of records logs): the box a model is checked over."""
    axes = [np.linspace(np.nanmin(a), np.nanmax(a), n) for a in (u, v, r)]
    g = np.meshgrid(*axes, indexing="ij")
    return tuple(a.ravel() for a in g)
