"""Effects as model components: named physical effects the model can be given (see :mod:`.base`).

Registry: :data:`REGISTRY` maps the effect name to its class; adding an effect is one new
module with an :class:`~mmg.effects.base.Effect` subclass plus one :func:`register` line here.

========================  =============  =========================================================
name                      kind           parameters
========================  =============  =========================================================
``current``               kinematic      ``speed_mps``, ``direction_deg`` (sets towards)
``wind``                  force          ``scale``, ``sway_factor``, ``yaw_factor``, ``yaw_sin``
``rudder_offset``         force          ``offset_deg``
``heading_bias``          measurement    ``bias_deg``
``shallow_water``         coefficients   ``depth_to_draft``
========================  =============  =========================================================

:func:`effect_set` builds an :class:`~mmg.effects.base.EffectSet` from a mapping such as a
config section ``{"current": {"speed_mps": 0.05, "direction_deg": 90}, "rudder_offset": {...}}``
(unknown effects or parameters, values out of range: :class:`mmg.errors.InputError`).
"""
from __future__ import annotations

from ..errors import InputError
from .base import Context, Effect, EffectSet, Parameter
from .current import Current
from .heading_bias import HeadingBias
from .rudder_offset import RudderOffset
from .shallow_water import ShallowWater
from .wind import Wind

__all__ = ["Effect", "EffectSet", "Parameter", "Context", "REGISTRY", "register", "get", "names", "effect_set",
           "statements", "refuse_twice", "Current", "Wind", "RudderOffset", "HeadingBias", "ShallowWater"]

REGISTRY: dict = {}


def register(cls):
    """Add an :class:`Effect` subclass to :data:`REGISTRY` under its ``name``."""
    REGISTRY[cls.name] = cls
    return cls


for _c in (Current, Wind, RudderOffset, HeadingBias, ShallowWater):
    register(_c)


def names() -> list:
    return list(REGISTRY)


def get(name: str, owner: str = "effects"):
    try:
        return REGISTRY[name]
    except KeyError:
        raise InputError(owner, name, f"unknown effect; expected one of {', '.join(REGISTRY)}") from None


def effect_set(spec=None, owner: str = "effects", source: str | None = None) -> EffectSet:
    """An :class:`EffectSet` from ``{name: {parameter: value}}`` (a value ``None`` or ``{}``: defaults).

    Parameters
    ----------
    spec : mapping, optional
        Effect name -> its named parameter values (a config's ``effects:`` section).
    owner : str
        The field the spec sits in (``"effects"``), named in errors.
    source : str, optional
        The file the spec came from: errors then read ``FILE: effects.current.speed_mps: ...``.

    Raises
    ------
    mmg.errors.InputError
        An unknown effect or parameter, a value that is not a number or out of its range, a
        section that is not a mapping.
    """
    if spec is not None and not isinstance(spec, dict):
        raise InputError(source or owner, owner if source else "",
                         f"must be a mapping of effect names ({', '.join(REGISTRY)}) to their parameters")
    items = []
    for nm, vals in dict(spec or {}).items():
        try:
            cls = get(str(nm), owner)
            if vals is not None and not isinstance(vals, dict):
                raise InputError(f"{owner}.{nm}", "", "must be a mapping of parameter names to numbers, e.g. "
                                 + ", ".join(f"{q.name}: {q.default:g}" for q in cls.parameters if q.default == q.default))
            items.append((cls, cls.values(vals or {}, f"{owner}.{nm}")))
        except InputError as e:
            if source is None:
                raise
            raise InputError(source, ".".join(x for x in (e.source, e.field) if x), e.message) from None
    return EffectSet(tuple(items))


def statements(spec, es: EffectSet, owner: str = "effects", source: str = "") -> list:
    """Every value an ``effects:`` section states itself: ``(effect, parameter, source, field, value)``.

    ``spec`` is the section as written (validated by :func:`effect_set` into ``es``); a parameter
    the section leaves out (its default) is not stated.  Used to refuse a value given in two places
    (:func:`refuse_twice`)."""
    out = []
    for nm, vals in dict(spec or {}).items():
        for k in dict(vals or {}):
            out.append((str(nm), str(k), source, f"{owner}.{nm}.{k}", es.get(str(nm))[str(k)]))
    return out


def refuse_twice(stated, source: str) -> None:
    """InputError when two of ``stated`` ((effect, parameter, source, field, value) tuples, from one
    config or from a trial and its ship) give the same effect parameter, even with equal values:
    one line naming the later place (in ``source``) and the earlier one (with its file when that
    is another)."""
    first: dict = {}
    for eff, par, src, field, value in stated:
        key = (eff, par)
        if key in first:
            osrc, ofield, ovalue = first[key]
            there = ofield if osrc == src else f"{ofield} of {osrc}"
            raise InputError(src or source, field, f"{value:g} here and {ovalue:g} in {there}: the {eff} "
                                                   f"{par} is given twice; give it in one place")
        first[key] = (src, field, value)
