"""Calibration of the naming floors of ``mmg diagnose`` (:mod:`trials.measured.diagnose.decision`) from the
diagnoses of clean records, and of records with effects, of ships that differ from the config as
real ships do (:mod:`trials.measured.mismatch`; the records of ``bench/bench_diagnose.py --mismatch``,
each with its ``truth`` and every search round's candidate statistics).

For every clean record the first search round tries each candidate on top of the fitted ship; its
*clean magnitude* is the candidate's :func:`~trials.measured.diagnose.decision.magnitude` where its dBIC and
z clear their thresholds (it would be named but for the floor), else 0.  Where they do not clear,
the magnitude says nothing: a rudder offset on a turning circle wanders to its 10 deg bound at z 1.

A candidate is named on a clean record when it clears dBIC and z (probability p, the share that
did) *and* its magnitude exceeds the floor.  Per effect and kind of record (turn, zigzag) the floor
holds that chance to alpha / m (m candidates, alpha 0.05: the acceptance's false-alarm rate per
record), the passing magnitudes taken as half-normal (the law of |x| for a zero-mean normal x: a
size the ship's own mismatch lends an effect, with no preferred sign or direction) with their RMS
as the scale:

    floor = RMS(passing) * Q_half-normal(1 - alpha / (m p)),   0 where p <= alpha / m

and never below the largest passing magnitude seen.  A parametric tail, not the sample maximum
alone: 20 records per kind cannot place a 1 % quantile by themselves.

Effects whose floor on a kind of record exceeds the size worth detecting cannot be shown there at
that size (:func:`hidden_effects`: a rudder offset on one turning circle, reported
``not_identifiable``); the records that have them at such sizes lend the other candidates sizes that
count as clean samples (:func:`clean_magnitudes`), so :func:`calibrate` sets the floors twice: once
from the clean records, once with those.

``bench/calibrate_diagnose.py`` is the command over this module: it reads the bench's JSON and
writes the packaged ``configs/calibration/diagnose.yaml``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .decision import MAGNITUDE_UNITS, PART_UNITS
from .rules import module_rule, rule

__all__ = [
    "MIN_PASSING",
    "RESIDUAL_QUANTILE",
    "RESIDUAL_UNITS",
    "UNITS",
    "Calibration",
    "calibrate",
    "clean_magnitudes",
    "floors",
    "hidden_effects",
    "merge_kinds",
    "only_kind",
    "record_kind_of",
    "residual_floors",
    "short_of_name",
]

UNITS = {**MAGNITUDE_UNITS, **PART_UNITS}
"""Units of the floors and clean magnitudes, per effect (and per part of a current on zigzags: along the
heading a fraction of the records' speed U, across it over sqrt(gL))."""
RESIDUAL_UNITS = {"u": "fraction of U", "v": "fraction of U", "r": "r L / U", "heading": "deg"}
"""Units of the residual floors, per channel."""


def clean_magnitudes(records, L: float, hidden: dict | None = None, part_units: dict | None = None) -> tuple:
    """({effect: {kind: [clean magnitude]}}, the same of whether dBIC and z cleared, the same of
    the magnitudes whether or not they cleared).

    A candidate's sample is *clean* where the record does not have that effect and the model it is
    tried on holds exactly the effects the record has: every first round of a clean record, and the
    round of a record with effects right after its true effects were named (a wind named, what does
    the ship's mismatch lend a shallow-water candidate on top of it).  Before the true effects are
    in, the other candidates soak up theirs (a current takes a heading bias on a zigzag): that is
    the confusion :mod:`trials.measured.diagnose.identifiability` reports, not the ship's mismatch.

    ``hidden`` ({kind: {effect: floor}}, :func:`hidden_effects`, or {kind: set of effects}): effects
    that cannot be named on that kind of record (a rudder offset on one turning circle).  A record's
    true effects among them, at a size within their floor (:func:`_hidden_here`), are never in the
    model, so its rounds count as clean for the other candidates once its other true effects are
    in: what such an effect lends a current or shallow water on a turn is a nuisance of the same
    kind as the ship's own mismatch, and a name given for it is a wrong name."""
    import math

    from .decision import COMPONENT_FLOORS, current_components, magnitude, part_size

    bic, z_min = rule("bic_threshold"), rule("z_threshold")
    units = PART_UNITS if part_units is None else part_units
    out: dict = {}
    passes: dict = {}
    raw: dict = {}
    for rec in records:
        truth = set(rec.get("truth") or {})
        for rd in rec.get("rounds") or []:
            kind = rd.get("kind") or _trial_kind(rec)
            if set(rd.get("model", [])) != truth - _hidden_here(rec, (hidden or {}).get(kind, ()), L):
                continue       # before the true effects are in, a candidate soaks up theirs: not a clean sample
            for c in rd["candidates"]:
                if c["effect"] in truth:
                    continue
                ok = bool(c["delta_bic"] > bic and c["z"] > z_min)
                sizes = [(c["effect"], magnitude(c["effect"], c["parameters"], L))]
                if c["effect"] == "current" and kind in COMPONENT_FLOORS:
                    # bench runs of the family sail at heading 0 (trials.measured.mismatch.trial_records)
                    parts = current_components(c["parameters"], L, math.radians(rd.get("heading_deg", 0.0)))
                    speed = rd.get("speed_mps") or rec.get("speed_mps")
                    sizes += [(k, abs(part_size(x, units[k], L, speed))) for k, x in zip(COMPONENT_FLOORS[kind], parts)]
                for e, m in sizes:
                    out.setdefault(e, {}).setdefault(kind, []).append(float(m) if ok else 0.0)
                    passes.setdefault(e, {}).setdefault(kind, []).append(ok)
                    raw.setdefault(e, {}).setdefault(kind, []).append(float(m))
    return out, passes, raw


def _hidden_here(rec: dict, hidden, L: float) -> set:
    """The record's true effects among ``hidden`` (a set, or {effect: floor} from
    :func:`hidden_effects`) at a size its floor could lend: a larger one could have been named.  The
    bench's truth holds the fit values (``speed_mps``, ``offset_deg``, ``bias_deg``)."""
    from .decision import magnitude

    truth = rec.get("truth") or {}
    if not isinstance(hidden, dict):
        return set(hidden) & set(truth)
    return {e for e, fl in hidden.items() if e in truth and not magnitude(e, truth[e], L) > fl}


def floors(clean: dict, alpha: float, raw: dict | None = None) -> dict:
    """{effect: {kind: floor}} (module docstring): the passing share p taken at its upper 95 %
    (Clopper-Pearson) bound, not its estimate (0 of 23 is not a bound of 0); the scale the RMS of
    the passing sizes, or, with fewer than ``min_passing`` (the diagnosis rules, :mod:`.rules`) of them, of
    every size the candidate took (``raw``), passing or not (a conservative stand-in)."""
    from scipy.stats import beta, halfnorm

    from .decision import COMPONENT_FLOORS

    comps = {c for cs in COMPONENT_FLOORS.values() for c in cs}
    m0 = max(len([e for e in clean if e not in comps]), 1)
    out = {}
    for e, kinds in clean.items():
        out[e] = {}
        m = m0 * (2 if e in comps else 1)       # a current named when either component clears: alpha split
        for k, v in kinds.items():
            v = np.asarray(v, float)
            on = v[v > 0]
            n, kk = len(v), len(on)
            p_up = float(beta.ppf(0.95, kk + 1, max(n - kk, 1))) if n else 1.0
            f = 0.0
            if p_up > alpha / m:
                pool = on if kk >= rule("min_passing") else np.asarray((raw or {}).get(e, {}).get(k, v), float)
                scale = float(np.sqrt(np.mean(pool * pool))) if len(pool) else 0.0
                f = max(scale * float(halfnorm.ppf(1.0 - alpha / (m * p_up))), float(on.max()) if kk else 0.0)
            out[e][k] = float(f"{f:.4g}")
    return out


def record_kind_of(rec: dict) -> str:
    """The kind of record set a bench record was diagnosed as (its first round's, else by its trial)."""
    return (rec.get("rounds") or [{}])[0].get("kind") or _trial_kind(rec)


def _trial_kind(rec: dict) -> str:
    """A bench record's kind by its trial's name, for records whose rounds do not say it."""
    return "turn" if str(rec.get("trial", "")).startswith("turn") else "zigzag"


def only_kind(rec: dict, kind: str):
    """``rec`` when it is of ``kind`` (:func:`record_kind_of`), else None: a run's records of one kind,
    where the diagnosis of the other kind has changed since the run."""
    return rec if record_kind_of(rec) == kind else None


def hidden_effects(fl: dict, L: float) -> dict:
    """{kind: {effect: floor}} of the effects whose floor on that kind of record exceeds the size worth detecting
    (:data:`trials.measured.diagnose.identifiability.DETECTION_SIZE`): at the sizes worth detecting they are
    not named there, only reported ``not_identifiable``.  A current judged by its parts along and
    across the heading (on zigzags) is hidden only where the smaller part's floor exceeds it
    (:func:`~trials.measured.diagnose.decision.least_floor`)."""
    from .decision import least_floor
    from .identifiability import detection_size, floor_in_fit_unit

    out: dict = {}
    for e, kinds in fl.items():
        for k in kinds:
            least = least_floor(e, k, fl)
            if floor_in_fit_unit(e, least, L) > detection_size(e, L):
                out.setdefault(k, {})[e] = least
    return out


_RULES = {"MIN_PASSING": "min_passing", "RESIDUAL_QUANTILE": "residual_quantile"}
"""The module's names of numbers of the diagnosis rules (:mod:`.rules`), read-only: ``MIN_PASSING``, the
fewest passing sizes a floor's scale is taken from (else from every size the candidate took);
``RESIDUAL_QUANTILE``, the percentile of the clean records' residuals the residual floors are."""
__getattr__ = module_rule(__name__, _RULES)


def residual_floors(records) -> dict:
    """{kind: {channel: floor}}: the ``residual_quantile`` percentile (the diagnosis rules) of the residual RMS
    after the fit on the clean records: u, v over the
    speed, r as r L / U, heading [deg] (:func:`trials.measured.diagnose.decision.residual_floor`)."""
    import math

    vals: dict = {}
    for rec in records:
        if rec.get("truth") or "rms_after" not in rec:
            continue
        kind = record_kind_of(rec)
        ra, U, L = rec["rms_after"], rec["speed_mps"], rec["L_m"]
        v = vals.setdefault(kind, {"u": [], "v": [], "r": [], "heading": []})
        v["u"].append(ra["u"] / U)
        v["v"].append(ra["v"] / U)
        v["r"].append(math.radians(ra["r"]) * L / U)
        v["heading"].append(ra["heading"])
    q = rule("residual_quantile")
    return {k: {c: float(f"{np.percentile(x, q):.4g}") for c, x in v.items() if x}
            for k, v in vals.items()}


@dataclass(frozen=True)
class Calibration:
    """The floors of :func:`calibrate` and what they rest on.

    Attributes
    ----------
    floors : dict
        {effect: {kind: floor}} in :data:`UNITS`.
    residual_floors : dict
        {kind: {channel: floor}} in :data:`RESIDUAL_UNITS`.
    clean : dict
        {effect: {kind: [clean magnitude]}} (0 where dBIC or z did not clear), the second pass's.
    passes : dict
        {effect: {kind: [whether dBIC and z cleared]}}, alike.
    hidden : dict
        {kind: {effect: floor}} not named at the size worth detecting (the first pass's floors).
    n_clean, n_effects : int
        Records without and with effects.
    alpha : float
        The false-alarm rate per record the floors hold.
    """
    floors: dict
    residual_floors: dict
    clean: dict
    passes: dict
    hidden: dict
    n_clean: int
    n_effects: int
    alpha: float = 0.05
    units: dict = field(default_factory=lambda: dict(UNITS))

    def to_json(self) -> dict:
        """The document ``configs/calibration/diagnose.yaml`` holds (without its ``source``)."""
        return {"alpha": self.alpha, "units": self.units, "floors": self.floors,
                "residual_floors": self.residual_floors, "residual_floor_units": dict(RESIDUAL_UNITS),
                "clean": {e: {k: [float(f"{x:.4g}") for x in v] for k, v in kinds.items()}
                          for e, kinds in self.clean.items()}}

    def to_pandas(self):
        """One row per effect and kind: samples, passing dBIC and z, largest passing size, floor."""
        import pandas as pd

        rows = [{"effect": e, "kind": k, "samples": len(v), "passing": int(sum(self.passes[e][k])),
                 "max_passing": float(np.max(v)) if len(v) else 0.0, "floor": self.floors[e][k],
                 "unit": self.units.get(e, "")}
                for e, kinds in self.clean.items() for k, v in kinds.items()]
        return pd.DataFrame(rows)


def merge_kinds(old: dict, new: dict, kinds, effects=None) -> dict:
    """The calibration document ``old`` with the floors, residual floors and clean samples of the
    record ``kinds`` (e.g. ``("turn", "turn_pair")``) taken from ``new``, the other kinds' kept: a
    change of the diagnosis of one kind of record (its baseline) is recalibrated on that kind's runs
    alone.  A kind ``new`` has no floor for is dropped from ``old`` too: no floor of the diagnosis it
    replaced survives.  With ``effects`` (e.g. ``("current_along",)``) only those effects' floors,
    clean samples and units are taken from ``new``; every other figure of ``old`` (its residual
    floors too) is kept."""
    kinds = set(kinds)
    take = (lambda e: True) if effects is None else set(effects).__contains__
    out = dict(old)                                       # the old document's keys, in its order
    out.update({k: v for k, v in new.items() if k not in ("floors", "residual_floors", "clean", "source", "units")})
    out["units"] = {**old.get("units", {}), **{e: u for e, u in new.get("units", {}).items() if take(e)}}
    for key in ("floors", "clean"):
        merged = {}
        for e in dict.fromkeys([*old.get(key, {}), *new.get(key, {})]):     # old's effects first, in order
            row = {k: v for k, v in old.get(key, {}).get(e, {}).items() if k not in kinds or not take(e)}
            if take(e):
                row.update({k: v for k, v in new.get(key, {}).get(e, {}).items() if k in kinds})
            if row:
                merged[e] = row
        out[key] = merged
    res = {k: v for k, v in old.get("residual_floors", {}).items() if k not in kinds or effects is not None}
    if effects is None:
        res.update({k: v for k, v in new.get("residual_floors", {}).items() if k in kinds})
    out["residual_floors"] = res
    return out


def short_of_name(records, L: float) -> tuple[int, int]:
    """(clean records whose first round has a candidate with evidence short of a name, clean records):
    :func:`~trials.measured.diagnose.decision.evidence_short` with its size over the packaged floor, which
    ``mmg diagnose`` reports ``not_identifiable`` (:func:`trials.measured.diagnose.weak_evidence`).

    The first round, where ``weak_evidence`` reads the last: the calibration runs are made without
    floors (``MMG_DIAGNOSE_CALIBRATION=none``), so their later rounds follow names that the packaged
    floors would not have made; on a clean record that names nothing, which is what the floors are
    for, the last round of ``mmg diagnose`` is its first.  The floors are the packaged ones, not
    those a ``bench/calibrate_diagnose.py`` run has just computed (the same when it reruns the runs
    that made the packaged file)."""
    import math

    from .decision import clears_floor, evidence_short

    n = k = 0
    for r in records:
        if r.get("truth"):
            continue
        n += 1
        first = (r.get("rounds") or [{}])[0]
        kind, head = record_kind_of(r), math.radians(first.get("heading_deg") or 0.0)
        speed = first.get("speed_mps") or r.get("speed_mps")
        k += any(evidence_short(c["delta_bic"], c["z"]) and clears_floor(c["effect"], c["parameters"], L, kind, head, speed)
                 for c in first.get("candidates", []))
    return k, n


def calibrate(records, L: float, alpha: float = 0.05, part_units: dict | None = None) -> Calibration:
    """The naming floors from bench records (module docstring): a first pass over the clean
    records, then a second in which the records of effects a kind of record cannot show
    (:func:`hidden_effects`) count as clean samples for the other candidates.

    Parameters
    ----------
    records : list of dict
        Records of ``bench/bench_diagnose.py --mismatch`` (``truth``, ``rounds``, ``rms_after``, ...).
    L : float
        Length of the config's ship [m] (the current's sqrt(g L) unit).
    alpha : float
        False-alarm rate per clean record.
    part_units : dict, optional
        {part floor: unit} of a current's parts on zigzags (default :data:`PART_UNITS`; e.g.
        :func:`~trials.measured.diagnose.decision.speed_part_units`).
    """
    records = list(records)
    units = PART_UNITS if part_units is None else part_units
    clean, passes, raw = clean_magnitudes(records, L, part_units=units)
    hidden = hidden_effects(floors(clean, alpha, raw), L)
    clean, passes, raw = clean_magnitudes(records, L, hidden, units)
    n = sum(1 for r in records if not r.get("truth"))
    return Calibration(floors=floors(clean, alpha, raw), residual_floors=residual_floors(records), clean=clean,
                       passes=passes, hidden=hidden, n_clean=n, n_effects=len(records) - n, alpha=alpha,
                       units={**UNITS, **units})
