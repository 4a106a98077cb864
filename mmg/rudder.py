"""Rudder laws of the trials, defined once: the heading-switch law and its reconstruction.

:func:`switch_side` is the heading-switch law of zigzag and S-type trials (the rudder
side reverses when the heading change reaches the upper switch level and back when it
falls to the lower one).  The compiled simulator (:func:`mmg.integrate.simulate_kernel`)
runs it on the simulated heading; :func:`reconstruct_rudder` runs it on a *recorded*
heading to rebuild the rudder of a log that has no rudder channel (Rhee & Kim's sea-trial
log: time, position, heading, speed, rpm), passing the order through the steering gear
(:func:`mmg.model.steering_rate`, eq. 20).  The estimators' preprocessing, the raw-log
EKF, the output-error fit and the Nomoto analysis all rebuild rudders through it, and
:func:`movement_starts` is the one segmentation of a rudder history into movements.
"""
from __future__ import annotations

import numpy as np
from ._jit import njit

from .model import steering_rate
from .rk4 import rk4_step


@njit(cache=True, error_model="numpy")
def switch_side(side, dpsi, hi, lo):
    """The heading-switch law: the rudder side (+1 starboard, -1 port) after seeing heading change ``dpsi``.

    Starboard rudder reverses to port once the heading change reaches ``hi``; port rudder
    reverses to starboard once it falls to ``lo`` [rad].  Zigzag: hi = -lo = the switching
    heading; S-type: (hi, lo) = (psi_S, 0) starting to starboard, (0, -psi_S) to port.
    """
    if side > 0.0 and dpsi >= hi:
        return -1.0
    if side < 0.0 and dpsi <= lo:
        return 1.0
    return side


def switch_levels(kind: str, manoeuvre: dict) -> tuple[float, float, float]:
    """(first side, hi, lo) of the heading-switch law of a ``zigzag`` or ``stype`` manoeuvre (SI)."""
    side = 1.0 if manoeuvre.get("first", "starboard") == "starboard" else -1.0
    if kind == "zigzag":
        return side, float(manoeuvre["heading"]), -float(manoeuvre["heading"])
    if kind == "stype":
        h = float(manoeuvre["switch_heading"])
        return (side, h, 0.0) if side > 0 else (side, 0.0, -h)
    raise ValueError(f"a {kind!r} trial has no heading-switch law")


@njit(cache=True)
def _steer(t, psi, law, amp, hi, lo, first, delta0, p, out_order, out_delta):
    """Rudder order by the trial's law and the rudder through the steering gear (:func:`mmg.rk4.rk4_step` per sample)."""
    side = first
    d = delta0
    psi0 = psi[0]
    for k in range(t.shape[0]):
        if law == 0:
            cmd = amp
        else:
            side = switch_side(side, psi[k] - psi0, hi, lo)
            cmd = side * amp
        out_order[k] = cmd
        out_delta[k] = d
        if k + 1 < t.shape[0]:
            d = rk4_step(_gear_rhs, _axpy1, _ZERO1, (d,), t[k + 1] - t[k], (cmd, p))[0]


@njit(cache=True, error_model="numpy", inline="always")
def _gear_rhs(y, tau, args):
    """The steering gear's right-hand side for :func:`mmg.rk4.rk4_step`: the rudder rate at the order held
    over the step (``args`` = (order, p))."""
    return (steering_rate(args[0], y[0], args[1]),)


@njit(cache=True, error_model="numpy", inline="always")
def _axpy1(a, c, b):
    """a + c b of two 1-tuples (the rudder angle and its rate)."""
    return (a[0] + c * b[0],)


_ZERO1 = (0.0,)


def reconstruct_rudder(t, psi, kind: str, manoeuvre: dict, p: np.ndarray, delta0: float = 0.0):
    """Rudder order and angle [rad] at times ``t`` from the trial's logic and a heading series.

    kind : "turning" (constant order ``rudder``), "zigzag" (``rudder``, ``heading``, ``first``)
    or "stype" (``rudder``, ``switch_heading``, ``first``); angles in rad. ``p`` is a packed
    parameter vector holding at least the steering gear constants. ``delta0`` is the rudder at t[0].
    """
    amp = float(manoeuvre["rudder"])
    if kind == "turning":
        law, side, hi, lo = 0, 1.0, 0.0, 0.0
    elif kind in ("zigzag", "stype"):
        law = 1
        side, hi, lo = switch_levels(kind, manoeuvre)
    else:
        raise ValueError(f"cannot reconstruct the rudder of a {kind!r} trial")
    order = np.empty(len(t))
    delta = np.empty(len(t))
    _steer(np.asarray(t, float), np.asarray(psi, float), law, amp, hi, lo, side, float(delta0),
           np.asarray(p, float), order, delta)
    return order, delta


REBUILT_KINDS = ("turning", "zigzag", "stype")   # trial kinds whose rudder is rebuilt from their logic
MOVEMENT_LEAD_S = 1.0   # a rudder movement is taken to start this long [s] before its order change


def movement_starts(order: np.ndarray, dt: float, lead: float = MOVEMENT_LEAD_S) -> np.ndarray:
    """Steps (int64, increasing) at which rudder movements start: step 0, and ``lead`` [s] before
    each change of the rudder ``order`` sampled every ``dt`` [s] (at least step 1).

    The one segmentation of the raw-log EKF's per-movement timing offset
    (:mod:`ekf.log_filter`) and of the matching Cramer-Rao bound (:mod:`trials.planning.fisher`).
    """
    sw = np.nonzero(np.diff(np.asarray(order, float)) != 0)[0] + 1
    return np.unique(np.r_[0, np.maximum(sw - int(round(lead / dt)), 1)]).astype(np.int64)


def movements(order: np.ndarray, dt: float, lead: float = MOVEMENT_LEAD_S) -> np.ndarray:
    """Rudder-movement index (int64, from 0) of every step: see :func:`movement_starts`."""
    seg = np.zeros(len(order), dtype=np.int64)
    seg[movement_starts(order, dt, lead)[1:]] = 1
    return np.cumsum(seg)


def reversal_times(t: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """Times [s] at which the rudder angle ``delta`` crosses zero (linear between samples)."""
    t, d = np.asarray(t, float), np.asarray(delta, float)
    k = np.nonzero(np.diff(np.sign(d)) != 0)[0]
    return t[k] - d[k] * (t[k + 1] - t[k]) / (d[k + 1] - d[k])


def reversal_timing_errors(t: np.ndarray, rebuilt: np.ndarray, t_true: np.ndarray, true: np.ndarray) -> np.ndarray:
    """Rebuilt minus true reversal time [s] of every reversal of the true rudder (``true`` at
    ``t_true``), paired with the nearest reversal of the ``rebuilt`` rudder (at ``t``)."""
    tr, rb = reversal_times(t_true, true), reversal_times(t, rebuilt)
    if len(tr) == 0 or len(rb) == 0:
        return np.empty(0)
    return np.array([rb[np.argmin(np.abs(rb - x))] - x for x in tr])


