"""Standard manoeuvre metrics (IMO MSC.137(76) definitions) from time histories.

Turning: advance and transfer at 90 deg heading change, tactical diameter (transfer at
180 deg), steady turning diameter (circle fitted to the track once the turn is steady),
speed loss 1 - U_steady / U_0, all from the execute point.  Zigzag: overshoot angles in
order, initial turning time (time from the first execute to the second, i.e. to the first
rudder reversal), period.  Positions are of midship, x north and y east [m]; headings [rad];
times [s].

Executes
--------
With a rudder order (simulations, truth files) the executes are where the order steps.  With
a *measured* rudder (real records) an execute is where the rudder moves to the manoeuvre's
amplitude and stays there ("holds") until the heading condition: for a turn the longest hold
at 5 deg or more, for a zigzag the longest chain of holds at the amplitude in which each one
is left by a direct move to the other side's amplitude.  The rudder corrections of an
accelerating approach are therefore not taken for executes.  The execute time is when the
rudder starts to move (midway between the last sample before the move and the first sample
of it).  Without a rudder channel a zigzag or S-type is switched by the heading (the law of
the simulator: reversal when the heading change from the first execute reaches the check
heading), with the crossing interpolated between samples.

Overshoots are measured from the heading at which the rudder was reversed (the switching
heading: the check heading for a heading-switched log, the heading at the reversal for a
record with rudder) to the extreme heading after the reversal, found with a parabola through
the samples around the extreme sample (three samples on a coarse log; the samples within
1 s on a dense one, which also averages the sensor noise).

:func:`record_metrics` (what ``mmg metrics`` runs) also refuses, with
:class:`mmg.errors.InputError`, a record that is not the manoeuvre asked for: a "turn"
whose rudder is not held through 90 deg of heading change, a "zigzag" without rudder
reversals at one switching heading per side (a random-rudder run), a log whose heading
never reaches the check heading.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mmg.units import DEG


HEADING_JUMP = 1.5 * DEG
"""A heading step this much larger than the yaw rate explains, on a dense record, is a sensor step."""
HOLD_TOL = 1.0 * DEG
"""Rudder samples within this of a hold's first sample belong to the hold."""
MIN_HOLD_S = 2.0
"""Shortest hold [s] of a measured rudder that can be a manoeuvre's (the approach corrections are shorter)."""
MIN_MANOEUVRE_RUDDER = 5.0 * DEG
"""Smallest rudder amplitude of a manoeuvre."""
PEAK_WINDOW_S = 1.0
"""Half-width [s] of the parabola fitted around a heading extreme on a dense record."""


# --------------------------------------------------------------------------- helpers

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


def _median_dt(t) -> float:
    return float(np.median(np.diff(t))) if len(t) > 1 else 1.0


def fit_circle(x, y):
    """Least-squares (Kasa) circle through points: centre (xc, yc) and radius [m]."""
    A = np.column_stack([x, y, np.ones_like(x)])
    b = x * x + y * y
    c, *_ = np.linalg.lstsq(A, b, rcond=None)
    xc, yc = c[0] / 2, c[1] / 2
    return xc, yc, float(np.sqrt(c[2] + xc * xc + yc * yc))


def corrected_heading(t, psi, r=None):
    """Heading with the sensor's steps removed, and the steps found.

    On a dense record (step <= 1 s) with a yaw-rate channel, a heading change between two
    samples that differs from the integrated yaw rate by more than :data:`HEADING_JUMP` is a
    step of the heading sensor (the FRT-DS-ESSO ``psi_hat`` jumps by up to 7 deg when its
    estimate is re-aligned, with the position; the gyro ``r`` and the autopilot do not see
    it).  The steps are subtracted from the rest of the record.

    Returns
    -------
    (psi_corrected, steps) where steps is a list of (t [s], step [deg]).
    """
    from ...files.logio import DENSE_STEP_S, _step_within     # here: a simulation's metrics import no pandas

    t, psi = np.asarray(t, dtype=float), np.asarray(psi, dtype=float)
    if r is None or len(t) < 3 or not _step_within(_median_dt(t), hi=DENSE_STEP_S):
        return psi, []
    r = np.asarray(r, dtype=float)
    res = np.diff(psi) - 0.5 * (r[1:] + r[:-1]) * np.diff(t)
    j = np.flatnonzero(np.abs(res) > HEADING_JUMP)
    if j.size == 0:
        return psi, []
    corr = np.zeros_like(psi)
    corr[j + 1] = res[j]
    return psi - np.cumsum(corr), [(float(t[i + 1]), float(res[i] / DEG)) for i in j]


def _extreme(t, y, i0, i1, sign, dense):
    """The extreme of ``sign * y`` over samples i0..i1 (inclusive), refined by a parabola.

    Returns (time, value of y) or None when the extreme sample is the last one of the window
    (the record or the hold ends before the extreme).
    """
    if i1 <= i0:
        return None
    seg = sign * y[i0:i1 + 1]
    k = int(np.argmax(seg))
    if k == len(seg) - 1:
        return None
    i = i0 + k
    half = PEAK_WINDOW_S if dense else 1.01 * _median_dt(t)
    lo = max(0, int(np.searchsorted(t, t[i] - half - 1e-9)))
    hi = min(len(t) - 1, int(np.searchsorted(t, t[i] + half + 1e-9, side="right")) - 1)
    lo, hi = min(lo, i - 1) if i > 0 else lo, max(hi, i + 1)
    hi = min(hi, len(t) - 1)
    tt, yy = t[lo:hi + 1] - t[i], sign * y[lo:hi + 1]
    if len(tt) >= 3:
        c = np.polyfit(tt, yy, 2)
        if c[0] < 0:
            tv = -c[1] / (2 * c[0])
            if tt[0] <= tv <= tt[-1]:
                return float(t[i] + tv), float(sign * np.polyval(c, tv))
    return float(t[i]), float(y[i])


# --------------------------------------------------------------------------- the rudder's holds

@dataclass(frozen=True)
class Hold:
    """A stretch where the rudder stays at one angle.

    first, last : sample indices of the hold; level : its angle [rad] (median);
    move : last sample before the rudder began to move towards the level (== first when it
    was already there at the start of the record); the move is the monotonic run of steps into
    the hold, not counting steps slower than a tenth of its fastest one.
    """

    first: int
    last: int
    level: float
    move: int

    @property
    def moved(self) -> bool:
        return self.move < self.first


def rudder_holds(t, rudder, measured=True) -> list[Hold]:
    """The holds of a rudder angle or order, in time order.

    A hold is a run of samples within :data:`HOLD_TOL` of its first sample lasting at least
    :data:`MIN_HOLD_S` (a measured rudder) or two samples (an order, which steps exactly).
    """
    t, d = np.asarray(t, dtype=float), np.asarray(rudder, dtype=float)
    n = len(d)
    runs, s = [], 0
    for i in range(1, n + 1):
        if i == n or abs(d[i] - d[s]) > HOLD_TOL:
            runs.append((s, i - 1))
            s = i
    holds, prev = [], 0
    for a, b in runs:
        if b == a or (measured and t[b] - t[a] < MIN_HOLD_S):
            continue
        level = float(np.median(d[a:b + 1]))
        j = a
        if a > 0:
            # back along the move into the hold while the rudder moves towards it, and not at a crawl
            # (a tenth of the move's fastest step: the slow corrections of an approach are not the move)
            sg, fastest = np.sign(level - d[a - 1]), 0.0
            while j > prev and sg != 0 and sg * (d[j] - d[j - 1]) > 1e-12:
                step = abs(d[j] - d[j - 1])
                fastest = max(fastest, step)
                if step < 0.1 * fastest:
                    break
                j -= 1
        holds.append(Hold(a, b, level, j))
        prev = b
    return holds


def _execute_time(t, h: Hold, measured: bool) -> float:
    if not h.moved:
        return float(t[h.first])
    if measured:
        return float(0.5 * (t[h.move] + t[h.move + 1]))
    return float(t[h.move + 1])


def _turn_hold(t, rudder, measured) -> Hold | None:
    """The longest hold at a manoeuvre's rudder angle (>= MIN_MANOEUVRE_RUDDER)."""
    holds = [h for h in rudder_holds(t, rudder, measured) if abs(h.level) >= MIN_MANOEUVRE_RUDDER]
    if not holds:
        return None
    t = np.asarray(t, dtype=float)
    return max(holds, key=lambda h: t[h.last] - t[h.first])


def execute_time(t, delta=None, order=None):
    """Rudder execute time [s] of a turn.

    From the rudder order when known, else from the measured rudder angle: when the rudder
    starts to move to the longest hold at 5 deg or more (the turn), so that the rudder
    corrections of an approach are not taken for the execute; else the start of the record.
    """
    t = np.asarray(t, dtype=float)
    rudder, measured = (order, False) if order is not None else (delta, True)
    if rudder is None:
        return float(t[0])
    h = _turn_hold(t, rudder, measured)
    return float(t[0]) if h is None else _execute_time(t, h, measured)


# --------------------------------------------------------------------------- turning

def turning_metrics(t, x, y, psi, U, L, t_execute=None, delta=None, order=None, n=None) -> dict:
    """Turning-circle metrics; lengths divided by L.

    Parameters
    ----------
    t, x, y, psi, U : arrays
        Time [s], midship position north/east [m], heading [rad, unwrapped], speed [m/s].
    L : float
        Ship length [m].
    t_execute : float, optional
        Rudder execute time [s]; when omitted, from the rudder order or the measured rudder
        ``delta``: the start of the move to the turn's hold (see :func:`execute_time`), and the
        turn then ends where the rudder leaves that hold or the propeller ``n`` [rps] stops.
    delta, order : array, optional
        Rudder angle and rudder order [rad].
    n : array, optional
        Propeller revolutions [rps] (a turn ends where they fall below half their value at the execute).

    Returns
    -------
    dict with advance_L, transfer_L, tactical_diameter_L, steady_diameter_L, speed_loss
    (1 - mean speed of the steady turn / approach speed), steady_speed_ratio, time_to_90_s,
    time_to_180_s, turn ("starboard"/"port"), heading_change_deg (within the turn),
    approach_speed_mps (at the execute), execute_s, turn_end_s, rudder_deg (the held angle,
    None without a rudder), steady_from_deg (360, or 180 when the turn ends before 450 deg). Missing values are None when the turn does not reach the heading
    change they need.
    """
    t, x, y, psi, U = (np.asarray(a, dtype=float) for a in (t, x, y, psi, U))
    te, iend, rudder_deg = _turn_span(t, t_execute, delta, order, n)
    psi0, x0, y0, U0 = (float(np.interp(te, t, a)) for a in (psi, x, y, U))
    # the turn: from the execute (values interpolated there) to its end
    k = np.arange(iend + 1)
    k = k[t[k] > te]
    tt = np.concatenate([[te], t[k]])
    pp, xx, yy, UU = (np.concatenate([[a0], a[k]]) for a, a0 in ((psi, psi0), (x, x0), (y, y0), (U, U0)))
    dpsi = pp - psi0
    side = 1.0 if dpsi[int(np.argmax(np.abs(dpsi)))] >= 0 else -1.0
    turn = side * dpsi
    c, s = np.cos(psi0), np.sin(psi0)
    along = (xx - x0) * c + (yy - y0) * s
    across = side * (-(xx - x0) * s + (yy - y0) * c)
    out = {"turn": "starboard" if side > 0 else "port", "heading_change_deg": float(turn[-1] / DEG),
           "max_heading_change_deg": float(np.max(turn) / DEG),
           "approach_speed_mps": U0, "execute_s": te, "turn_end_s": float(tt[-1]), "rudder_deg": rudder_deg}
    t90, w90 = _cross_time(tt, turn, np.pi / 2)
    t180, w180 = _cross_time(tt, turn, np.pi)
    out["advance_L"] = float(_at(along, w90) / L) if w90 is not None else None
    out["transfer_L"] = float(_at(across, w90) / L) if w90 is not None else None
    out["tactical_diameter_L"] = float(_at(across, w180) / L) if w180 is not None else None
    out["time_to_90_s"] = None if t90 is None else float(t90 - te)
    out["time_to_180_s"] = None if t180 is None else float(t180 - te)
    out.update(_steady_turn(turn, xx, yy, UU, U0, L))
    return out


def _turn_span(t, t_execute, delta, order, n) -> tuple:
    """(execute time [s], index of the turn's last sample, held rudder [deg] or None) of
    :func:`turning_metrics`: the execute given, or read from the order or the measured rudder (the turn
    then ends where the rudder leaves its hold); the turn ends earlier where the propeller revolutions
    ``n`` fall below half their value at the execute."""
    iend = len(t) - 1
    rudder_deg = None
    if t_execute is not None:
        te = float(t_execute)
    else:
        rudder, measured = (order, False) if order is not None else (delta, True)
        h = _turn_hold(t, rudder, measured) if rudder is not None else None
        if h is None:
            te = float(t[0])
        else:
            te = _execute_time(t, h, measured)
            iend = h.last if h.last < len(t) - 1 else iend
            rudder_deg = h.level / DEG
    i0 = min(int(np.searchsorted(t, te)), len(t) - 1)
    if n is not None:
        n = np.asarray(n, dtype=float)
        n0 = float(np.interp(te, t, n))
        stop = np.flatnonzero(np.abs(n[i0:iend + 1]) < 0.5 * abs(n0)) if abs(n0) > 0 else np.array([], int)
        if stop.size:
            iend = i0 + int(stop[0]) - 1 if stop[0] > 0 else i0
    return te, iend, rudder_deg


def _steady_turn(turn, xx, yy, UU, U0: float, L: float) -> dict:
    """The steady part of a turn (after 360 deg of turn if reached, else after 180 deg with at least 90 deg
    more): ``steady_from_deg``, ``steady_diameter_L`` (a circle fitted to its track), ``steady_speed_ratio``
    and ``speed_loss`` (its mean speed against the approach speed ``U0``); None where there is none."""
    out = {"steady_from_deg": None}
    steady = None
    for start in (2 * np.pi, np.pi):
        m = turn >= start
        if m.sum() > 10 and turn[-1] - start >= np.pi / 2:
            steady, out["steady_from_deg"] = m, float(start / DEG)
            break
    if steady is not None and U0 > 0:
        _, _, R = fit_circle(xx[steady], yy[steady])
        Us = float(np.mean(UU[steady]))
        out["steady_diameter_L"] = 2 * R / L
        out["steady_speed_ratio"] = Us / U0
        out["speed_loss"] = 1.0 - Us / U0
    else:
        out["steady_diameter_L"] = out["steady_speed_ratio"] = out["speed_loss"] = None
    return out


# --------------------------------------------------------------------------- zigzag

@dataclass
class _Switches:
    times: list           # execute times [s]: the first execute, then each reversal
    headings: list        # heading [rad] at each execute (the switching heading for reversals)
    sides: list           # rudder side (+1 starboard, -1 port) from each execute on
    windows: list         # per reversal: (i0, i1) samples in which its extreme must lie
    amplitude: float | None = None
    measured: bool = False

    def heading_at(self, t, psi, k: int) -> float:
        """Heading of ``psi`` at execute k, evaluated as the switching heading was."""
        if self.measured is None:                 # heading-switched: the level itself, shifted as psi is
            return self.headings[k]
        te = self.times[k]
        if self.measured:                          # midway between the samples before and in the move
            return float(np.interp(te, t, psi))
        return float(psi[min(int(np.searchsorted(t, te)), len(t) - 1)])


def _chain(t, rudder, measured):
    """Longest chain of holds at the amplitude, each left by a direct move to the other side's
    amplitude; plus a final direct reversal that reaches the amplitude but is not held (the run
    ended)."""
    t, d = np.asarray(t, dtype=float), np.asarray(rudder, dtype=float)
    holds = rudder_holds(t, d, measured)
    big = [h for h in holds if abs(h.level) >= MIN_MANOEUVRE_RUDDER]
    if not big:
        return [], None, None
    A = abs(max(big, key=lambda h: t[h.last] - t[h.first]).level)
    tol = max(2 * DEG, 0.2 * A)
    near = [abs(abs(h.level) - A) <= tol and abs(h.level) >= MIN_MANOEUVRE_RUDDER for h in holds]
    best, cur = [], []
    for k, h in enumerate(holds):
        if not near[k]:
            cur = []
            continue
        if cur and np.sign(h.level) == -np.sign(cur[-1].level) and h.move == cur[-1].last:
            cur.append(h)
        else:
            cur = [h]
        if len(cur) > len(best):
            best = list(cur)
    final = None
    if best:
        h = best[-1]
        sg = -np.sign(h.level)
        k = h.last
        while k + 1 < len(d) and sg * (d[k + 1] - d[k]) > 1e-12:
            k += 1
        if k > h.last and abs(d[k] - sg * A) <= tol:
            final = h.last
    return best, final, A


def _rudder_switches(t, psi, rudder, measured) -> _Switches:
    t = np.asarray(t, dtype=float)
    chain, final, A = _chain(t, rudder, measured)
    if not chain:
        return _Switches([float(t[0])], [float(psi[0])], [0.0], [], None, bool(measured))
    times = [_execute_time(t, h, measured) for h in chain]
    sides = [float(np.sign(h.level)) for h in chain]
    ends = [h.last for h in chain]
    if final is not None:
        times.append(float(0.5 * (t[final] + t[final + 1])) if measured else float(t[final + 1]))
        sides.append(-sides[-1])
    windows = []
    for k in range(1, len(chain)):           # reversals into a hold: extreme within that hold
        i0 = int(np.searchsorted(t, times[k]))
        windows.append((i0, ends[k]))
    sw = _Switches(times, [], sides, windows, A, bool(measured))
    sw.headings = [sw.heading_at(t, psi, k) for k in range(len(times))]
    return sw


def _heading_switches(t, psi, hi, lo, first, t0=None) -> _Switches:
    """The simulator's heading-switching law on a record without rudder: from the first execute at
    ``t0`` (default the start) with the rudder to side ``first``, reverse to port when the heading
    change reaches ``hi`` and to starboard when it comes down to ``lo`` [rad]; crossings interpolated."""
    t, psi = np.asarray(t, dtype=float), np.asarray(psi, dtype=float)
    t0 = float(t[0]) if t0 is None else float(t0)
    base = float(np.interp(t0, t, psi))
    d = psi - base
    i = int(np.searchsorted(t, t0))
    times, heads, sides, idx = [t0], [base], [float(first)], [i]
    side = float(first)
    n = len(t)
    level = hi if side > 0 else lo
    for j in range(i, n):                       # one pass: a switch only looks for the next level
        if side * (d[j] - level) < 0:
            continue
        if j == 0 or t[j - 1] < t0:
            tc = float(t[j])
        else:
            w = (level - d[j - 1]) / (d[j] - d[j - 1]) if d[j] != d[j - 1] else 1.0
            tc = float(t[j - 1] + w * (t[j] - t[j - 1]))
        times.append(tc)
        heads.append(base + level)
        side = -side
        sides.append(side)
        idx.append(j)
        level = hi if side > 0 else lo
    windows = []
    for k in range(1, len(idx)):
        windows.append((idx[k], idx[k + 1] - 1 if k + 1 < len(idx) else n - 1))
    return _Switches(times, heads, sides, windows, None, None)


def zigzag_switches(t, psi, order=None, angle=None, first=None):
    """Indices of the executes of a zigzag (the first sample at or after each execute time).

    With ``order`` (a rudder order or a measured rudder angle): see the module docstring.
    Without: the heading-switched law for switching heading ``angle`` [rad], first side +1
    (starboard) or -1, taken from the first clear heading change when None.
    """
    t = np.asarray(t, dtype=float)
    if order is not None:
        sw = _rudder_switches(t, psi, order, measured=True)
    else:
        if angle is None:
            raise ValueError("a zigzag record without rudder needs its switching heading angle")
        first = _first_side(psi, angle) if first is None else first
        sw = _heading_switches(t, psi, angle, -angle, first)
    return np.array([min(int(np.searchsorted(t, x)), len(t) - 1) for x in sw.times], dtype=int)


def _first_side(psi, angle):
    d = np.asarray(psi, dtype=float) - psi[0]
    big = np.flatnonzero(np.abs(d) > 0.2 * angle)
    return float(np.sign(d[big[0]])) if big.size else 1.0


def zigzag_metrics(t, psi, order=None, angle=None, first=None, U=None, L=None, *, measured=None,
                   levels=None, t_execute=None, r=None) -> dict:
    """Zigzag (and S-type) metrics.

    Parameters
    ----------
    t, psi : arrays
        Time [s], heading [rad, unwrapped].
    order : array, optional
        Rudder order or rudder angle [rad]; executes are read from it when given.
    angle : float, optional
        Switching heading change [rad] of a zigzag without ``order``.
    first : +1 or -1, optional
        First rudder side when ``order`` is absent.
    U, L : optional
        Speed [m/s] and length [m] for the distance to the second execute in L.
    measured : bool, optional
        Whether ``order`` is a measured rudder angle (holds of at least 2 s, the execute where
        the rudder starts to move) or an order (steps); default: an order when it only takes
        a few distinct values.
    levels : (hi, lo), optional
        Heading changes [rad] of the reversals without ``order`` (an S-type: (psi_S, 0));
        default (angle, -angle).
    t_execute : float, optional
        First execute [s] without ``order`` (default the start of the record).
    r : array, optional
        Yaw rate [rad/s]: a heading-sensor step it does not show (see :func:`corrected_heading`)
        between a reversal and its extreme is taken out of that overshoot.

    Returns
    -------
    dict with overshoots_deg (list, in order), initial_turning_time_s (first to second
    execute), period_s (mean full-cycle time), execute_times_s, switching_headings_deg
    (heading change from the first execute at each reversal), reversal_sides (+1 from a
    starboard rudder), rudder_deg (amplitude, None without rudder), heading_steps_removed
    ((t [s], step [deg]) taken out of the overshoots), approach_speed_mps and
    distance_to_second_execute_L when U (and L) are given.
    """
    t, psi = np.asarray(t, dtype=float), np.asarray(psi, dtype=float)
    if order is not None:
        o = np.asarray(order, dtype=float)
        sw = _rudder_switches(t, psi, o, len(np.unique(o)) > 8 if measured is None else measured)
    else:
        if levels is None:
            if angle is None:
                raise ValueError("a zigzag record without rudder needs its switching heading angle")
            levels = (angle, -angle)
        if first is None:
            first = _first_side(psi, max(abs(levels[0]), abs(levels[1])))
        sw = _heading_switches(t, psi, levels[0], levels[1], first, t_execute)
    out = {"execute_times_s": [float(x) for x in sw.times],
           "switching_headings_deg": [float((h - sw.headings[0]) / DEG) for h in sw.headings[1:]],
           "reversal_sides": [int(s) for s in sw.sides[:-1]][:max(len(sw.times) - 1, 0)],
           "rudder_deg": None if sw.amplitude is None else float(sw.amplitude / DEG)}
    out["heading_steps_removed"], out["overshoots_deg"] = _overshoots(t, psi, r, sw)
    out.update(_zigzag_times(t, sw.times, U, L))
    return out


def _overshoots(t, psi, r, sw) -> tuple[list, list]:
    """(heading-sensor steps taken out, overshoots [deg] in order) of the zigzag whose reversals are
    ``sw``: each hold's heading extreme beyond the heading at its reversal, while the heading turns back
    within the hold (:func:`zigzag_metrics`)."""
    dense = _median_dt(t) <= 0.25
    psi_c, steps = corrected_heading(t, psi, r)
    margin = (0.5 if dense else 0.2) * DEG     # a peak: the heading comes back by this much within the hold
    overs, used = [], []
    for k, (i0, i1) in enumerate(sw.windows, start=1):
        dirn = sw.sides[k - 1] or 1.0          # the heading still moves the way the previous rudder turned it
        ext = _extreme(t, psi_c, i0, i1, dirn, dense)
        if ext is None:
            break
        j = int(np.searchsorted(t, ext[0]))
        after = dirn * psi_c[j:i1 + 1]
        if after.size == 0 or dirn * ext[1] - np.min(after) < margin:
            break                              # the hold (record) ends before the heading turns back
        overs.append(float(dirn * (ext[1] - sw.heading_at(t, psi_c, k)) / DEG))
        used += [st for st in steps if sw.times[k] < st[0] <= ext[0]]
    return used, overs


def _zigzag_times(t, ts, U, L) -> dict:
    """The zigzag's ``initial_turning_time_s``, ``period_s`` (mean full cycle), and with the speed ``U``
    (and the length ``L``) ``approach_speed_mps`` and ``distance_to_second_execute_L``, from its execute
    times ``ts`` [s]."""
    out = {"initial_turning_time_s": float(ts[1] - ts[0]) if len(ts) > 1 else None}
    odd = ts[1::2]
    if len(ts) > 3:
        out["period_s"] = float(np.mean(np.diff(odd))) if len(odd) > 1 else float(ts[3] - ts[1])
    else:
        out["period_s"] = None
    if U is not None:
        U = np.asarray(U, dtype=float)
        out["approach_speed_mps"] = float(np.interp(ts[0], t, U))
        if L is not None and len(ts) > 1:
            m = (t > ts[0]) & (t < ts[1])
            tt = np.concatenate([[ts[0]], t[m], [ts[1]]])
            uu = np.interp(tt, t, U)
            out["distance_to_second_execute_L"] = float(np.trapezoid(uu, tt) / L)
    return out


def zigzag_problem(m: dict) -> str | None:
    """Why the zigzag metrics ``m`` are not those of a zigzag (or S-type), or None.

    A zigzag's rudder is reversed at least twice, always at the same heading change on each
    side (the check heading), and the reversals from a starboard rudder lie to starboard of
    those from a port rudder.  A random-rudder run reverses at no consistent heading.
    """
    sw = np.asarray(m["switching_headings_deg"], dtype=float)
    sides = np.asarray(m["reversal_sides"][:len(sw)], dtype=float)
    if len(sw) < 2:
        return (f"the rudder is reversed {len(sw)} time{'s' if len(sw) != 1 else ''} "
                f"(a zigzag reverses it at the check heading at least twice)")
    hi, lo = sw[sides > 0], sw[sides < 0]
    if hi.size and lo.size:
        sep = float(hi.min() - lo.max())
        spread = max(float(np.ptp(hi)), float(np.ptp(lo)))
        if sep < 2.0 or spread > max(4.0, 0.25 * sep):
            return (f"the rudder is reversed at heading changes {', '.join(f'{v:.1f}' for v in sw)} deg from the "
                    f"first execute: not at one check heading per side (a random-rudder or manual run?)")
    if len(m["overshoots_deg"]) == 0:
        return "no overshoot: the heading never turns back after a reversal within the record"
    return None


STOPPED_FRACTION = 0.01
"""A ship is stopped (dead in the water, MSC/Circ.1053 on the stopping test) when its surge speed through
the water has fallen to this fraction of the approach speed: where the simulator ends a run
(:func:`mmg.kernel.simulate_kernel`).  The distance still run from there to u = 0 is at most
(0.01 V)^2 / (2 a): centimetres for a ship braking at any astern thrust."""


def stopping_metrics(t, x, y, psi, u, v, L, t_execute: float = 0.0) -> dict:
    """Full-astern stopping test metrics (MSC.137(76) 5.3.4, MSC/Circ.1053); lengths divided by L.

    From the astern order at ``t_execute`` to the time the surge speed u first falls to
    :data:`STOPPED_FRACTION` of its value at the order (interpolated between samples; extrapolated
    from the last two when the record ends less than a step before it, as the simulator ends a run):

    * ``track_reach_L``: the distance along the path (the polyline of the positions);
    * ``head_reach_L``: the advance along the heading at the order;
    * ``lateral_deviation_L``: the offset from the approach line at the stop, + to starboard;
    * ``time_to_stop_s``, ``heading_change_deg`` (at the stop), ``sway_at_stop_mps`` (v there).

    Parameters
    ----------
    t, x, y, psi, u, v : arrays
        Time [s], midship position north / east [m], heading [rad], surge and sway speed through
        the water [m/s].
    L : float
        Ship length [m].
    t_execute : float
        Time of the astern order [s].

    Returns
    -------
    dict
        The figures above and ``stopped`` (False, the figures None, when u never falls that low).
    """
    t, x, y, psi, u, v = (np.asarray(a, dtype=float) for a in (t, x, y, psi, u, v))
    i0 = min(int(np.searchsorted(t, t_execute - 1e-9)), len(t) - 1)
    u_stop = STOPPED_FRACTION * u[i0]
    below = np.flatnonzero(u[i0:] <= u_stop)
    out = {"stopped": False, "track_reach_L": None, "head_reach_L": None, "lateral_deviation_L": None,
           "time_to_stop_s": None, "heading_change_deg": None, "sway_at_stop_mps": None}
    if below.size:
        i = i0 + int(below[0])
    elif len(t) - i0 >= 2 and 0.0 < u[-2] - u[-1] and u[-1] - u_stop <= u[-2] - u[-1]:
        i = len(t) - 1          # the simulator ends the run before the step that falls to u_stop: extrapolated
    else:
        return out
    if i == i0:
        return out
    w = (u[i - 1] - u_stop) / (u[i - 1] - u[i])        # of the way from sample i-1 to i (<= 2: one step on)

    def at(a):
        return a[i - 1] + w * (a[i] - a[i - 1])

    xs, ys = np.append(x[i0:i], at(x)), np.append(y[i0:i], at(y))
    c, s = np.cos(psi[i0]), np.sin(psi[i0])
    dx, dy = xs[-1] - x[i0], ys[-1] - y[i0]
    out.update(stopped=True, track_reach_L=float(np.sum(np.hypot(np.diff(xs), np.diff(ys)))) / L,
               head_reach_L=float(dx * c + dy * s) / L, lateral_deviation_L=float(-dx * s + dy * c) / L,
               time_to_stop_s=float(at(t) - t[i0]), heading_change_deg=float((at(psi) - psi[i0]) / DEG),
               sway_at_stop_mps=float(at(v)))
    return out
