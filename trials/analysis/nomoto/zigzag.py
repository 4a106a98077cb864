"""A recorded zigzag found in a trial record and converted to dimensionless variables.

:func:`zigzag_data` segments the record (rudder plateaus, execute,
counter-rudders, overshoots, heading zero crossings), sets s' = (t - t_e) U/L
and derives omega', eps' with :func:`trials.analysis.nomoto.smoothing.smooth_derivatives`;
the result is a :class:`ZigzagData`, the input of every identification method.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from scipy.integrate import cumulative_trapezoid

from mmg.errors import InputError
from trials.analysis.nomoto.points import ZigzagPoints
from trials.analysis.nomoto.smoothing import smooth_derivatives
from trials.files.records import TrialRecord

__all__ = ["ZigzagData", "approach_speed", "zigzag_data"]


@dataclass(frozen=True)
class ZigzagData:
    """A recorded zigzag converted to Artyszuk's dimensionless variables.

    Heading and rudder are taken relative to the first execute (s' = 0 there)
    and the rudder integral starts there; if the first execute was to port all
    signs are flipped so that the first rudder is positive, as in the paper.
    Produced by :func:`zigzag_data`.

    Attributes
    ----------
    s, psi, omega, eps, delta, Delta : ndarray
        From the first execute to the end of the last zigzag rudder plateau.
        psi, delta are increments from their values at the execute [rad];
        omega', eps' are absolute [-]; Delta = integral of the absolute rudder [rad].
    psi_e, omega_e, eps_e, delta_e : float
        Values at the execute [rad, -, -, rad]; omega_e, eps_e, delta_e (flipped)
        are the initial state for simulations, psi_e is the smoothed heading at
        the execute in the record's own sign convention (not flipped).
    sign : float
        +1 or -1, the flip applied.
    L, U : float
        Ship length [m] and the speed used for s' [m/s].
    t_execute : float
        Record time of the execute [s].
    s_cr, s_os, s_z : tuple of float
        Counter-rudder abscissas (rudder leaves a zigzag plateau), overshoot
        abscissas (omega' = 0) and heading zero crossings, [-].
    delta0 : float
        Nominal rudder angle from the plateaus [rad].
    yaw_rate_source : str
        "recorded" or "derived from heading".
    name : str
        Record name.
    psi_raw : ndarray
        Recorded (unsmoothed) heading increment from the execute [rad]; the
        whole-record fits use it, so the smoother cannot bias them.
    """

    s: np.ndarray
    psi: np.ndarray
    omega: np.ndarray
    eps: np.ndarray
    delta: np.ndarray
    Delta: np.ndarray
    psi_e: float
    omega_e: float
    eps_e: float
    delta_e: float
    sign: float
    L: float
    U: float
    t_execute: float
    s_cr: tuple
    s_os: tuple
    s_z: tuple
    delta0: float
    yaw_rate_source: str
    name: str = ""
    psi_raw: Optional[np.ndarray] = None

    def at(self, s: float) -> dict:
        """Linearly interpolated values at one abscissa (psi, delta as increments).

        Parameters
        ----------
        s : float
            Abscissa s' [-].

        Returns
        -------
        dict
            Keys s, eps, omega, Delta, delta, psi.
        """
        return {"s": float(s), **{k: float(np.interp(s, self.s, getattr(self, k)))
                                  for k in ("eps", "omega", "Delta", "delta", "psi")}}

    def points(self, n: int = 2) -> "ZigzagPoints":
        """Artyszuk's abscissas CR1, OS1, CR2, OS2 (n pairs), omega' = 0 at the overshoots.

        eps' and omega' enter the four-point matrix as increments from the execute,
        which makes eq. (15) exact for a ship that was not yet steady at the execute.

        Parameters
        ----------
        n : int
            Number of (counter-rudder, overshoot) pairs.

        Raises
        ------
        InputError
            Fewer than ``n`` counter-rudders or overshoots in the record.
        """
        if len(self.s_cr) < n or len(self.s_os) < n:
            raise InputError(self.name, "heading",
                             f"too short for the four-point method: found {len(self.s_cr)} counter-rudder(s) "
                             f"and {len(self.s_os)} overshoot(s), need {n} of each")
        names, rows = [], []
        for k in range(n):
            for nm, s in ((f"CR{k + 1}", self.s_cr[k]), (f"OS{k + 1}", self.s_os[k])):
                r = self.at(s)
                r["eps"] -= self.eps_e
                r["omega"] = 0.0 if nm.startswith("OS") else r["omega"] - self.omega_e
                names.append(nm)
                rows.append(r)
        return ZigzagPoints.from_rows(names, rows)


def _runs(mask):
    """(start, end_inclusive) index pairs of True runs."""
    m = np.concatenate([[False], mask, [False]]).astype(int)
    d = np.diff(m)
    return list(zip(np.where(d == 1)[0], np.where(d == -1)[0] - 1))


def _check_finite(record: TrialRecord, names):
    """Raise :class:`InputError` naming the first NaN/inf of the given channels (missing ones skipped)."""
    src = record.source or record.name or "record"
    for c in names:
        a = getattr(record, c)
        if a is None:
            continue
        bad = ~np.isfinite(a)
        if bad.any():
            i = int(np.argmax(bad))
            raise InputError(src, c, f"contains {int(bad.sum())} NaN/inf value(s), first at t = {record.t[i]:g} s")


def approach_speed(record: TrialRecord, t_execute: float) -> float:
    """Mean approach speed [m/s] before the first execute.

    The mean of the speed over the pre-execute samples whose speed is at least
    90 % of the speed at the execute: a ship (or a free-running model that starts
    from rest, as in the FRT-DS-ESSO pond tests) is then taken in its settled
    approach condition, not while still accelerating.

    Parameters
    ----------
    record : TrialRecord
        Record with a speed channel (U, u/v or the track).
    t_execute : float
        Time of the first execute [s].

    Returns
    -------
    float
        Approach speed [m/s]; the first speed sample if no sample precedes the execute.
    """
    sp = np.asarray(record.speed(), float)
    pre = record.t <= t_execute
    if pre.sum() < 1:
        return float(sp[0])
    ue = sp[pre][-1]
    sel = pre & (sp >= 0.9 * ue)
    return float(np.mean(sp[sel])) if sel.any() else float(ue)


def _plateaus(delta):
    """Zigzag rudder plateaus: list of (start, end, sign) with alternating sign, and delta0 [rad]."""
    # plateau levels from the samples where the rudder is held still, so that operator
    # steering before the execute (which may go beyond the zigzag angle) is ignored
    amax = np.max(np.abs(delta))
    d = np.diff(delta)
    flat = np.zeros(len(delta), bool)
    flat[1:-1] = (np.abs(d[:-1]) < 1e-3 * amax) & (np.abs(d[1:]) < 1e-3 * amax)
    dp = np.max(delta[flat], initial=0.0)
    dm = np.min(delta[flat], initial=0.0)
    if dp <= 0 or dm >= 0:
        return [], 0.0
    lp = np.median(delta[flat & (delta >= 0.5 * dp)])
    lm = np.median(delta[flat & (delta <= 0.5 * dm)])
    d0 = 0.5 * (lp - lm)
    tol = max(0.05 * d0, np.radians(0.25))
    n = len(delta)
    min_len = max(3, int(0.02 * n))
    runs = []
    for lev, sg in ((lp, 1.0), (lm, -1.0)):
        for a, b in _runs(np.abs(delta - lev) < tol):
            if b - a + 1 >= min_len:
                runs.append([a, b, sg])
    runs.sort()
    merged = []
    for r in runs:  # same-sign runs separated by a short glitch are one plateau
        if merged and merged[-1][2] == r[2] and r[0] - merged[-1][1] <= min_len:
            merged[-1][1] = r[1]
        else:
            merged.append(r)
    # the longest chain of alternating plateaus, each joined to the next by one monotone
    # rudder movement (a counter-rudder), not by operator steering back and forth
    def monotone(a, b, direction):
        d = np.diff(delta[a:b + 1])
        return bool(np.all(direction * d >= -0.5 * tol))

    best, cur = [], []
    for r in merged:
        if cur and cur[-1][2] != r[2] and monotone(cur[-1][1], r[0], r[2]):
            cur.append(r)
        else:
            cur = [r]
        if len(cur) > len(best):
            best = list(cur)
    return [tuple(r) for r in best], float(d0)


def _counter_rudders(plats, delta, dl, s, ie: int, sign: float) -> tuple:
    """s' of each counter-rudder: where the ramp leaving plateau k, extended back, meets the plateau
    level (delta the whole record's rudder, dl and s from the execute at sample ie)."""
    s_cr = []
    for (a, b, sg) in plats[:-1]:
        level = float(np.median(delta[a:b + 1]))
        sc = s[b - ie]
        if b + 2 - ie < len(s):
            i1, i2 = b + 1 - ie, b + 2 - ie
            slope = (dl[i2] - dl[i1]) / (s[i2] - s[i1])
            if slope * sg * sign < 0:
                sc = float(np.clip(s[i1] - (dl[i1] - level) / slope, s[a - ie], s[i1]))
        s_cr.append(float(sc))
    return tuple(s_cr)


def _overshoots(s, psi, omega, s_cr) -> tuple:
    """s' of each overshoot: the extreme of the heading between counter-rudder k and the next one,
    refined to omega' = 0; stops at the first window still turning at its end."""
    s_os = []
    bounds = list(s_cr) + [s[-1]]
    side = 1.0
    for k, a in enumerate(s_cr):
        m = np.where((s >= a) & (s <= bounds[k + 1]))[0]
        if len(m) < 3:
            break
        i = m[np.argmax(side * psi[m])]
        if i == m[-1]:  # still turning at the end of the window: no overshoot yet
            break
        # refine: omega' sign change next to the extreme
        lo, hi = max(i - 1, m[0]), min(i + 1, m[-1])
        so = s[i]
        for q in range(lo, hi):
            if omega[q] * side > 0 >= omega[q + 1] * side:
                so = s[q] + (s[q + 1] - s[q]) * omega[q] / (omega[q] - omega[q + 1])
        s_os.append(float(so))
        side = -side
    return tuple(s_os)


def _zero_crossings(s, psi, s_os) -> tuple:
    """s' of the heading's first zero crossing after each overshoot (those there are)."""
    s_z = []
    for so in s_os:
        m = np.where((s > so))[0]
        for q in m[:-1]:
            if psi[q] * psi[q + 1] <= 0 and psi[q] != psi[q + 1] and abs(psi[q]) > 0:
                s_z.append(float(s[q] + (s[q + 1] - s[q]) * psi[q] / (psi[q] - psi[q + 1])))
                break
    return tuple(s_z)


def _zigzag_input(record: TrialRecord, L: float) -> tuple:
    """(the record's name for messages, its times) after the checks :func:`zigzag_data` needs: a positive
    length, heading and rudder channels, finite values, at least 10 strictly increasing times."""
    src = record.source or record.name or "record"
    if not (np.isfinite(L) and L > 0):
        raise InputError("--length", "", f"ship length must be positive, got {L}")
    for c in ("psi", "delta"):
        if getattr(record, c) is None:
            from trials.files.logio import missing_channel

            raise missing_channel(record, c, "a zigzag analysis needs heading and rudder")
    _check_finite(record, ("t", "psi", "delta", "r"))
    t = np.asarray(record.t, float)
    if len(t) < 10 or np.any(np.diff(t) <= 0):
        raise InputError(src, "t", "need at least 10 samples with strictly increasing time")
    return src, t


def _zigzag_speed(record: TrialRecord, t_e: float, U: Optional[float], src: str) -> float:
    """The speed for s' [m/s]: ``U`` where given, else the approach speed at the execute ``t_e``; positive."""
    given = U is not None
    if not given:
        try:
            U = approach_speed(record, t_e)
        except ValueError:
            raise InputError(src, "U", "no speed channel; give --speed") from None
    if not (np.isfinite(U) and U > 0):
        raise InputError("--speed" if given else src, "U", f"speed must be positive, got {U}")
    return U


def zigzag_data(record: TrialRecord, L: float, U: Optional[float] = None, per_knot: Optional[int] = None) -> ZigzagData:
    """Find the zigzag in a record and convert it to dimensionless variables.

    Steps: (1) the rudder plateaus at +-delta0 are found and the longest chain of
    alternating plateaus is taken as the zigzag (operator steering before it is
    ignored); (2) the execute is where the rudder starts moving to the first
    plateau, each counter-rudder where it leaves a plateau (the ramp leaving it,
    extended back, meets the plateau level); (3) s' = (t - t_e) U/L
    with a constant speed (the linear model's assumption), U defaulting to the
    approach speed (:func:`approach_speed`); (4) omega' from the recorded yaw rate
    (smoothed), or from the heading by :func:`smooth_derivatives`; eps' is the
    derivative of the same spline; (5) overshoots are the extremes of the
    smoothed heading between counter-rudders, refined to omega' = 0; (6) the
    heading zero crossings after each overshoot are recorded for eq. (11).

    Parameters
    ----------
    record : TrialRecord
        Needs t, psi and delta (r and a speed channel optional).
    L : float
        Ship length [m].
    U : float, optional
        Speed for s' [m/s]; default: approach speed.
    per_knot : int, optional
        Samples per knot interval of the differentiator (None: chosen by GCV),
        see :func:`~trials.analysis.nomoto.smoothing.smooth_derivatives`.

    Returns
    -------
    ZigzagData
        The zigzag from the execute to the end of the last rudder plateau.

    Raises
    ------
    InputError
        Missing channels, NaN, no zigzag (no counter-rudder), bad L or U.
    """
    src, t = _zigzag_input(record, L)
    delta_raw = np.asarray(record.delta, float)
    plats, d0 = _plateaus(delta_raw)
    if len(plats) < 2:
        raise InputError(src, "delta", "not a zigzag: no counter-rudder found (need the rudder held at +delta0 "
                                       "then reversed to -delta0)")
    sign = plats[0][2]
    delta = sign * delta_raw
    # execute: walk back from the first plateau while the rudder was still moving towards it
    ie = plats[0][0]
    while ie > 0 and delta[ie] - delta[ie - 1] > 1e-4 * d0:
        ie -= 1
    t_e = t[ie]
    U = _zigzag_speed(record, t_e, U, src)
    end = plats[-1][1]
    sl = slice(ie, end + 1)
    s = (t[sl] - t_e) * U / L
    if len(s) < 10:
        raise InputError(src, "t", "zigzag too short")
    psi_abs = sign * np.asarray(record.psi, float)[sl]
    psi_s, dpsi, d2psi = smooth_derivatives(s, psi_abs, per_knot)
    if record.r is not None:
        om_raw = sign * np.asarray(record.r, float)[sl] * L / U
        omega, eps, _ = smooth_derivatives(s, om_raw, per_knot)
        src_r = "recorded"
    else:
        omega, eps = dpsi, d2psi
        src_r = "derived from heading"
    dl = delta[sl]
    Delta = cumulative_trapezoid(dl, s, initial=0.0)
    psi = psi_s - psi_s[0]
    s_cr = _counter_rudders(plats, delta, dl, s, ie, sign)
    s_os = _overshoots(s, psi, omega, s_cr)
    s_z = _zero_crossings(s, psi, s_os)
    return ZigzagData(s=s, psi=psi, omega=omega, eps=eps, delta=dl - dl[0], Delta=Delta,
                      psi_e=float(sign * psi_s[0]), omega_e=float(omega[0]), eps_e=float(eps[0]),
                      delta_e=float(dl[0]), sign=float(sign), L=float(L), U=float(U), t_execute=float(t_e),
                      s_cr=s_cr, s_os=s_os, s_z=s_z, delta0=d0, yaw_rate_source=src_r,
                      name=record.name or src, psi_raw=psi_abs - psi_s[0])


