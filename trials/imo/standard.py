"""The IMO standard manoeuvres of one ship and its criteria, deterministic.

Source: IMO Resolution MSC.137(76) (2002), *Standards for Ship Manoeuvrability*, Annex section 5.3
(criteria), with the explanatory notes MSC/Circ.1053 (2002) (the tests and their definitions).
The limits are defined once, in :mod:`trials.analysis.metrics` (``ADVANCE_LIMIT_L``,
:func:`~trials.analysis.metrics.zz10_overshoot_limits`, ...); this module names one criterion per
side of each manoeuvre and reads its value from the trial metrics of the same module.

The manoeuvres, at the approach speed V (MSC.137(76) 4.2.1 asks for at least 90 % of the speed at
85 % of the maximum engine output; here the speed the ship's bundled trial configs use, or the one
given), from a steady straight run, in calm deep water (a ship config's wind, current and shallow
water are left out):

* turning circles at 35 deg rudder (or the steering gear's maximum when smaller) to starboard and
  port: advance (<= 4.5 L) and tactical diameter (<= 5 L) (5.3.1);
* 10/10 zigzags, first rudder to starboard and to port: the track reach by the time the heading has
  changed by 10 deg, i.e. the distance run to the second execute (initial turning, <= 2.5 L, 5.3.2),
  the first and second overshoots (10 / 20 / 5 + L/(2V) deg and 25 / 40 / 17.5 + 0.75 L/V deg for
  L/V below 10 s, from 30 s, between; 5.3.3.1-2);
* 20/20 zigzags to both sides: first overshoot (<= 25 deg, 5.3.3.3);
* the full-astern stopping test (5.3.4): track reach <= 15 L (the Administration may accept up to
  20 L for ships of large displacement; the verdict is against 15 L), the rudder at midships, the
  engine ordered full astern from the approach revolutions (:class:`mmg.engine_order.AsternOrder`:
  a linear ramp to 0.7 of them astern in 120 s at full scale, 120 / sqrt(lambda) s on a model of scale
  lambda (:func:`mmg.engine_order.reversal_time`), the revolutions prescribed, the constants' sources
  there); the track reach is the distance along the path from the order to the ship stopped dead in
  the water, taken as the surge speed down to 1 % of the approach speed
  (:func:`trials.analysis.metrics.stopping_metrics`, which also gives the head reach and the lateral
  deviation).

A criterion's side is that of the turn, or of a zigzag's first rudder order.  The reversal ramp is the
manoeuvres' one time in seconds: the approach is a steady state, the rudder is ordered at t = 0, the run
lengths and time steps are in L / V and the steering gear's rate and time constant are the ship config's.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

from mmg.errors import InputError
from mmg.ship import Ship, load_ship, read_yaml
from mmg.model import G
from mmg.units import _QUANTITY, DEG, KNOT, MAX_SHIP_SPEED, UNITS, to_si

from ..analysis import metrics as MET
from ..runs.run import prepare_trial, run_trial
from ..runs.trial import Trial, stopping, turning, zigzag

__all__ = ["Criterion", "Plan", "criteria", "plan", "run_manoeuvres", "criterion_values", "approach_speed",
           "example_speed", "speed_label", "calm_water", "SIDES", "STOPPING", "STOPPING_RUN", "CALM_WATER_DROPS"]

SIDES = ("starboard", "port")
STOPPING = "stopping track reach"
STOPPING_RUN = "full astern stopping"
"""The run name of the stopping test (its metrics: :func:`trials.analysis.metrics.stopping_metrics`)."""
CALM_WATER_DROPS = ("wind", "current", "shallow_water")
"""Effects of a ship config left out of the standard manoeuvres (MSC.137(76) 4.2: deep, unrestricted
water, calm environment)."""

RUN_LENGTHS_L = {"turning circle": 14.0, "10/10 zigzag": 14.0, "20/20 zigzag": 8.0, STOPPING_RUN: 48.0}
"""First simulated run of each manoeuvre [L / V each: ship lengths at the approach speed]: the Esso Osaka
turns 180 deg in 10.3 L/V, its 10/10 second overshoot is past in 9.5 L/V, its 20/20 first in 4 L/V, it stops from full astern in 36 L/V (a stopping run ends
when the ship has stopped).  A run
that ends before its criteria can be read is run again twice as long, up to :data:`MAX_RUN_LENGTHS_L`
(the figures do not depend on the run's length once it gives them)."""
MAX_RUN_LENGTHS_L = 200.0
STEPS_PER_L = 600.0
"""Integration steps per L / V (rounded down to 1, 2 or 5 times a power of ten seconds: 0.1 s for the
325 m Esso Osaka at 10 kn, as its bundled trials)."""
STOPPING_STEPS_PER_L = 120.0
"""Integration steps per L / V of the stopping run (rounded down as :data:`STEPS_PER_L`, at most half the
steering gear's time constant): 0.5 s for the Esso Osaka.  The stop is slow (36 L/V): its track reach
with 0.5 s steps is within 0.003 L (0.02 %) of the one with 0.1 s steps (15.963 against 15.960 L), at a
quarter of the cost (12 against 44 ms a run), which matters in a sampled run."""


@dataclass(frozen=True)
class Criterion:
    """One criterion on one side: its name (the ``imo.json`` name), unit, limit, the manoeuvre run it
    is read from and the metric (a key of the trial metrics, or ``overshoots_deg[k]``)."""

    name: str
    unit: str
    limit: float | None
    manoeuvre: str | None
    metric: str | None


def criteria(L_over_V: float) -> list[Criterion]:
    """The criteria for L/V [s], one per side of each manoeuvre, the stopping test last (limits from
    :mod:`trials.analysis.metrics`)."""
    os1, os2 = MET.zz10_overshoot_limits(L_over_V)
    out = []
    for s in SIDES:
        out += [Criterion(f"advance, {s}", "L", MET.ADVANCE_LIMIT_L, f"turning circle, {s}", "advance_L"),
                Criterion(f"tactical diameter, {s}", "L", MET.TACTICAL_DIAMETER_LIMIT_L, f"turning circle, {s}",
                          "tactical_diameter_L")]
    out += [Criterion(f"initial turning track reach, {s}", "L", MET.INITIAL_TURNING_LIMIT_L, f"10/10 zigzag, {s}",
                      "distance_to_second_execute_L") for s in SIDES]
    out += [Criterion(f"10/10 first overshoot, {s}", "deg", os1, f"10/10 zigzag, {s}", "overshoots_deg[0]")
            for s in SIDES]
    out += [Criterion(f"10/10 second overshoot, {s}", "deg", os2, f"10/10 zigzag, {s}", "overshoots_deg[1]")
            for s in SIDES]
    out += [Criterion(f"20/20 first overshoot, {s}", "deg", MET.ZZ20_FIRST_OVERSHOOT_LIMIT_DEG, f"20/20 zigzag, {s}",
                      "overshoots_deg[0]") for s in SIDES]
    out.append(Criterion(STOPPING, "L", MET.STOPPING_LIMIT_L, STOPPING_RUN, "track_reach_L"))
    return out


def _metric(m: dict, key: str) -> float | None:
    if key.startswith("overshoots_deg["):
        k = int(key[len("overshoots_deg["):-1])
        ov = m.get("overshoots_deg") or []
        return float(ov[k]) if len(ov) > k else None
    v = m.get(key)
    return None if v is None else float(v)


@dataclass(frozen=True)
class Plan:
    """The standard manoeuvres of a ship: one :class:`~trials.runs.trial.Trial` per run name, built at
    ``speed`` (as given, e.g. ``"10 kn"``) with ``u0`` [m/s] and the turning rudder [rad]."""

    ship: Ship
    speed: str
    u0: float
    rudder: float
    trials: dict
    notes: tuple = ()

    @property
    def L_over_V(self) -> float:
        """L / V [s]: the ship length over the approach speed."""
        return self.ship.particulars.L / self.u0


def calm_water(ship: Ship) -> tuple[Ship, list[str]]:
    """``ship`` without the effects of :data:`CALM_WATER_DROPS`, and a note per effect left out."""
    es = ship.effect_set()
    gone = [n for n in CALM_WATER_DROPS if es.get(n) is not None]
    if not gone:
        return ship, []
    rest = es.without(*gone)
    return (replace(ship, effects=rest if rest.items else None),
            [f"the ship config's {', '.join(gone)} left out: the standard's manoeuvres are in calm deep water"])


def _nice_step(x: float) -> float:
    """The largest 1, 2 or 5 times a power of ten not above ``x``."""
    e = 10.0 ** math.floor(math.log10(x))
    return max(m * e for m in (1.0, 2.0, 5.0) if m * e <= x * (1 + 1e-9))


def _parse_speed(speed: str) -> float:
    try:
        return to_si(speed, "speed", 0.0, MAX_SHIP_SPEED, lo_open=True)
    except ValueError as e:
        raise InputError("speed", str(speed), str(e)) from None


def plan(ship: Ship, speed: str) -> Plan:
    """The standard manoeuvres of ``ship`` at ``speed`` (a string with its unit), in calm deep water.

    Parameters
    ----------
    ship : Ship
    speed : str
        Approach speed, e.g. ``"10 kn"``.

    Returns
    -------
    Plan

    Raises
    ------
    mmg.errors.InputError
        A speed that is not a positive speed with its unit, or one the trial builders refuse.
    """
    u0 = _parse_speed(speed)
    calm, notes = calm_water(ship)
    L = calm.particulars.L
    dt = f"{_nice_step(L / u0 / STEPS_PER_L):g} s"
    dur = {k: f"{v * L / u0:.6g} s" for k, v in RUN_LENGTHS_L.items()}
    rud = min(35.0 * DEG, calm.steering.delta_max)
    if rud < 35.0 * DEG:
        notes.append(f"turning circles at the steering gear's maximum {rud / DEG:g} deg (below 35 deg)")
    if L < 100.0:
        notes.append(f"L = {L:g} m: MSC.137(76) applies to ships of 100 m and over; the L/V limits use this "
                     f"hull's own L/V = {L / u0:.3g} s (a Froude-scaled model's full-scale L/V is sqrt(scale) times it)")
    trials = {}
    for k, s in enumerate(SIDES):
        sign = 1.0 if k == 0 else -1.0
        kw = {"speed": speed, "dt": dt}
        trials[f"turning circle, {s}"] = turning(calm, rudder=f"{sign * rud / DEG:.12g} deg",
                                                 duration=dur["turning circle"], **kw)
        trials[f"10/10 zigzag, {s}"] = zigzag(calm, rudder="10 deg", heading="10 deg", first=s,
                                              duration=dur["10/10 zigzag"], **kw)
        trials[f"20/20 zigzag, {s}"] = zigzag(calm, rudder="20 deg", heading="20 deg", first=s,
                                              duration=dur["20/20 zigzag"], **kw)
    dt_stop = f"{_nice_step(min(L / u0 / STOPPING_STEPS_PER_L, calm.steering.T_E / 2)):g} s"
    trials[STOPPING_RUN] = stopping(calm, speed=speed, dt=dt_stop, duration=dur[STOPPING_RUN],
                                    log={"interval": dt_stop})
    return Plan(calm, speed, u0, rud, trials, tuple(notes))


def _needed(name: str, L_over_V: float) -> list[str]:
    return [c.metric for c in criteria(L_over_V) if c.manoeuvre == name]


def run_manoeuvres(p: Plan, ship: Ship | None = None) -> dict:
    """Run every manoeuvre of plan ``p`` (with ``ship`` instead of the plan's, e.g. a sampled one).

    A run that ends before its criteria can be read (a slow turn, a long zigzag) is run again twice
    as long, up to :data:`MAX_RUN_LENGTHS_L` ship lengths.

    Returns
    -------
    dict
        Run name -> (:class:`~trials.runs.run.TrialRun`, its metrics dict).
    """
    out, prepared = {}, None
    max_s = MAX_RUN_LENGTHS_L * p.L_over_V
    for name, trial in p.trials.items():
        tr: Trial = trial if ship is None else replace(trial, ship=ship)
        prepared = prepared or prepare_trial(tr)          # one approach for all: same ship, speed, effects
        keys = _needed(name, p.L_over_V)
        while True:
            run = run_trial(tr, prepared)
            m = run.metrics()
            if (all(_metric(m, k) is not None for k in keys) or not run.result.completed
                    or 2 * tr.duration > max_s * (1 + 1e-9)):
                break
            tr = replace(tr, duration=2 * tr.duration)
        out[name] = (run, m)
    return out


def criterion_values(p: Plan, runs: dict) -> dict:
    """Criterion name -> value (None where the run does not give it)."""
    return {c.name: _metric(runs[c.manoeuvre][1], c.metric) for c in criteria(p.L_over_V)}


def approach_speed(ship: Ship) -> tuple[str, list[str]]:
    """The approach speed of ``ship``'s bundled turning and zigzag trials (``configs/trials``), and their files.

    Raises
    ------
    mmg.errors.InputError
        No bundled trial of this ship (a ship of one's own, an identified one), or trials at several
        speeds: the speed must be given.
    """
    from mmg.resources import bundled, ship_path, trial_path

    speeds, files = {}, []
    for name in bundled("trials"):
        path = trial_path(name)
        data = read_yaml(path)
        man = data.get("manoeuvre") or {}
        if man.get("kind") not in ("turning", "zigzag") or not isinstance(data.get("ship"), str):
            continue
        spec = data["ship"]
        sp = (path.parent / spec) if ("/" in spec or spec.endswith((".yaml", ".yml"))) else ship_path(spec)
        if _ship_name(Path(sp)) != ship.name:
            continue
        v = str((data.get("approach") or {}).get("speed"))
        speeds.setdefault(v, []).append(Path(path).name)
        files.append(Path(path).name)
    if len(speeds) == 1:
        return next(iter(speeds)), files
    if not speeds:
        raise InputError("speed", "", f"no bundled turning or zigzag trial of {ship.name!r} gives its approach speed: "
                                      f"give it (mmg imo --speed, e.g. {example_speed(ship)})")
    raise InputError("speed", "", f"the bundled trials of {ship.name!r} approach at several speeds "
                                  f"({', '.join(speeds)}): give one (mmg imo --speed)")


EXAMPLE_FULL_SCALE_SPEED = 10.0 * KNOT
"""A full-scale ship's approach speed in the examples of the messages [m/s] (10 kn, the Esso Osaka's trials)."""
EXAMPLE_FROUDE_NUMBER = 0.1
"""Froude number V / sqrt(g L) of the example speed of a ship with no ``full_scale:`` section (approach
speeds of large ships are Froude numbers 0.09-0.12)."""


def example_speed(ship: Ship) -> str:
    """An approach speed in ``ship``'s own scale, with where it comes from, for a message.

    A model (its config's ``full_scale:`` section) gets 10 kn Froude-scaled from the full-scale ship,
    10 kn / sqrt(lambda) (:attr:`mmg.ship.Ship.froude_scale`); any other ship the speed of Froude number
    :data:`EXAMPLE_FROUDE_NUMBER`, 0.1 sqrt(g L).

    Returns
    -------
    str
        E.g. ``"'0.49 m/s' (10 kn Froude-scaled to this 2.98 m model, lambda = 109)"``.
    """
    L = ship.particulars.L
    if ship.full_scale is not None:
        lam = ship.froude_scale
        u = EXAMPLE_FULL_SCALE_SPEED / math.sqrt(lam)
        why = f"10 kn Froude-scaled to this {L:.3g} m model, lambda = {lam:.3g}"
    else:
        u = EXAMPLE_FROUDE_NUMBER * math.sqrt(G * L)
        why = (f"Froude number {EXAMPLE_FROUDE_NUMBER:g} for L = {L:.3g} m, {EXAMPLE_FROUDE_NUMBER:g} sqrt(g L); "
               f"0.09-0.12 is usual")
    return f"'{u:.2g} m/s' ({why})"


def speed_label(speed: str, u0: float) -> str:
    """The approach speed as given, then in m/s when it was given in another unit: ``"10 kn (5.144 m/s)"``,
    ``"0.5 m/s"`` (never the same speed twice)."""
    text = str(speed).strip()
    m = _QUANTITY.match(text)
    if m and UNITS["speed"].get(m.group(2) or m.group(3)) == 1.0:
        return text
    return f"{text} ({u0:.4g} m/s)"


_NAMES: dict = {}


def _ship_name(path: Path) -> str | None:
    key = str(path.resolve())
    if key not in _NAMES:
        try:
            _NAMES[key] = load_ship(path).name
        except InputError:
            _NAMES[key] = None
    return _NAMES[key]
