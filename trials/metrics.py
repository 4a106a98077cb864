"""Standard manoeuvre metrics (IMO MSC.137(76) definitions) from time histories.

Turning: advance and transfer at 90 deg heading change, tactical diameter (transfer at
180 deg), steady turning diameter (circle fitted to the track once the turn is steady),
speed loss 1 - U_steady / U_0.  Zigzag: overshoot angles in order, initial turning time
(time from the first execute to the second, i.e. to the first rudder reversal), period.
Positions are of midship, x north and y east [m]; headings [rad]; times [s].
"""
from __future__ import annotations

import numpy as np

from mmg.errors import InputError
from mmg.units import DEG


def _cross_time(t, s, level):
    """First time the increasing signal ``s`` reaches ``level`` (linear interpolation), index."""
    idx = np.flatnonzero(s >= level)
    if idx.size == 0:
        return None, None
    i = idx[0]
    if i == 0:
        return t[0], 0
    w = (level - s[i - 1]) / (s[i] - s[i - 1])
    return t[i - 1] + w * (t[i] - t[i - 1]), (i - 1, w)


def _at(arr, where):
    if where == 0:
        return arr[0]
    i, w = where
    return arr[i] + w * (arr[i + 1] - arr[i])


def fit_circle(x, y):
    """Least-squares (Kasa) circle through points: centre (xc, yc) and radius [m]."""
    A = np.column_stack([x, y, np.ones_like(x)])
    b = x * x + y * y
    c, *_ = np.linalg.lstsq(A, b, rcond=None)
    xc, yc = c[0] / 2, c[1] / 2
    return xc, yc, float(np.sqrt(c[2] + xc * xc + yc * yc))


def execute_time(t, delta=None, order=None):
    """Rudder execute time [s].

    From the rudder order when known (the instant it departs from its initial value by
    more than 0.5 deg: the IMO execute); else from the measured rudder angle, as the
    instant it first reaches half of its final (held) value, which is robust to the
    small rudder motions of an approach; else the start of the record.
    """
    t = np.asarray(t, dtype=float)
    if order is not None:
        o = np.asarray(order, dtype=float)
        moved = np.flatnonzero(np.abs(o - o[0]) > 0.5 * DEG)
        return float(t[moved[0]]) if moved.size else float(t[0])
    if delta is None:
        return float(t[0])
    d = np.asarray(delta, dtype=float)
    final = float(np.median(d[len(d) // 2:]))
    if abs(final) < 1 * DEG:
        return float(t[0])
    reached = np.flatnonzero(np.sign(final) * d >= 0.5 * abs(final))
    return float(t[reached[0]]) if reached.size else float(t[0])


def turning_metrics(t, x, y, psi, U, L, t_execute=None, delta=None, order=None) -> dict:
    """Turning-circle metrics; lengths divided by L.

    Parameters
    ----------
    t, x, y, psi, U : arrays
        Time [s], midship position north/east [m], heading [rad, unwrapped], speed [m/s].
    L : float
        Ship length [m].
    t_execute : float, optional
        Rudder execute time [s]; from ``delta`` (see :func:`execute_time`) when omitted.
    delta, order : array, optional
        Rudder angle and rudder order [rad] (for the execute time).

    Returns
    -------
    dict with advance_L, transfer_L, tactical_diameter_L, steady_diameter_L, speed_loss
    (fraction of approach speed lost in the steady turn), steady_speed_ratio, time_to_90_s,
    time_to_180_s, turn ("starboard"/"port"), heading_change_deg. Missing values are None
    when the record does not reach the heading change they need.
    """
    t, x, y, psi, U = (np.asarray(a, dtype=float) for a in (t, x, y, psi, U))
    te = execute_time(t, delta, order) if t_execute is None else float(t_execute)
    i0 = int(np.searchsorted(t, te))
    i0 = min(i0, len(t) - 1)
    psi0, x0, y0, U0 = psi[i0], x[i0], y[i0], U[i0]
    dpsi = psi - psi0
    side = 1.0 if dpsi[-1] >= 0 else -1.0
    turn = side * dpsi
    c, s = np.cos(psi0), np.sin(psi0)
    along = (x - x0) * c + (y - y0) * s
    across = side * (-(x - x0) * s + (y - y0) * c)
    out = {"turn": "starboard" if side > 0 else "port", "heading_change_deg": float(turn[-1] / DEG),
           "approach_speed_mps": float(U0)}
    t90, w90 = _cross_time(t[i0:], turn[i0:], np.pi / 2)
    t180, w180 = _cross_time(t[i0:], turn[i0:], np.pi)

    def shift(w):
        return w if w == 0 else (w[0] + i0, w[1])

    out["advance_L"] = float(_at(along, shift(w90)) / L) if w90 is not None else None
    out["transfer_L"] = float(_at(across, shift(w90)) / L) if w90 is not None else None
    out["tactical_diameter_L"] = float(_at(across, shift(w180)) / L) if w180 is not None else None
    out["time_to_90_s"] = None if t90 is None else float(t90 - te)
    out["time_to_180_s"] = None if t180 is None else float(t180 - te)
    # steady part: after 360 deg of turn if reached, else after 180 deg with at least 90 deg more
    steady = None
    for start in (2 * np.pi, np.pi):
        m = turn >= start
        if m.sum() > 10 and turn[-1] - start >= np.pi / 2:
            steady = m
            break
    if steady is not None:
        _, _, R = fit_circle(x[steady], y[steady])
        Us = float(np.mean(U[steady]))
        out["steady_diameter_L"] = 2 * R / L
        out["steady_speed_ratio"] = Us / U0
        out["speed_loss"] = 1.0 - Us / U0
    else:
        out["steady_diameter_L"] = out["steady_speed_ratio"] = out["speed_loss"] = None
    return out


def zigzag_switches(t, psi, order=None, angle=None, first=None):
    """Indices of the rudder executes of a zigzag.

    With the rudder order (or measured angle) ``order``: the samples where it first
    reaches half of the zigzag's rudder amplitude (the largest |order|) on one side, then
    each time it reaches half the amplitude on the other side -- so small rudder motions
    during the approach are not taken for executes.  For a measured rudder the index is
    moved back to where the rudder started to move towards the new side (the order
    instant).  Without a rudder: heading-triggered switches for a zigzag of switching
    heading ``angle`` [rad], first side +1 (starboard) or -1, taken from the first clear
    heading change when None.
    """
    t, psi = np.asarray(t), np.asarray(psi)
    if order is not None:
        o = np.asarray(order, dtype=float)
        half = 0.5 * np.max(np.abs(o))
        sig = np.where(np.abs(o) >= half, np.sign(o), 0.0)
        idx = []
        cur = 0.0
        for i, sg in enumerate(sig):
            if sg != 0.0 and sg != cur:
                j = i
                # back to where the rudder began moving towards this side
                while j > 0 and sg * (o[j] - o[j - 1]) > 1e-9 and (not idx or j - 1 > idx[-1]):
                    j -= 1
                idx.append(j + 1 if j < i else i)  # first sample of the move
                cur = sg
        return np.array(idx, dtype=int)
    if angle is None:
        raise ValueError("a zigzag record without rudder needs its switching heading angle")
    d = psi - psi[0]
    if first is None:
        big = np.flatnonzero(np.abs(d) > 0.2 * angle)
        if big.size == 0:
            return np.array([0], dtype=int)
        first = np.sign(d[big[0]])
    idx = [0]
    side = first
    for i in range(len(d)):
        if side > 0 and d[i] >= angle:
            idx.append(i)
            side = -1
        elif side < 0 and d[i] <= -angle:
            idx.append(i)
            side = 1
    return np.array(idx, dtype=int)


def zigzag_metrics(t, psi, order=None, angle=None, first=None, U=None, L=None) -> dict:
    """Zigzag metrics.

    Parameters
    ----------
    t, psi : arrays
        Time [s], heading [rad, unwrapped].
    order : array, optional
        Rudder order or rudder angle [rad]; executes are read from it when given.
    angle : float, optional
        Switching heading change [rad] (needed without ``order``).
    first : +1 or -1, optional
        First rudder side when ``order`` is absent.
    U, L : optional
        Speed [m/s] and length [m] for the distance to the second execute in L.

    Returns
    -------
    dict with overshoots_deg (list, in order), initial_turning_time_s (first to second
    execute), period_s (mean full-cycle time), execute_times_s, and
    distance_to_second_execute_L when U and L are given.
    """
    t, psi = np.asarray(t, dtype=float), np.asarray(psi, dtype=float)
    sw = zigzag_switches(t, psi, order, angle, first)
    out = {"execute_times_s": [float(t[i]) for i in sw]}
    overs = []
    for k in range(1, len(sw)):
        i = sw[k]
        j = sw[k + 1] if k + 1 < len(sw) else len(t)
        seg = psi[i:j] - psi[i]
        # after a reversal to port the heading still rises to its peak, and vice versa
        dirn = np.sign(psi[i] - psi[sw[k - 1]]) or 1.0
        peak = np.max(dirn * seg)
        if j == len(t) and np.argmax(dirn * seg) == len(seg) - 1:
            break  # record ends before the peak
        overs.append(float(peak / DEG))
    out["overshoots_deg"] = overs
    out["initial_turning_time_s"] = float(t[sw[1]] - t[sw[0]]) if len(sw) > 1 else None
    if len(sw) > 3:
        out["period_s"] = float(np.mean(np.diff(t[sw[1::2]]))) if len(sw[1::2]) > 1 else float(t[sw[3]] - t[sw[1]])
    else:
        out["period_s"] = None
    if U is not None and L is not None and len(sw) > 1:
        U = np.asarray(U, dtype=float)
        i0, i1 = sw[0], sw[1]
        out["distance_to_second_execute_L"] = float(np.trapezoid(U[i0:i1 + 1], t[i0:i1 + 1]) / L)
    return out


def imo_criteria(L: float, U0: float, turning: dict | None = None, zz10: dict | None = None,
                 zz20: dict | None = None) -> list[dict]:
    """IMO MSC.137(76) manoeuvring criteria checked against the metrics given.

    L [m], U0 approach speed [m/s]; L/V sets the 10/10 overshoot limits.
    """
    LV = L / U0
    rows = []

    def add(name, value, limit):
        rows.append({"criterion": name, "value": value, "limit": limit,
                     "pass": None if value is None else bool(value <= limit)})

    if turning:
        add("advance (L)", turning.get("advance_L"), 4.5)
        add("tactical diameter (L)", turning.get("tactical_diameter_L"), 5.0)
    if zz10:
        lim1 = 10.0 if LV < 10 else (20.0 if LV >= 30 else 5.0 + 0.5 * LV)
        lim2 = 25.0 if LV < 10 else (40.0 if LV >= 30 else 17.5 + 0.75 * LV)
        ov = zz10.get("overshoots_deg", [])
        add("10/10 first overshoot (deg)", ov[0] if len(ov) > 0 else None, lim1)
        add("10/10 second overshoot (deg)", ov[1] if len(ov) > 1 else None, lim2)
        add("initial turning: distance to 2nd execute (L)", zz10.get("distance_to_second_execute_L"), 2.5)
    if zz20:
        ov = zz20.get("overshoots_deg", [])
        add("20/20 first overshoot (deg)", ov[0] if len(ov) > 0 else None, 25.0)
    return rows


def record_metrics(rec, kind=None, length=None, angle=None) -> dict:
    """Metrics of a read record (kind guessed from the heading history when not given).

    Parameters
    ----------
    rec : TrialRecord
    kind : {"turning", "zigzag", "stype"}, optional
    length : float, optional
        Ship length L [m] when the record does not say.
    angle : float, optional
        Switching heading [rad] of a zigzag record without rudder channel or header.
    """
    L = length or rec.meta.get("length_m")
    if L is None:
        raise InputError(rec.source, "--length", "the log does not give the ship length; pass --length")
    L = float(L)
    kind = kind or rec.meta.get("kind")
    if kind not in ("turning", "zigzag", "stype"):
        kind = "turning" if abs(rec.psi[-1] - rec.psi[0]) > np.pi else "zigzag"
    out = {"record": rec.name, "source": rec.source, "kind": kind, "length_m": L}
    U = rec.speed()
    if kind == "turning":
        if rec.x is None:
            raise InputError(rec.source, "lat_deg", "turning metrics need the track (positions)")
        out.update(turning_metrics(rec.t, rec.x, rec.y, rec.psi, U, L,
                                   t_execute=rec.meta.get("execute_s"), delta=rec.delta,
                                   order=rec.meta.get("delta_order")))
    else:
        order = rec.meta.get("delta_order", rec.delta)
        ang = angle
        if order is None and ang is None:
            key = "heading_deg" if kind == "zigzag" else "switch_heading_deg"
            if key not in rec.meta:
                raise InputError(rec.source, "heading_deg", "a zigzag log without rudder needs --zigzag-angle")
            ang = float(rec.meta[key]) * np.pi / 180
        first = None
        if rec.meta.get("first") in ("starboard", "port"):
            first = 1 if rec.meta["first"] == "starboard" else -1
        if kind == "stype" and order is None:
            raise InputError(rec.source, "rudder", "S-type metrics from a log need the rudder channel")
        out.update(zigzag_metrics(rec.t, rec.psi, order=order, angle=ang, first=first, U=U, L=L))
    return out
