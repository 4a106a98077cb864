"""The metrics of a record (:func:`record_metrics`, what ``mmg metrics`` runs): the manoeuvre's kind taken
from the trial or guessed from the record, its values filled from the trial that made it, and the refusal
of a record that is not the manoeuvre asked for.
"""
from __future__ import annotations

import numpy as np

from mmg.errors import InputError
from mmg.units import DEG

from .manoeuvres import _turn_hold, turning_metrics, zigzag_metrics, zigzag_problem


# --------------------------------------------------------------------------- records

def _header_angle(rec, key):
    v = rec.meta.get(key)
    if v is None:
        return None
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise InputError(rec.source, key, f"header value {v!r} is not a number of degrees") from None
    if not (np.isfinite(v) and 0 < abs(v) <= 180):
        raise InputError(rec.source, key, f"header value {v!r} is not a heading change in degrees (0 to 180)")
    return abs(v) * DEG


def _rad_hint(rec) -> str:
    span = float(np.ptp(rec.psi)) if rec.psi is not None and len(rec.psi) else 0.0
    return " (heading in radians where degrees are expected?)" if rec.meta.get("format") == "log" and span < 2 * np.pi * DEG else ""


MIN_TURN_DIAMETER_L = 1.0
"""Smallest tactical or steady turning diameter [ship lengths] of any ship.  The handiest ships
(twin-screw ferries, high-lift rudders) turn on tactical diameters of about 1.5-2 L, a single-screw
tanker on 2.5-3.5 L (the Esso Osaka's 3 m model: 2.6 L; the full-scale 325 m logs: 2.9-3.2 L): below
1 L the length given is not the ship's (a 3 m model's turn read with L = 20 m is 0.39 L).
``bench/turn_diameter_margins.py`` prints the margins on the real and simulated turns."""


def check_turning_diameters(m: dict, L: float, src: str) -> None:
    """Refuse turning metrics ``m`` whose tactical or steady diameter is below :data:`MIN_TURN_DIAMETER_L`
    (the record is not of a ship of length ``L`` [m]); the message gives the figure and the length it implies."""
    for key, words in (("tactical_diameter_L", "tactical diameter"), ("steady_diameter_L", "steady turning diameter")):
        d = m.get(key)
        if d is not None and np.isfinite(d) and d < MIN_TURN_DIAMETER_L:
            raise InputError(src, "length_m", f"{words} {d:.3g} L ({d * L:.3g} m for L = {L:g} m): no ship turns on a "
                                              f"circle smaller than {MIN_TURN_DIAMETER_L:g} L; not this ship's length? "
                                              f"(this turn is of a ship of at most {d * L / MIN_TURN_DIAMETER_L:.3g} m)")


TRIAL_DEFINED = {"rudder_deg": "rudder_deg"}
"""Metrics a trial defines, by the trial header's key they are filled from when the record cannot give them
(:func:`fill_from_trial`): the rudder angle of a turn, the rudder amplitude of a zigzag or S-type."""


def fill_from_trial(m: dict, trial: dict, notes: list | None = None) -> dict:
    """Fill the metrics of :data:`TRIAL_DEFINED` that ``m`` leaves None (a record without its rudder
    channel, a turn whose execute the trial set) from the trial's definition.

    Parameters
    ----------
    m : dict
        Metrics (:func:`turning_metrics`, :func:`zigzag_metrics`); filled in place.
    trial : dict
        The trial's header values (``rudder_deg``: the commanded rudder [deg], signed for a turn, the
        amplitude for a zigzag or S-type, as in :meth:`trials.runs.trial.Trial.summary`).
    notes : list, optional
        Gets a line per metric filled.

    Returns
    -------
    dict
        ``m``.
    """
    for key, src in TRIAL_DEFINED.items():
        if key in m and m[key] is None and trial.get(src) is not None:
            m[key] = float(trial[src])
            if notes is not None:
                notes.append(f"{key} is the trial's commanded {src} (the record has no rudder channel)")
    return m


def record_metrics(rec, kind=None, length=None, angle=None) -> dict:
    """Metrics of a read record, refusing one that is not the manoeuvre asked for.

    Parameters
    ----------
    rec : TrialRecord
    kind : {"turning", "zigzag", "stype"}, optional
        Default: the header's ``kind``; else, with a rudder channel, a zigzag if the rudder is
        reversed like one, a turn if it is held through 90 deg of heading change (a record that
        is neither is refused); without a rudder, a turn if the heading changes by more than 180 deg.
    length : float, optional
        Ship length L [m] when the record does not say.
    angle : float, optional
        Switching heading [rad] of a zigzag record without rudder channel or header.

    Returns
    -------
    dict: record, source, kind, length_m, execute_s (the first execute), notes (what was
    ignored or corrected on the way), and the metrics of :func:`turning_metrics` or
    :func:`zigzag_metrics`.

    Raises
    ------
    InputError
        No length, no channel the metrics need, a record that is not a turn / zigzag, or a turn
        on circles smaller than any ship's for this length (:func:`check_turning_diameters`).
    """
    src = rec.source or rec.name or "record"
    L = _record_length(rec, length, src)
    if rec.psi is None:
        from trials.files.logio import missing_channel

        raise missing_channel(rec, "psi", "manoeuvre metrics need the heading")
    notes = list(rec.meta.get("notes", []))
    psi = np.asarray(rec.psi, dtype=float)
    order = rec.meta.get("delta_order")
    rudder = order if order is not None else rec.delta
    U = rec.speed()
    asked = kind
    kind = kind or rec.meta.get("kind")
    if kind not in ("turning", "zigzag", "stype"):
        if kind and not asked:
            raise InputError(src, "kind", f"the header's trial kind is {kind}: mmg metrics measures turning, zigzag "
                                          f"and S-type trials (pass --kind to read the record as one)")
        kind = _guess_kind(rec, psi, rudder, order is None, src)
    out = {"record": rec.name, "source": rec.source, "kind": kind, "length_m": L}
    ctx = (src, f"--kind {asked}" if asked else "kind", notes)
    if kind == "turning":
        out.update(_record_turning(rec, psi, U, L, ctx))
    else:
        out.update(_record_zigzag(rec, psi, (U, L), kind, angle, ctx))
    if rec.meta.get("kind") == kind:                     # the header describes this trial
        fill_from_trial(out, rec.meta, notes)
    out["execute_s"] = out.get("execute_s", out.get("execute_times_s", [None])[0])
    te, U0 = out["execute_s"], out.get("approach_speed_mps")
    if te is not None and U0 and te - 10.0 >= rec.t[0]:
        Ub = float(np.interp(te - 10.0, rec.t, U))
        if abs(U0 - Ub) > 0.05 * U0:
            notes.append(f"the approach is not steady: the speed {'rose' if U0 > Ub else 'fell'} from {Ub:.3g} to "
                         f"{U0:.3g} m/s in the 10 s before the execute at t = {te:g} s")
    out["notes"] = notes
    return out


def _record_length(rec, length, src: str) -> float:
    """Ship length L [m]: ``length``, else the record's; a positive finite number."""
    L = length if length is not None else rec.meta.get("length_m")
    if L is None:
        raise InputError(src, "--length", "the log does not give the ship length; pass --length")
    try:
        L = float(L)
    except (TypeError, ValueError):
        raise InputError(src, "length_m", f"ship length {L!r} is not a number") from None
    if not (np.isfinite(L) and L > 0):
        raise InputError(src, "length_m", f"ship length {L!r} is not a positive number of metres")
    return L


def _record_turning(rec, psi, U, L: float, ctx) -> dict:
    """:func:`turning_metrics` of a record, refused when it is no turn; ctx = (source, field, notes)."""
    src, what, notes = ctx
    order = rec.meta.get("delta_order")
    rudder = order if order is not None else rec.delta
    if rec.x is None or rec.y is None:
        from trials.files.logio import missing_channel

        raise missing_channel(rec, "x" if rec.x is None else "y", "turning metrics need the track (positions)")
    te = rec.meta.get("execute_s") if rudder is None else None
    m = turning_metrics(rec.t, rec.x, rec.y, psi, U, L, t_execute=te,
                        delta=None if order is not None else rec.delta, order=order, n=rec.n)
    if m["advance_L"] is None:
        held = "" if m["rudder_deg"] is None else (f" while the rudder is held at {m['rudder_deg']:.1f} deg "
                                                   f"({m['execute_s']:g} to {m['turn_end_s']:g} s)")
        raise InputError(src, what, f"not a turning test: the heading turns by at most {m['max_heading_change_deg']:.1f} deg "
                                    f"from the execute at t = {m['execute_s']:g} s{held}; a turn needs 90 deg"
                                    f"{_rad_hint(rec)}")
    check_turning_diameters(m, L, src)
    if m["steady_from_deg"] == 180.0:
        notes.append(f"the turn ends at {m['heading_change_deg']:.0f} deg: steady diameter and speed loss are from "
                     f"the part after 180 deg, which may not be steady yet")
    return m


def _record_zigzag(rec, psi, speed_length, kind: str, angle, ctx) -> dict:
    """:func:`zigzag_metrics` of a record (zigzag or S-type), refused when it is neither; speed_length =
    (U, L), ctx = (source, field, notes)."""
    src, what, notes = ctx
    U, L = speed_length
    order = rec.meta.get("delta_order")
    rudder = order if order is not None else rec.delta
    if rudder is not None:
        m = zigzag_metrics(rec.t, psi, order=rudder, U=U, L=L, measured=order is None, r=rec.r)
    else:
        first = None
        if rec.meta.get("first") in ("starboard", "port"):
            first = 1 if rec.meta["first"] == "starboard" else -1
        if kind == "stype":
            a = _header_angle(rec, "switch_heading_deg") if angle is None else angle
            if a is None:
                from trials.files.logio import missing_channel

                raise missing_channel(rec, "delta", "an S-type trial without its rudder needs the switching "
                                                    "heading (switch_heading_deg) in its header")
            first = 1 if first is None else first
            levels = (a, 0.0) if first > 0 else (0.0, -a)
        else:
            a = angle if angle is not None else _header_angle(rec, "heading_deg")
            if a is None:
                from trials.files.logio import missing_channel

                raise missing_channel(rec, "delta", "a zigzag without its rudder needs --zigzag-angle (or "
                                                    "heading_deg in a log's header)")
            levels = (a, -a)
        m = zigzag_metrics(rec.t, psi, first=first, U=U, L=L, levels=levels, t_execute=rec.meta.get("execute_s"),
                           r=rec.r)
    why = zigzag_problem(m)
    if why is not None:
        name = "an S-type" if kind == "stype" else "a zigzag"
        raise InputError(src, what, f"not {name}: {why}{_rad_hint(rec) if rudder is None else ''}")
    for ts, st in m["heading_steps_removed"]:
        notes.append(f"a step of {st:+.1f} deg of the heading sensor at t = {ts:g} s, which the yaw rate does not "
                     f"show, is taken out of the overshoot it falls in")
    return m


def _guess_kind(rec, psi, rudder, measured, src) -> str:
    if rudder is None:
        return "turning" if abs(psi[-1] - psi[0]) > np.pi else "zigzag"
    z = zigzag_metrics(rec.t, psi, order=rudder, measured=measured)
    if zigzag_problem(z) is None:
        return "zigzag"
    h = _turn_hold(rec.t, rudder, measured)
    if h is not None and rec.x is not None:
        m = turning_metrics(rec.t, rec.x, rec.y, psi, rec.speed(), 1.0, delta=None if not measured else rudder,
                            order=None if measured else rudder, n=rec.n)
        if m["advance_L"] is not None:
            return "turning"
    raise InputError(src, "kind", f"neither a turning test (no rudder held through 90 deg of heading change) nor a zigzag "
                                  f"({zigzag_problem(z)}); pass --kind to say which it is meant to be")
