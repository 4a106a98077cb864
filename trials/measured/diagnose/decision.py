"""The naming decision of ``mmg diagnose``: what an effect's fit must clear to be named
(:func:`trials.measured.diagnose.diagnose`); a module of its own so that the report and the
identifiability check read it without importing the workflow.

An effect is named when three tests hold:

1. **evidence**: its dBIC exceeds :data:`BIC_THRESHOLD` (the model with it replays the records
   better by more than the parameters it costs);
2. **precision**: its presence parameters differ from their neutral values by more than
   :data:`Z_THRESHOLD` standard errors;
3. **size beyond the ship's own mismatch**: its magnitude (:func:`magnitude`: a current's speed over
   sqrt(g L), a rudder offset's or heading bias's |angle| in deg, a wind's load scale, shallow water's
   T/H) exceeds the *calibrated floor* for the effect and the kind of record set
   (:func:`record_kind`: turn or zigzag, by the rudder).  A ship is never its config: on records
   with no effect at all the fit of a candidate still finds a small current, offset or bias that
   soaks up the hull's, rudder's and propeller's own errors, and with 3500 samples its dBIC and z
   are large.  The floors bound the sizes the candidates took on clean records of a family of
   ships that differ from the config as real ships do (:mod:`trials.measured.mismatch`; hull
   linear terms +-10 %, nonlinear +-25 %, rudder and propeller constants +-15 %, other wind-load
   factors, another hull form): :func:`trials.measured.diagnose.calibration.calibrate` (its module docstring
   gives the rule) sets them and ``bench/calibrate_diagnose.py`` writes them, with their sources
   and the clean samples, to the packaged
   ``configs/calibration/diagnose.yaml``.  On a zigzag a current is judged by its components along
   and across the records' mean heading, each against its own floor (:func:`clears_floor`): the
   ship's own speed mismatch lends a current along the heading, hardly any across it.

:func:`false_alarm_probability` reads the same clean magnitudes: the share of clean records on
which the candidate's magnitude reached the value (with one added record for the value itself,
so never 0 from a finite sample).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

import mmg.effects as E
from mmg.model import G

from .rules import module_rule, rule

__all__ = ["BIC_THRESHOLD", "Z_THRESHOLD", "WEAK_BIC", "evidence_short", "KINDS", "magnitude", "record_kind", "floor",
           "false_alarm_probability", "calibration", "residual_floor", "current_components", "mean_heading",
           "clears_floor", "over_floor", "floor_parts", "least_floor", "COMPONENT_FLOORS", "STATISTICAL_REASON",
           "REASON_KINDS", "KIND_FALLBACK", "by_kind", "packaged_calibration", "PART_UNITS", "SPEED_UNIT", "speed_part_units",
           "part_units", "part_size", "part_name", "typical_speed"]

_RULES = {"BIC_THRESHOLD": "bic_threshold", "Z_THRESHOLD": "z_threshold", "WEAK_BIC": "weak_bic"}
"""The module's names of numbers of the diagnosis rules (:mod:`.rules`), read-only: ``BIC_THRESHOLD``, the dBIC
an effect must exceed to be named; ``Z_THRESHOLD``, the standard errors its presence parameters must lie from
neutral; ``WEAK_BIC``, the dBIC above which evidence short of a name is reported (:func:`evidence_short`)."""
__getattr__ = module_rule(__name__, _RULES)

KINDS = ("turn", "zigzag", "turn_pair", "turn_drift")
"""Kinds of record set the floors are calibrated for: :func:`record_kind`'s three, and ``turn_drift``,
turns to one side whose baseline freed the hull's drift nonlinearities
(:data:`trials.measured.diagnose.DRIFT_KIND`)."""
KIND_FALLBACK = {"turn_drift": "turn"}
"""The kind whose calibration stands in where a calibration file has none for a kind."""
STATISTICAL_REASON = "its standard error and correlation"
"""The ``reason`` of a ``not_identifiable`` entry reported for its statistics (its standard error could
not have shown the size to detect: :func:`trials.measured.diagnose.identifiability.verdict`), as against its
calibrated floor, its evidence or too little information."""

REASON_KINDS = ("statistics", "floor", "evidence", "information", "rival", "straight_run", "coefficients",
                "absorbed")
"""The kinds of ``not_identifiable`` reasons, each entry's ``reason_kind``: its standard error and
confounding (:data:`STATISTICAL_REASON`), the calibrated floor (the ship's own mismatch lends it as much),
evidence short of a name, too little information (:func:`trials.measured.diagnose.identifiability.verdict`,
:func:`trials.measured.diagnose.within_mismatch`, :func:`trials.measured.diagnose.weak_evidence`), and a
name withheld because another candidate with as much evidence takes its evidence away
(:func:`trials.measured.diagnose.withheld`), or whose fit the record's straight run contradicts
(:func:`trials.measured.diagnose.straight_contradicts`), or a coefficient effect not fitted because the fit
frees every coefficient it changes (:func:`trials.measured.diagnose._covered`), or one that cleared every
test in the round the wind was named and lost its evidence to the wind's shape terms
(:func:`trials.measured.diagnose.verdicts.absorbed`)."""

MAGNITUDE_UNITS = {n: c.magnitude_unit for n, c in E.REGISTRY.items()}
"""The unit of each effect's :func:`magnitude` (:attr:`mmg.effects.Effect.magnitude_unit`)."""


def evidence_short(delta_bic: float, z: float) -> bool:
    """Whether a candidate's evidence is some but short of a name (:data:`WEAK_BIC` < dBIC <=
    :data:`BIC_THRESHOLD`) while its precision would pass (z > :data:`Z_THRESHOLD`)."""
    return bool(rule("weak_bic") < delta_bic <= rule("bic_threshold") and z > rule("z_threshold"))


def magnitude(effect: str, values: dict, L: float) -> float:
    """How large an effect is, in a measure that does not depend on the ship's size: the effect's own
    :meth:`mmg.effects.Effect.magnitude` (unit :data:`MAGNITUDE_UNITS`) of its reported values and the ship's
    length ``L`` [m]; NaN for an effect not registered."""
    cls = E.REGISTRY.get(effect)
    return cls.magnitude(values, L) if cls is not None else math.nan


def current_components(values: dict, L: float, heading: float) -> tuple[float, float]:
    """A current's components along and across a heading, over sqrt(g L).

    Parameters
    ----------
    values : dict
        The current's reported values (``speed_mps``, ``direction_deg``: the direction it sets
        towards, clockwise from north).
    L : float
        Ship length [m].
    heading : float
        The heading [rad, clockwise from north] (:func:`mean_heading` of the records).

    Returns
    -------
    (float, float)
        Along (positive ahead) and across (positive to starboard) components over sqrt(g L).
    """
    s = float(values["speed_mps"]) / math.sqrt(G * L)
    a = math.radians(float(values["direction_deg"])) - heading
    return s * math.cos(a), s * math.sin(a)


def mean_heading(psis) -> float:
    """The circular mean [rad] of the logged headings of a set of records (arrays in rad)."""
    a = np.concatenate([np.asarray(p, float).ravel() for p in psis])
    a = a[np.isfinite(a)]
    return float(math.atan2(np.mean(np.sin(a)), np.mean(np.cos(a)))) if len(a) else 0.0


COMPONENT_FLOORS = {"zigzag": ("current_along", "current_across")}
"""Kinds of record on which a current's size is judged by its components along and across the mean
heading (in that order), each against a floor of its own (the calibration's ``current_along``, ``current_across``).
On a zigzag the ship's own speed mismatch (resistance, thrust, wake) lends a current along the
heading, hardly any across it (see ``bench/calibrate_diagnose.py``); a turn sweeps every heading and
keeps the speed's floor."""

SPEED_UNIT = "U"
"""The unit of a part floor that scales with the ship's speed: a fraction of the records'
:func:`typical_speed` U (a part of 0.015 U is 0.116 m/s at U = 7.72 m/s, 15 kn)."""
PART_UNITS = {part: MAGNITUDE_UNITS["current"] for parts in COMPONENT_FLOORS.values() for part in parts}
"""The units :mod:`.calibration` sets the part floors in by default: both over sqrt(g L), as the current's
:func:`magnitude`.  :func:`speed_part_units` sets the part along the heading in :data:`SPEED_UNIT`
instead (a resistance, thrust or wake mismatch errs the speed by a share of that speed).  A calibration
file says its own (its ``units``)."""


def speed_part_units() -> dict:
    """:data:`PART_UNITS` with the part along the heading in :data:`SPEED_UNIT`."""
    along = [parts[0] for parts in COMPONENT_FLOORS.values()]           # the first part: along the heading
    return {**PART_UNITS, **dict.fromkeys(along, SPEED_UNIT)}


def typical_speed(meas) -> float:
    """The records' typical speed U [m/s]: the median over every sample of every record of the logged
    speed over ground, hypot(u, v) (``meas`` a sequence of (N, >=2) arrays, u, v [m/s] their first
    columns); 0 where no sample is finite.

    Parameters
    ----------
    meas : sequence of array_like
        The records' measured states, each (N, >=2) with u, v [m/s] as its first two columns.

    Returns
    -------
    float
        U [m/s]; 0.0 where no sample is finite.
    """
    a = np.concatenate([np.hypot(np.asarray(m, float)[:, 0], np.asarray(m, float)[:, 1]) for m in meas])
    a = a[np.isfinite(a)]
    return float(np.median(a)) if len(a) else 0.0


def part_units(kind: str, units: dict | None = None) -> dict:
    """``{part floor: unit}`` of the parts a current is judged by on ``kind`` (:data:`COMPONENT_FLOORS`),
    as ``units`` (the calibration's by default) says them; a part it does not name is in sqrt(gL).

    Parameters
    ----------
    kind : str
        The kind of the record set (:func:`record_kind`); a kind without part floors has none.
    units : dict, optional
        ``{part floor: unit}``; the calibration file's ``units`` by default.

    Returns
    -------
    dict
        ``{part floor name (e.g. "current_along"): unit}``, the unit ``"sqrt(gL)"`` (as :func:`magnitude`
        gives a current) or :data:`SPEED_UNIT`; empty for a kind judged by the magnitude alone.
    """
    units = (calibration().get("units") or {}) if units is None else units
    return {c: str(units.get(c, MAGNITUDE_UNITS["current"])) for c in COMPONENT_FLOORS.get(kind, ())}


def part_size(x: float, unit: str, L: float, speed: float | None) -> float:
    """A current's part ``x`` (over sqrt(g L), :func:`current_components`) in a part floor's ``unit``:
    itself for sqrt(gL), x sqrt(g L) / U for :data:`SPEED_UNIT` (U = ``speed`` [m/s], the records'
    :func:`typical_speed`; NaN without a speed).

    Parameters
    ----------
    x : float
        The part, over sqrt(g L) [-].
    unit : str
        The part floor's unit (:func:`part_units`).
    L : float
        Ship length [m].
    speed : float or None
        The records' typical speed U [m/s]; needed for :data:`SPEED_UNIT` only.

    Returns
    -------
    float
        The part in ``unit`` [-]; NaN for :data:`SPEED_UNIT` without a positive speed.
    """
    if unit != SPEED_UNIT:
        return x
    return x * math.sqrt(G * L) / speed if speed and speed > 0 else math.nan


def part_name(part_floor: str) -> str:
    """The name a part floor's part is reported under: the last word of the floor's name.

    Parameters
    ----------
    part_floor : str
        A part floor's name (:data:`COMPONENT_FLOORS`, e.g. ``"current_along"``).

    Returns
    -------
    str
        The part (``"along"``, ``"across"``): the key of :func:`floor_parts` and of a candidate's ``parts``.
    """
    return part_floor.split("_")[-1]


def clears_floor(effect: str, values: dict, L: float, kind: str, heading: float | None = None,
                 speed: float | None = None) -> bool:
    """Whether an effect's size exceeds the calibrated floor on a record set of ``kind``: its
    :func:`magnitude` over :func:`floor`, or, for a current on a kind of :data:`COMPONENT_FLOORS`
    with its component floors calibrated and ``heading`` given (and ``speed`` where a part's floor is
    in :data:`SPEED_UNIT`), either component (:func:`floor_parts`) over its own floor.

    Parameters
    ----------
    effect : str
    values : dict
        Its reported values.
    L : float
        Ship length [m].
    kind : str
        :func:`record_kind`.
    heading : float, optional
        The records' mean heading [rad] (:func:`mean_heading`).
    speed : float, optional
        The records' typical speed U [m/s] (:func:`typical_speed`).
    """
    parts = floor_parts(effect, values, L, kind, heading, speed)
    return over_floor(magnitude(effect, values, L), floor(effect, kind), parts)


def over_floor(size: float, fl: float, parts: dict | None = None) -> bool:
    """The floor rule on plain figures, the one definition :func:`clears_floor` (on an effect's values)
    and the diagnosis's stored candidates use: with ``parts`` ({part: (size, floor)}, a current judged
    by its parts) either part over its own floor, else ``size`` over ``fl``; a NaN size (an effect
    :func:`magnitude` does not know) is not stopped by a floor."""
    if parts:
        return any(abs(x) > f for x, f in parts.values())
    return not size <= fl


def floor_parts(effect: str, values: dict, L: float, kind: str, heading: float | None = None,
                speed: float | None = None) -> dict:
    """``{part: (size, floor)}`` of a current judged by its parts (:func:`clears_floor`): ``along`` and
    ``across``, each in its floor's unit (:func:`part_units`: over sqrt(gL), or over the records' speed
    ``speed`` [m/s] for :data:`SPEED_UNIT`); empty where the effect is judged by its :func:`magnitude`
    alone, or where a part's floor is in :data:`SPEED_UNIT` and no speed is given."""
    comp = _component_floors(effect, kind, calibration().get("floors") or {})
    if not comp or heading is None:
        return {}
    units = part_units(kind)
    if any(units[c] == SPEED_UNIT for c in comp) and not (speed and speed > 0):
        return {}
    parts = current_components(values, L, heading)
    return {part_name(c): (float(f"{part_size(x, units[c], L, speed):.4g}"), floor(c, kind))
            for x, c in zip(parts, comp)}


def least_floor(effect: str, kind: str, floors: dict | None = None, froude: float | None = None,
                units: dict | None = None) -> float:
    """The least size of ``effect`` that can clear its floor on a record set of ``kind``, in the unit
    of :func:`magnitude`: its floor, or, for a current judged by its parts there
    (:data:`COMPONENT_FLOORS`, :func:`clears_floor`), the smaller part's floor (a current that size
    across the heading clears it); a part floor in :data:`SPEED_UNIT` counts as floor * ``froude``
    (the records' U / sqrt(g L)), and not at all without it.  ``floors`` ({effect: {kind: floor}}) and
    ``units`` ({part floor: unit}): the calibration's by default; ``units`` defaults to
    :data:`PART_UNITS` where ``floors`` is given."""
    if floors is None:
        floors = calibration().get("floors") or {}
    elif units is None:
        units = PART_UNITS
    units = part_units(kind, units)
    comp = _component_floors(effect, kind, floors)
    sizes = [float(by_kind(floors[c], kind)) * (froude if units[c] == SPEED_UNIT else 1.0)
             for c in comp if units[c] != SPEED_UNIT or froude]
    if sizes:
        return float(min(sizes))
    return float(by_kind(floors.get(effect), kind, 0.0))


def _component_floors(effect: str, kind: str, floors: dict) -> tuple:
    """The names of the part floors ``effect`` is judged by on ``kind`` (:data:`COMPONENT_FLOORS`),
    where ``floors`` holds them all; else ()."""
    comp = COMPONENT_FLOORS.get(kind, ()) if effect == "current" else ()
    return comp if comp and all(by_kind(floors.get(c), kind) is not None for c in comp) else ()


def record_kind(rudders) -> str:
    """The kind of a set of records, which the floors are calibrated for: ``"zigzag"`` when any
    record's rudder changes side (a zigzag among turns pins an offset or a bias as a zigzag alone
    does), else ``"turn_pair"`` for turns to both sides, diagnosed together (calibrated on pairs of
    35 deg turns: ``bench/bench_diagnose.py --mismatch --trials turn_pair``), else ``"turn"``.

    A record's rudder is on one side when a share of at least ``side_share`` of its samples beyond
    ``side_rudder_deg`` have one sign (the diagnosis rules, :mod:`.rules`).

    Parameters
    ----------
    rudders : sequence of arrays
        Each record's rudder angle [rad].
    """
    sides = []
    share, beyond = rule("side_share"), math.radians(rule("side_rudder_deg"))
    for d in rudders:
        d = np.asarray(d, float)
        big = d[np.abs(d) > beyond]
        if len(big) == 0:
            continue
        pos = float(np.mean(big > 0))
        if pos < share and 1.0 - pos < share:
            return "zigzag"
        sides.append(pos >= share)
    return "turn_pair" if len(set(sides)) > 1 else "turn"


@lru_cache(maxsize=1)
def calibration() -> dict:
    """The packaged calibration (``configs/calibration/diagnose.yaml``): ``{"floors": {effect:
    {kind: value}}, "clean": {effect: {kind: [magnitudes]}}, ...}``; empty when absent.  The
    environment variable ``MMG_DIAGNOSE_CALIBRATION`` names another file, or ``none`` for no floors
    (how the calibration runs themselves diagnose)."""
    import os
    from pathlib import Path

    env = os.environ.get("MMG_DIAGNOSE_CALIBRATION")
    if env and env.lower() == "none":
        return {}
    return _read_calibration(Path(env)) if env else packaged_calibration()


@lru_cache(maxsize=1)
def packaged_calibration() -> dict:
    """The calibration shipped in the wheel (``configs/calibration/diagnose.yaml``) whatever
    ``MMG_DIAGNOSE_CALIBRATION`` says; empty when absent."""
    from mmg.resources import config_dir

    p = config_dir() / "calibration" / "diagnose.yaml"
    return _read_calibration(p) if p.is_file() else {}


def _read_calibration(p) -> dict:
    """A calibration file read and checked (one-line :class:`~mmg.errors.InputError` when it is not one)."""
    import yaml

    from mmg.errors import InputError

    if not p.is_file():                   # a file the user named and that is not there: refused, not ignored
        raise InputError(str(p), "MMG_DIAGNOSE_CALIBRATION", "no such calibration file (or 'none' for no floors)")
    try:
        data = yaml.safe_load(p.read_text()) or {}
    except yaml.YAMLError as e:
        raise InputError(str(p), "", f"not a calibration YAML: {str(e).splitlines()[0]}") from None
    if not isinstance(data, dict) or not isinstance(data.get("floors", {}), dict):
        raise InputError(str(p), "floors", "a calibration file maps effect -> kind -> floor")
    units = data.get("units") or {}
    if not isinstance(units, dict):
        raise InputError(str(p), "units", "a calibration file maps effect -> unit")
    for c in sorted({c for cs in COMPONENT_FLOORS.values() for c in cs} & set(units)):
        if units[c] not in (SPEED_UNIT, MAGNITUDE_UNITS["current"]):
            raise InputError(str(p), f"units.{c}", f"{units[c]!r} is not a unit of a current's part floor "
                                                   f"({SPEED_UNIT!r}: a fraction of the records' speed, or "
                                                   f"{MAGNITUDE_UNITS['current']!r})")
    return data


def by_kind(table: dict | None, kind: str, default=None):
    """``table[kind]``, or where the calibration has no entry for that kind, its
    :data:`KIND_FALLBACK`'s (else ``default``)."""
    table = table or {}
    if kind in table:
        return table[kind]
    return table.get(KIND_FALLBACK.get(kind), default)


def floor(effect: str, kind: str) -> float:
    """The calibrated magnitude an effect must exceed on a record of ``kind`` (0 where not calibrated)."""
    return float(by_kind((calibration().get("floors") or {}).get(effect), kind, 0.0))


def false_alarm_probability(effect_name: str, kind: str, statistic_value: float):
    """The calibrated probability that a candidate reaches ``statistic_value`` on records without it.

    Parameters
    ----------
    effect_name : str
        The effect (``current``, ``wind``, ...).
    kind : str
        The kind of record (:data:`KINDS`).
    statistic_value : float
        The effect's :func:`magnitude`.

    Returns
    -------
    float or None
        (k + 1) / (n + 1), k of the n clean calibration records on which the candidate's magnitude
        was at least the value; None where the effect and kind are not calibrated.
    """
    clean = by_kind((calibration().get("clean") or {}).get(effect_name), kind)
    if not clean or statistic_value is None or not math.isfinite(statistic_value):
        return None
    a = np.asarray(clean, float)
    return float((np.sum(a >= statistic_value) + 1) / (len(a) + 1))


def residual_floor(channel: str, U: float, L: float, kind: str = "zigzag") -> float:
    """The residual RMS the ship's own mismatch leaves in ``channel`` after the diagnosis's fit (SI:
    m/s for u, v, rad/s for r, rad for heading), from the calibration's ``residual_floors`` (u, v
    as a fraction of the speed U, r as r L / U, heading in deg) for the kind of record; 0 where not
    calibrated.

    Parameters
    ----------
    channel : str
        ``"u"``, ``"v"``, ``"r"`` or ``"heading"``.
    U : float
        The records' typical speed [m/s].
    L : float
        Ship length [m].
    kind : str
        The kind of record (:func:`record_kind`).
    """
    f = float((by_kind(calibration().get("residual_floors"), kind) or {}).get(channel, 0.0))
    if channel in ("u", "v"):
        return f * U
    if channel == "r":
        return f * U / L
    if channel == "heading":
        return math.radians(f)
    return 0.0
