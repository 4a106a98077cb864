"""Rhee & Kim (1999) section 4.2: from a 5 s sea-trial log to the EKF's 0.1 s measurements.

Steps (the paper's numbering):

1. Interpolate latitude, longitude, heading and rpm from the log interval (5 s) to
   the filter step (0.1 s) with a second-order polynomial through three points:
   every output time uses the parabola through the nearest log sample and its two
   neighbours (at the ends, the first or last three samples).
2. Positions from latitude/longitude with the paper's metres per degree
   (1852 x 60 for latitude, 1526.16 x 60 for longitude; the log header may carry
   others), then u, v from the track velocity (the parabolas' derivatives) turned
   into the body axes with the interpolated heading.
3. r by differentiating the heading (the parabola's derivative).
4. delta, when the log has no rudder channel, from the trial's logic: constant order
   for a turning test, the heading-switch law (zigzag, S-type) driven by the
   *recovered* heading; the order is passed through the steering gear
   (:func:`mmg.model.steering_rate`, Rhee & Kim eq. 20) starting at the trim rudder.

:func:`recover` returns a :class:`Measurements`; :func:`compare_with_truth` gives the
RMS of each recovered channel against a truth file and :func:`ekf.plots.plot_comparison`
draws Rhee & Kim Figs 4-5 for all five channels.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mmg.errors import InputError

from mmg.rudder import reconstruct_rudder

CHANNELS = ("u", "v", "r", "delta", "n")
UNITS = {"u": "m/s", "v": "m/s", "r": "rad/s", "delta": "rad", "n": "rps"}


@dataclass(frozen=True)
class Measurements:
    """Recovered 0.1 s series (SI) and what they came from.

    t [s]; u, v [m/s]; r [rad/s]; delta [rad] (rudder angle, + starboard); n [rps];
    psi [rad] (interpolated heading); x, y [m]; meta: log header plus what was assumed.
    """

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    r: np.ndarray
    delta: np.ndarray
    n: np.ndarray
    psi: np.ndarray
    x: np.ndarray
    y: np.ndarray
    name: str = ""
    source: str = ""
    delta_source: str = ""
    meta: dict = field(default_factory=dict)

    def z(self) -> np.ndarray:
        """Measurement matrix (N, 4): u, v, r, n."""
        return np.column_stack([self.u, self.v, self.r, self.n])


def quadratic3(ts: np.ndarray, ys: np.ndarray, tq: np.ndarray):
    """Value and first derivative at ``tq`` of the parabola through three log samples.

    For each query time the three samples are the nearest one and its two
    neighbours (the first/last three at the ends) — Rhee & Kim's "second order
    polynomial function fitted by three points".
    """
    ts = np.asarray(ts, float)
    ys = np.asarray(ys, float)
    m = len(ts)
    if m < 3:
        raise ValueError("need at least three samples")
    i = np.searchsorted(ts, tq)
    i = np.clip(i, 1, m - 1)
    nearest = np.where(np.abs(tq - ts[i - 1]) <= np.abs(ts[i] - tq), i - 1, i)
    c = np.clip(nearest, 1, m - 2)
    t0, t1, t2 = ts[c - 1], ts[c], ts[c + 1]
    y0, y1, y2 = ys[c - 1], ys[c], ys[c + 1]
    # Lagrange basis and derivatives
    l0 = (tq - t1) * (tq - t2) / ((t0 - t1) * (t0 - t2))
    l1 = (tq - t0) * (tq - t2) / ((t1 - t0) * (t1 - t2))
    l2 = (tq - t0) * (tq - t1) / ((t2 - t0) * (t2 - t1))
    d0 = (2 * tq - t1 - t2) / ((t0 - t1) * (t0 - t2))
    d1 = (2 * tq - t0 - t2) / ((t1 - t0) * (t1 - t2))
    d2 = (2 * tq - t0 - t1) / ((t2 - t0) * (t2 - t1))
    return y0 * l0 + y1 * l1 + y2 * l2, y0 * d0 + y1 * d1 + y2 * d2


def recover(record, p: np.ndarray, dt: float = 0.1, kind: str | None = None, manoeuvre: dict | None = None,
            delta0: float | None = None) -> Measurements:
    """Rhee & Kim section 4.2 on a record (a :class:`trials.files.records.TrialRecord` or anything with its arrays).

    Parameters
    ----------
    record : TrialRecord
        Needs t, x, y (from lat/lon with the header's metres per degree), psi and n.
    p : ndarray
        Packed parameter vector of the ship (steering gear constants).
    dt : float
        Output step [s] (the filter step, 0.1 s).
    kind, manoeuvre : optional
        Trial logic for the rudder (:class:`ekf.data.RecordInfo`); needed when the record has
        no rudder channel.
    delta0 : float, optional
        Rudder at the start [rad] (the approach's trim rudder; 0 when None).
    """
    src = record.source or "log"
    for ch in ("x", "y", "psi", "n"):
        if getattr(record, ch) is None:
            raise InputError(src, ch, "missing channel: the estimator needs position, heading and rpm")
    ts = np.asarray(record.t, float)
    if len(ts) < 3:
        raise InputError(src, "time_s", "fewer than three samples")
    nq = int(np.floor((ts[-1] - ts[0]) / dt + 1e-9)) + 1
    tq = ts[0] + dt * np.arange(nq)
    x, xd = quadratic3(ts, record.x, tq)
    y, yd = quadratic3(ts, record.y, tq)
    psi, r = quadratic3(ts, record.psi, tq)
    n, _ = quadratic3(ts, record.n, tq)
    c, s = np.cos(psi), np.sin(psi)
    u = xd * c + yd * s
    v = -xd * s + yd * c
    meta = dict(record.meta)
    if record.delta is not None:
        delta, _ = quadratic3(ts, record.delta, tq)
        dsrc = "log rudder channel"
    else:
        if not kind or manoeuvre is None:
            raise InputError(src, "kind", "the record has no rudder channel and no trial logic (turning, zigzag, "
                                          "S-type) to rebuild it from")
        delta0 = 0.0 if delta0 is None else float(delta0)
        _, delta = reconstruct_rudder(tq, psi, kind, manoeuvre, p, delta0)
        dsrc = f"rebuilt from the {kind} logic and the recovered heading"
    return Measurements(tq, u, v, r, delta, n, psi, x, y, record.name, src, dsrc, meta)


def compare_with_truth(meas: Measurements, truth) -> dict:
    """RMS of (recovered - true) for u, v, r, delta, n on the common 0.1 s times.

    ``truth`` is a TrialRecord read from a truth file (or anything with t, u, v, r, delta, n).
    """
    out = {}
    for ch in CHANNELS:
        tv = np.interp(meas.t, truth.t, getattr(truth, ch))
        d = getattr(meas, ch) - tv
        out[ch] = float(np.sqrt(np.mean(d * d)))
    return out


