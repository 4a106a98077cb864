"""The ship's frozen dataclasses in SI: :class:`Ship` and its parts (:class:`Particulars`,
:class:`MassProperties`, :class:`HullModel`, :class:`Propeller`, :class:`Rudder`, :class:`SteeringGear`,
:class:`Engine`, :class:`Wind`, :class:`FullScale`) and what an identification writes with it
(:class:`ParameterCovariance`, :class:`IdentificationNotes`, :class:`RunSpread`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..effects import EffectSet


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
    astern: str = "as_ahead"
    """How the terms act with the ship moving astern (the config's ``hull.astern``): ``"as_ahead"``, each
    term of the flow along the hull as written for ahead; ``"end_for_end"``, the ship moving ahead turned
    end for end (:func:`mmg.model.astern_factor`)."""

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

    def resistance_names(self) -> tuple[str, ...]:
        """The resistance coefficients: the X coefficients whose term is not zero straight ahead
        (beta = v' = r' = 0), e.g. ``X_uu`` (``cos(beta)^2``) of the Kijima form, ``X_0`` (``1``) of the MMG
        standard method.  X' = sum of them straight ahead, -R' (the resistance)."""
        from ..terms import is_resistance

        return tuple(n for n, ax, t in zip(self.names, self.axes, self.terms) if is_resistance(n, t, ax))

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
    P_D: pitch ratio P/D (None when the config gives no pitch): picks the four-quadrant thrust curve
    (:mod:`mmg.fourquadrant`).
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
    P_D: float | None = None
    Y_P_astern: float = 0.0
    """Lateral force of the propeller running astern over rho n^2 D^4 (+ to starboard; a right-handed
    screw walks the stern to port: < 0): :func:`mmg.model.propeller_lateral`.  0: none."""


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
class Wind:
    """Wind loads from the measured relative wind (:mod:`mmg.wind`).

    enabled: whether the replay, the estimators and ``mmg predict`` apply them; coefficients: the
    regression (``"fujiwara1998"``: Fujiwara, Ueno & Nimura 1998, J. SNAJ 183); scale: a factor on
    all three loads (1 = as published); sway_factor, yaw_factor: further factors on the sway force
    and the yaw moment (the :class:`mmg.effects.Wind` effect's shape factors, 1 = as published);
    geometry: the above-water particulars the regression needs (:class:`mmg.wind.WindParticulars`:
    areas [m^2], lengths and heights [m], L the length over all, the moment arm).
    """

    enabled: bool
    coefficients: str
    geometry: "WindParticulars"
    scale: float = 1.0
    sway_factor: float = 1.0
    yaw_factor: float = 1.0

    def particulars(self):
        """The :class:`mmg.wind.WindParticulars` of this ship."""
        return self.geometry

    def values(self) -> dict:
        """The wind effect's values this section gives: ``scale``, ``sway_factor``, ``yaw_factor``."""
        return {"scale": self.scale, "sway_factor": self.sway_factor, "yaw_factor": self.yaw_factor}


@dataclass(frozen=True)
class ParameterCovariance:
    """The covariance of a ship's identified parameters: the ``covariance:`` section of a ship YAML.

    ``mmg identify`` writes it beside the fitted values (the Gauss-Newton covariance of the fit, in
    the fit's own parameter names and units); ``mmg imo --samples`` samples the ship from it.

    Attributes
    ----------
    names : tuple of str
        Parameter names as ``mmg identify --free`` takes them: hull coefficients (``N_r``) and ship
        constants (``w_P0``, ``epsilon``, ``kappa``, ``gamma_R_pos``, ``rudder_offset``, ``m_x``, ...).
    units : tuple of str
        The unit of each value (``"1"``: non-dimensional, as the primed coefficients; ``"rad"``,
        ``"kg"``, ``"kg m^2"``).
    values : tuple of float
        The values the covariance is about (the fitted values, in ``units``).
    matrix : tuple of tuples of float
        The covariance, in the products of ``units``; symmetric, positive semi-definite.
    source : str
        How it was obtained.
    method : str
        The method's short name (e.g. ``"posterior+run-jackknife"``); empty where the file gives none.
    state_range : tuple
        ((u_min, u_max), (v_min, v_max), (r_min, r_max)) [m/s, m/s, rad/s]: the states the training records
        log, over which a drawn ship is checked not to gain energy (:func:`trials.measured.draws.support_of`);
        empty where the file gives none.
    """

    names: tuple
    units: tuple
    values: tuple
    matrix: tuple
    source: str = ""
    method: str = ""
    state_range: tuple = ()

    def std(self) -> tuple:
        """Standard deviation of each parameter (the square roots of the diagonal), in ``units``."""
        return tuple(math.sqrt(max(self.matrix[i][i], 0.0)) for i in range(len(self.names)))


@dataclass(frozen=True)
class FullScale:
    """The full-scale ship a model is a Froude-scaled model of: the ``full_scale:`` section of a ship YAML.

    Attributes
    ----------
    name : str
        The full-scale ship's name (its config, e.g. ``esso_osaka``), for the reader.
    L : float
        Its length between perpendiculars [m]; the scale lambda = ``L`` / the model's L.
    """

    name: str
    L: float


@dataclass(frozen=True)
class IdentificationNotes:
    """What ``mmg identify`` says of its own fit: the ``identification:`` section of the ship YAML it writes.

    Attributes
    ----------
    converged : bool
        Every fit stage converged (none stopped at its evaluation limit).
    warnings : tuple of str
        The identification's warnings, one sentence each.
    covariance_method : str
        How the written ``covariance:`` section was made.
    training_replays_worse : tuple of str
        The training records whose identified replay is worse (heading RMS) than the initial model's.
    """

    converged: bool
    warnings: tuple = ()
    covariance_method: str = ""
    training_replays_worse: tuple = ()


@dataclass(frozen=True)
class RunSpread:
    """How much a run's own disturbance varies from one run to the next: the ``run_spread:`` section.

    ``mmg identify`` writes it (:func:`trials.measured.identify.run_spread`) from the spread of the
    per-record nuisances it fitted over the training records; ``mmg predict --samples`` offsets each
    replay's start state (and a per-record effect) by a zero-mean normal draw of these standard deviations.

    Attributes
    ----------
    names : tuple of str
        ``start.u``, ``start.v``, ``start.r``, ``start.psi`` (the start state's offsets) or
        ``<effect>.<parameter>`` (a per-record effect's fit parameter, ``..._rad`` for one in degrees).
    units : tuple of str
        The SI unit of each (``m/s``, ``rad/s``, ``rad``).
    std : tuple of float
        The standard deviation of each between runs, in ``units``.
    records : int
        The training records it was computed over.
    source : str
        How it was computed.
    """

    names: tuple
    units: tuple
    std: tuple
    records: int = 0
    source: str = ""


@dataclass(frozen=True)
class ModelForm:
    """How far a replay's heading and position stray from a record's with elapsed time, beyond what the
    parameters' covariance and the run spread carry: the ``model_form:`` section, the model-form term of a prediction band.

    ``mmg identify`` writes it (:func:`trials.measured.modelform.heading_error_growth`) from the heading
    and position errors of replays of records; ``mmg predict --samples`` adds to each drawn replay's heading a
    zero-mean normal error whose 90 % half-width grows as ``heading_q90_deg`` over ``elapsed_froude``, and
    to its position a circular normal offset whose 90 % radius grows as ``position_q90_L`` ship lengths.

    Attributes
    ----------
    elapsed_froude : tuple of float
        Elapsed times from a replay's start, in units of sqrt(L/g) (Froude time: the same numbers for a
        model and its full-scale ship), increasing.
    heading_q90_deg : tuple of float
        At each, the 90 % quantile of the absolute heading error [deg], non-decreasing; linear between
        the nodes, zero at the start, held beyond the last node.
    records : int
        The records the errors came from.
    source : str
        How it was made (which replays: kept out of the fit, or its own training records).
    position_q90_L : tuple of float or None
        At each elapsed time, the 90 % quantile of the distance between the replayed and the logged
        position, in ship lengths L, non-decreasing; None where the section gives no position term.
    unbounded_from_froude : float or None
        Elapsed time [sqrt(L/g)] from which the error is unbounded (replays that made the section diverged in
        the bin after its last node: a band drawn with the term is unbounded beyond it); None: bounded, held
        beyond the last node.
    """

    elapsed_froude: tuple
    heading_q90_deg: tuple
    records: int = 0
    source: str = ""
    position_q90_L: tuple | None = None
    unbounded_from_froude: float | None = None


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
    wind: Wind | None = None
    effects: "EffectSet | None" = None
    """The effects the ship config switches on (:mod:`mmg.effects`; its ``effects:`` section and
    ``wind.enabled``), applied by the simulator, the replay, the estimators and ``mmg diagnose``
    as part of the ship; None: none."""
    stated: tuple = field(default=(), compare=False, repr=False)
    """The effect values the ship file states itself, ``(effect, parameter, file, field, value)``
    (``wind.scale``, ``effects.current.speed_mps``, ...): a trial on this ship may not give them
    again (:func:`trials.runs.trial.trial_from_dict`)."""
    covariance: ParameterCovariance | None = field(default=None, compare=False, repr=False)
    """The covariance of the identified parameters (the ``covariance:`` section), or None."""
    full_scale: FullScale | None = field(default=None, compare=False, repr=False)
    """The full-scale ship this one is a model of (the ``full_scale:`` section), or None: a full-scale ship."""
    identification: IdentificationNotes | None = field(default=None, compare=False, repr=False)
    """``mmg identify``'s account of the fit that made this ship (the ``identification:`` section), or None."""

    @property
    def froude_scale(self) -> float:
        """lambda = L of the full-scale ship / L of this one (1 for a full-scale ship): times scale as
        sqrt(lambda) between the two."""
        return 1.0 if self.full_scale is None else self.full_scale.L / self.particulars.L
    run_spread: RunSpread | None = field(default=None, compare=False, repr=False)
    """The spread of a run's own disturbance between runs (the ``run_spread:`` section), or None."""
    model_form: ModelForm | None = field(default=None, compare=False, repr=False)
    """The heading and position error a replay gains with elapsed time beyond its parameters' doubt (the
    ``model_form:`` section), or None."""

    def effect_set(self):
        """:attr:`effects` as an :class:`mmg.effects.EffectSet` (an empty one when None)."""
        if self.effects is not None:
            return self.effects
        from ..effects import EffectSet

        return EffectSet()

    def with_hull(self, changes: dict[str, float]) -> "Ship":
        """A copy with some hull coefficients changed (e.g. for sensitivity)."""
        return replace(self, hull=self.hull.with_values(changes))

    def with_hull_astern(self, rule: str) -> "Ship":
        """A copy whose hull acts astern by ``rule``, ``"as_ahead"`` or ``"end_for_end"`` (:attr:`HullModel.astern`)."""
        if rule not in ("as_ahead", "end_for_end"):
            raise ValueError(f"hull.astern {rule!r}: expected as_ahead or end_for_end")
        return replace(self, hull=replace(self.hull, astern=rule))
