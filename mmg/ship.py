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
  ``w_P0`` wake fraction in straight run, ``x_P_prime`` propeller position.
* Rudder: ``A_R`` area, ``H_R`` span, ``f_alpha`` normal-force lift-gradient coefficient
  (Rhee & Kim's C_N), ``epsilon`` wake ratio (1-w_R)/(1-w_P), ``kappa`` propeller
  slipstream factor, ``eta`` = D/H_R, ``t_R, a_H, x_H_prime`` hull-rudder interaction,
  ``x_R_prime`` rudder position, ``gamma_R`` flow straightening, ``l_R_prime`` effective
  rudder position for the flow angle.
* Steering gear: ``T_E`` time constant [s], ``rate_max`` [rad/s], ``delta_max`` [rad].
* Engine: constant power (steam turbine, Rhee & Kim eqs. 15-19) or constant rpm.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal, Optional

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from .errors import InputError
from .terms import AXES, TERMS
from .units import to_si

# --------------------------------------------------------------------------- dataclasses (SI)


@dataclass(frozen=True)
class Particulars:
    """Main dimensions [m, m^2], block coefficient and water density [kg/m^3]."""

    L: float
    B: float
    T: float
    C_b: float
    S_wetted: float
    x_G: float
    rho: float


@dataclass(frozen=True)
class MassProperties:
    """Mass and inertia, primed (see :mod:`mmg.nondim`)."""

    m_prime: float
    m_x_prime: float
    m_y_prime: float
    I_zG_prime: float
    J_z_prime: float


@dataclass(frozen=True)
class HullModel:
    """Hull forces as named coefficients times named terms (see :mod:`mmg.terms`).

    ``names[i]`` (e.g. ``"Y_beta"``) multiplies term ``terms[i]`` (e.g. ``"beta"``)
    in the primed force on axis ``axes[i]`` (``"X"``, ``"Y"`` or ``"N"``).
    """

    names: tuple[str, ...]
    axes: tuple[str, ...]
    terms: tuple[str, ...]
    values: tuple[float, ...]

    def value(self, name: str) -> float:
        """Value of one coefficient."""
        return self.values[self.index(name)]

    def index(self, name: str) -> int:
        """Position of a coefficient; KeyError names the known ones."""
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"no hull coefficient {name!r}; have {', '.join(self.names)}") from None

    def as_dict(self) -> dict[str, float]:
        """Coefficient name -> value."""
        return dict(zip(self.names, self.values))

    def with_values(self, changes: dict[str, float]) -> "HullModel":
        """A copy with some coefficients changed."""
        vals = list(self.values)
        for k, v in changes.items():
            vals[self.index(k)] = float(v)
        return replace(self, values=tuple(vals))


@dataclass(frozen=True)
class Propeller:
    """Propeller and wake. Polynomials are coefficient tuples, lowest power first.

    K_T(J), K_Q(J): open-water thrust and torque coefficients.
    t_P(u), w_P0(u): thrust deduction and straight-run wake fraction, polynomials in u [m/s]
    (Rhee & Kim eqs. 13-14; a constant is a one-term polynomial).
    wake_model: ``"kijima"`` w_P = w_P0 exp(-C_wake beta_P^2), or ``"mmg2015"``
    (1-w_P) = (1-w_P0)[1 + (1-exp(-C_1|beta_P|))(C_2-1)], with beta_P = beta - x_P' r'.
    K_Q_scale: factor on K_Q (1 unless calibrated to the engine's power, see :mod:`mmg.equilibrium`).
    """

    D: float
    K_T: tuple[float, ...]
    K_Q: tuple[float, ...]
    t_P: tuple[float, ...]
    w_P0: tuple[float, ...]
    x_P_prime: float
    wake_model: str
    C_wake: float = 4.0
    C_1: float = 2.0
    C_2_pos: float = 1.0
    C_2_neg: float = 1.0
    K_Q_scale: float = 1.0


@dataclass(frozen=True)
class Rudder:
    """MMG rudder force constants (SI lengths; primes on L)."""

    A_R: float
    H_R: float
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


@dataclass(frozen=True)
class SteeringGear:
    """Rhee & Kim eq. (20): time constant T_E [s], rate limit [rad/s], angle limit [rad]."""

    T_E: float
    rate_max: float
    delta_max: float


@dataclass(frozen=True)
class Engine:
    """Main engine.

    mode: ``"constant_power"`` (torque Q_E = P_0 / (2 pi n) with P_0 = watts_per_hp * SHP_0(u_0),
    Rhee & Kim eqs. 15-19) or ``"constant_rpm"`` (n held at its commanded value).
    SHP_0: polynomial in the approach speed u_0 [m/s], giving horse power.
    shaft_inertia_coefficient: (I_Pp + J_Pp) = coefficient * D^5 [kg m^2] (eq. 16).
    """

    mode: str
    SHP_0: tuple[float, ...] = (0.0,)
    watts_per_hp: float = 745.0
    shaft_inertia_coefficient: float = 2.0


@dataclass(frozen=True)
class Ship:
    """A ship: everything the simulator needs, in SI and primes."""

    name: str
    particulars: Particulars
    mass: MassProperties
    hull: HullModel
    propeller: Propeller
    rudder: Rudder
    steering: SteeringGear
    engine: Engine
    source: str = ""

    def with_hull(self, changes: dict[str, float]) -> "Ship":
        """A copy with some hull coefficients changed (e.g. for sensitivity)."""
        return replace(self, hull=self.hull.with_values(changes))


# --------------------------------------------------------------------------- YAML schema

Length = str
Quantity = str


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _Particulars(_Strict):
    L: Quantity
    B: Quantity
    T: Quantity
    C_b: float = Field(gt=0, le=1)
    S_wetted: Quantity
    x_G: Quantity = "0 m"
    rho: Quantity = "1025 kg/m^3"

    def build(self) -> Particulars:
        out = Particulars(
            L=to_si(self.L, "length"),
            B=to_si(self.B, "length"),
            T=to_si(self.T, "length"),
            C_b=self.C_b,
            S_wetted=to_si(self.S_wetted, "area"),
            x_G=to_si(self.x_G, "length"),
            rho=to_si(self.rho, "density"),
        )
        for k in ("L", "B", "T", "S_wetted", "rho"):
            if getattr(out, k) <= 0:
                raise ValueError(f"{k} must be positive")
        return out


class _Mass(_Strict):
    m_prime: float = Field(gt=0)
    m_x_prime: float = Field(ge=0)
    m_y_prime: float = Field(ge=0)
    I_zG_prime: float = Field(gt=0)
    J_z_prime: float = Field(ge=0)


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

    def build(self) -> HullModel:
        names, axes, terms, values = [], [], [], []
        for name, c in self.coefficients.items():
            axis = name.split("_", 1)[0]
            if axis not in AXES:
                raise ValueError(f"coefficient {name!r} must start with X_, Y_ or N_")
            names.append(name)
            axes.append(axis)
            terms.append(c.term)
            values.append(c.value)
        return HullModel(tuple(names), tuple(axes), tuple(terms), tuple(values))


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

    def build(self) -> Propeller:
        return Propeller(
            D=to_si(self.D, "length"),
            K_T=tuple(self.K_T),
            K_Q=tuple(self.K_Q),
            t_P=tuple(self.t_P),
            w_P0=tuple(self.w_P0),
            x_P_prime=self.wake.x_P_prime,
            wake_model=self.wake.model,
            C_wake=self.wake.C_wake,
            C_1=self.wake.C_1,
            C_2_pos=self.wake.C_2_pos,
            C_2_neg=self.wake.C_2_neg,
        )


class _Rudder(_Strict):
    A_R: Quantity
    H_R: Quantity
    f_alpha: float = Field(gt=0)
    epsilon: float = Field(gt=0)
    kappa: float
    eta: float = Field(gt=0, le=1.5)
    t_R: float
    a_H: float
    x_H_prime: float
    x_R_prime: float
    gamma_R_pos: float
    gamma_R_neg: float
    l_R_prime: float

    def build(self) -> Rudder:
        d = self.model_dump()
        d["A_R"] = to_si(self.A_R, "area")
        d["H_R"] = to_si(self.H_R, "length")
        return Rudder(**d)


class _Steering(_Strict):
    T_E: Quantity
    rate_max: Quantity
    delta_max: Quantity

    def build(self) -> SteeringGear:
        return SteeringGear(
            T_E=to_si(self.T_E, "time"),
            rate_max=to_si(self.rate_max, "angular_rate"),
            delta_max=to_si(self.delta_max, "angle"),
        )


class _Engine(_Strict):
    mode: Literal["constant_power", "constant_rpm"]
    SHP_0: list[float] = Field(default=[0.0], min_length=1, max_length=6)
    watts_per_hp: float = 745.0
    shaft_inertia_coefficient: float = Field(default=2.0, gt=0)


class _ShipFile(_Strict):
    name: str
    source: str = ""
    particulars: _Particulars
    mass: _Mass
    hull: _Hull
    propeller: _Propeller
    rudder: _Rudder
    steering: _Steering
    engine: _Engine


def _loc(err: dict) -> str:
    return ".".join(str(p) for p in err.get("loc", ()))


def ship_from_dict(data: dict, source: str = "<dict>") -> Ship:
    """Validate a ship mapping (as read from YAML) and build the :class:`Ship`.

    Raises :class:`trials.errors.InputError`-compatible ``ConfigError`` naming the field.
    """
    try:
        f = _ShipFile.model_validate(data)
    except ValidationError as e:
        err = e.errors()[0]
        raise ConfigError(source, _loc(err), err["msg"]) from None
    parts = {}
    for key, build in (
        ("particulars", f.particulars.build),
        ("hull", f.hull.build),
        ("propeller", f.propeller.build),
        ("rudder", f.rudder.build),
        ("steering", f.steering.build),
    ):
        try:
            parts[key] = build()
        except ValueError as e:
            raise ConfigError(source, key, str(e)) from None
    return Ship(
        name=f.name,
        particulars=parts["particulars"],
        mass=MassProperties(**f.mass.model_dump()),
        hull=parts["hull"],
        propeller=parts["propeller"],
        rudder=parts["rudder"],
        steering=parts["steering"],
        engine=Engine(**{**f.engine.model_dump(), "SHP_0": tuple(f.engine.SHP_0)}),
        source=f.source,
    )


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
        An unknown name, a missing file, malformed YAML or an invalid field.
    """
    from .resources import ship_path

    path = ship_path(name_or_path)
    data = read_yaml(path)
    return ship_from_dict(data, str(path))


def read_yaml(path: Path) -> dict:
    """Read a YAML mapping; ConfigError on a missing file or malformed YAML."""
    try:
        with open(path) as fh:
            data = yaml.safe_load(fh)
    except FileNotFoundError:
        raise ConfigError(str(path), "", "file not found") from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f"line {mark.line + 1}" if mark is not None else ""
        raise ConfigError(str(path), where, f"malformed YAML ({getattr(e, 'problem', e)})") from None
    if not isinstance(data, dict):
        raise ConfigError(str(path), "", "expected a mapping at the top level")
    return data


ConfigError = InputError
"""Bad configuration: alias of :class:`mmg.errors.InputError`."""
