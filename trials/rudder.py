"""Rebuilding the rudder of a trial from its logic when a log does not record it.

Rhee & Kim's sea-trial log (time, position, heading, speed, rpm) has no rudder
channel; the rudder is rebuilt from the trial's logic: a constant order for a
turning test, the heading-switch law for zigzag and S-type trials driven by the
*recorded* heading, passed through the steering gear (:func:`mmg.model.steering_rate`,
eq. 20).  Used by the estimator's preprocessing and by the Nomoto analysis.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
from numba import njit

from mmg.errors import InputError
from mmg.model import N_PARAMS, P_DMAX, P_RATE, P_TE, steering_rate
from mmg.units import DEG

from .records import TrialRecord


@njit(cache=True)
def _steer(t, psi, law, amp, hi, lo, first, delta0, p, out_order, out_delta):
    """Rudder order by the trial's law and the rudder through the steering gear (RK4 per sample)."""
    side = first
    d = delta0
    psi0 = psi[0]
    for k in range(t.shape[0]):
        if law == 0:
            cmd = amp
        else:
            dpsi = psi[k] - psi0
            if side > 0.0 and dpsi >= hi:
                side = -1.0
            elif side < 0.0 and dpsi <= lo:
                side = 1.0
            cmd = side * amp
        out_order[k] = cmd
        out_delta[k] = d
        if k + 1 < t.shape[0]:
            h = t[k + 1] - t[k]
            k1 = steering_rate(cmd, d, p)
            k2 = steering_rate(cmd, d + 0.5 * h * k1, p)
            k3 = steering_rate(cmd, d + 0.5 * h * k2, p)
            k4 = steering_rate(cmd, d + h * k3, p)
            d = d + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def reconstruct_rudder(t, psi, kind: str, manoeuvre: dict, p: np.ndarray, delta0: float = 0.0):
    """Rudder order and angle [rad] at times ``t`` from the trial's logic and a heading series.

    kind : "turning" (constant order ``rudder``), "zigzag" (``rudder``, ``heading``, ``first``)
    or "stype" (``rudder``, ``switch_heading``, ``first``); angles in rad. ``p`` is a packed
    parameter vector holding at least the steering gear constants. ``delta0`` is the rudder at t[0].
    """
    amp = float(manoeuvre["rudder"])
    side = 1.0 if manoeuvre.get("first", "starboard") == "starboard" else -1.0
    if kind == "turning":
        law, hi, lo = 0, 0.0, 0.0
    elif kind == "zigzag":
        law, hi, lo = 1, float(manoeuvre["heading"]), -float(manoeuvre["heading"])
    elif kind == "stype":
        h = float(manoeuvre["switch_heading"])
        law, (hi, lo) = 1, ((h, 0.0) if side > 0 else (0.0, -h))
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
    (:mod:`ekf.log_filter`) and of the matching Cramer-Rao bound (:mod:`trials.fisher`).
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


def manoeuvre_from_meta(meta: dict, source: str = "log") -> tuple[str, dict]:
    """The trial kind and its rudder logic (SI) from a log header."""
    kind = str(meta.get("kind", ""))
    if kind not in REBUILT_KINDS:
        raise InputError(source, "kind", f"the log has no rudder channel and its header gives no turning/zigzag/stype "
                                         f"trial kind to rebuild it from (kind: {kind or 'missing'})")
    try:
        m = {"rudder": float(meta["rudder_deg"]) * DEG, "first": str(meta.get("first", "starboard"))}
        if kind == "zigzag":
            m["heading"] = float(meta["heading_deg"]) * DEG
        elif kind == "stype":
            m["switch_heading"] = float(meta["switch_heading_deg"]) * DEG
    except KeyError as e:
        raise InputError(source, str(e.args[0]), "missing from the log header; needed to rebuild the rudder") from None
    return kind, m


def steering_from_meta(meta: dict, source: str = "log") -> np.ndarray:
    """A parameter vector holding the steering gear constants written in a log header."""
    p = np.zeros(N_PARAMS)
    try:
        p[P_TE] = float(meta["steering_T_E_s"])
        p[P_RATE] = float(meta["steering_rate_deg_s"]) * DEG
        p[P_DMAX] = float(meta["steering_delta_max_deg"]) * DEG
    except KeyError as e:
        raise InputError(source, str(e.args[0]), "missing from the log header; needed to rebuild the rudder") from None
    return p


def with_rebuilt_rudder(rec: TrialRecord, dt: float = 0.1) -> TrialRecord:
    """The record on a ``dt`` grid with the rudder rebuilt from the trial logic in its header.

    Heading (and the other channels) are interpolated by cubic splines through the log
    samples; the rudder order follows the trial's law on the interpolated heading and the
    rudder angle follows the steering gear, starting from the header's trim rudder.
    """
    from scipy.interpolate import CubicSpline

    src = rec.source or "log"
    if rec.psi is None:
        raise InputError(src, "heading_deg", "a rudder can only be rebuilt from a heading channel")
    kind, man = manoeuvre_from_meta(rec.meta, src)
    p = steering_from_meta(rec.meta, src)
    t = np.arange(rec.t[0], rec.t[-1] + 1e-9, dt)
    kw = {"t": t}
    for c in rec.channels():
        kw[c] = CubicSpline(rec.t, getattr(rec, c))(t)
    order, delta = reconstruct_rudder(t, kw["psi"], kind, man, p, float(rec.meta.get("trim_rudder_deg", 0.0)) * DEG)
    kw["delta"] = delta
    return replace(rec, **kw, meta={**rec.meta, "delta_order": order, "rudder": "rebuilt from the trial logic"})
