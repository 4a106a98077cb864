"""Open-loop replay: the MMG model driven by a record's own rudder and propeller history.

The steering gear and the engine are bypassed: the rudder angle delta(t) [rad] and the propeller
revolutions n(t) [rps] are prescribed, linear between samples, and so are any external forces
(wind, from the measured relative wind, :mod:`mmg.wind`), given as (X, Y, N) [N, N, N m] about
midship at the samples.  The state is the rigid-body part of :data:`mmg.model.STATE_NAMES`,

    s = [u, v, r, x0, y0, psi]

and the right-hand side is :func:`mmg.model.forces_of`, :func:`mmg.model.accelerations_of` and
:func:`mmg.model.track_of` (the one physics of the simulator, the estimators and the workflow).  Between two samples the step is
split into equal RK4 sub-steps no longer than ``dt_max``, each the simulator's own step
(:func:`mmg.kernel.rk4_step`: one integrator for both), and a steady true wind acts through the
simulator's branch (:func:`mmg.model.with_steady_wind`).

With ``reset`` the state is set back to the measured one at the flagged samples: the prediction
of each segment then starts from the record (segment-wise output error, multiple shooting).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from ._jit import carray, njit
from .kernel import rk4_step

from .model import P_L, PackedShip, accelerations_of, forces_of, inverse_mass, track_of, with_steady_wind

__all__ = ["ReplayInputs", "replay", "replay_states", "default_dt_max", "STATE", "deriv", "replay_rhs", "axpy6",
           "ZERO6"]

STATE = ("u", "v", "r", "x", "y", "psi")
"""Replayed state, in this order: u, v [m/s], r [rad/s], x0, y0 [m] (north, east), psi [rad]."""


@dataclass(frozen=True)
class ReplayInputs:
    """What drives a replay, at the record's sample times.

    Parameters
    ----------
    t : ndarray (N,)
        Sample times [s], strictly increasing.
    delta : ndarray (N,)
        Rudder angle [rad], positive to starboard.
    n : ndarray (N,)
        Propeller revolutions [rps].
    ext : ndarray (N, 3), optional
        External force and moment (X, Y, N) [N, N, N m] about midship, ship axes (wind); zeros
        when ``None``.
    """

    t: np.ndarray
    delta: np.ndarray
    n: np.ndarray
    ext: np.ndarray | None = None

    def external(self) -> np.ndarray:
        """(N, 3) external forces [N, N, N m] (zeros when there are none)."""
        if self.ext is None:
            return np.zeros((len(self.t), 3))
        return np.ascontiguousarray(self.ext, dtype=float)


def default_dt_max(L: float) -> float:
    """Longest RK4 sub-step [s] for a ship of length L [m]: 0.1 sqrt(L / g) (0.58 s at 325 m,
    0.055 s for a 3 m model), a fiftieth of the yaw time scale of a slow manoeuvre."""
    return 0.1 * float(np.sqrt(L / 9.80665))


@njit(cache=True, error_model="numpy", inline="always")
def deriv(s, d, n, fx, fy, fn, minv, p, poly, hull_axis, hull_term, hull_coef):
    """d/dt of the replayed state with the rudder, revolutions and external loads prescribed.

    Parameters
    ----------
    s : tuple of 6 float
        The state (:data:`STATE`).
    d, n : float
        Rudder angle [rad] and propeller revolutions [rps].
    fx, fy, fn : float
        External surge, sway force [N] and yaw moment [N m] about midship, ship axes.
    minv : ndarray (9,)
        The inverse mass matrix of the rigid body and added masses (:func:`mmg.model.inverse_mass`), row-major.
    p, poly, hull_axis, hull_term, hull_coef
        The packed ship (:meth:`mmg.model.PackedShip.args`).

    Returns
    -------
    tuple of 6 float
        du/dt, dv/dt [m/s^2], dr/dt [rad/s^2], dx0/dt, dy0/dt [m/s], dpsi/dt [rad/s].
    """
    u, v, r, psi = s[0], s[1], s[2], s[5]
    X, Y, N, _ = forces_of(u, v, r, d, n, p, poly, hull_axis, hull_term, hull_coef)
    du, dv, dr = accelerations_of(X, Y, N, u, v, r, p)
    dx, dy, dpsi = track_of(u, v, r, psi, p)
    fx, fy, fn = with_steady_wind(fx, fy, fn, u, v, psi, p)     # the simulator's steady-wind branch
    return (du + minv[0] * fx + minv[1] * fy + minv[2] * fn,
            dv + minv[3] * fx + minv[4] * fy + minv[5] * fn,
            dr + minv[6] * fx + minv[7] * fy + minv[8] * fn, dx, dy, dpsi)


@njit(cache=True, error_model="numpy", inline="always")
def axpy6(a, c, b):
    """a + c b of two 6-tuples (the state and a stage derivative), as a tuple."""
    return (a[0] + c * b[0], a[1] + c * b[1], a[2] + c * b[2], a[3] + c * b[3], a[4] + c * b[4],
            a[5] + c * b[5])


ZERO6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@njit(cache=True, error_model="numpy", inline="always")
def replay_rhs(y, tau, args):
    """The replay's right-hand side for :func:`mmg.kernel.rk4_step`: :func:`deriv` with the inputs
    linear in the sample interval, at the fraction (k + tau) / m of it (sub-step k of m).

    Parameters
    ----------
    y : tuple of 6 float
        The stage state (:data:`STATE`).
    tau : float
        The stage's fraction of the sub-step (0, 1/2 or 1).
    args : tuple
        (k, m, i, delta, n, ext, minv, p, poly, hull_axis, hull_term, hull_coef): sub-step k of m in the
        interval from sample i, the record's rudder [rad], revolutions [rps] and external loads (N, 3) at
        its samples, then :func:`deriv`'s ``minv`` and packed ship.

    Returns
    -------
    tuple of 6 float
        :func:`deriv` at that instant.
    """
    k, m, i, delta, n, ext, minv, p, poly, hull_axis, hull_term, hull_coef = args
    a = (k + tau) / m
    d = delta[i] + a * (delta[i + 1] - delta[i])
    nn = n[i] + a * (n[i + 1] - n[i])
    fx = ext[i, 0] + a * (ext[i + 1, 0] - ext[i, 0])
    fy = ext[i, 1] + a * (ext[i + 1, 1] - ext[i, 1])
    fn = ext[i, 2] + a * (ext[i + 1, 2] - ext[i, 2])
    return deriv(y, d, nn, fx, fy, fn, minv, p, poly, hull_axis, hull_term, hull_coef)


@njit(cache=True, error_model="numpy", nogil=True, _nrt=False)
def _replay(t, delta, n, ext, s0, meas, reset, dt_max, minv, p, poly, hull_axis, hull_term, hull_coef, out):
    """RK4 of the dynamics along a record: sub-steps of at most ``dt_max`` between samples, inputs linear
    within a sample interval, the state reset to ``meas`` where ``reset``; fills ``out`` (N, 6), returns the
    number of valid rows."""
    N = t.shape[0]
    # the state as a 6-tuple of scalars (kept in registers across the stages)
    s = (s0[0], s0[1], s0[2], s0[3], s0[4], s0[5])
    for j in range(6):
        out[0, j] = s[j]
    for i in range(N - 1):
        if reset[i]:
            s = (meas[i, 0], meas[i, 1], meas[i, 2], meas[i, 3], meas[i, 4], meas[i, 5])
        h = t[i + 1] - t[i]
        m = int(np.ceil(h / dt_max - 1e-9))
        if m < 1:
            m = 1
        dt = h / m
        for k in range(m):                       # the simulator's RK4 step (one inlined copy of the model)
            s = rk4_step(replay_rhs, axpy6, ZERO6, s, dt,
                         (k, m, i, delta, n, ext, minv, p, poly, hull_axis, hull_term, hull_coef))
        ok = True
        for j in range(6):
            if not np.isfinite(s[j]):
                ok = False
        if not ok:
            for ii in range(i + 1, N):
                for j in range(6):
                    out[ii, j] = np.nan
            return i + 1
        for j in range(6):
            out[i + 1, j] = s[j]
    return N




def replay_states(packed: PackedShip, inputs: ReplayInputs, s0, *, meas=None, reset=None,
                  dt_max: float | None = None) -> np.ndarray:
    """The replayed states (N, 6) of :data:`STATE` at the sample times (NaN after a divergence).

    Parameters
    ----------
    packed : PackedShip
        The ship (:func:`mmg.model.pack`); its hull coefficients may be any candidate's.
    inputs : ReplayInputs
        Prescribed rudder, revolutions and external forces.
    s0 : array_like (6,)
        Initial state (u, v, r, x0, y0, psi).
    meas : ndarray (N, 6), optional
        Measured states, the state is set to at the samples flagged in ``reset``.
    reset : ndarray of bool (N,), optional
        Samples at which the replay restarts from ``meas`` (segments); none when omitted.
    dt_max : float, optional
        Longest RK4 sub-step [s]; :func:`default_dt_max` of the ship when omitted.
    """
    t = np.ascontiguousarray(inputs.t, dtype=float)
    N = len(t)
    if dt_max is None:
        dt_max = default_dt_max(float(packed.p[P_L]))
    if reset is None:
        reset = np.zeros(N, dtype=np.bool_)
        meas = np.zeros((1, 6))
    elif meas is None:
        raise ValueError("reset needs the measured states meas")
    out = np.empty((N, 6))
    minv = np.array(inverse_mass(packed.p, np.zeros(8)))
    # carray: read-only inputs (pandas columns) would compile a second specialisation of the replay
    _replay(carray(t), carray(inputs.delta), carray(inputs.n), carray(inputs.external()), carray(s0),
            carray(meas), carray(reset, np.bool_), float(dt_max), minv, *(carray(a, a.dtype) for a in packed.args()), out)
    return out


def replay(packed: PackedShip, inputs: ReplayInputs, s0, dt_max: float | None = None) -> np.ndarray:
    """Open-loop replay from s0 over the whole record: :func:`replay_states` without resets."""
    return replay_states(packed, inputs, s0, dt_max=dt_max)
