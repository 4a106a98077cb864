"""The candidate search: the effects to try (:func:`_candidates`, :func:`_covered`), forward selection
over them from the baseline, one round per name (:func:`_search`), and the final check of the named
ones in their joint fit (:func:`_prune`); :func:`search` is the three in order."""
from __future__ import annotations

import math
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from .baseline import DRIFT_KIND
from .decision import MAGNITUDE_UNITS, clears_floor, floor, floor_parts, magnitude, part_name, part_units
from .fit import _Model
from .options import DiagnoseOptions
from .rules import rule
from .report import fmt3, format_values, round_header, size_with_unit
from .statistics import _COLS, _chi2, _delta_bic, _effect_index, _effect_report, _taus

__all__ = ["search", "Searched", "straight_contradicts"]


def _candidates(recs, names, say):
    """(the effect classes to try, the log entries of those skipped and why)."""
    import mmg.effects as E

    cand, cand_log = [], []
    for nm in names:
        cls = E.get(nm, "--candidates")
        why = None
        if nm == "wind" and recs[0].seg.inputs.ext is not None:
            why = "wind loads are already in the model (ship config wind on)"
        for r in recs:
            why = why or cls.unavailable(r.seg.context)
            if why:
                why = f"{r.name}: {why}" if len(recs) > 1 and not why.startswith("wind loads") else why
                break
        if why:
            cand_log.append({"effect": nm, "skipped": why})
            say(f"candidate {nm} skipped: {why}")
        else:
            cand.append(cls)
    return cand, cand_log


def _covered(fitter, cand, say) -> tuple[list, list]:
    """(the candidates to fit, ``not_identifiable`` entries of those left out): a coefficient effect
    whose every changed coefficient (:meth:`mmg.effects.Effect.changed_coefficients`) the baseline
    frees is a change of the ship's own coefficients there, not something the records can tell from
    them, and is not fitted (shallow water on a turn whose drift terms are freed, :data:`DRIFT_KIND`)."""
    free = {f.name for f in fitter.ship_free}
    keep, out = [], []
    for cls in cand:
        ch = cls.changed_coefficients(fitter.ship)
        if not ch or not set(ch) <= free:
            keep.append(cls)
            continue
        reason = f"a change of coefficients this fit frees, every one ({', '.join(ch)})"
        say(f"candidate {cls.name} not fitted: {reason}")
        out.append({"effect": cls.name, "confused_with": list(ch), "correlation": None,
                    "what_would_separate": f"{cls.measured_by}, or a zigzag diagnosed with these records",
                    "reason": reason,
                    "reason_kind": "coefficients"})
    return keep, out


def _try_candidate(fitter, current, cls, taus, inflate, ns, o: DiagnoseOptions):
    """(dBIC, clears the thresholds, cls, fit, values, standard errors, z, magnitude) of ``current``
    plus ``cls``: screened with ``screen_nfev``, a promising one the budget stopped fitted on to
    ``max_nfev``; named only above the calibrated floor of its magnitude (:mod:`.decision`)."""
    effs = current.effects + [cls]
    ship0 = None if o.candidate_start == "config" else current.theta[:ns]
    m = fitter.fit(effs, start_ship=ship0, start_eff=list(current.theta[ns:]), max_nfev=o.screen_nfev)
    k = len(cls.fit_parameters())
    dbic = _delta_bic(current, m, k, taus, o.stride)
    vals, se, z = _effect_report(m, cls, inflate)
    if m.fit.iterations >= o.screen_nfev and o.max_nfev > o.screen_nfev and (dbic > 0 or z > rule("z_threshold")):
        m = fitter.fit(effs, start=m.theta, max_nfev=o.max_nfev - o.screen_nfev)
        dbic = _delta_bic(current, m, k, taus, o.stride)
        vals, se, z = _effect_report(m, cls, inflate)
    L = fitter.ship.particulars.L
    if ship0 is None and ns > 0 and _retry_from_current(fitter, cls, dbic, z, vals):
        m, dbic, vals, se, z = _nested_start(fitter, current, cls, taus, inflate, ns, o, (m, dbic, vals, se, z))
    mag = magnitude(cls.name, vals, L)
    ok = (dbic > rule("bic_threshold") and z > rule("z_threshold")
          and clears_floor(cls.name, vals, L, fitter.kind, fitter.heading, fitter.speed)
          and not straight_contradicts(current.straight, m.straight))
    return dbic, ok, cls, m, vals, se, z, mag, _confounding(m, cls)


def _retry_from_current(fitter, cls, dbic: float, z: float, vals: dict) -> bool:
    """Whether a candidate fitted from the config's ship terms is fitted again from the model it is
    tested against (:func:`_nested_start`, the better kept): where that fit stopped short of it (dBIC
    below 0) though its precision and size would name it; on a turn whose baseline freed the drift
    nonlinearities (:data:`TURN_HULL_TERMS`, :data:`DRIFT_KIND`) wherever it falls short of the
    evidence to name it: from the config's values a budget of a few evaluations does not
    bring them and the effect's own parameters together."""
    if fitter.kind == DRIFT_KIND:
        return dbic <= rule("bic_threshold")
    L = fitter.ship.particulars.L
    return dbic < 0 and z > rule("z_threshold") and clears_floor(cls.name, vals, L, fitter.kind, fitter.heading, fitter.speed)


def straight_contradicts(before, after) -> bool:
    """Whether a model leaves some record's straight run (:class:`ekf.identify.StraightRun`) more than
    :data:`~trials.measured.diagnose.decision.Z_THRESHOLD` of its standard errors off, and further off than the
    model it was tested against: the straight run reads a heading bias plus a current's cross part
    directly, so an effect whose fit it contradicts is asked for by the rest of the record (the
    ship's own mismatch on a turn), not by itself."""
    b, a = np.abs(np.asarray(before, float)), np.abs(np.asarray(after, float))
    return bool(len(a) and np.any((a > rule("z_threshold")) & (a > b)))


def _nested_start(fitter, current, cls, taus, inflate, ns, o: DiagnoseOptions, first):
    """The better (by dBIC) of ``first`` = (fit, dBIC, values, se, z) and a fit started from ``current``
    itself with the effect at its neutral start.  ``current`` plus the effect holds ``current`` (the
    effect at neutral), so a dBIC below zero says the fit from the config's ship terms stopped short
    of it within its budget; a candidate whose precision and size would name it is then not judged on
    that unfinished fit."""
    effs = current.effects + [cls]
    m = fitter.fit(effs, start_ship=current.theta[:ns], start_eff=list(current.theta[ns:]), max_nfev=o.max_nfev)
    dbic = _delta_bic(current, m, len(cls.fit_parameters()), taus, o.stride)
    if dbic <= first[1]:
        return first
    return (m, dbic, *_effect_report(m, cls, inflate))


def _parts(fitter, name: str, values: dict) -> dict:
    """``{"parts": {part: [size, floor]}, "part_units": {part: unit}}`` of a candidate judged by its
    parts (a current on a zigzag: :func:`~trials.measured.diagnose.decision.floor_parts`,
    :func:`~trials.measured.diagnose.decision.part_units`), else ``{}``."""
    p = floor_parts(name, values, fitter.ship.particulars.L, fitter.kind, fitter.heading, fitter.speed)
    if not p:
        return {}
    units = {part_name(c): u for c, u in part_units(fitter.kind).items()}
    return {"parts": {k: list(v) for k, v in p.items()}, "part_units": {k: units[k] for k in p}}


def _search(fitter, base, cand, ns, o: DiagnoseOptions, say):
    """Forward selection from the baseline: each round tries every remaining candidate and names the
    best that clears the thresholds and holds beside its rival (:func:`_best_standing`).  Each round
    fits with the straight runs weighted by sqrt(tau_v) of its model (the v channel's: the straight run
    is a mean of v).  Returns (final fit, named effects, the rounds' log, the last round's fitter)."""
    current, named, rounds, remaining = base, [], [], list(cand)
    lt = (fitter.ship.particulars.L, fitter.ship.particulars.T)
    while remaining:
        current = _polish(fitter, current, o)
        taus, inflate = _taus(current, o.stride)
        fitter = replace(fitter, straight_weight=math.sqrt(taus[1]))
        results, parts = [], []
        say(round_header(len(rounds) + 1, named))
        for cls in remaining:
            results.append(_try_candidate(fitter, current, cls, taus, inflate, ns, o))
            dbic, _, _, _, vals, _, z, mag, _ = results[-1]
            parts.append(_parts(fitter, cls.name, vals))
            pt, pu = parts[-1].get("parts"), parts[-1].get("part_units") or {}
            sz = lambda x, u=MAGNITUDE_UNITS.get(cls.name, ''): size_with_unit(x, u, *lt, fitter.speed)  # noqa: E731
            size = (", ".join(f"{k} {sz(abs(a), pu[k])} (floor {sz(f, pu[k])})" for k, (a, f) in pt.items()) if pt
                    else f"{sz(mag)} (floor {sz(floor(cls.name, fitter.kind))})")
            say(f"  {cls.name}: dBIC {fmt3(dbic)}, z {fmt3(z)}, {format_values(cls.name, vals)}, size {size}")
        rounds.append({"round": len(rounds) + 1, "model": [e.name for e in current.effects],
                       "tau_samples": {c: round(float(t), 1) for c, t in zip(_COLS, taus)},
                       "kind": fitter.kind, "heading_deg": round(math.degrees(fitter.heading), 2),
                       "speed_mps": round(float(fitter.speed), 4),
                       "candidates": [{"effect": c.name, "delta_bic": round(d, 2), "z": round(z, 2),
                                       "magnitude": float(f"{g:.4g}"), "floor": floor(c.name, fitter.kind),
                                       **pa, "R": round(rr, 4) if math.isfinite(rr) else None,
                                       "clears_threshold": bool(ok), "parameters": v, "standard_errors": s,
                                       **({"straight_z": [round(float(x), 2) for x in m.straight],
                                           "straight_contradicts": straight_contradicts(current.straight, m.straight)}
                                          if len(m.straight) else {})}
                                      for (d, ok, c, m, v, s, z, g, rr), pa in zip(results, parts)]})
        best = _best_standing(fitter, current, results, taus, inflate, o, rounds[-1], say)
        if best is None:
            break
        named.append(best[2].name)
        current = best[3]
        remaining.remove(best[2])
    return current, named, rounds, fitter


def _polish(fitter, current, o: DiagnoseOptions):
    """On a turn whose baseline freed the drift terms (:data:`DRIFT_KIND`), ``current`` fitted on by
    another ``max_nfev`` evaluations from where it stopped (the
    better of the two kept): a candidate there is fitted again from ``current``
    (:func:`_retry_from_current`), and its dBIC must not count the further convergence of the ship's
    own terms that its longer fit reached as evidence for the effect."""
    if fitter.kind != DRIFT_KIND:
        return current
    m = fitter.fit(current.effects, start=current.theta, max_nfev=o.max_nfev)
    return m if _chi2(m) < _chi2(current) else current


def _rival(results, r):
    """The candidate of the round's ``results`` that did not clear the naming tests though its dBIC
    cleared the threshold and is within :data:`~trials.measured.diagnose.decision.WEAK_BIC` of ``r``'s or above
    (the most evidence of such), or None: the records hold as much evidence for it as for ``r``."""
    rivals = [x for x in results if not x[1] and x[0] > rule("bic_threshold") and x[0] > r[0] - rule("weak_bic")]
    return max(rivals, key=lambda x: x[0]) if rivals else None


def _best_standing(fitter, current, results, taus, inflate, o: DiagnoseOptions, rnd: dict, say):
    """The round's candidate to name: the one with the most evidence among those that clear the tests
    and hold beside their rival (:func:`_rival`), or None.

    A candidate with as much evidence (dBIC) that a name could not be given to (its size within the
    ship's own mismatch, or its z short) may explain the same thing: on a turn, the straight run's
    drift is a heading bias or a current's cross part, and a current too small for its floor still
    drifts the circle.  The named one must then still clear dBIC, z and its floor with the rival in
    the model; else it is withheld (``rnd["withheld"]``, reported ``not_identifiable`` by
    :func:`withheld`)."""
    for r in sorted((x for x in results if x[1]), key=lambda x: -x[0]):
        rival = _rival(results, r)
        if rival is None:
            return r
        with_rival = rival[3]
        cls = r[2]
        m = fitter.fit(with_rival.effects + [cls], start=np.concatenate([with_rival.theta,
                                                                         r[3].theta[len(current.theta):]]),
                       max_nfev=o.max_nfev)
        dbic = _delta_bic(with_rival, m, len(cls.fit_parameters()), taus, o.stride)
        stands, z, vals = _holds(fitter, m, cls, inflate)
        stands = stands and dbic > rule("bic_threshold") and not straight_contradicts(with_rival.straight, m.straight)
        rnd.setdefault("withheld" if not stands else "beside_rival", []).append(
            {"effect": cls.name, "rival": rival[2].name, "delta_bic": round(dbic, 2), "z": round(z, 2),
             "parameters": vals})
        say(f"  {cls.name} beside {rival[2].name}: dBIC {fmt3(dbic)}, z {fmt3(z)}: "
            f"{'named' if stands else 'withheld (they explain the same evidence)'}")
        if stands:
            return r
    return None


def _holds(fitter, model: _Model, cls, inflate: float) -> tuple[bool, float, dict]:
    """(whether a named effect still clears z and its floor in ``model``, its z, its values)."""
    vals, _, z = _effect_report(model, cls, inflate)
    ok = z > rule("z_threshold") and clears_floor(cls.name, vals, fitter.ship.particulars.L, fitter.kind, fitter.heading, fitter.speed)
    return ok, z, vals


def _prune(fitter, current, named, rounds, ns: int, o: DiagnoseOptions, say):
    """The final check of forward selection: an effect named early can lose its evidence to one named
    after it (a heading bias on a zigzag is first taken for a cross current; once the bias is in, the
    current shrinks to nothing).  Every named effect must still clear z and its floor in the final
    joint fit; the weakest that does not is dropped (the rest refitted from where they were) and
    the check repeated.  Each drop is logged in the last round's ``dropped`` list."""
    while len(current.effects) > 1:
        _, inflate = _taus(current, o.stride)
        checks = [(cls, *_holds(fitter, current, cls, inflate)) for cls in current.effects]
        weak = [c for c in checks if not c[1]]
        if not weak:
            break
        cls, _, z, vals = min(weak, key=lambda c: c[2])
        keep = [e for e in current.effects if e is not cls]
        idx = set(_effect_index(current, cls))
        start = [v for i, v in enumerate(current.theta) if i not in idx]
        m = fitter.fit(keep, start=np.asarray(start), max_nfev=o.max_nfev)
        say(f"dropped {cls.name}: in the joint fit z {fmt3(z)}, {format_values(cls.name, vals)} "
            f"(no longer clears z or its floor)")
        if rounds:
            rounds[-1].setdefault("dropped", []).append({"effect": cls.name, "z": round(z, 2), "parameters": vals})
        current = m
        named = [n for n in named if n != cls.name]
    return current, named


def _confounding(model: _Model, effect) -> float:
    """R: the multiple correlation of the effect's presence parameters with every other fitted one
    (:func:`trials.measured.diagnose.identifiability.block_confounding` of the fit's covariance); NaN where
    the covariance is not finite."""
    from .identifiability import block_confounding

    idx = _effect_index(model, effect, presence_only=True)
    std = np.asarray(model.fit.std, float)
    cov = np.nan_to_num(model.fit.corr, nan=0.0) * np.outer(std, std)
    np.fill_diagonal(cov, std * std)
    if not idx or not np.all(np.isfinite(cov)) or np.any(np.diag(cov) <= 0):
        return math.nan
    try:
        return float(block_confounding(cov, idx)["R"])
    except (np.linalg.LinAlgError, ValueError):
        return math.nan


class Searched(NamedTuple):
    """What :func:`search` returns."""

    current: object
    """The final fit (a :class:`~trials.measured.diagnose.fit._Model`)."""
    named: list
    """The named effects, in the order named."""
    rounds: list
    """The rounds' log (the candidates' figures, and what was withheld, dropped or demoted)."""
    fitter: object
    """The fitter of the last round (its straight-run weight), for what follows."""
    fitted: list
    """The candidate effect classes that were fitted."""
    covered: list
    """``not_identifiable`` entries of the candidates not fitted (:func:`_covered`)."""


def search(fitter, base, cand, o: DiagnoseOptions, say) -> Searched:
    """The candidate search from the baseline fit ``base``: the candidates ``cand`` less those the
    baseline's own parameters cover (:func:`_covered`), forward selection over them (:func:`_search`),
    then the final check of the names (:func:`_prune`)."""
    ns = len(fitter.ship_free)
    cand, covered = _covered(fitter, cand, say)
    current, named, rounds, fitter = _search(fitter, base, cand, ns, o, say)
    current, named = _prune(fitter, current, named, rounds, ns, o, say)
    return Searched(current, named, rounds, fitter, cand, covered)
