"""Named effects whose fit shows that the model's form, not the effect, is the gap: ``model_form_mismatch``.

The search of :func:`trials.measured.diagnose.diagnose` names an effect when its fit replays the records
better, precisely and by more than the ship's own mismatch lends it.  A fit can clear all three by
bending the effect into what the ship model lacks; it then says so in its own values.  A named effect
is reported ``model_form_mismatch`` instead of named (:func:`effect_form`) when

1. **a shape parameter sits on its bound, where the records pin it**: a fitted parameter that shapes
   the effect without saying whether it is there (the fit parameters not among
   :meth:`mmg.effects.Effect.presence_parameters`, e.g. the wind's ``sway_factor`` and ``yaw_factor``)
   lies within ``bound_tolerance`` of its range from a bound of that range, and more than
   :data:`~trials.measured.diagnose.decision.Z_THRESHOLD` of its standard errors from its neutral value (the
   published curve's 1): the records ask for a load of a form the effect cannot follow, and the bound
   stopped it.  A shape the records do not pin (z at most that) merely wandered to its bound along a
   direction they do not resolve (a zigzag sees the wind from a narrow band of angles), which says
   nothing of the form; or
2. **a value lies outside what the measured channels allow**: a parameter outside its physically
   plausible range (``plausible``, per effect and parameter): e.g. a wind's ``scale``, a factor on the
   loads the record's *measured* relative wind makes, far beyond the scatter of real ships' wind
   loads about a regression.

Both numbers, each with its meaning and source, are the ``model_form`` section of the packaged
calibration (``configs/calibration/diagnose.yaml``, :func:`rules`); a calibration without that
section applies neither.  The effect stays in the fitted model (``rms_after``, the ship's fitted
coefficients were found beside it); it leaves the named effects, and its values, standard errors,
interval and evidence move into its entry (:func:`reclassify`) with the shapes and coefficients
involved, the ship coefficients the same fit took beyond their priors, and a reason.
"""
from __future__ import annotations

import math

from .decision import calibration
from .rules import rule as _tuned

__all__ = ["STATUS", "rules", "shape_parameters", "effect_form", "reclassify"]

STATUS = "model_form_mismatch"
"""The status of an effect reported for its form (:attr:`trials.measured.diagnose.Diagnosis.effect_status`)."""


def rules(cal: dict | None = None) -> dict:
    """``{"bound_tolerance": float or None, "plausible": {effect: {parameter: (lo, hi)}}}`` from the
    calibration's ``model_form`` section (``cal``, or :func:`trials.measured.diagnose.decision.calibration`);
    empty ones where it has none."""
    import os

    from mmg.errors import InputError

    sec = ((calibration() if cal is None else cal) or {}).get("model_form") or {}
    try:
        tol = (sec.get("bound_tolerance") or {}).get("value")
        plaus = {e: {p: _range(d["range"]) for p, d in (ps or {}).items()}
                 for e, ps in (sec.get("plausible") or {}).items()}
        return {"bound_tolerance": None if tol is None else float(tol), "plausible": plaus}
    except (AttributeError, KeyError, TypeError, ValueError) as e:
        src = os.environ.get("MMG_DIAGNOSE_CALIBRATION") or "configs/calibration/diagnose.yaml"
        raise InputError(src, "model_form", "expected bound_tolerance: {value: fraction} and plausible: "
                         f"{{effect: {{parameter: {{range: [lo, hi]}}}}}} ({type(e).__name__}: {e})") from None


def _range(r) -> tuple:
    """A plausible range ``[lo, hi]`` as two floats, lo <= hi."""
    lo, hi = (float(x) for x in r)
    if not lo <= hi:
        raise ValueError(f"range {r}: lo above hi")
    return lo, hi


def shape_parameters(cls) -> list:
    """The fit parameters of effect class ``cls`` that shape it (not among its presence parameters)
    and have a finite range: :class:`mmg.effects.base.Parameter` objects."""
    pres = set(cls.presence_parameters())
    return [p for p in cls.fit_parameters() if p.name not in pres and math.isfinite(p.lower)
            and math.isfinite(p.upper) and p.upper > p.lower]


def effect_form(effect: str, values: dict, rule: dict, ship_mismatch: dict | None = None,
                standard_errors: dict | None = None) -> dict | None:
    """The ``model_form_mismatch`` entry of a named effect, or None when its fit keeps within its form.

    Parameters
    ----------
    effect : str
        A registered effect (:mod:`mmg.effects`).
    values : dict
        Its reported values (:meth:`mmg.effects.Effect.from_fit`).
    rule : dict
        :func:`rules`.
    ship_mismatch : dict, optional
        The ship coefficients the same fit took beyond their priors
        (:func:`trials.measured.diagnose.model_form_mismatch`).
    standard_errors : dict, optional
        Its reported standard errors; a shape without a finite one is not judged on its bound.

    Returns
    -------
    dict or None
        ``{"effect", "status", "shapes": {parameter: {"fitted", "lower", "upper", "z"}}, "coefficients":
        {parameter: {"fitted", "plausible"}}, "ship_coefficients": [names], "reason"}``.
    """
    import mmg.effects as E

    cls = E.REGISTRY.get(effect)
    if cls is None:
        return None
    shapes, coefs = {}, {}
    tol = rule.get("bound_tolerance")
    se = standard_errors or {}
    for p in shape_parameters(cls) if tol is not None else ():
        v, s = values.get(p.name), se.get(p.name)
        if v is None or s is None or not math.isfinite(s) or min(v - p.lower, p.upper - v) > tol * (p.upper - p.lower):
            continue
        z = abs(v - p.default) / s if s > 0 else math.inf
        if z > _tuned("z_threshold"):
            shapes[p.name] = {"fitted": float(v), "lower": p.lower, "upper": p.upper, "z": round(z, 2)}
    for name, (lo, hi) in (rule.get("plausible") or {}).get(effect, {}).items():
        v = values.get(name)
        if v is not None and not lo <= abs(v) <= hi:
            coefs[name] = {"fitted": float(v), "plausible": [lo, hi]}
    if not shapes and not coefs:
        return None
    why = [f"{k} {v['fitted']:.3g} on its bound (range {v['lower']:g}-{v['upper']:g}), {v['z']:.3g} standard errors "
           "from the published curve's" for k, v in shapes.items()]
    why += [f"{k} {v['fitted']:.3g} outside the plausible {v['plausible'][0]:.3g}-{v['plausible'][1]:.3g}"
            for k, v in coefs.items()]
    return {"effect": effect, "status": STATUS, "shapes": shapes, "coefficients": coefs,
            "ship_coefficients": sorted(ship_mismatch or {}),
            "reason": "; ".join(why) + ": the records ask for more than this effect's form can give, so its fit "
                      "stands for a gap of the model's form, not for the effect"}


def reclassify(diag, rule: dict | None = None) -> tuple:
    """(``diag`` with the named effects :func:`effect_form` flags moved out of its named effects into its
    ``model_form_effects``, those entries): each entry carries the effect's ``parameters``,
    ``standard_errors``, ``intervals_95`` and ``evidence``.  ``diag`` is a
    :class:`trials.measured.diagnose.Diagnosis`, returned as it is when nothing moves; ``rule``:
    :func:`rules` by default."""
    from dataclasses import replace

    rule = rules() if rule is None else rule
    out = []
    for e in diag.named:
        ent = effect_form(e, diag.parameters.get(e, {}), rule, diag.model_form_mismatch,
                          (diag.standard_errors or {}).get(e))
        if ent is not None:
            out.append({**ent, **{key: (getattr(diag, key) or {}).get(e, {})
                                  for key in ("parameters", "standard_errors", "intervals_95", "evidence")}})
    if not out:
        return diag, out
    moved = {ent["effect"] for ent in out}
    keep = {key: {k: v for k, v in (getattr(diag, key) or {}).items() if k not in moved}
            for key in ("parameters", "standard_errors", "intervals_95", "evidence")}
    return replace(diag, named=[e for e in diag.named if e not in moved],
                   model_form_effects=list(diag.model_form_effects) + out, **keep), out
