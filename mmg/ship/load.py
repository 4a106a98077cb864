"""Ship data: frozen dataclasses in SI, loaded and validated from YAML.

Everything about a particular ship lives in ``configs/ships/*.yaml``; no ship's
number is written in Python.  Dimensional fields carry units in the YAML
(see :mod:`mmg.units`); primed (non-dimensional) fields are plain numbers,
non-dimensionalised as :mod:`mmg.nondim` defines.

Symbols follow the MMG literature (Yasukawa & Yoshimura 2015; Rhee & Kim 1999):

* ``L, B, T`` length between perpendiculars, breadth, draught [m]; ``C_b`` block coefficient.
* ``S_wetted`` wetted surface [m^2] (Rhee & Kim's Table 1 "A_w").
* ``x_G`` longitudinal centre of gravity from midship, forward positive [m].
* ``m_prime, m_x_prime, m_y_prime`` mass and added masses (1/2 rho L^2 T).
* ``I_zG_prime, J_z_prime`` yaw moment of inertia about G and added inertia (1/2 rho L^4 T).
* Propeller: ``D`` diameter, ``K_T(J)``, ``K_Q(J)``, ``t_P`` thrust deduction,
  ``w_P0`` wake fraction in straight run, ``x_P_prime`` propeller position, ``Y_P_astern``
  (optional, 0) lateral force of the propeller running astern over rho n^2 D^4.
* Rudder: ``A_R`` area, ``H_R`` span, ``f_alpha`` normal-force lift-gradient coefficient
  (Rhee & Kim's C_N), ``epsilon`` wake ratio (1-w_R)/(1-w_P), ``kappa`` propeller
  slipstream factor, ``eta`` = D/H_R, ``t_R, a_H, x_H_prime`` hull-rudder interaction,
  ``x_R_prime`` rudder position, ``gamma_R`` flow straightening, ``l_R_prime`` effective
  rudder position for the flow angle.
* Steering gear: ``T_E`` time constant [s], ``rate_max`` [rad/s], ``delta_max`` [rad].
* Engine: constant power (steam turbine, Rhee & Kim eqs. 15-19) or constant rpm.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Literal, Optional

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from ..errors import InputError
from ..terms import AXES, TERMS
from ..units import (DENSITY_RANGE, MAX_RUDDER, MAX_STEERING_RATE, MAX_STEERING_TIME_CONSTANT, SHIP_LENGTH_RANGE,
                     check_range, to_si)
from .data import (Engine, FullScale, HullModel, IdentificationNotes, MassProperties, ParameterCovariance, Particulars,
                   ModelForm, Propeller, Rudder, RunSpread, Ship, SteeringGear, Wind)
from .yamlfile import ConfigError, field_path, one_line, read_yaml


# --------------------------------------------------------------------------- YAML schema
#
# The schema checks types and keys (strict: a number is an int or a float, never a bool or a
# string; NaN and inf are refused); _build then converts units and checks every value against
# bounds a naval architect would accept for any displacement ship modelled with MMG, from a
# 0.5 m model to a 500 m tanker (SI bounds; primes as in mmg.nondim):
#
#   particulars  L 0.5-500 m; 1 < L/B <= 30 (B <= L); 0 < T <= B; C_b 0.3-1;
#                S_wetted 0.3-1.5 x L (B + 2T); |x_G| <= 0.1 L; rho 950-1100 kg/m^3
#   mass         m' within 25 % of 2 C_b B / L (its definition with the same L, B, T);
#                0 <= m_x' <= m'; 0 <= m_y' <= 3 m'; I_zG' = m' (k_zz/L)^2 with k_zz/L 0.1-0.5;
#                0 <= J_z' <= 3 I_zG'
#   hull         at least one X_, Y_ and N_ coefficient; |value| <= 20
#   propeller    0 < D <= 1.5 T; 0 < P <= 3 D; K_T(0) in (0, 1); K_Q(0) in (0, 0.2] for a
#                constant-power engine; t_P(0), w_P0(0) in [0, 1); polynomial coefficients
#                |c| <= 10; |x_P'| <= 1; C_wake, C_1 0-50; C_2 0-10; |Y_P_astern| <= 0.3
#   rudder       A_R 0.002-0.1 L T; 0 < H_R <= 1.5 T; f_alpha 0-10; epsilon 0-3; kappa 0-2;
#                eta 0-1.5; t_R in [0, 1); a_H 0-3; |x_H'|, |x_R'| <= 1; gamma_R 0-2; |l_R'| <= 3
#   steering     0 < T_E <= 60 s; 0 < rate_max <= 60 deg/s; 0 < delta_max <= 90 deg
#   engine       constant power: SHP_0 not all zero; watts_per_hp 700-800;
#                0 < shaft_inertia_coefficient <= 100
#   full_scale   (a model's) the full-scale ship's name and L, a ship's length longer than this L
#                (scale lambda = full_scale.L / L, Ship.froude_scale)
#   identification  (mmg identify's) converged, warnings, covariance_method,
#                training_replays_worse: what the fit says of itself (trials.imo reads it)
#   effects      {name: {parameter: value}} of mmg.effects (current, wind, rudder_offset,
#                heading_bias, shallow_water), each parameter within its effect's bounds;
#                wind needs the wind section; wind.enabled: true is effects: {wind: {scale,
#                sway_factor, yaw_factor}} (wind.sway_factor, wind.yaw_factor: 0.2-3, default 1);
#                a value given twice (wind.scale and effects.wind.scale, even equal) is refused,
#                and so is effects.wind with wind.enabled: false
#
# A value outside them is refused with one line naming the ship file and the field.

Length = str
Quantity = str


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


class _Particulars(_Strict):
    L: Quantity
    B: Quantity
    T: Quantity
    C_b: float
    S_wetted: Quantity
    x_G: Quantity = "0 m"
    rho: Quantity = "1025 kg/m^3"


class _Mass(_Strict):
    m_prime: float
    m_x_prime: float
    m_y_prime: float
    I_zG_prime: float
    J_z_prime: float


class _Coefficient(_Strict):
    term: str
    value: float

    @field_validator("term")
    @classmethod
    def _known(cls, v):
        if v not in TERMS:
            raise ValueError(f"unknown hull term {v!r}; known: {', '.join(TERMS)}")
        return v


class _Hull(_Strict):
    form: str = ""
    coefficients: dict[str, _Coefficient]
    astern: Literal["as_ahead", "end_for_end"] = "as_ahead"


class _Wake(_Strict):
    model: Literal["kijima", "mmg2015"]
    x_P_prime: float
    C_wake: float = 4.0
    C_1: float = 2.0
    C_2_pos: float = 1.0
    C_2_neg: float = 1.0


class _Propeller(_Strict):
    D: Quantity
    P: Optional[Quantity] = None
    K_T: list[float] = Field(min_length=1, max_length=6)
    K_Q: list[float] = Field(min_length=1, max_length=6)
    t_P: list[float] = Field(min_length=1, max_length=6)
    w_P0: list[float] = Field(min_length=1, max_length=6)
    wake: _Wake
    Y_P_astern: float = 0.0


class _Rudder(_Strict):
    A_R: Quantity
    H_R: Quantity
    f_alpha: float
    epsilon: float
    kappa: float
    eta: float
    t_R: float
    a_H: float
    x_H_prime: float
    x_R_prime: float
    gamma_R_pos: float
    gamma_R_neg: float
    l_R_prime: float


class _Steering(_Strict):
    T_E: Quantity
    rate_max: Quantity
    delta_max: Quantity


class _Engine(_Strict):
    mode: Literal["constant_power", "constant_rpm"]
    SHP_0: list[float] = Field(default=[0.0], min_length=1, max_length=6)
    watts_per_hp: float = 745.0
    shaft_inertia_coefficient: float = 2.0


class _Wind(_Strict):
    enabled: bool
    coefficients: Literal["fujiwara1998"] = "fujiwara1998"
    A_T: Quantity
    A_L: Quantity
    L_oa: Optional[Quantity] = None
    A_OD: Quantity
    H_BR: Quantity
    x_AL: Quantity
    z_AL: Quantity
    x_AOD: Quantity
    scale: float = 1.0
    sway_factor: float = 1.0
    yaw_factor: float = 1.0


class _Covariance(_Strict):
    names: list[str]
    units: list[str]
    values: list[float]
    matrix: list[list[float]]
    source: str = ""
    method: str = ""
    state_range: Optional[dict[str, list[float]]] = None


class _FullScale(_Strict):
    name: str = ""
    L: Quantity


class _Identification(_Strict):
    converged: bool
    warnings: list[str] = []
    covariance_method: str = ""
    training_replays_worse: list[str] = []


class _RunSpread(_Strict):
    names: list[str]
    units: list[str]
    std: list[float]
    records: int = 0
    source: str = ""


class _ModelForm(_Strict):
    elapsed_froude: list[float]
    heading_q90_deg: list[float]
    position_q90_L: Optional[list[float]] = None
    unbounded_from_froude: Optional[float] = None
    records: int = 0
    source: str = ""


class _ShipFile(_Strict):
    name: str = Field(min_length=1)
    source: str = ""
    particulars: _Particulars
    mass: _Mass
    hull: _Hull
    propeller: _Propeller
    rudder: _Rudder
    steering: _Steering
    engine: _Engine
    wind: Optional[_Wind] = None
    effects: Optional[dict] = None
    covariance: Optional[_Covariance] = None
    full_scale: Optional[_FullScale] = None
    identification: Optional[_Identification] = None
    run_spread: Optional[_RunSpread] = None
    model_form: Optional[_ModelForm] = None


_UNIT_HINT = {"L": "m", "B": "m", "T": "m", "S_wetted": "m^2", "x_G": "m", "rho": "kg/m^3", "D": "m", "P": "m",
              "A_R": "m^2", "H_R": "m", "T_E": "s", "rate_max": "deg/s", "delta_max": "deg"}


def _loc(err: dict) -> str:
    return field_path(err.get("loc", ()))


def pydantic_message(err: dict, hints: dict[str, str]) -> str:
    """Pydantic's message, made plain; a number where a quantity is expected names the unit to add."""
    loc = err.get("loc", ())
    field = str(loc[-1]) if loc else ""
    value = err.get("input")
    typ = str(err.get("type", ""))
    if typ == "string_type" and isinstance(value, (int, float)) and not isinstance(value, bool) and field in hints:
        if isinstance(value, float) and not math.isfinite(value):     # (an int is finite however large)
            return f"{value!r} is not a finite number with a unit, e.g. '1.0 {hints[field]}'"
        return (f"{value!r} has no unit; write it with one, e.g. '{value} {hints[field]}' "
                "(plain numbers are refused)")
    msg = one_line(err.get("msg", "invalid")).removeprefix("Value error, ")
    if typ.endswith("_type") or typ.startswith(("greater_than", "less_than", "too_", "string_too")) \
            or typ in ("finite_number", "literal_error", "int_from_float", "enum"):
        msg += f", got {_short(value)}"
    return msg


def _short(value) -> str:
    r = repr(value)
    return one_line(r if len(r) <= 60 else r[:57] + "...")


def _num(src: str, field: str, x: float, lo=None, hi=None, *, lo_open=False, hi_open=False, why="") -> float:
    try:
        return check_range(x, lo, hi, lo_open=lo_open, hi_open=hi_open, why=why)
    except ValueError as e:
        raise InputError(src, field, str(e)) from None


def _qty(src: str, field: str, value: str, dimension: str, lo=None, hi=None, *, lo_open=False, hi_open=False,
         why="") -> float:
    try:
        return to_si(value, dimension, lo, hi, lo_open=lo_open, hi_open=hi_open, why=why)
    except ValueError as e:
        raise InputError(src, field, str(e)) from None


def _poly(src: str, field: str, c: list[float], bound: float) -> tuple[float, ...]:
    for i, v in enumerate(c):
        _num(src, f"{field}.{i}", v, -bound, bound, why=f"a polynomial coefficient of magnitude at most {bound:g}")
    return tuple(float(v) for v in c)


def _particulars(f: _ShipFile, src: str) -> Particulars:
    """particulars: SI, checked (the other sections' bounds scale with them)."""
    pa = f.particulars
    L = _qty(src, "particulars.L", pa.L, "length", *SHIP_LENGTH_RANGE)
    B = _qty(src, "particulars.B", pa.B, "length", L / 30, L, why=f"1 < L/B <= 30 with L = {L:g} m")
    T = _qty(src, "particulars.T", pa.T, "length", 0.0, B, lo_open=True,
             why=f"the draught cannot exceed the breadth B = {B:g} m")
    C_b = _num(src, "particulars.C_b", pa.C_b, 0.3, 1.0)
    box = L * (B + 2 * T)
    S = _qty(src, "particulars.S_wetted", pa.S_wetted, "area", 0.3 * box, 1.5 * box,
             why=f"0.3-1.5 x L (B + 2T) = {box:.6g} m^2")
    x_G = _qty(src, "particulars.x_G", pa.x_G, "length", -0.1 * L, 0.1 * L, why=f"|x_G| <= 0.1 L = {0.1 * L:g} m")
    rho = _qty(src, "particulars.rho", pa.rho, "density", *DENSITY_RANGE)
    return Particulars(L=L, B=B, T=T, C_b=C_b, S_wetted=S, x_G=x_G, rho=rho)


def _mass(f: _ShipFile, src: str, pa: Particulars) -> MassProperties:
    """mass: checked against the particulars (m' near 2 C_b B / L)."""
    ms = f.mass
    C_b, B, L = pa.C_b, pa.B, pa.L
    m0 = 2 * C_b * B / L
    m = _num(src, "mass.m_prime", ms.m_prime, 0.75 * m0, 1.25 * m0,
             why=f"within 25 % of 2 C_b B / L = {m0:.4g}, the primed mass of these particulars")
    mass = MassProperties(
        m_prime=m,
        m_x_prime=_num(src, "mass.m_x_prime", ms.m_x_prime, 0.0, m, why=f"0 to m' = {m:.4g}"),
        m_y_prime=_num(src, "mass.m_y_prime", ms.m_y_prime, 0.0, 3 * m, why=f"0 to 3 m' = {3 * m:.4g}"),
        I_zG_prime=_num(src, "mass.I_zG_prime", ms.I_zG_prime, 0.01 * m, 0.25 * m,
                        why="m' (k_zz/L)^2 with a radius of gyration k_zz of 0.1-0.5 L"),
        J_z_prime=0.0,
    )
    mass = replace(mass, J_z_prime=_num(src, "mass.J_z_prime", ms.J_z_prime, 0.0, 3 * mass.I_zG_prime,
                                        why=f"0 to 3 I_zG' = {3 * mass.I_zG_prime:.4g}"))
    return mass


def _hull(f: _ShipFile, src: str) -> HullModel:
    """hull.coefficients: names on X_, Y_, N_ (each axis at least one), primed values."""
    names, axes, terms, values = [], [], [], []
    for name, c in f.hull.coefficients.items():
        field = f"hull.coefficients.{field_path([name])}"
        axis = name.split("_", 1)[0]
        if axis not in AXES or "_" not in name:
            raise InputError(src, field, "a coefficient name must start with X_, Y_ or N_")
        names.append(name)
        axes.append(axis)
        terms.append(c.term)
        values.append(_num(src, f"{field}.value", c.value, -20.0, 20.0,
                           why="a primed hull coefficient of magnitude at most 20; is it primed?"))
    for axis in AXES:
        if axis not in axes:
            raise InputError(src, "hull.coefficients", f"no {axis}_ coefficient: the hull model needs at least one "
                                                       "force term on each of X, Y and N")
    return HullModel(tuple(names), tuple(axes), tuple(terms), tuple(values), f.hull.astern)


def _propeller(f: _ShipFile, src: str, pa: Particulars) -> Propeller:
    """propeller: SI, checked (D against the draught, the polynomials' constant terms)."""
    pr = f.propeller
    T = pa.T
    D = _qty(src, "propeller.D", pr.D, "length", 0.0, 1.5 * T, lo_open=True,
             why=f"0 < D <= 1.5 T = {1.5 * T:g} m: the propeller works under water")
    P = None
    if pr.P is not None:
        P = _qty(src, "propeller.P", pr.P, "length", 0.0, 3 * D, lo_open=True, why=f"0 < P <= 3 D = {3 * D:g} m")
    K_T = _poly(src, "propeller.K_T", pr.K_T, 10.0)
    _num(src, "propeller.K_T.0", K_T[0], 0.0, 1.0, lo_open=True, hi_open=True, why="the bollard K_T(0) is 0-1")
    K_Q = _poly(src, "propeller.K_Q", pr.K_Q, 10.0)
    if f.engine.mode == "constant_power":
        _num(src, "propeller.K_Q.0", K_Q[0], 0.0, 0.2, lo_open=True,
             why="a constant-power engine balances the shaft with K_Q: K_Q(0) is 0-0.2")
    t_P = _poly(src, "propeller.t_P", pr.t_P, 10.0)
    _num(src, "propeller.t_P.0", t_P[0], 0.0, 1.0, hi_open=True, why="a thrust deduction t_P is 0 to below 1")
    w_P0 = _poly(src, "propeller.w_P0", pr.w_P0, 10.0)
    _num(src, "propeller.w_P0.0", w_P0[0], 0.0, 1.0, hi_open=True, why="a wake fraction w_P0 is 0 to below 1")
    wk = pr.wake
    return Propeller(
        D=D, K_T=K_T, K_Q=K_Q, t_P=t_P, w_P0=w_P0,
        x_P_prime=_num(src, "propeller.wake.x_P_prime", wk.x_P_prime, -1.0, 1.0, why="a position within +-1 L"),
        wake_model=wk.model,
        C_wake=_num(src, "propeller.wake.C_wake", wk.C_wake, 0.0, 50.0),
        C_1=_num(src, "propeller.wake.C_1", wk.C_1, 0.0, 50.0),
        C_2_pos=_num(src, "propeller.wake.C_2_pos", wk.C_2_pos, 0.0, 10.0, lo_open=True),
        C_2_neg=_num(src, "propeller.wake.C_2_neg", wk.C_2_neg, 0.0, 10.0, lo_open=True),
        P_D=None if P is None else P / D,
        Y_P_astern=_num(src, "propeller.Y_P_astern", pr.Y_P_astern, -0.3, 0.3,
                        why="a transverse force of a propeller astern is at most of the order of its bollard "
                            "thrust, K_T(0) < 0.5"),
    )


def _rudder(f: _ShipFile, src: str, pa: Particulars) -> Rudder:
    """rudder: SI, checked (area against L T)."""
    ru = f.rudder
    L, T = pa.L, pa.T
    LT = L * T
    return Rudder(
        A_R=_qty(src, "rudder.A_R", ru.A_R, "area", 0.002 * LT, 0.1 * LT,
                 why=f"0.002-0.1 L T = {0.002 * LT:.4g}-{0.1 * LT:.4g} m^2 (ships: 1/70-1/30 L T)"),
        H_R=_qty(src, "rudder.H_R", ru.H_R, "length", 0.0, 1.5 * T, lo_open=True, why=f"0 < H_R <= 1.5 T = {1.5 * T:g} m"),
        f_alpha=_num(src, "rudder.f_alpha", ru.f_alpha, 0.0, 10.0, lo_open=True),
        epsilon=_num(src, "rudder.epsilon", ru.epsilon, 0.0, 3.0, lo_open=True),
        kappa=_num(src, "rudder.kappa", ru.kappa, 0.0, 2.0),
        eta=_num(src, "rudder.eta", ru.eta, 0.0, 1.5, lo_open=True),
        t_R=_num(src, "rudder.t_R", ru.t_R, 0.0, 1.0, hi_open=True),
        a_H=_num(src, "rudder.a_H", ru.a_H, 0.0, 3.0),
        x_H_prime=_num(src, "rudder.x_H_prime", ru.x_H_prime, -1.0, 1.0, why="a position within +-1 L"),
        x_R_prime=_num(src, "rudder.x_R_prime", ru.x_R_prime, -1.0, 1.0, why="a position within +-1 L"),
        gamma_R_pos=_num(src, "rudder.gamma_R_pos", ru.gamma_R_pos, 0.0, 2.0),
        gamma_R_neg=_num(src, "rudder.gamma_R_neg", ru.gamma_R_neg, 0.0, 2.0),
        l_R_prime=_num(src, "rudder.l_R_prime", ru.l_R_prime, -3.0, 3.0),
    )


def _steering(f: _ShipFile, src: str) -> SteeringGear:
    """steering: SI, checked."""
    st = f.steering
    return SteeringGear(
        T_E=_qty(src, "steering.T_E", st.T_E, "time", 0.0, MAX_STEERING_TIME_CONSTANT, lo_open=True),
        rate_max=_qty(src, "steering.rate_max", st.rate_max, "angular_rate", 0.0, MAX_STEERING_RATE, lo_open=True),
        delta_max=_qty(src, "steering.delta_max", st.delta_max, "angle", 0.0, MAX_RUDDER, lo_open=True),
    )


def _engine(f: _ShipFile, src: str) -> Engine:
    """engine: checked (a constant-power engine needs its power curve)."""
    en = f.engine
    SHP_0 = tuple(float(v) for v in en.SHP_0)
    if en.mode == "constant_power" and not any(SHP_0):
        raise InputError(src, "engine.SHP_0", "a constant-power engine needs its power curve SHP_0(u) [hp], "
                                              "lowest power of u [m/s] first (all zero here)")
    return Engine(
        mode=en.mode, SHP_0=SHP_0,
        watts_per_hp=_num(src, "engine.watts_per_hp", en.watts_per_hp, 700.0, 800.0, why="one horse power is 735.5-745.7 W"),
        shaft_inertia_coefficient=_num(src, "engine.shaft_inertia_coefficient", en.shaft_inertia_coefficient,
                                       0.0, 100.0, lo_open=True),
    )


def _wind(f: _ShipFile, src: str, pa: Particulars) -> Wind | None:
    """wind (None when the file has none): SI, areas and lengths checked against L."""
    if f.wind is None:
        return None
    from ..wind import WindParticulars

    w = f.wind
    L, B = pa.L, pa.B
    area = (0.001 * L * L, 0.5 * L * L)           # a tenth of a per cent of L^2 to half of it
    return Wind(
        enabled=w.enabled, coefficients=w.coefficients,
        geometry=WindParticulars(
            A_T=_qty(src, "wind.A_T", w.A_T, "area", *area, lo_open=True),
            A_L=_qty(src, "wind.A_L", w.A_L, "area", *area, lo_open=True),
            L=_qty(src, "wind.L_oa", w.L_oa, "length", L, 1.3 * L) if w.L_oa is not None else L,
            B=B,
            A_OD=_qty(src, "wind.A_OD", w.A_OD, "area", 0.0, 0.5 * L * L, lo_open=True),
            H_BR=_qty(src, "wind.H_BR", w.H_BR, "length", 0.0, L, lo_open=True),
            x_AL=_qty(src, "wind.x_AL", w.x_AL, "length", -0.5 * L, 0.5 * L),
            z_AL=_qty(src, "wind.z_AL", w.z_AL, "length", 0.0, L, lo_open=True),
            x_AOD=_qty(src, "wind.x_AOD", w.x_AOD, "length", -0.5 * L, 0.5 * L)),
        scale=_num(src, "wind.scale", w.scale, 0.0, 10.0),
        **{k: _num(src, f"wind.{k}", getattr(w, k), q.lower, q.upper) for k, q in _shape_parameters().items()},
    )


def _shape_parameters() -> dict:
    """The wind effect's shape factors (name -> :class:`mmg.effects.Parameter`): their bounds are the effect's."""
    from ..effects import Wind as WindEffect
    from ..effects.wind import SHAPE_FACTORS

    return {q.name: q for q in WindEffect.parameters if q.name in SHAPE_FACTORS}


def _build(f: _ShipFile, src: str) -> Ship:
    """Units to SI and every value checked against the bounds above (InputError naming the field), section
    by section in the file's order."""
    particulars = _particulars(f, src)
    mass = _mass(f, src, particulars)
    hull = _hull(f, src)
    propeller = _propeller(f, src, particulars)
    rudder = _rudder(f, src, particulars)
    steering = _steering(f, src)
    engine = _engine(f, src)
    wind = _wind(f, src, particulars)
    effects, stated = _effects(f, wind, src)
    if effects is not None and effects.get("wind") is not None:
        wind = replace(wind, enabled=True, **{k: effects.get("wind")[k] for k in wind.values()})
    return Ship(name=f.name, particulars=particulars, mass=mass, hull=hull, propeller=propeller, rudder=rudder,
                steering=steering, engine=engine, source=f.source, wind=wind, effects=effects, stated=stated,
                covariance=_covariance(f, src), full_scale=_full_scale(f, src, particulars),
                identification=_identification(f), run_spread=_run_spread(f, src),
                model_form=_model_form(f, src))


def _full_scale(f: _ShipFile, src: str, pa: Particulars) -> FullScale | None:
    """full_scale: the full-scale ship's L, longer than this ship's and a ship's length."""
    if f.full_scale is None:
        return None
    L = _qty(src, "full_scale.L", f.full_scale.L, "length", *SHIP_LENGTH_RANGE)
    if not L > pa.L:
        raise InputError(src, "full_scale.L", f"{f.full_scale.L} is not longer than this ship's L = {pa.L:g} m "
                                              f"(a model's full-scale ship is larger)")
    return FullScale(f.full_scale.name, L)


def _identification(f: _ShipFile) -> IdentificationNotes | None:
    c = f.identification
    if c is None:
        return None
    return IdentificationNotes(c.converged, tuple(c.warnings), c.covariance_method, tuple(c.training_replays_worse))


def _run_spread(f: _ShipFile, src: str) -> RunSpread | None:
    """run_spread: one name, unit and non-negative standard deviation per quantity, each name once."""
    c = f.run_spread
    if c is None:
        return None
    n = len(c.names)
    if len(set(c.names)) != n:
        raise InputError(src, "run_spread.names", "a quantity is named twice")
    for key in ("units", "std"):
        if len(getattr(c, key)) != n:
            raise InputError(src, f"run_spread.{key}", f"{len(getattr(c, key))} entries for {n} names")
    for i, x in enumerate(c.std):
        if x < 0:
            raise InputError(src, f"run_spread.std.{i}", f"a negative standard deviation {x:g}")
    return RunSpread(tuple(c.names), tuple(c.units), tuple(float(x) for x in c.std), int(c.records), c.source)


def _model_form(f: _ShipFile, src: str) -> ModelForm | None:
    """model_form: as many finite errors as elapsed times, the times positive and increasing, the errors
    (heading, and position where given) non-negative and non-decreasing (an error that shrinks with time is
    not a growth curve)."""
    c = f.model_form
    if c is None:
        return None
    t = np.asarray(c.elapsed_froude, float)
    errors = {"heading_q90_deg": np.asarray(c.heading_q90_deg, float)}
    if c.position_q90_L is not None:
        errors["position_q90_L"] = np.asarray(c.position_q90_L, float)
    for key, x in (("elapsed_froude", t), *errors.items()):
        if len(x) != len(t) or not len(t):
            raise InputError(src, f"model_form.{key}", f"{len(x)} entries for {len(t)} elapsed times (one or more)")
        if not np.all(np.isfinite(x)):
            raise InputError(src, f"model_form.{key}", "a value that is not a finite number")
    if t[0] <= 0 or np.any(np.diff(t) <= 0):
        raise InputError(src, "model_form.elapsed_froude", "elapsed times (in sqrt(L/g)) must be positive and increasing")
    for key, x in errors.items():
        if x[0] < 0 or np.any(np.diff(x) < 0):
            raise InputError(src, f"model_form.{key}", "must be non-negative and non-decreasing with elapsed time")
    u = c.unbounded_from_froude
    if u is not None and not (np.isfinite(u) and u >= t[-1]):
        raise InputError(src, "model_form.unbounded_from_froude",
                         f"{u} must be a finite elapsed time (in sqrt(L/g)) at or after the last of elapsed_froude")
    pos = errors.get("position_q90_L")
    return ModelForm(tuple(float(x) for x in t), tuple(float(x) for x in errors["heading_q90_deg"]), int(c.records),
                     c.source, None if pos is None else tuple(float(x) for x in pos), None if u is None else float(u))


def _covariance(f: _ShipFile, src: str) -> ParameterCovariance | None:
    """covariance: one name, unit and value per row of a square, symmetric, positive semi-definite matrix."""
    c = f.covariance
    if c is None:
        return None
    n = len(c.names)
    if n == 0:
        raise InputError(src, "covariance.names", "no parameter named")
    if len(set(c.names)) != n:
        raise InputError(src, "covariance.names", "a parameter is named twice")
    for key in ("units", "values", "matrix"):
        if len(getattr(c, key)) != n:
            raise InputError(src, f"covariance.{key}", f"{len(getattr(c, key))} entries for {n} names")
    for i, row in enumerate(c.matrix):
        if len(row) != n:
            raise InputError(src, f"covariance.matrix.{i}", f"{len(row)} columns in a {n} x {n} matrix")
    big = max(abs(c.matrix[i][i]) for i in range(n)) or 1.0
    for i in range(n):
        if c.matrix[i][i] < 0:
            raise InputError(src, f"covariance.matrix.{i}.{i}", f"a negative variance {c.matrix[i][i]:g}")
        for j in range(i):
            if abs(c.matrix[i][j] - c.matrix[j][i]) > 1e-9 * big:
                raise InputError(src, f"covariance.matrix.{i}.{j}", "the matrix is not symmetric")
    import numpy as np

    if float(np.linalg.eigvalsh(np.asarray(c.matrix, dtype=float)).min()) < -1e-9 * big:
        raise InputError(src, "covariance.matrix", "not positive semi-definite (a negative eigenvalue): not a covariance")
    return ParameterCovariance(tuple(c.names), tuple(c.units), tuple(float(v) for v in c.values),
                               tuple(tuple(float(x) for x in row) for row in c.matrix), c.source, c.method,
                               _state_range(c.state_range, src))


STATE_RANGE_KEYS = ("u_mps", "v_mps", "r_radps")
"""The keys of a covariance's ``state_range`` (each ``[min, max]``)."""


def _state_range(d: dict | None, src: str) -> tuple:
    """covariance.state_range: ``u_mps``, ``v_mps``, ``r_radps``, each a finite [min, max]."""
    if d is None:
        return ()
    out = []
    for k in STATE_RANGE_KEYS:
        x = d.get(k)
        if x is None or len(x) != 2 or not all(math.isfinite(float(v)) for v in x) or float(x[0]) > float(x[1]):
            raise InputError(src, f"covariance.state_range.{k}", "expected a finite [min, max]")
        out.append((float(x[0]), float(x[1])))
    extra = set(d) - set(STATE_RANGE_KEYS)
    if extra:
        raise InputError(src, f"covariance.state_range.{sorted(extra)[0]}", f"not one of {', '.join(STATE_RANGE_KEYS)}")
    return tuple(out)


def _effects(f: _ShipFile, wind: Wind | None, src: str):
    """(the ship's :class:`mmg.effects.EffectSet` or None, the effect values the file states itself).

    ``wind.enabled: true`` is shorthand for ``effects: {wind: {scale: <wind.scale>}}``; a value given
    both ways (``wind.scale`` and ``effects.wind.scale``, even equal) is refused naming both places,
    and so is ``effects.wind`` with ``wind.enabled: false`` (the one says on, the other off)."""
    from ..effects import effect_set, refuse_twice, statements

    stated = []
    for k, v in (wind.values() if wind is not None else {}).items():     # scale and the shape factors
        if k in f.wind.model_fields_set:
            stated.append(("wind", k, src, f"wind.{k}", v))
    if f.effects is None and not (wind is not None and wind.enabled):
        return None, tuple(stated)
    effects = effect_set(f.effects, "effects", src)
    stated += statements(f.effects, effects, "effects", src)
    refuse_twice(stated, src)
    if effects.get("wind") is not None:
        if wind is None:
            raise InputError(src, "effects.wind", "the wind effect needs the ship's wind section "
                                                  "(areas and heights of the above-water body)")
        if not wind.enabled:
            raise InputError(src, "effects.wind", "switches the wind on and wind.enabled: false switches it off: "
                                                  "give one (wind.enabled: true, or drop effects.wind)")
        given = dict(f.effects["wind"] or {})                       # the wind section's values (stated or 1)
        effects = effects.merged(effect_set({"wind": {**effects.get("wind"),
                                                      **{k: v for k, v in wind.values().items() if k not in given}}}))
    elif wind is not None and wind.enabled:                           # wind.enabled: the shorthand
        effects = effects.merged(effect_set({"wind": wind.values()}))
    return (effects if effects.items else None), tuple(stated)


def ship_from_dict(data: Mapping, source: str = "<dict>") -> Ship:
    """Validate a ship mapping (as read from YAML) and build the :class:`Ship`.

    Parameters
    ----------
    data : mapping
        A ship YAML's content.
    source : str
        Names the ship in error messages (the ship file's path).

    Returns
    -------
    Ship

    Raises
    ------
    mmg.errors.InputError
        One line naming ``source`` and the field: an unknown or missing key, a wrong type or
        unit, a NaN or infinite number, a value outside the bounds listed in this module.
    """
    src = str(source)
    if not isinstance(data, Mapping):
        raise InputError(src, "", f"expected a mapping of ship fields, got {type(data).__name__}")
    try:
        f = _ShipFile.model_validate(dict(data))
    except ValidationError as e:
        err = e.errors()[0]
        raise ConfigError(src, _loc(err), pydantic_message(err, _UNIT_HINT)) from None
    return _build(f, src)


def load_ship(name_or_path: str | Path) -> Ship:
    """Read and validate a ship YAML file.

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A bundled ship name (``"esso_osaka"``, ``"kvlcc2_l7"``: the stem of a file in
        ``configs/ships``) or a path to a ship YAML file.

    Returns
    -------
    Ship

    Raises
    ------
    mmg.errors.InputError
        An unknown name, a missing file, malformed YAML or an invalid field (naming the ship
        file, never a trial that names it).
    """
    from ..resources import ship_path

    path = ship_path(name_or_path)
    data = read_yaml(path)
    return ship_from_dict(data, str(path))
