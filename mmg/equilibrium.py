"""Steady straight run: the rpm, trim rudder and drift that hold a given speed.

Rhee & Kim (1999) start every trial from 10 kn straight ahead with the rpm that
zeroes the surge equation (their n_0 = 54.12 rpm).  Y_0 and N_0 make delta = 0
non-straight, so we also solve the small trim rudder angle and sway velocity
that make Y = N = 0 with r = 0.  For a constant-power engine the delivered power
is P_0 = watts_per_hp * SHP_0(u_0) (eqs. 18-19); since no Esso Osaka K_Q(J) is
published, the K_Q curve is scaled so that the shaft is in torque balance at the
solved point (the fact sheet's recommendation), which makes the straight run a
true equilibrium of all eight states.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ._jit import interpreted
from .numdiff import central_jacobian
from .model import POLY_KQ, N_, PackedShip, forces, pack, polyval, rhs
from .ship import Ship


@dataclass(frozen=True)
class Equilibrium:
    """A steady straight run.

    u [m/s], v [m/s], delta [rad] (trim rudder), n [rps], engine power P_0 [W],
    K_Q_scale (factor applied to K_Q so the shaft balances; 1 for constant rpm),
    residual: max |du/dt|, |dv/dt|, |dr/dt|, |dn/dt| at the solution.
    """

    u: float
    v: float
    delta: float
    n: float
    power_W: float
    K_Q_scale: float
    residual: float

    def state(self) -> np.ndarray:
        """Initial state vector [u, v, r, x, y, psi, delta, n] at the origin heading north."""
        return np.array([self.u, self.v, 0.0, 0.0, 0.0, 0.0, self.delta, self.n])


def engine_power(ship: Ship, u0: float) -> float:
    """Constant engine power P_0 [W] = watts_per_hp * SHP_0(u0), eq. (18)-(19)."""
    return ship.engine.watts_per_hp * float(np.polyval(ship.engine.SHP_0[::-1], u0))


def model_functions():
    """(rhs, forces) as the straight-run solver calls them: :func:`mmg.model.rhs` and
    :func:`mmg.model.forces` run by the interpreter (:func:`mmg._jit.interpreted`).  The solver
    evaluates the model 30-60 times (a few ms interpreted); compiling the two functions would cost
    3 s of a cold cache's first simulation and does not pay for itself."""
    return interpreted(rhs), interpreted(forces)


def _accels(pk: PackedShip, u, v, delta, n):
    x = np.array([u, v, 0.0, 0.0, 0.0, 0.0, delta, n])
    out = np.zeros(8)
    model_functions()[0](x, float(delta), *pk.args(), out)
    return out


def _newton(fun, z0, tol: float = 1e-13, max_iter: int = 50) -> np.ndarray:
    """Newton's method with a central-difference Jacobian and step halving, for the few smooth
    unknowns of the straight run (rpm, sway, trim rudder); converges to rounding in a handful of
    steps.  (A small solver here instead of scipy.optimize.fsolve: ``import scipy.optimize`` costs
    more than a simulation.)

    Raises
    ------
    ValueError
        When it does not converge (no straight run at this speed).
    """
    z = np.asarray(z0, float).copy()
    f = np.asarray(fun(z), float)
    for _ in range(max_iter):
        if not np.all(np.isfinite(f)):
            break
        J = central_jacobian(fun, z, 1e-3, f)
        try:
            step = np.linalg.solve(J, -f)
        except np.linalg.LinAlgError:
            break
        lam, n0 = 1.0, np.linalg.norm(f)
        while lam > 1e-4:
            zn = z + lam * step
            fn = np.asarray(fun(zn), float)
            if np.all(np.isfinite(fn)) and np.linalg.norm(fn) <= n0:
                break
            lam *= 0.5
        z, f = zn, fn
        if np.all(np.abs(lam * step) <= tol * np.maximum(np.abs(z), 1e-3)) or np.linalg.norm(f) == 0.0:
            return z
    if np.all(np.isfinite(f)) and np.max(np.abs(f)) < 1e-10:
        return z
    raise ValueError("the straight-run equations did not converge (no steady straight run at this speed)")


def straight_run(ship: Ship, u0: float, n: float | None = None, trim: bool = True, effects=None) -> Equilibrium:
    """Solve the steady straight run at surge speed ``u0`` [m/s].

    Parameters
    ----------
    ship : Ship
    u0 : float
        Approach speed [m/s].
    n : float, optional
        Propeller revolutions [rps]; solved from the surge balance when None.
    trim : bool
        Solve the trim rudder and sway velocity that cancel Y_0, N_0 (else delta = v = 0).
    effects : mmg.effects.EffectSet, optional
        Effects in the packed ship (:meth:`mmg.effects.EffectSet.pack`): a rudder offset, shallow
        water, a steady wind (the approach is then the straight run in that wind at heading 0).
    """
    power = engine_power(ship, u0) if ship.engine.mode == "constant_power" else 0.0

    def pack_all(sh):
        pk = pack(sh, power)
        return pk if effects is None else effects.pack(pk, sh)

    pk = pack_all(ship)
    n_guess = n if n is not None else u0 / (0.6 * ship.propeller.D)

    def unpack(z):
        nn = z[0] if n is None else n
        vv, dd = (z[-2], z[-1]) if trim else (0.0, 0.0)
        return nn, vv, dd

    def resid(z):
        nn, vv, dd = unpack(z)
        a = _accels(pk, u0, vv, dd, nn)
        out = []
        if n is None:
            out.append(a[0])
        if trim:
            out += [a[1], a[2]]
        return out

    z0 = ([n_guess] if n is None else []) + ([0.0, 0.0] if trim else [])
    z = _newton(resid, z0) if z0 else []
    nn, vv, dd = unpack(z)
    scale = 1.0
    if ship.engine.mode == "constant_power":
        x = np.array([u0, vv, 0.0, 0.0, 0.0, 0.0, dd, nn])
        J = model_functions()[1](x, *pk.args())[3]
        kq = interpreted(polyval)(pk.poly, POLY_KQ, J)     # no specialisation compiled for one call
        D, rho = ship.propeller.D, ship.particulars.rho
        scale = power / (2 * np.pi * nn) / (rho * nn**2 * D**5 * kq)
        if not (np.isfinite(scale) and scale > 0):
            # K_Q(J) <= 0: the propeller is beyond zero torque (it would drive the shaft); a negative
            # scale would turn the shaft's load into a drive that runs n through zero
            raise ValueError(f"at {nn * 60:.4g} rpm and {u0:.4g} m/s the propeller's K_Q(J = {J:.3g}) is {kq:.3g}: "
                             "no constant-power straight run (the rpm is far below the one the speed needs)")
    pk2 = pack_all(with_kq_scale(ship, scale))
    a = _accels(pk2, u0, vv, dd, nn)
    res = float(np.max(np.abs(a[[0, 1, 2, N_]])))
    return Equilibrium(u=u0, v=float(vv), delta=float(dd), n=float(nn), power_W=power,
                       K_Q_scale=float(scale), residual=res)


def with_kq_scale(ship: Ship, scale: float) -> Ship:
    """The ship with its K_Q curve scaled (see module docstring)."""
    return replace(ship, propeller=replace(ship.propeller, K_Q_scale=scale))
