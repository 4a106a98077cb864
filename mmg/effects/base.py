"""The abstract :class:`Effect`: a named physical effect the MMG model can be given.

An effect is defined once here and used by the simulator (through the parameter-vector slots
of :mod:`mmg.model`), the replay (:mod:`mmg.replay`: packed ship, external loads, measured
states), the estimators (:mod:`ekf.identify` frees its parameters) and the discrepancy workflow
(:mod:`trials.measured.diagnose`).  It declares

* its named parameters (:class:`Parameter`: unit, default, bounds, the prior width used when
  it is fitted), in the units their names carry (``speed_mps``, ``direction_deg``, ...);
* how it acts, by overriding any of

  - :meth:`Effect.pack`: the packed ship with the effect in it (parameter-vector slots such as
    the current or the rudder offset, or corrected hull coefficients for shallow water);
  - :meth:`Effect.external`: time-dependent external loads (X, Y, N) from the record's logged
    channels (wind from the measured relative wind);
  - :meth:`Effect.to_model` / :meth:`Effect.to_logged`: the map between the logged states and
    the model's states (a heading bias; a current turning over-ground velocities into
    water-relative ones), applied to the record's states before a replay (its initial and reset
    states) and to the replayed states before they are compared with the record;

* the logged channels it needs (:attr:`Effect.channels`): a record without them skips the
  effect with :meth:`Effect.unavailable`'s reason.

The states are the replay's ``(u, v, r, x, y, psi)`` (:data:`mmg.replay.STATE`): *logged* states
are as a record logs them (FRT-DS-ESSO: u, v over ground, in ship axes resolved in the logged
heading; heading as logged); *model* states are the MMG state (u, v through the water, true
heading; x, y over ground in both).

Fitting: :attr:`Effect.fit_parameters` are the parameters the estimator varies (by default the
named ones; the current is fitted in north/east components, which stay regular at zero speed)
and :meth:`Effect.report` maps fitted values and their covariance back to the named parameters
with standard errors (delta method).
"""
from __future__ import annotations

import abc
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..errors import InputError

__all__ = ["Parameter", "Context", "Effect", "EffectSet"]


@dataclass(frozen=True)
class Parameter:
    """A named effect parameter in the unit its name carries.

    default: the value that switches the effect off (or its neutral value); lower, upper: the
    physically allowed range; sigma: the prior standard deviation a fit uses (wide: a prior
    that keeps a fit regular, not information); start: where a fit starts.  The one prior of the
    parameter: every estimator reads it through :func:`ekf.identify.effect_prior` (``mmg identify``,
    ``mmg diagnose`` alike)."""

    name: str
    unit: str
    default: float
    lower: float
    upper: float
    sigma: float
    description: str = ""
    start: float | None = None

    def check(self, owner: str, value) -> float:
        if isinstance(value, bool):
            raise InputError(owner, self.name, f"must be a number [{self.unit}], got {value!r}")
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise InputError(owner, self.name, f"must be a number [{self.unit}], got {value!r:.40}") from None
        if not math.isfinite(v):
            raise InputError(owner, self.name, f"must be a finite number [{self.unit}], got {v!r}")
        if not self.lower <= v <= self.upper:
            raise InputError(owner, self.name, f"{v:g} {self.unit} is outside {self.lower:g} to {self.upper:g} {self.unit}")
        return v


@dataclass(frozen=True)
class Context:
    """What an effect may read from a record besides the states: times, inputs, logged channels.

    t : (N,) [s]; delta (N,) [rad]; n (N,) [rps]; channels: logged channel name -> (N,) array
    (``wind_speed_rel`` [m/s], ``wind_dir_rel`` [rad], ...); ship: the :class:`mmg.ship.Ship`
    (wind geometry, particulars) or None."""

    t: np.ndarray
    delta: np.ndarray
    n: np.ndarray
    channels: dict = field(default_factory=dict)
    ship: object = None


class Effect(abc.ABC):
    """A physical effect with named parameters (module docstring).  Subclasses set the class
    attributes and override the hooks that apply; the defaults do nothing."""

    name: ClassVar[str]
    kind: ClassVar[str]          # "force", "kinematic", "measurement" or "coefficients"
    description: ClassVar[str]
    parameters: ClassVar[tuple]  # of Parameter
    channels: ClassVar[tuple] = ()
    affects: ClassVar[tuple] = ()   # residual channels it shows in: u, v, r, heading, position
    measured_by: ClassVar[str] = "a measurement of it independent of the motion"
    """What measures the effect itself (a ``"coefficients"`` effect's advice where the records cannot
    tell it from the coefficients it changes)."""
    magnitude_unit: ClassVar[str] = "1"
    """The unit of :meth:`magnitude`."""
    detection_size: ClassVar[tuple] = (math.inf, "1")
    """(size, unit): the smallest size of the effect that matters physically, in its fit parameters'
    unit (``"sqrt(gL)"``: a speed over sqrt(g L)): the size a diagnosis should be able to show.  An effect
    whose marginal 2-sigma on the records exceeds it could have been there at a size that matters
    without being named.  Infinite: none stated."""

    @classmethod
    def magnitude(cls, values: dict, L: float) -> float:
        """How large the effect is in a measure that does not depend on the ship's size (unit
        :attr:`magnitude_unit`), from its reported values (:meth:`from_fit`) and the ship's length
        ``L`` [m]; NaN where the effect states none."""
        return math.nan

    # ---------------------------------------------------------------- values
    @classmethod
    def defaults(cls) -> dict:
        return {p.name: p.default for p in cls.parameters}

    @classmethod
    def values(cls, given=None, owner: str | None = None) -> dict:
        """The named values, checked (unknown names and values out of range: InputError)."""
        owner = owner or cls.name
        given = dict(given or {})
        out = cls.defaults()
        names = {p.name: p for p in cls.parameters}
        for k, v in given.items():
            if k not in names:
                raise InputError(owner, k, f"unknown parameter of {cls.name}; expected one of {', '.join(names)}")
            out[k] = names[k].check(owner, v)
        return out

    # ---------------------------------------------------------------- fitting
    @classmethod
    def fit_parameters(cls) -> tuple:
        """The parameters a fit varies (default: the named ones)."""
        return cls.parameters

    @classmethod
    def presence_parameters(cls) -> tuple:
        """Names of the fit parameters whose departure from their neutral value means the effect is
        there (default: every fit parameter; the wind: its scale alone, its shape factors only shape
        a wind that is there).  :mod:`trials.measured.diagnose` judges an effect present on these."""
        return tuple(p.name for p in cls.fit_parameters())

    @classmethod
    def presence_z(cls, theta, cov) -> float:
        """How far the fit says the effect is from absent, in standard errors: the root sum of squares
        of the :meth:`presence_parameters`' departures from their neutral values over their standard
        errors (default).  ``theta``, ``cov``: the effect's fitted parameters (in :meth:`fit_parameters`
        order) and their covariance."""
        th = np.asarray(theta, float)
        std = np.sqrt(np.clip(np.diag(np.asarray(cov, float)), 0.0, None))
        pres = cls.presence_parameters()
        on = np.array([q.name in pres for q in cls.fit_parameters()])
        neutral = np.array([q.default for q in cls.fit_parameters()])
        with np.errstate(divide="ignore", invalid="ignore"):
            return float(np.sqrt(np.sum(((th - neutral)[on] / np.where(std > 0, std, np.inf)[on]) ** 2)))

    @classmethod
    def from_fit(cls, theta) -> dict:
        """Named values from fitted ones (identity by default)."""
        return {p.name: float(v) for p, v in zip(cls.fit_parameters(), theta)}

    @classmethod
    def report(cls, theta, cov) -> tuple[dict, dict]:
        """Named values and standard errors from the fitted ``theta`` and its covariance (delta
        method, numerically)."""
        theta = np.asarray(theta, float)
        cov = np.atleast_2d(np.asarray(cov, float))
        vals = cls.from_fit(theta)
        names = list(vals)
        f0 = np.array([vals[k] for k in names])
        Jm = np.zeros((len(names), len(theta)))
        for j in range(len(theta)):
            h = 1e-7 * max(abs(theta[j]), 1e-3)
            th = theta.copy()
            th[j] += h
            fj = cls.from_fit(th)
            with np.errstate(invalid="ignore"):
                d = np.array([fj[k] for k in names]) - f0
            d[~np.isfinite(d)] = 0.0
            if "direction_deg" in names:                      # wrap angle differences
                i = names.index("direction_deg")
                d[i] = (d[i] + 180.0) % 360.0 - 180.0
            Jm[:, j] = d / h
        c = Jm @ cov @ Jm.T
        std = np.sqrt(np.abs(np.diag(c)))
        return vals, {k: float(s) for k, s in zip(names, std)}

    # ---------------------------------------------------------------- availability
    @classmethod
    def needs(cls, values: dict | None = None) -> tuple:
        """The logged channels the effect needs with ``values`` (default: :attr:`channels`)."""
        return cls.channels

    @classmethod
    def missing(cls, channels, values: dict | None = None) -> str | None:
        """Why a record with ``channels`` (name -> array or None) cannot give the effect with ``values``
        what it needs (:meth:`needs`), or None when it can."""
        gone = [c for c in cls.needs(values) if (channels or {}).get(c) is None]
        if gone:
            return f"the record has no {' / '.join(gone)} channel{'s' if len(gone) > 1 else ''}"
        return None

    @classmethod
    def unavailable(cls, ctx: Context) -> str | None:
        """Why the effect cannot be applied to this record (None when it can)."""
        return cls.missing(ctx.channels)

    @classmethod
    def changed_coefficients(cls, ship) -> tuple:
        """The names of the ship's own coefficients a ``"coefficients"`` effect changes (hull terms by
        their config names, ``m_x``, ``m_y``, ``J_z``, ``w_P0``); () for an effect of another kind.  A
        fit that frees every one of them cannot tell the effect from the ship."""
        return ()

    # ---------------------------------------------------------------- how it acts
    @classmethod
    def slots(cls, values: dict) -> dict:
        """Parameter-vector index -> value (:mod:`mmg.model`); empty by default."""
        return {}

    @classmethod
    def pack(cls, packed, values: dict, ship=None):
        """The packed ship with the effect in it (default: :meth:`slots` written into ``p``)."""
        s = cls.slots(values)
        if not s:
            return packed
        from dataclasses import replace

        p = packed.p.copy()
        for k, v in s.items():
            p[k] = v
        return replace(packed, p=p)

    @classmethod
    def external(cls, values: dict, ctx: Context):
        """(N, 3) external loads [N, N, N m] about midship in ship axes, or None."""
        return None

    @classmethod
    def to_model(cls, values: dict, states: np.ndarray) -> np.ndarray:
        """Logged (N, 6) states -> model states (identity by default)."""
        return states

    @classmethod
    def to_logged(cls, values: dict, states: np.ndarray) -> np.ndarray:
        """Model (N, 6) states -> logged states (identity by default)."""
        return states


@dataclass(frozen=True)
class EffectSet:
    """Several effects with their values, applied together: packed ship, loads, state maps.

    ``items`` is a tuple of (Effect class, values dict).  The measurement side composes in a
    fixed order: logged -> model applies the measurement effects first (a heading bias gives the
    true heading), then the kinematic ones (a current, resolved in the true heading); model ->
    logged the reverse."""

    items: tuple = ()

    _ORDER = {"measurement": 0, "kinematic": 1, "force": 2, "coefficients": 3}

    def __hash__(self):            # the values are dicts: hash their items (a Ship holding a set stays hashable)
        return hash(tuple((e.name, tuple(sorted(v.items()))) for e, v in self.items))

    def _sorted(self):
        return sorted(self.items, key=lambda it: self._ORDER.get(it[0].kind, 9))

    def names(self) -> list:
        return [e.name for e, _ in self.items]

    def get(self, name: str):
        """The values of effect ``name``, or None when it is not in the set."""
        for e, v in self.items:
            if e.name == name:
                return v
        return None

    def merged(self, other: "EffectSet | None") -> "EffectSet":
        """This set with ``other``'s effects added; an effect in both takes ``other``'s values
        (a trial's ``effects:`` over its ship's)."""
        if other is None or not other.items:
            return self
        mine = {e.name: (e, v) for e, v in self.items}
        for e, v in other.items:
            mine[e.name] = (e, v)
        return EffectSet(tuple(mine.values()))

    def usable(self, channels) -> tuple["EffectSet", list]:
        """(this set without the effects a record with ``channels`` cannot feed, [(name, why), ...]).

        The one rule every command applies to a record (``mmg predict``, ``mmg identify``, ``mmg
        diagnose`` through :func:`trials.measured.predict.measured_run`): an effect whose logged channels
        (:meth:`Effect.needs`, e.g. the measured relative wind) the record lacks is left out, and
        why is said, instead of being applied to channels that are not there."""
        keep, gone = [], []
        for e, v in self.items:
            why = e.missing(channels, v)
            (gone.append((e.name, why)) if why else keep.append((e, v)))
        return EffectSet(tuple(keep)), gone

    def without(self, *names: str) -> "EffectSet":
        """This set without the named effects."""
        return EffectSet(tuple(it for it in self.items if it[0].name not in names))

    def summary(self) -> str:
        """One line, e.g. ``current speed_mps=0.3 direction_deg=90; rudder_offset offset_deg=1`` ("none")."""
        if not self.items:
            return "none"
        return "; ".join(f"{e.name} " + " ".join(f"{k}={v:g}" for k, v in vals.items()) for e, vals in self.items)

    def pack(self, packed, ship=None):
        for e, v in self.items:
            packed = e.pack(packed, v, ship)
        return packed

    def external(self, ctx: Context, base=None):
        out = None if base is None else np.array(base, float)
        for e, v in self.items:
            f = e.external(v, ctx)
            if f is not None:
                out = f if out is None else out + f
        return out

    def to_model(self, states):
        s = np.array(states, float)
        for e, v in self._sorted():
            s = e.to_model(v, s)
        return s

    def to_logged(self, states):
        s = np.array(states, float)
        for e, v in reversed(self._sorted()):
            s = e.to_logged(v, s)
        return s
