"""The verdicts on the candidates left unnamed (``not_identifiable``): a name withheld beside its rival,
every candidate's identifiability (:mod:`.identifiability`), a size within the ship's own mismatch, evidence
short of a name; and the names the records cannot separate from the ship's own coefficients, taken out
(:func:`_demote`).  :func:`verdicts` is the whole step."""
from __future__ import annotations

import numpy as np

from .decision import MAGNITUDE_UNITS, evidence_short, over_floor
from .identifiability import _size_of
from .options import DiagnoseOptions
from .report import format_values
from .rules import rule
from .statistics import _effect_index, _taus

__all__ = ["verdicts", "to_demote", "withheld", "rivals_withheld", "absorbed", "weak_evidence", "within_mismatch"]


def to_demote(table) -> list:
    """The named effects of an identifiability ``table`` (:func:`trials.measured.diagnose.identifiability.assess`)
    that :func:`_demote` takes out: the statistics reason holds for them and their calibrated floor is
    above their detection size."""
    return [t["effect"] for t in table if t["named"] and t.get("reason_kind") == "statistics"
            and t.get("floor", 0.0) > t["detection_size"]]


def _demote(fitter, current, named, demote, rounds, o: DiagnoseOptions, say):
    """The model without the named effects in ``demote`` (refitted from where it was): names the records
    cannot separate from the ship's own coefficients (the statistics reason of
    :func:`trials.measured.diagnose.identifiability.verdict`: its marginal sd could not have shown its detection
    size, and confounding is why) on a kind of record whose calibrated floor for it is above that size
    (the ship's own mismatch lends it more than matters): reported ``not_identifiable`` rather than named
    as a guess.  The floor condition keeps an effect judged present on its loads (a wind whose scale
    alone trades with its shape factors) named.  Logged in the last round's ``demoted``."""
    drop = [cls for cls in current.effects if cls.name in demote]
    keep = [e for e in current.effects if e not in drop]
    idx = {i for cls in drop for i in _effect_index(current, cls)}
    start = np.asarray([v for i, v in enumerate(current.theta) if i not in idx])
    m = fitter.fit(keep, start=start, max_nfev=o.max_nfev)
    for cls in drop:
        say(f"demoted {cls.name}: these records cannot separate it from the ship's own coefficients")
        if rounds:
            rounds[-1].setdefault("demoted", []).append({"effect": cls.name})
    return m, [n for n in named if n not in demote]


def _identifiability(fitter, current, named, cand, o: DiagnoseOptions, rounds=()):
    """(not_identifiable entries, every candidate's figures): a candidate whose name was withheld beside
    its rival (:func:`withheld`), :func:`trials.measured.diagnose.identifiability.assess`, a candidate of the last
    round whose dBIC and z cleared but whose size did not clear its calibrated floor
    (:func:`within_mismatch`), one with evidence short of a name (:func:`weak_evidence`), and a rival
    nothing else reports (:func:`rivals_withheld`); one entry per effect, none for a named one."""
    from .identifiability import assess

    _, inflate = _taus(current, o.stride)
    weak = weak_evidence(rounds)
    entries, table = assess(fitter, current, named, cand, inflate, o.segment_s, o.say, weak=weak)
    held = list({h["effect"]: h for h in withheld(rounds) if h["effect"] not in named}.values())   # the last round's
    entries = held + [e for e in entries if e["effect"] not in {h["effect"] for h in held}]
    have = {e["effect"] for e in entries}
    extra = within_mismatch(rounds, fitter.ship.particulars.L) + [
        {"effect": k, "confused_with": ["the ship's own coefficients"], "correlation": None,
         "what_would_separate": "a longer record, or one where the effect is larger", "reason": why,
         "reason_kind": "evidence"}
        for k, why in weak.items()] + rivals_withheld(rounds) + absorbed(rounds, named)   # those assess could not assess
    out = list(entries)
    have |= set(named)
    for e in extra:
        if e["effect"] not in have:
            out.append(e)
            have.add(e["effect"])
    return out, table


def withheld(rounds) -> list:
    """``not_identifiable`` entries (kind "rival") of the candidates whose name was withheld because a
    rival with as much evidence took theirs away (:func:`_best_standing`)."""
    return [_rival_entry(w["effect"], w["rival"], f"{w['rival']} explains the same evidence on these records: "
                         f"beside it {w['effect']} falls to dBIC {w['delta_bic']:.3g}, z {w['z']:.3g}")
            for rnd in rounds for w in rnd.get("withheld", [])]


def rivals_withheld(rounds) -> list:
    """``not_identifiable`` entries (kind "rival") of the rivals that took a withheld candidate's evidence
    (:func:`_best_standing`): used only where nothing else reports them."""
    return [_rival_entry(w["rival"], w["effect"], f"it explains the evidence {w['effect']} had (beside it "
                         f"{w['effect']} falls to dBIC {w['delta_bic']:.3g}, z {w['z']:.3g}), but did not clear "
                         "a name itself")
            for rnd in rounds for w in rnd.get("withheld", [])]


def absorbed(rounds, named) -> list:
    """``not_identifiable`` entries (kind "absorbed") of the candidates whose evidence the wind took: an
    effect with shape terms (:func:`has_shape_terms`: the wind's) named in some round and still named at
    the end (``named``), and a candidate that cleared every naming test in that round, at a size of at
    least its detection size (:func:`~.identifiability._size_of`, in its magnitude's unit), and no longer cleared them in the
    next round, beside it and the effects named before it.  The shape terms are free within their priors
    to follow a load curve that is not the regression's, so they can take part of the candidate's signature
    (of a rudder offset's most, ``bench/wind_alias.py``): its value in that fit is no evidence that it is
    absent, and the records do not say whether it is there as well.  Between effects without shape terms (a
    current and a heading bias) the joint fit separates them by their physics, and its value stands.

    Parameters
    ----------
    rounds : list of dict
        The search's rounds (:func:`~.search.search`): ``round``, ``model`` (the effects named before it),
        ``candidates`` (``effect``, ``delta_bic``, ``z``, ``magnitude``, ``clears_threshold``, ``parameters``).
    named : sequence of str
        The effects named at the end.

    Returns
    -------
    list of dict
        One ``not_identifiable`` entry per such candidate (``effect``, ``confused_with``, ``correlation``
        None, ``what_would_separate``, ``reason``, ``reason_kind`` ``"absorbed"``)."""
    import mmg.effects as E

    out = {}
    for i, rnd in enumerate(rounds[:-1]):
        nxt = rounds[i + 1]
        taken = [e for e in nxt.get("model", []) if e not in rnd.get("model", [])]
        shaped = [e for e in taken if e in named and has_shape_terms(E.get(e))]
        beside = {x["effect"]: x for x in nxt["candidates"]} if shaped else {}
        for c in rnd["candidates"]:
            eff, after = c["effect"], beside.get(c["effect"])
            if (after is None or after["clears_threshold"] or not c["clears_threshold"] or eff in named
                    or eff in out or abs(c["magnitude"]) < _size_of(eff)[0]):
                continue
            before = f" beside {', '.join(rnd['model'])}" if rnd.get("model") else ""
            out[eff] = {"effect": eff, "confused_with": [shaped[0]], "correlation": None,
                        "what_would_separate": "a record where they act differently: the same manoeuvre on another "
                                               "heading to the wind, or the mirror manoeuvre",
                        "reason": (f"in round {rnd.get('round', i + 1)}{before} it cleared every test "
                                   f"({format_values(eff, c['parameters'])}, dBIC {c['delta_bic']:.3g}, z {c['z']:.3g}); "
                                   f"once {shaped[0]} was named, it fell to dBIC {after['delta_bic']:.3g}, z "
                                   f"{after['z']:.3g} ({format_values(eff, after['parameters'])}): {shaped[0]}'s shape "
                                   f"terms took its evidence, so these records do not say whether {eff} is there too"),
                        "reason_kind": "absorbed"}
    return list(out.values())


def has_shape_terms(cls) -> bool:
    """Whether an effect fits parameters beyond its presence ones (:meth:`mmg.effects.Effect.presence_parameters`):
    shape terms that only shape an effect that is there (the wind's ``sway_factor``, ``yaw_factor``, ``yaw_sin``).

    Parameters
    ----------
    cls : type
        An effect class (:class:`mmg.effects.Effect`).

    Returns
    -------
    bool
    """
    return bool({p.name for p in cls.fit_parameters()} - set(cls.presence_parameters()))


def _rival_entry(effect: str, other: str, reason: str) -> dict:
    return {"effect": effect, "confused_with": [other], "correlation": None,
            "what_would_separate": "a record where they act differently: the mirror turn or a zigzag, or a longer "
                                   "straight run", "reason": reason, "reason_kind": "rival"}


def weak_evidence(rounds) -> dict:
    """``{effect: reason}`` for the last round's candidates with some evidence that did not reach a
    name (:func:`~trials.measured.diagnose.decision.evidence_short`) with a size over the calibrated floor
    (the size and precision tests a name needs pass; only the evidence falls short).  Such an effect
    may be there; dropping it silently would report a clean record.  How often a clean record of the
    calibration runs has one: ``bench/calibrate_diagnose.py`` prints it."""
    out = {}
    last = rounds[-1] if rounds else {"candidates": []}
    for c in last["candidates"]:
        if c.get("clears_threshold") or not evidence_short(c["delta_bic"], c["z"]) or not _over_floor(c):
            continue
        out[c["effect"]] = (f"at dBIC {c['delta_bic']:.3g} (a name needs {rule('bic_threshold'):.3g}), z {c['z']:.3g}, "
                            f"{_size_text(c, MAGNITUDE_UNITS.get(c['effect'], ''))}: the record holds too little "
                            "evidence to tell it from the ship's own mismatch")
    return out


def _over_floor(c: dict) -> bool:
    """Whether a stored candidate's size cleared its floor: a part over its own floor where it was
    judged by its parts (:func:`_parts`), else its size over its floor (the rule of
    :func:`~trials.measured.diagnose.decision.clears_floor`, on the figures the round kept)."""
    return over_floor(c["magnitude"], c.get("floor") or 0.0, c.get("parts"))


def _size_text(c: dict, unit: str) -> str:
    """A stored candidate's size against its floor(s), in ``unit``: its parts along and across the
    heading each with its floor, in the part's unit (``part_units``, else ``unit``), where it was judged
    by them, else its size and floor."""
    if c.get("parts"):
        pu = c.get("part_units") or {}
        sizes = ", ".join(f"{k} {abs(v[0]):.3g} (floor {v[1]:.3g}) {pu.get(k, unit)}" for k, v in c["parts"].items())
        return f"its parts along and across the heading, {sizes}"
    return f"size {c['magnitude']:.3g} {unit} (floor {c.get('floor') or 0.0:.3g} {unit})"


def within_mismatch(rounds, L: float) -> list:
    """``not_identifiable`` entries of the last round's candidates that the evidence and precision
    tests passed but the calibrated floor stopped: an effect of that size is there in the statistics,
    and the ship's own mismatch (:mod:`.decision`) could lend it as much."""
    out = []
    last = rounds[-1] if rounds else {"candidates": []}
    for c in last["candidates"]:
        if c["delta_bic"] > rule("bic_threshold") and c["z"] > rule("z_threshold") and not c["clears_threshold"]:
            unit = MAGNITUDE_UNITS.get(c["effect"], "")
            if c.get("straight_contradicts") and _over_floor(c):
                z = max(abs(x) for x in c["straight_z"])
                out.append({"effect": c["effect"], "confused_with": ["the ship's own coefficients"],
                            "correlation": None, "what_would_separate": "a ship model closer to this ship",
                            "reason": (f"at dBIC {c['delta_bic']:.3g}, z {c['z']:.3g}, {_size_text(c, unit)}, but its fit "
                                       f"leaves the record's straight run {z:.3g} sd off: the straight run reads it "
                                       "directly, so the rest of the record asks for it, not the effect"),
                            "reason_kind": "straight_run"})
                continue
            out.append({"effect": c["effect"], "confused_with": ["the ship's own coefficients"], "correlation": None,
                        "what_would_separate": "a ship model closer to this ship (e.g. identified on other "
                                               "records) or a larger effect",
                        "reason": _within_reason(c, unit), "reason_kind": "floor"})
    return out


def _within_reason(c: dict, unit: str) -> str:
    """Why a candidate that cleared dBIC and z was not named: its size (or parts) and floor(s)."""
    return (f"at dBIC {c['delta_bic']:.3g}, z {c['z']:.3g}, {_size_text(c, unit)}, within what the ship's own "
            "mismatch lends it (calibrated)")


def verdicts(fitter, current, named, cand, covered, rounds, o: DiagnoseOptions, say):
    """(final fit, named effects, ``not_identifiable`` entries, every candidate's identifiability figures)
    after the search: the candidates judged (:func:`_identifiability`), the names the records cannot
    separate from the ship's own coefficients taken out (:func:`to_demote`, :func:`_demote`) and the
    candidates judged again on the model without them; ``covered`` (the candidates not fitted,
    :func:`~.search._covered`) follow the entries."""
    ni, table = _identifiability(fitter, current, named, cand, o, rounds)
    demote = to_demote(table)
    if demote:
        current, named = _demote(fitter, current, named, demote, rounds, o, say)
        ni, table = _identifiability(fitter, current, named, cand, o, rounds)
    return current, named, ni + list(covered), table
