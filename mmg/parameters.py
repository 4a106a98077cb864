"""The ship's parameters an estimator can free: one table.

Each entry (:class:`ShipParameter`) says, for one parameter under its fit name (``mmg identify --free``):
its unit in a fit (SI; ``"1"``: non-dimensional), its prior family (the key of a relative-std table such as
:data:`PRIOR_REL_STD`) and how its prior std, floor and hard bounds follow from the config value, how a fit
applies it (its rule :attr:`ShipParameter.apply` on the packed ship at its ``slot``, or
:attr:`ShipParameter.loads` on the records' external loads: :func:`ekf.identify.apply_parameters`), how it is read
from and written into a :class:`mmg.ship.Ship`, and where a ship YAML holds it.  The hull coefficients are
the ship's own (:func:`hull_parameter`, one entry per name of its hull model); the rest are the constants
of :data:`CONSTANTS`.  Estimators, the writers of ship configs and the samplers loop over this table.

The wind's scale and shape factors and the rudder offset are :mod:`mmg.effects` parameters: their priors
and bounds are the effects' own (:func:`ekf.identify.effect_prior`); a fitted wind value is a factor on the
loads the ship's wind section gives (:meth:`mmg.effects.Wind.load_factors`), a fitted rudder offset enters
through the effect's slots (:func:`through_effect`).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from .model import (P_EPS, P_GNEG, P_GPOS, P_JZ, P_KAPPA, P_LR, P_MX, P_MY, P_RUDDER_OFFSET, P_YP_ASTERN, POLY_WP0,
                    PackedShip)
from .nondim import inertia_scale, mass_scale
from .terms import is_resistance

__all__ = ["ShipParameter", "CONSTANTS", "PRIOR_REL_STD", "DIAGNOSIS_PRIOR_REL_STD",
           "hull_parameter", "parameter", "ship_value", "with_value", "write_yaml_value", "unit_of", "is_resistance",
           "EffectPrior", "WIND_COLUMNS", "config_values", "MASS_NAMES", "to_slot", "to_hull", "to_wake",
           "not_packed", "through_effect", "to_load_factor", "rule_of_kind", "LINEAR_TERMS"]

PRIOR_REL_STD = {"hull": 0.5, "epsilon": 0.5, "kappa": 0.5, "rudder": 0.5, "mass": 0.5}
"""Prior std of a freed ship coefficient relative to its config value, per family (identification's: the
value is known to a factor of about 2 either way).  Floors are the entries' own (:class:`ShipParameter`);
``w_P0`` and ``Y_P_astern`` take absolute stds; effect parameters carry their own prior
(:class:`mmg.effects.Parameter`)."""

DIAGNOSIS_PRIOR_REL_STD = {**PRIOR_REL_STD, "mass": 0.2, "hull": 0.15, "hull_nonlinear": 0.30, "resistance": 0.10,
                           "w_P0": 0.20, "epsilon": 0.10, "hull_floor": 0.002, "rudder": 0.15}
"""The diagnosis's prior widths: what is known of a config's source, not identification's factor of 2.
Linear sway/yaw derivatives (``hull``: the terms in beta, r, v) from captive tests or Kijima-type
regressions are good to 10-15 %, their nonlinear terms (``hull_nonlinear``: r|r|) to about 30 %, the
resistance (``resistance``: cos(beta)^2, u^2) to 10 %, the wake fraction w_P0 (``w_P0``, relative here) to
20 %; the rudder's inflow ratio epsilon = (1 - w_R) / (1 - w_P) to 10 % (the rudder normal force goes as
epsilon^2, so its force to about 20 %, the spread of the rudder-wake regressions and of the rudder lift slope
a config takes from Fujii's formula); ``hull_floor`` is the smallest std of a primed hull coefficient.  The
rudder's flow-straightening coefficients gamma_R (``rudder``, freed on zigzags) to 15 %, the spread of a
ship's rudder constants about a config's.  The added masses at 20 %: the diagnosis frees them with every
candidate effect, and an added mass a few % off leaves a residual (surge speed loss in the turn, sway and yaw
lag) an effect would otherwise take; a wider prior would let them take an effect's residual instead."""

LINEAR_TERMS = ("beta", "r", "v")
"""Hull terms counted as linear (the sway/yaw derivatives in beta, r, v): their coefficients take the
diagnosis's ``hull`` width of :data:`DIAGNOSIS_PRIOR_REL_STD`; the straight-ahead resistance
(:func:`is_resistance`) its ``resistance`` width, every other hull term its ``hull_nonlinear`` one."""

WIND_COLUMNS = {"wind_scale": ("scale", 0), "wind_sway_factor": ("sway_factor", 1), "wind_yaw_factor": ("yaw_factor", 2)}
"""Fit name of a wind value -> (the wind effect's parameter and the ship's ``wind:`` key it multiplies, the
column of the records' external loads X, Y, N it multiplies; 0: all three)."""


def to_slot(packed: PackedShip, index: int, value: float) -> None:
    """Apply rule: ``value`` into the parameter vector at ``index`` (a rudder or propeller constant, an added mass).

    Parameters
    ----------
    packed : mmg.model.PackedShip
        The packed ship a fit evaluates (its arrays are the fit's copies, written in place).
    index : int
        The entry's :attr:`ShipParameter.slot`: its index in :attr:`mmg.model.PackedShip.p`.
    value : float
        The fitted value, in the fit's unit.
    """
    packed.p[index] = value


def to_hull(packed: PackedShip, index: int, value: float) -> None:
    """Apply rule: ``value`` as hull coefficient ``index`` of the hull model.

    Parameters
    ----------
    packed : mmg.model.PackedShip
        The packed ship a fit evaluates (its arrays are the fit's copies, written in place).
    index : int
        The coefficient's index in :attr:`mmg.model.PackedShip.hull_coef`.
    value : float
        The fitted primed coefficient [-].
    """
    packed.hull_coef[index] = value


def to_wake(packed: PackedShip, index: int, value: float) -> None:
    """Apply rule: ``value`` as the constant term of the wake polynomial (w_P0 at u = 0).

    Parameters
    ----------
    packed : mmg.model.PackedShip
        The packed ship a fit evaluates (its arrays are the fit's copies, written in place).
    index : int
        Not used (the term's place is fixed).
    value : float
        The fitted wake fraction w_P0 [-].
    """
    packed.poly[POLY_WP0][0] = value


def not_packed(packed: PackedShip, index: int, value: float) -> None:
    """Apply rule of a value that does not go into the packed ship (a factor on the records' loads, an
    effect's parameter applied through its :class:`mmg.effects.EffectSet`, a record's start offset): it
    writes nothing.

    Parameters
    ----------
    packed : mmg.model.PackedShip
        The packed ship a fit evaluates (its arrays are the fit's copies, written in place).
    index : int
        Not used.
    value : float
        Not used.
    """


def through_effect(prior: "EffectPrior") -> Callable:
    """Apply rule of an effect's parameter that acts through the packed ship (the rudder offset): the value,
    in the fit's unit, back in the effect's (``prior.factor``) and written by the effect's own
    :meth:`mmg.effects.Effect.slots`, the one way the effect enters the model in a simulation, a
    diagnosis and an identification.

    Parameters
    ----------
    prior : EffectPrior
        The effect, its parameter and the factor from its unit to the fit's.

    Returns
    -------
    callable
        ``apply(packed, index, value)`` (``index`` not used: the effect knows its slots).
    """
    def apply(packed: PackedShip, index: int, value: float) -> None:
        import mmg.effects as E

        for slot, v in E.get(prior.effect).slots({prior.parameter: value / prior.factor}).items():
            packed.p[slot] = v
    return apply


def to_load_factor(factors: np.ndarray, index: int, value: float) -> None:
    """Load rule of a wind value: ``value`` as the wind effect's fit parameter ``index`` (scale, sway and yaw
    factor, :meth:`mmg.effects.Wind.fit_parameters`) in ``factors``, which :meth:`mmg.effects.Wind.load_factors`
    turns into the factor on each column of the records' loads.

    Parameters
    ----------
    factors : ndarray
        The wind effect's fit parameters (scale, sway factor, yaw factor), written in place.
    index : int
        The entry's :attr:`ShipParameter.slot`: 0 scale, 1 sway factor, 2 yaw factor (:data:`WIND_COLUMNS`).
    value : float
        The fitted factor [-] (1: the ship's own wind loads).
    """
    factors[index] = value


@dataclass(frozen=True)
class EffectPrior:
    """Where an effect parameter's prior comes from: the effect's (registered) name, its parameter, and the
    factor from the effect's units to the fit's (degrees to radians for the rudder offset)."""

    effect: str
    parameter: str
    factor: float = 1.0


@dataclass(frozen=True)
class ShipParameter:
    """One freeable parameter of a ship (module docstring).

    Attributes
    ----------
    name : str
        The fit name (``mmg identify --free``).
    unit : str
        Its unit in a fit, SI (``"1"``: non-dimensional).
    family : str
        The key of its relative prior std in a family table (:data:`PRIOR_REL_STD`), or ``""`` for an absolute
        std (``abs_std``) or an effect's own prior (``effect``).
    kind : str
        Its kind (:attr:`ekf.identify.FreeParameter.kind`), a label a caller can select by: ``"hull"``,
        ``"w_P0"``, ``"epsilon"``, ``"kappa"``, ``"rudder"``, ``"propeller"``, ``"mass"``, ``"wind_scale"``,
        ``"rudder_offset"``.
    slot : int
        Its index in :attr:`mmg.model.PackedShip.p` (a hull coefficient's in ``hull_coef``; the wind's: the
        loads' column, :data:`WIND_COLUMNS`), the ``index`` its rules are given.
    yaml : str
        Where a ship YAML holds it (documentation; :func:`write_yaml_value` writes it).
    floor : float
        Smallest prior std (a relative std of a small value would pin it).
    abs_std : float
        An absolute prior std (``family`` empty), 0 where none.
    bounds : callable
        ``bounds(config_value) -> (lower, upper)``: hard bounds.
    effect : EffectPrior or None
        For an :mod:`mmg.effects` parameter: where its prior comes from.
    apply : callable
        ``apply(packed, slot, value)``: writes a fitted value into a packed ship (a copy: the caller's arrays
        ``p``, ``poly`` and ``hull_coef`` are copies, written in place); :func:`to_slot` by default,
        :func:`through_effect` for an effect's parameter that the effect writes into the packed ship,
        :func:`not_packed` for a value that acts elsewhere.
    loads : callable or None
        ``loads(factors, slot, value)``: where the value acts on the records' external loads instead
        (:func:`to_load_factor`); None: it does not.
    diagnosis_family : str
        The key of its relative prior std in :data:`DIAGNOSIS_PRIOR_REL_STD` where the diagnosis sets it
        apart from the family table (a hull coefficient's by its term, :data:`LINEAR_TERMS`; ``w_P0``
        relative); ``""``: the diagnosis takes the prior of the family table as it is.
    diagnosis_floor : float
        Smallest diagnosis prior std (with ``diagnosis_family``).
    keeps_sign : bool
        The diagnosis bounds it to its config value's sign (the signs that define a ship: a positive
        Y_beta, a negative N_r).
    multiplies : callable or None
        ``multiplies(ship)``: the config value a fitted value is a factor on (a wind factor: ship.yaml
        writes their product, so the product's bounds are the fit's over it); None: not a factor.
    """

    name: str
    unit: str
    family: str
    kind: str
    slot: int
    yaml: str
    read: Callable
    write: Callable
    write_yaml: Callable
    packed: Callable
    floor: float = 0.0
    abs_std: float = 0.0
    bounds: Callable = lambda v: (-np.inf, np.inf)
    effect: EffectPrior | None = None
    apply: Callable = to_slot
    loads: Callable | None = None
    config_key: str = ""
    """The key of the value in the config's own unit, where it differs from ``name`` (an added mass's primed
    ``m_x_prime``: :meth:`in_config`)."""
    config_scale: Callable | None = None
    """``config_scale(ship)``: the config's unit in the fit's (the fit's value over it is the config's), where
    they differ."""
    diagnosis_family: str = ""
    diagnosis_floor: float = 0.0
    keeps_sign: bool = False
    multiplies: Callable | None = None

    def config_value(self, packed: PackedShip) -> float:
        """The value the packed ship carries (the prior's centre), in the fit's unit.

        Parameters
        ----------
        packed : mmg.model.PackedShip
            The ship's packed form.

        Returns
        -------
        float
            The value, in :attr:`unit`.
        """
        return float(self.packed(packed))

    def in_config(self, ship, value: float) -> tuple[str, float]:
        """(the config's key, ``value`` in the config's unit): an added mass [kg] as the primed value.

        Parameters
        ----------
        ship : mmg.ship.Ship
            The ship whose dimensions give the config's unit (:attr:`config_scale`).
        value : float
            A value in the fit's unit (:attr:`unit`).

        Returns
        -------
        key : str
            :attr:`config_key`, or :attr:`name` where the units agree.
        value : float
            ``value`` in the config's unit.
        """
        if self.config_scale is None:
            return self.name, float(value)
        return self.config_key, float(value) / self.config_scale(ship)

    def prior_std(self, value: float, rel: dict) -> float:
        """The prior std about ``value`` from the family table ``rel`` (its floor kept), or the absolute one.

        Parameters
        ----------
        value : float
            The prior's centre (the config's value), in the fit's unit.
        rel : dict
            ``{family: relative std}``, e.g. :data:`PRIOR_REL_STD` or :data:`DIAGNOSIS_PRIOR_REL_STD`.

        Returns
        -------
        float
            The prior standard deviation, in the fit's unit: ``rel[family] * |value|`` but at least
            :attr:`floor` (``rel[family] * value`` where the entry has no floor), or :attr:`abs_std`
            where :attr:`family` is empty.
        """
        if not self.family:
            return self.abs_std
        s = rel[self.family] * (abs(value) if self.floor > 0 else value)
        return max(s, self.floor) if self.floor > 0 else s


def _mass_scale(ship, name: str) -> float:
    pa = ship.particulars
    return inertia_scale(pa.rho, pa.L, pa.T) if name == "J_z" else mass_scale(pa.rho, pa.L, pa.T)


def _load_ship(ship_path):
    from .ship import load_ship

    return load_ship(ship_path)


def _rudder(name: str, slot: int, family: str, lo: float, hi: float, floor: float = 0.0) -> ShipParameter:
    """A constant of :class:`mmg.ship.Rudder`."""
    return ShipParameter(
        name, "1", family, family if family in ("epsilon", "kappa") else "rudder", slot, f"rudder.{name}",
        read=lambda s: float(getattr(s.rudder, name)),
        write=lambda s, v: replace(s, rudder=replace(s.rudder, **{name: float(v)})),
        write_yaml=lambda d, v, path: d["rudder"].__setitem__(name, float(f"{v:.6g}")),
        packed=lambda p: p.p[slot], floor=floor, bounds=lambda v: (lo, hi))


def _mass(name: str, slot: int, unit: str) -> ShipParameter:
    """An added mass [kg] or added moment of inertia [kg m^2]: the config's primed value times its scale."""
    def write_yaml(d, v, path):
        d["mass"][f"{name}_prime"] = float(f"{v / _mass_scale(_load_ship(path), name):.6g}")

    return ShipParameter(
        name, unit, "mass", "mass", slot, f"mass.{name}_prime",
        read=lambda s: getattr(s.mass, f"{name}_prime") * _mass_scale(s, name),
        write=lambda s, v: replace(s, mass=replace(s.mass, **{f"{name}_prime": v / _mass_scale(s, name)})),
        write_yaml=write_yaml, packed=lambda p: p.p[slot], bounds=lambda v: (0.0, 3.0 * v),
        config_key=f"{name}_prime", config_scale=lambda s: _mass_scale(s, name))


def _with_w_P0(s, v):
    w = list(s.propeller.w_P0)
    w[0] = v
    return replace(s, propeller=replace(s.propeller, w_P0=tuple(w)))


def _with_offset(s, v):
    import mmg.effects as E

    return replace(s, effects=s.effect_set().merged(E.effect_set({"rudder_offset": {"offset_deg": float(np.degrees(v))}})))


def _offset_of(s) -> float:
    off = s.effect_set().get("rudder_offset")
    return float(np.radians(off["offset_deg"])) if off else 0.0


def _offset_yaml(d, v, path):
    d["effects"] = dict(d.get("effects") or {})
    d["effects"]["rudder_offset"] = {"offset_deg": float(f"{np.degrees(v):.6g}")}


def _with_wind(key: str):
    """Write a fitted wind factor: multiplies the ship's ``wind:`` value and its ``wind`` effect's."""
    def write(s, v):
        if s.wind is None:
            return s
        s = replace(s, wind=replace(s.wind, **{key: getattr(s.wind, key) * v}))
        w = s.effect_set().get("wind")
        if w is not None:
            import mmg.effects as E

            s = replace(s, effects=s.effect_set().merged(E.effect_set({"wind": {**w, key: float(w.get(key, 1.0)) * v}})))
        return s
    return write


def _wind_yaml(key: str):
    def write_yaml(d, v, path):
        if "wind" not in d:
            return
        eff = (d.get("effects") or {}).get("wind")
        if isinstance(eff, dict) and key in eff:               # the value given in the effects section
            eff[key] = float(f"{float(eff[key]) * v:.6g}")
            d["wind"].pop(key, None)
        else:
            d["wind"][key] = float(f"{float(d['wind'].get(key, 1.0)) * v:.6g}")
    return write_yaml


def _wind(name: str) -> ShipParameter:
    key, col = WIND_COLUMNS[name]
    return ShipParameter(name, "1", "", "wind_scale", col, f"wind.{key}", read=lambda s: 1.0, write=_with_wind(key),
                         write_yaml=_wind_yaml(key), packed=lambda p: 1.0, effect=EffectPrior("wind", key),
                         apply=not_packed, loads=to_load_factor, multiplies=lambda s: float(getattr(s.wind, key)))


_OFFSET = EffectPrior("rudder_offset", "offset_deg", np.pi / 180.0)


def _constants() -> dict:
    def set_yaml(section, key, index=None):
        def w(d, v, path):
            if index is None:
                d[section][key] = float(f"{v:.6g}")
            else:
                d[section][key][index] = float(f"{v:.6g}")
        return w

    out = [
        ShipParameter("w_P0", "1", "", "w_P0", 0, "propeller.w_P0[0]", read=lambda s: s.propeller.w_P0[0],
                      write=_with_w_P0, write_yaml=set_yaml("propeller", "w_P0", 0),
                      packed=lambda p: p.poly[POLY_WP0][0], abs_std=0.15, bounds=lambda v: (0.0, 0.8), apply=to_wake,
                      diagnosis_family="w_P0", diagnosis_floor=0.01),
        _rudder("epsilon", P_EPS, "epsilon", 0.3, 3.0),
        _rudder("kappa", P_KAPPA, "kappa", 0.0, 1.0),
        _wind("wind_scale"), _wind("wind_sway_factor"), _wind("wind_yaw_factor"),
        ShipParameter("rudder_offset", "rad", "", "rudder_offset", P_RUDDER_OFFSET, "effects.rudder_offset.offset_deg",
                      read=_offset_of, write=_with_offset, write_yaml=_offset_yaml,
                      packed=lambda p: p.p[P_RUDDER_OFFSET], effect=_OFFSET, apply=through_effect(_OFFSET)),
        ShipParameter("Y_P_astern", "1", "", "propeller", P_YP_ASTERN, "propeller.Y_P_astern",
                      read=lambda s: s.propeller.Y_P_astern,
                      write=lambda s, v: replace(s, propeller=replace(s.propeller, Y_P_astern=float(v))),
                      write_yaml=set_yaml("propeller", "Y_P_astern"), packed=lambda p: p.p[P_YP_ASTERN],
                      abs_std=0.03, bounds=lambda v: (-0.3, 0.3)),
        _rudder("gamma_R_pos", P_GPOS, "rudder", 0.0, 1.5, 0.05),
        _rudder("gamma_R_neg", P_GNEG, "rudder", 0.0, 1.5, 0.05),
        _rudder("l_R_prime", P_LR, "rudder", -2.0, 0.0, 0.05),
        _mass("m_x", P_MX, "kg"), _mass("m_y", P_MY, "kg"), _mass("J_z", P_JZ, "kg m^2"),
    ]
    return {p.name: p for p in out}


CONSTANTS = _constants()
"""The ship constants besides the hull coefficients, by fit name (module docstring).  ``Y_P_astern``: the
propeller's lateral force astern, Y_P / (rho n^2 D^4) (:func:`mmg.model.propeller_lateral`), absolute std 0.03
about the config's value (a few per cent of the bollard thrust, K_T(0) about 0.3, is what single screws show);
``w_P0``: the constant term of the wake polynomial (the model-scale wake), absolute std 0.15; the rudder's
flow-straightening coefficients gamma_R of the inflow angle (positive and negative beta_R) and the effective
lever l_R' of the yaw rate in it; the added masses and moment of inertia."""


MASS_NAMES = tuple(n for n, p in CONSTANTS.items() if p.kind == "mass")
"""The added masses and the added moment of inertia (the table's ``"mass"`` entries)."""


def rule_of_kind(kind: str) -> tuple[Callable, Callable | None]:
    """(apply rule, load rule) of the table's entries of ``kind`` (:attr:`ShipParameter.apply`,
    :attr:`ShipParameter.loads`): the rules of a parameter given by its kind alone (a hand-made
    :class:`ekf.identify.FreeParameter`); a kind not in the table goes into the parameter vector.

    Parameters
    ----------
    kind : str
        A :attr:`ShipParameter.kind` (``"hull"``, ``"w_P0"``, ``"wind_scale"``, ...).

    Returns
    -------
    apply : callable
        The first entry of that kind's :attr:`ShipParameter.apply` (:func:`to_slot` for an unknown kind).
    loads : callable or None
        Its :attr:`ShipParameter.loads` (None for an unknown kind).
    """
    for p in (*CONSTANTS.values(), hull_parameter("", 0)):
        if p.kind == kind:
            return p.apply, p.loads
    return to_slot, None


def hull_parameter(name: str, index: int, term: str = "") -> ShipParameter:
    """The entry of hull coefficient ``name`` (primed, non-dimensional), at ``index`` of the ship's hull model;
    the straight-ahead resistance (:func:`is_resistance`) bounded to stay negative.

    Parameters
    ----------
    name : str
        The coefficient's name in the ship's hull model (e.g. ``"Y_v"``).
    index : int
        Its index in the hull model's coefficients (:attr:`mmg.model.PackedShip.hull_coef`).
    term : str, optional
        Its term in the hull model (tells the resistance, :func:`is_resistance`).

    Returns
    -------
    ShipParameter
        Family and kind ``"hull"``, relative prior with a floor of 0.01, applied by :func:`to_hull`.
    """
    resistance = is_resistance(name, term)
    bounds = (lambda v: (-np.inf, 0.0)) if resistance else (lambda v: (-np.inf, np.inf))
    diagnosis = "hull" if term in LINEAR_TERMS else "resistance" if resistance else "hull_nonlinear"

    def write_yaml(d, v, path):
        d["hull"]["coefficients"][name]["value"] = float(f"{v:.6g}")

    return ShipParameter(name, "1", "hull", "hull", index, f"hull.coefficients.{name}.value",
                         read=lambda s: s.hull.value(name), write=lambda s, v: s.with_hull({name: float(v)}),
                         write_yaml=write_yaml, packed=lambda p: p.hull_coef[index], floor=0.01, bounds=bounds,
                         apply=to_hull, diagnosis_family=diagnosis,
                         diagnosis_floor=DIAGNOSIS_PRIOR_REL_STD["hull_floor"], keeps_sign=True)


def parameter(name: str, hull_names=(), hull_terms=()) -> ShipParameter:
    """The table's entry for ``name``: a hull coefficient of ``hull_names`` (its term from ``hull_terms``,
    same order) or a constant of :data:`CONSTANTS`.

    Parameters
    ----------
    name : str
        A fit name (``mmg identify --free``).
    hull_names : sequence of str
        The ship's hull coefficient names (:attr:`mmg.ship.HullModel.names`).
    hull_terms : sequence of str
        Their terms, in the same order.

    Returns
    -------
    ShipParameter

    Raises
    ------
    KeyError
        Neither.
    """
    hull_names = list(hull_names)
    if name in hull_names:
        i = hull_names.index(name)
        return hull_parameter(name, i, hull_terms[i] if i < len(hull_terms) else "")
    if name in CONSTANTS:
        return CONSTANTS[name]
    raise KeyError(f"unknown parameter {name!r}: not a hull coefficient of the ship nor one of {tuple(CONSTANTS)}")


def _of_ship(ship, name: str) -> ShipParameter:
    return parameter(name, ship.hull.names, ship.hull.terms)


def ship_value(ship, name: str) -> float:
    """The ship's own value of parameter ``name``, in the fit's unit.

    Parameters
    ----------
    ship : mmg.ship.Ship
    name : str
        A fit name: a hull coefficient of the ship or a key of :data:`CONSTANTS`.

    Returns
    -------
    float
        The value in the fit's unit (:func:`unit_of`; a wind factor is 1, the ship's own loads).

    Raises
    ------
    KeyError
        An unknown name.
    """
    return float(_of_ship(ship, name).read(ship))


def with_value(ship, name: str, value: float):
    """``ship`` with parameter ``name`` set to ``value`` (the fit's unit; a wind value is a factor on the
    ship's); an unknown name (a record's own nuisance, an effect's) leaves the ship as it is.

    Parameters
    ----------
    ship : mmg.ship.Ship
    name : str
        A fit name.
    value : float
        Its value in the fit's unit.

    Returns
    -------
    mmg.ship.Ship
        A new ship (``ship`` itself for an unknown name).
    """
    try:
        p = _of_ship(ship, name)
    except KeyError:
        return ship
    return p.write(ship, value)


def write_yaml_value(data: dict, name: str, value: float, ship_path) -> None:
    """Write parameter ``name``'s fitted ``value`` into ``data``, a ship YAML's mapping (of the file
    ``ship_path``); an unknown name is left out.

    Parameters
    ----------
    data : dict
        The parsed ship YAML, written in place.
    name : str
        A fit name.
    value : float
        Its fitted value in the fit's unit (a wind value: a factor on the file's).
    ship_path : str or path
        The ship file ``data`` was read from (an added mass's scale needs its dimensions).
    """
    hull = (data.get("hull") or {}).get("coefficients") or {}
    if name in hull:
        p = hull_parameter(name, 0)
    elif name in CONSTANTS:
        p = CONSTANTS[name]
    else:
        return
    p.write_yaml(data, value, ship_path)


def config_values(ship, values: dict) -> dict:
    """Fitted ``values`` (fit names and units) under the config's keys and in its units
    (:meth:`ShipParameter.in_config`: the added masses primed); names not in the table as given.

    Parameters
    ----------
    ship : mmg.ship.Ship
    values : dict
        ``{fit name: value}`` in the fit's units.

    Returns
    -------
    dict
        ``{config key: value}`` in the config's units.
    """
    out = {}
    for k, v in values.items():
        try:
            key, x = _of_ship(ship, k).in_config(ship, v)
        except KeyError:
            key, x = k, float(v)
        out[key] = x
    return out


def unit_of(name: str) -> str:
    """A fitted parameter's unit (``"1"`` for a hull coefficient and any name not in the table).

    Parameters
    ----------
    name : str
        A fit name.

    Returns
    -------
    str
        The unit, SI (``"1"``: non-dimensional; ``"kg"``, ``"kg m^2"``, ``"rad"``).
    """
    return CONSTANTS[name].unit if name in CONSTANTS else "1"
