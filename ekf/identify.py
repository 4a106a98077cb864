"""Joint identification over measured records: segment-wise output error with a prior.

Each record (its measured states and prescribed inputs, :class:`mmg.replay.ReplayInputs`) is cut
into segments of ``segment_s`` seconds; every segment is replayed (:func:`mmg.replay.replay_states`
with ``reset``) from the measured state at its start, so an error in one segment does not carry
into the next (multiple shooting without continuity constraints).  The residuals are the
differences of u, v, r and heading between replay and record, each divided by its scale
(:class:`Scales`), over every segment of every record, plus the prior residuals
(theta - theta_0) / sigma_0 that keep coefficients the records do not inform at their config
values (a maximum a posteriori output-error fit).  Levenberg-Marquardt-like trust-region steps
(:func:`scipy.optimize.least_squares`) with forward-difference Jacobian columns computed on all
cores (threads; the compiled replay releases the GIL).

The free parameters (:class:`FreeParameter`) are hull coefficients by name and, optionally,
the ship constants ``"w_P0"`` (the constant term of the wake polynomial: the model-scale wake),
``"epsilon"`` (rudder inflow ratio), ``"kappa"`` (the share of the propeller slipstream's speed-up
that reaches the rudder, Yasukawa & Yoshimura 2015) and the others of :mod:`mmg.parameters`.  The standard errors
are from the Gauss-Newton covariance at the optimum, scaled by the residual variance per
degree of freedom; correlated residuals (10 Hz samples are not independent) make them optimistic.

Effects (:mod:`mmg.effects`): ``identify_segments(..., effects=[Current, ...], ship=ship)`` adds
named effects to the model; their fit parameters are free parameters of kind ``"effect"``
(:func:`effect_parameters`; ``index`` the effect's position in ``effects``, ``sub`` the
parameter's), fitted with the ship's.  Each record's replay then uses the packed ship with the
effects in it, their external loads (from the record's logged channels, ``Segmented.context``),
starts and restarts from the model states of the logged ones and is compared in logged states
(:class:`mmg.effects.EffectSet`).  ``Scales.pos`` [m] adds the position residuals (x, y) to the
fit; without effects and ``pos`` the fit is the one above, bit for bit.

Start states (:func:`start_parameters`): a free parameter of kind ``"start"`` is an offset on one
logged state (``sub``: u, v, r, x, y, psi) of one record's first sample (``record``), the state its
replay starts from; the residuals stay against the measured samples.  Fitted as a per-record
nuisance beside the ship's parameters, so the noise of one sample does not drift a whole open-loop
replay (and is not absorbed by the shared parameters).  :attr:`IdentifyResult.info_data` keeps the
data rows' J^T J apart from the prior's, so a caller can weigh the two differently.
"""
from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace

import numpy as np

from mmg.model import PackedShip
from mmg.parameters import CONSTANTS, DIAGNOSIS_PRIOR_REL_STD, PRIOR_REL_STD, parameter
from mmg.replay import ReplayInputs, replay_states

from .covariance import run_jackknife_covariance  # noqa: F401  (part of this module's API)

__all__ = ["Segmented", "Scales", "FreeParameter", "IdentifyResult", "free_parameters", "apply_parameters",
           "segment_resets", "identify_segments", "FitOptions", "SHIP_CONSTANTS", "record_weights",
           "record_residual_rms", "RECORD_WEIGHTINGS", "effect_parameters", "effect_prior", "wind_scaled",
           "PRIOR_REL_STD", "DIAGNOSIS_PRIOR_REL_STD", "logged_residual", "record_effect_parameters", "effect_set_of",
           "predict_logged", "start_parameters", "record_residuals", "model_states", "StraightRun",
           "straight_run_residual", "STRAIGHT_RUN_DRIFT_SD", "FAILED_RESIDUAL", "run_jackknife_covariance"]

SHIP_CONSTANTS = tuple(CONSTANTS)
"""Ship constants besides the hull coefficients that :func:`free_parameters` can free: the names of the
parameter table's constants (:data:`mmg.parameters.CONSTANTS`; ``"wind_scale"``, the wind's shape factors
and ``"rudder_offset"`` are the ``wind`` and ``rudder_offset`` effects' parameters under their
``mmg identify --free`` names: their priors and bounds are the effects' own, :func:`effect_prior`)."""


@dataclass(frozen=True)
class StraightRun:
    """A record's leading steady straight run (rudder at its trim, no yaw): its first ``n`` samples.

    Any hull sails a straight run with (almost) no drift through the water: the model's own trim
    drift is 0.009 deg for the bundled Esso Osaka.  The sway over ground the record logs there is
    then what the measurement and kinematic effects make of none (a heading bias: -u sin b; a
    current: its part across the heading), whatever the hull coefficients are; this is the one
    stretch of a turning circle where a heading bias does not trade with them
    (:func:`straight_run_residual`)."""

    n: int
    """Samples of the straight run, from the record's first."""
    sigma: float
    """Standard error [m/s] of the run's mean logged sway as a measure of that: the noise's over the
    run's samples and the hull's own straight-run drift (:data:`STRAIGHT_RUN_DRIFT_SD`)."""


STRAIGHT_RUN_DRIFT_SD = math.radians(0.1)
"""Std [rad] of a hull's drift angle in its straight run that the model does not have: ten times
the bundled Esso Osaka's own trim drift (0.009 deg), for a real hull's asymmetry and the small
wind a straight run is accepted with (:func:`trials.measured.diagnose.records.leading_straight_run`)."""


@dataclass(frozen=True)
class Segmented:
    """One record for the fit: measured states (N, 6), inputs and the segment starts (bool (N,))."""

    name: str
    meas: np.ndarray
    inputs: ReplayInputs
    reset: np.ndarray
    context: object = None
    """:class:`mmg.effects.Context` of the record (logged channels the effects read), or None."""
    start: np.ndarray | None = None
    """States (N, 6) the replay starts and restarts from (e.g. a smoothed ``meas``: a restart
    from one noisy sample leaves a transient through the whole segment); ``meas`` when None.
    The residuals are always against ``meas``."""
    fixed: object = None
    """:class:`mmg.effects.EffectSet` of effects the ship config has on (a current, a rudder offset,
    shallow water, a steady wind), applied with their values and not fitted; None: none."""
    speed_only: bool = False
    """The record logs the speed over ground, not u and v (``meas`` u is that speed, v a stand-in
    zero): u is compared as the predicted speed over ground and v not at all (:func:`logged_residual`)."""
    straight: StraightRun | None = None
    """Its leading steady straight run, whose mean sway over ground is one more residual of the fit
    (:func:`straight_run_residual`); None: not used."""

    @property
    def restart(self) -> np.ndarray:
        return self.meas if self.start is None else self.start

    def first_segment(self) -> "Segmented":
        """The record up to its second segment start (the whole record when it has one segment): what
        an offset of its start state moves, every later segment restarting from its own state."""
        later = np.flatnonzero(np.asarray(self.reset, bool)[1:])
        n = len(self.meas) if len(later) == 0 else int(later[0]) + 1
        if n == len(self.meas):
            return self
        cut = lambda a: None if a is None else a[:n]  # noqa: E731
        ctx = self.context
        if ctx is not None:
            ctx = replace(ctx, t=ctx.t[:n], delta=ctx.delta[:n], n=ctx.n[:n],
                          channels={k: np.asarray(v)[:n] for k, v in ctx.channels.items()})
        inp = self.inputs
        return replace(self, meas=self.meas[:n], reset=self.reset[:n], start=cut(self.start), context=ctx,
                       inputs=replace(inp, t=inp.t[:n], delta=inp.delta[:n], n=inp.n[:n], ext=cut(inp.ext)))


@dataclass(frozen=True)
class Scales:
    """Residual scales: u, v [m/s], r [rad/s], heading [rad]."""

    u: float
    v: float
    r: float
    psi: float
    pos: float | None = None
    """Position scale [m]: x, y residuals are added when given."""

    def array(self) -> np.ndarray:
        return np.array([self.u, self.v, self.r, self.psi])


@dataclass(frozen=True)
class FreeParameter:
    """A parameter being fitted: its name, kind (``"hull"`` index or ship constant), prior value and std, and
    how it acts (:attr:`apply`, :attr:`loads`: its parameter-table entry's rules)."""

    name: str
    kind: str
    index: int
    prior: float
    sigma: float
    lower: float = -np.inf
    upper: float = np.inf
    sub: int = 0
    """For kind ``"effect"``: the parameter's position in the effect's ``fit_parameters()``."""
    record: int | None = None
    """For a record's own nuisance parameter (:func:`record_effect_parameters`): the record's index
    in the fit; None: shared by every record."""
    start: float | None = None
    """Where a fit starts (:func:`identify_segments` without ``start``); the prior when None."""
    apply: object = None
    """``apply(packed, index, value)``: writes the value into a packed ship's copied arrays
    (:attr:`mmg.parameters.ShipParameter.apply`).  None: the rule of its ``kind`` (a parameter made by
    hand): nothing for kinds ``"effect"`` and ``"start"`` (applied by :func:`effect_set_of` and to the
    start states), else the parameter table's rule of that kind (:func:`mmg.parameters.rule_of_kind`)."""
    loads: object = None
    """``loads(factors, sub, value)``: where the value acts on the records' external loads
    (:attr:`mmg.parameters.ShipParameter.loads`), or None; as :attr:`apply` when ``apply`` is None."""

    def __post_init__(self):
        if self.apply is None:
            from mmg.parameters import not_packed, rule_of_kind

            rules = (not_packed, None) if self.kind in ("effect", "start") else rule_of_kind(self.kind)
            object.__setattr__(self, "apply", rules[0])
            object.__setattr__(self, "loads", self.loads if self.loads is not None else rules[1])


def effect_prior(effect, name: str, nm: str | None = None, kind: str = "effect", index: int = 0,
                 factor: float = 1.0, centre: float | None = None) -> "FreeParameter":
    """The :class:`FreeParameter` of fit parameter ``name`` of ``effect`` (:meth:`mmg.effects.Effect.fit_parameters`)
    with the effect's own prior, bounds and start, the values times ``factor`` (e.g. degrees to
    radians) and the prior centred on ``centre`` (default the parameter's own): the one place an
    estimator reads an effect parameter's prior."""
    fp = effect.fit_parameters()
    j = [q.name for q in fp].index(name)
    q = fp[j]
    start = None if q.start is None else factor * q.start
    return FreeParameter(nm or f"{effect.name}.{q.name}", kind, index,
                         factor * q.default if centre is None else float(centre), factor * q.sigma,
                         factor * q.lower, factor * q.upper, sub=j, start=start)


def _packed_terms(packed: PackedShip) -> list[str]:
    """The term expression of each of the packed ship's hull coefficients (:data:`mmg.terms.TERMS`)."""
    from mmg.terms import TERMS

    name = {i: k for k, i in TERMS.items()}
    return [name[int(t)] for t in packed.hull_term]


def free_parameters(packed: PackedShip, hull_names, names, prior_rel_std: float | None = None,
                    priors: dict | None = None, hull_terms=()) -> list[FreeParameter]:
    """The :class:`FreeParameter` list for ``names`` (hull coefficient names or :data:`SHIP_CONSTANTS`), from
    the parameter table (:mod:`mmg.parameters`).

    The prior std of a ship coefficient is its family's relative std (``priors``, default
    :data:`PRIOR_REL_STD`) times its config value, with the entry's floor; ``prior_rel_std``, when
    given, is one relative std for every family instead.  Effect parameters (``"rudder_offset"``,
    ``"wind_scale"`` and the wind's shape factors) take the effects' priors (:func:`effect_prior`).
    ``hull_terms`` (the hull model's term of each name) marks the straight-ahead resistance, bounded to
    stay negative; without them the packed ship's own terms tell it."""
    import mmg.effects as E

    rel = dict(priors or PRIOR_REL_STD)
    if prior_rel_std is not None:
        rel = {k: float(prior_rel_std) for k in rel}
    terms = list(hull_terms) or _packed_terms(packed)
    out = []
    for nm in names:
        spec = parameter(nm, hull_names, terms)
        v = spec.config_value(packed)
        rules = {"apply": spec.apply, "loads": spec.loads}
        if spec.effect is not None:
            on_loads = spec.loads is not None         # a factor on the records' loads (sub: their column)
            f = effect_prior(E.get(spec.effect.effect), spec.effect.parameter, nm, spec.kind,
                             0 if on_loads else spec.slot, spec.effect.factor, None if on_loads else v)
            out.append(replace(f, sub=spec.slot, **rules) if on_loads else replace(f, **rules))
            continue
        lo, hi = spec.bounds(v)
        out.append(FreeParameter(nm, spec.kind, spec.slot, v, spec.prior_std(v, rel), lo, hi, **rules))
    return out


def apply_parameters(packed: PackedShip, free: list[FreeParameter], theta) -> PackedShip:
    """A copy of ``packed`` with the free parameters set to ``theta``, each by its own rule
    (:attr:`FreeParameter.apply`: the parameter table's, :mod:`mmg.parameters`)."""
    out = replace(packed, p=packed.p.copy(), poly=packed.poly.copy(), hull_coef=packed.hull_coef.copy())
    for f, v in zip(free, theta):
        f.apply(out, f.index, v)
    return out


def effect_parameters(effects) -> list[FreeParameter]:
    """Free parameters (kind ``"effect"``, named ``"<effect>.<parameter>"``) of every fit parameter
    of ``effects`` (:mod:`mmg.effects` classes), priors at the parameters' neutral values."""
    out = []
    for i, e in enumerate(effects):
        for j, q in enumerate(e.fit_parameters()):
            out.append(effect_prior(e, q.name, index=i))
    return out


def record_effect_parameters(effects, n_records: int, first_index: int = 0, names=None) -> list[FreeParameter]:
    """Nuisance parameters: every fit parameter of ``effects`` once for each of ``n_records`` records
    (named ``"<effect>.<parameter>[<record>]"`` with the record's name from ``names`` or its index,
    :attr:`FreeParameter.record` its index), each acting on its own record only.  ``first_index``:
    the position of ``effects[0]`` in the effects list of the fit."""
    out = []
    for k in range(n_records):
        tag = names[k] if names is not None else k
        for i, e in enumerate(effects):
            for j, q in enumerate(e.fit_parameters()):
                out.append(replace(effect_prior(e, q.name, f"{e.name}.{q.name}[{tag}]", index=first_index + i),
                                   record=k))
    return out


def start_parameters(sigmas, names=None, channels=(0, 1, 2, 5)) -> list[FreeParameter]:
    """Nuisance offsets of each record's start state (kind ``"start"``, prior 0): ``sigmas`` (n_records, 6)
    the prior std of each logged state's offset (u, v [m/s], r [rad/s], x, y [m], psi [rad]) per record;
    one parameter per record and channel of ``channels`` whose std is positive and finite, named
    ``"start.<state>[<record>]"`` (the record's name from ``names`` or its index)."""
    from mmg.replay import STATE

    out = []
    for k, sig in enumerate(np.asarray(sigmas, float)):
        tag = names[k] if names is not None else k
        for j in channels:
            if np.isfinite(sig[j]) and sig[j] > 0:
                out.append(FreeParameter(f"start.{STATE[j]}[{tag}]", "start", j, 0.0, float(sig[j]), sub=j, record=k))
    return out


def _started(rec: Segmented, free, theta, record) -> Segmented:
    """``rec`` with its first restart state moved by record ``record``'s start offsets (kind ``"start"``)."""
    off = [(f.sub, float(v)) for f, v in zip(free, theta) if f.kind == "start" and f.record == record]
    if not off:
        return rec
    st = np.array(rec.restart, float, copy=True)
    for j, v in off:
        st[0, j] += v
    return replace(rec, start=st)


def effect_set_of(effects, free: list[FreeParameter], theta, record: int | None = None):
    """The :class:`mmg.effects.EffectSet` of ``effects`` at the fitted values ``theta`` (effect
    parameters not in ``free`` at their fit-parameter defaults) for record ``record``: the shared
    parameters and that record's own (:func:`record_effect_parameters`)."""
    from mmg.effects import EffectSet

    items = []
    for i, e in enumerate(effects or ()):
        fp = e.fit_parameters()
        vec = [q.default for q in fp]
        for f, v in zip(free, theta):
            if f.kind == "effect" and f.index == i and (f.record is None or f.record == record):
                vec[f.sub] = float(v)
        items.append((e, e.from_fit(vec)))
    return EffectSet(tuple(items))


def model_states(es, logged: np.ndarray, speed_only: bool = False) -> np.ndarray:
    """The model's states (through the water, true heading) of logged ones (N, 6) under the effects
    ``es`` (:meth:`mmg.effects.EffectSet.to_model`): what a replay starts and restarts from.  A record
    that logs no sway (``speed_only``: v a stand-in zero) starts with none through the water, whatever
    the effects make of the stand-in (a current would turn it into a sway of minus its cross part)."""
    mm = es.to_model(logged)
    if speed_only:
        mm[:, 1] = 0.0
    return mm


def predict_logged(packed: PackedShip, rec: Segmented, effects=None, free=(), theta=(), ship=None,
                   record: int | None = None) -> np.ndarray:
    """The replayed states of ``rec`` (segments as in ``rec.reset``) as the record logs them:
    (N, 6) u, v, r, x, y, psi with the ship parameters and effects at ``theta`` (with the nuisance
    parameters of record index ``record``)."""
    pk = apply_parameters(packed, list(free), theta) if len(free) else packed
    if not effects and rec.fixed is None:
        return replay_states(pk, rec.inputs, rec.restart[0], meas=rec.restart, reset=rec.reset)
    es = effect_set_of(effects, list(free), theta, record)
    if rec.fixed is not None:
        es = rec.fixed.merged(es)
    pk = es.pack(pk, ship)
    ext = es.external(rec.context, base=rec.inputs.ext)
    inputs = replace(rec.inputs, ext=ext) if ext is not None else rec.inputs
    mm = model_states(es, rec.restart, rec.speed_only)
    pred = replay_states(pk, inputs, mm[0], meas=mm, reset=rec.reset)
    return es.to_logged(pred)


def segment_resets(t: np.ndarray, segment_s: float) -> np.ndarray:
    """Segment starts (bool (N,)): the first sample and every sample ``segment_s`` [s] after the last start."""
    reset = np.zeros(len(t), dtype=bool)
    nxt = t[0]
    for i, ti in enumerate(t):
        if ti >= nxt - 1e-9:
            reset[i] = True
            nxt = ti + segment_s
    return reset


def wind_scaled(inputs: ReplayInputs, scale: float, sway_factor: float = 1.0, yaw_factor: float = 1.0) -> ReplayInputs:
    """``inputs`` with their external (measured-wind) loads (X, Y, N) times the wind effect's factors of a
    fitted ``wind_scale``, ``sway_factor`` and ``yaw_factor`` (:meth:`mmg.effects.Wind.load_factors`): how
    the fitted values act, in the fit and in the identified model's replays."""
    from mmg.effects import Wind

    if inputs.ext is None:
        return inputs
    return replace(inputs, ext=inputs.ext * Wind.load_factors(scale, sway_factor, yaw_factor))


def _wind_scaled(rec: Segmented, free, theta) -> Segmented:
    if rec.inputs.ext is None:
        return rec
    f = np.ones(3)                       # wind_scale (sub 0), sway and yaw factors (sub 1, 2)
    hit = False
    for p, v in zip(free, theta):
        if p.loads is not None:
            p.loads(f, p.sub, v)
            hit = True
    return replace(rec, inputs=wind_scaled(rec.inputs, *f)) if hit else rec


def straight_run_residual(rec: Segmented, effects=None, free=(), theta=(), record: int | None = None) -> float | None:
    """The mean sway over ground of ``rec``'s straight run (:class:`StraightRun`) that the effects at
    ``theta`` predict, minus the logged one, over its ``sigma``; None where the record has none.

    The model's states there are the logged ones through the effects (:meth:`mmg.effects.EffectSet.to_model`)
    with no sway through the water, logged back (:meth:`~mmg.effects.EffectSet.to_logged`): a heading
    bias b predicts -u sin b, a current its part across the heading, and the hull coefficients
    nothing, so the residual moves with the effects' parameters alone."""
    st = rec.straight
    if st is None:
        return None
    meas = np.asarray(rec.meas[:st.n], float)
    es = effect_set_of(effects, list(free), theta, record)
    if rec.fixed is not None:
        es = rec.fixed.merged(es)
    mm = es.to_model(meas)
    mm[:, 1] = 0.0
    return float(np.mean(es.to_logged(mm)[:, 1] - meas[:, 1])) / st.sigma


FAILED_RESIDUAL = 1e3
"""The scaled residual a diverged (non-finite) segment's samples are given: a large, finite misfit the
least-squares fit can still step away from."""


def logged_residual(pred: np.ndarray, rec: Segmented) -> np.ndarray:
    """Predicted minus measured states (N, 6) of what the record logs: for a record that logs only the
    speed over ground (:attr:`Segmented.speed_only`), u is that speed on both sides and v is 0."""
    diff = pred - rec.meas
    if rec.speed_only:
        diff[:, 0] = np.hypot(pred[:, 0], pred[:, 1]) - rec.meas[:, 0]
        diff[:, 1] = 0.0
    return diff


def _residual_one(packed, rec: Segmented, sc: np.ndarray, stride: int, effects=None, free=(), theta=(),
                  ship=None, pos=None, record: int | None = None) -> np.ndarray:
    rec = _started(_wind_scaled(rec, free, theta), free, theta, record)
    if effects or rec.fixed is not None:
        pred = predict_logged(packed, rec, effects, free, theta, ship, record)
    else:
        pred = replay_states(packed, rec.inputs, rec.restart[0], meas=rec.restart, reset=rec.reset)
    diff = logged_residual(pred, rec)[::stride]
    d = diff[:, [0, 1, 2, 5]] / sc
    if pos is not None:
        d = np.column_stack([d, diff[:, [3, 4]] / pos])
    d[~np.isfinite(d)] = FAILED_RESIDUAL              # a diverged segment: a large, finite misfit
    return d.ravel()


@dataclass(frozen=True)
class IdentifyResult:
    """The fit: free parameters, values, standard errors, correlation, cost before and after."""

    free: list
    theta: np.ndarray
    std: np.ndarray
    corr: np.ndarray
    cost_initial: float
    cost_final: float
    n_residuals: int
    iterations: int
    message: str
    status: int = 1
    """scipy's ``least_squares`` status: 0 the evaluation limit stopped it, > 0 converged."""
    info_data: np.ndarray | None = None
    """J_d^T J_d of the data rows alone (the residuals of the records, without the prior's rows) at the
    solution, unscaled; None where not computed."""
    ss_data: float | None = None
    """Sum of squares of the data rows' residuals at the solution (twice the cost without the prior's part)."""
    record_scores: np.ndarray | None = None
    """(n_records, n) each record's score J_k^T r_k at the solution: its data rows (its block and its
    straight-run row) alone, in the fit's weighted units; None where not computed."""
    record_info: np.ndarray | None = None
    """(n_records, n, n) each record's J_k^T J_k at the solution, as :attr:`record_scores`; their sum is
    :attr:`info_data`."""

    def warnings(self) -> list[str]:
        """What a reader of the values should not miss, one sentence each: a parameter on one of its
        bounds (the bound, not the data, set it), a parameter whose sign is the opposite of its
        prior's (for a hull derivative: another physics, e.g. a damping that feeds the motion), and a
        fit stopped by its evaluation limit instead of converging."""
        out = []
        for f, v in zip(self.free, self.theta):
            v = float(v)
            for side, b in (("lower", f.lower), ("upper", f.upper)):
                if np.isfinite(b) and abs(v - b) <= 1e-6 * (1.0 + abs(b)):
                    out.append(f"{f.name} is at its {side} bound {b:.4g}: the bound, not the data, set it")
            if f.prior != 0.0 and v != 0.0 and np.sign(v) != np.sign(f.prior):
                out.append(f"{f.name} changed sign: {f.prior:.4g} in the config, {v:.4g} identified")
        if self.status == 0:
            out.append(f"the fit stopped at its evaluation limit after {self.iterations} evaluations without "
                       f"converging ({self.message})")
        return out

    def values(self) -> dict:
        """Fitted value of each free parameter, by name (a record's start-state offsets, kind ``"start"``,
        left out: they move one replay's start, not the model)."""
        return {f.name: float(v) for f, v in zip(self.free, self.theta) if f.kind != "start"}

    def to_pandas(self):
        """One row per parameter: prior, estimate, standard error, change from the prior [%]."""
        import pandas as pd

        rows = [{"name": f.name, "prior": f.prior, "estimate": float(v), "std": float(s),
                 "change_pct": 100.0 * (float(v) - f.prior) / abs(f.prior) if f.prior else np.nan}
                for f, v, s in zip(self.free, self.theta, self.std)]
        return pd.DataFrame(rows).set_index("name")


RECORD_WEIGHTINGS = ("samples", "equal", "relative")
"""How the records' residual blocks are weighted (:func:`record_weights`)."""


def record_weights(records: list[Segmented], weighting: str = "samples", stride: int = 2, rms=None) -> np.ndarray:
    """Factor on each record's residual block.

    ``"samples"``: 1 (every sample counts the same: a record counts in proportion to its length).
    ``"equal"``: sqrt(mean n / n_i), n_i the record's residual samples, so each record's sum of
    squares is its mean square times the mean n: every record counts the same whatever its length.
    ``"relative"``: as ``"equal"`` and divided by the record's residual RMS ``rms`` (at the stage's
    start) over the median of those, so a record counts by its relative improvement: a record
    whose open-loop heading error grows to tens of degrees does not outweigh one already within a
    few.  The factors keep the total count of residuals, so the prior weighs the same against them."""
    if weighting not in RECORD_WEIGHTINGS:
        raise ValueError(f"record weighting {weighting!r}: one of {RECORD_WEIGHTINGS}")
    n = np.array([len(r.meas[::stride]) for r in records], float)
    if weighting == "samples":
        return np.ones(len(records))
    w = np.sqrt(n.mean() / n)
    if weighting == "relative":
        if rms is None:
            raise ValueError("record weighting 'relative' needs each record's residual RMS")
        rms = np.asarray(rms, float)
        w = w * float(np.median(rms)) / np.maximum(rms, 1e-12)
    return w


def record_residual_rms(packed: PackedShip, records: list[Segmented], free: list[FreeParameter], theta,
                        scales: Scales, stride: int = 2, effects=None, ship=None) -> np.ndarray:
    """RMS of each record's (scaled) residuals with the free parameters at ``theta``."""
    pk = apply_parameters(packed, free, theta)
    return np.array([float(np.sqrt(np.mean(_residual_one(pk, rec, scales.array(), stride, effects, free, theta,
                                                          ship, scales.pos, k) ** 2))) for k, rec in enumerate(records)])


def record_residuals(packed: PackedShip, records: list[Segmented], free: list[FreeParameter], theta,
                     scales: Scales, stride: int = 2, effects=None, ship=None) -> list[np.ndarray]:
    """Each record's scaled, unweighted residuals (n_k, 4: u, v, r, heading; 6 with ``scales.pos``) at
    ``theta``, every ``stride``-th sample, as the fit sees them (start offsets and nuisance included)."""
    pk = apply_parameters(packed, free, theta)
    nch = 4 if scales.pos is None else 6
    return [_residual_one(pk, rec, scales.array(), stride, effects, free, theta, ship, scales.pos, k).reshape(-1, nch)
            for k, rec in enumerate(records)]


@dataclass(frozen=True)
class FitOptions:
    """How :func:`identify_segments` fits (each field also a keyword argument of it).

    Attributes
    ----------
    stride : int
        Use every ``stride``-th sample in the residuals.
    n_jobs : int, optional
        Threads for the Jacobian columns; all cores when omitted.
    max_nfev : int
        Most trust-region iterations.
    progress : callable, optional
        ``progress(iteration, cost)`` after each Jacobian.
    start : array_like, optional
        Starting values (a previous fit's); the priors when omitted.
    effects : list of mmg.effects classes, optional
        Effects in the model; their parameters are the ``free`` ones of kind ``"effect"``
        (:func:`effect_parameters`).
    ship : mmg.ship.Ship, optional
        The ship (coefficient effects such as ``shallow_water`` need its particulars).
    weights : array_like, optional
        Factor on each record's residual block (:func:`record_weights`); 1 when omitted.
    loss, f_scale : str, float
        :func:`scipy.optimize.least_squares`'s loss ("linear": least squares; "soft_l1", "cauchy":
        robust) and its residual scale (in units of the scaled residuals).
    straight_weight : float
        Factor on each record's straight-run residual (:func:`straight_run_residual`, one row per
        record that has a :class:`StraightRun`, after the records' blocks).  The records' rows are
        weighted as if independent; where they are correlated, a caller gives the straight run
        (one mean, with its own standard error) the weight that keeps its balance against them:
        ``mmg diagnose`` gives sqrt(tau_v), the v rows' correlation time, as its dBIC counts each v
        row 1/tau_v times (:mod:`trials.measured.diagnose`).
    """

    stride: int = 2
    n_jobs: int | None = None
    max_nfev: int = 40
    progress: object = None
    start: object = None
    effects: object = None
    ship: object = None
    weights: object = None
    loss: str = "linear"
    f_scale: float = 1.0
    straight_weight: float = 1.0


class _SegmentFit:
    """The residuals and forward-difference Jacobian of one :func:`identify_segments` fit."""

    def __init__(self, packed: PackedShip, records: list[Segmented], free: list[FreeParameter], scales: Scales,
                 opts: FitOptions, pool: ThreadPoolExecutor):
        self.packed, self.records, self.free, self.opts, self.pool = packed, records, free, opts, pool
        self.sc, self.pos = scales.array(), scales.pos
        self.theta0 = np.array([f.prior for f in free])
        self.sig0 = np.array([f.sigma for f in free])
        self.by_columns = opts.effects is not None or self.pos is not None   # few records: the columns in parallel
        n = len(records)
        self.wts = np.ones(n) if opts.weights is None else np.asarray(opts.weights, float)
        if self.wts.shape != (n,):
            raise ValueError(f"weights: one per record ({n}), got {self.wts.shape}")
        self.own = [f.record for f in free]                   # a record's own (nuisance) parameter, or None
        nch = 4 if self.pos is None else 6
        self.start = np.cumsum([0] + [len(r.meas[::opts.stride]) * nch for r in records])   # each record's block
        self.heads = {k: records[k].first_segment() for k in set(self.own) - {None}}   # what a start offset moves
        self.straight = [k for k, r in enumerate(records) if r.straight is not None]   # one row each, after the blocks
        self.longest_first = sorted(range(n), key=lambda k: -len(records[k].meas))   # the pool's order (see resid)
        self.count = 0
        self._last = None                                     # (theta's bytes, its residuals): see resid

    def record_rows(self) -> list[np.ndarray]:
        """Each record's data rows in the residual vector: its block, then its straight-run row if any."""
        s, end = self.start, self.start[-1]
        return [np.r_[np.arange(s[k], s[k + 1]), [end + self.straight.index(k)] if k in self.straight else []]
                .astype(int) for k in range(len(self.records))]

    def block(self, theta, k, pk=None, rec=None):
        """Record k's weighted residuals (of ``rec``, a part of it such as its first segment, when given)."""
        o = self.opts
        pk = apply_parameters(self.packed, self.free, theta) if pk is None else pk
        rec = self.records[k] if rec is None else rec
        return self.wts[k] * _residual_one(pk, rec, self.sc, o.stride, o.effects, self.free, theta, o.ship, self.pos, k)

    def straight_row(self, theta, k):
        """Record k's weighted straight-run residual (:func:`straight_run_residual`)."""
        o = self.opts
        return o.straight_weight * self.wts[k] * straight_run_residual(self.records[k], o.effects, self.free, theta, k)

    def resid(self, theta, parallel=True):
        """Every record's residuals, then their straight runs', then the prior's.  The last vector made on
        the main thread (``parallel``) is kept: the Jacobian at a point the solver has just evaluated
        starts from it instead of replaying the records again."""
        if not parallel:                                  # a Jacobian column on a pool thread
            return self._resid(theta, False)
        key = np.asarray(theta, float).tobytes()
        if self._last is None or self._last[0] != key:
            self._last = (key, self._resid(theta, True))
        return self._last[1].copy()

    def _resid(self, theta, parallel):
        pk = apply_parameters(self.packed, self.free, theta)
        one = lambda k: self.block(theta, k, pk)  # noqa: E731
        if parallel:       # longest records first, so no long one is left to run alone at the end
            done = dict(zip(self.longest_first, self.pool.map(one, self.longest_first)))
            parts = [done[k] for k in range(len(self.records))]
        else:
            parts = [one(k) for k in range(len(self.records))]
        straight = np.array([self.straight_row(theta, k) for k in self.straight])
        return np.concatenate(parts + [straight, (theta - self.theta0) / self.sig0])

    def _steps(self, theta):
        """(step sizes, stepped parameter vectors), stepping down at an upper bound."""
        h = 1e-6 * np.maximum(np.abs(theta), self.sig0)
        steps = []
        for j in range(len(theta)):
            th = theta.copy()
            if th[j] + h[j] > self.free[j].upper:
                h[j] = -h[j]
            th[j] += h[j]
            steps.append(th)
        return h, steps

    def _own_column(self, j, step, h, r0):
        """A record's own parameter moves only its record's block (and its prior residual): that record
        alone; an offset of its start state (kind ``"start"``) only its first segment, which alone is replayed."""
        col = np.zeros_like(r0)
        k, s = self.own[j], self.start
        b = self.block(step, k, rec=self.heads[k] if self.free[j].kind == "start" else None)
        col[s[k]:s[k] + len(b)] = (b - r0[s[k]:s[k] + len(b)]) / h
        if k in self.straight:
            i = s[-1] + self.straight.index(k)
            col[i] = (self.straight_row(step, k) - r0[i]) / h
        col[s[-1] + len(self.straight) + j] = 1.0 / self.sig0[j]
        return col

    def jac(self, theta):
        """Forward-difference Jacobian, its columns on the pool."""
        r0 = self.resid(theta)
        h, steps = self._steps(theta)
        n = len(theta)
        shared = [j for j in range(n) if self.own[j] is None]
        owned = [j for j in range(n) if self.own[j] is not None]
        if self.by_columns:
            cols = dict(zip(shared, self.pool.map(lambda j: (self.resid(steps[j], parallel=False) - r0) / h[j],
                                                  shared)))
        else:
            cols = {j: (self.resid(steps[j]) - r0) / h[j] for j in shared}
        cols.update(zip(owned, self.pool.map(lambda j: self._own_column(j, steps[j], h[j], r0), owned)))
        self.count += 1
        if self.opts.progress:
            self.opts.progress(self.count, 0.5 * float(r0 @ r0))
        return np.column_stack([cols[j] for j in range(n)])


def _result(free, sol, cost_initial: float, record_rows=None) -> IdentifyResult:
    """The fit with its Gauss-Newton covariance scaled by the residual variance per degree of freedom;
    with ``record_rows`` (one index array per record: its data rows) each record's score and information."""
    J = sol.jac
    n = len(free)
    dof = max(len(sol.fun) - n, 1)
    s2 = float(sol.fun @ sol.fun) / dof
    try:
        cov = np.linalg.inv(J.T @ J) * s2
    except np.linalg.LinAlgError:
        cov = np.full((n, n), np.nan)
    std = np.sqrt(np.abs(np.diag(cov)))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(std, std)
    Jd, fd = np.asarray(J)[:-n], sol.fun[:-n]                # the prior's rows are the last n
    scores = info = None
    if record_rows is not None:
        scores = np.array([Jd[i].T @ fd[i] for i in record_rows]).reshape(len(record_rows), n)
        info = np.array([Jd[i].T @ Jd[i] for i in record_rows]).reshape(len(record_rows), n, n)
    return IdentifyResult(free=free, theta=sol.x, std=std, corr=corr, cost_initial=cost_initial,
                          cost_final=float(sol.cost), n_residuals=len(sol.fun), iterations=int(sol.nfev),
                          message=str(sol.message), status=int(sol.status), info_data=Jd.T @ Jd,
                          ss_data=float(fd @ fd), record_scores=scores, record_info=info)


def identify_segments(packed: PackedShip, records: list[Segmented], free: list[FreeParameter], scales: Scales,
                      options: FitOptions | None = None, **kwargs) -> IdentifyResult:
    """Fit ``free`` jointly over ``records`` (module docstring).

    Parameters
    ----------
    packed : PackedShip
        The ship with its config values (the prior and the starting point).
    records : list of Segmented
    free : list of FreeParameter
    scales : Scales
        Residual scales of u, v, r, heading.
    options : FitOptions, optional
        How to fit; defaults when omitted.
    **kwargs
        Any :class:`FitOptions` field by name (``stride``, ``n_jobs``, ``max_nfev``, ``progress``,
        ``start``, ``effects``, ``ship``, ``weights``, ``loss``, ``f_scale``, ``straight_weight``), over
        ``options``.
    """
    from scipy.optimize import least_squares

    o = FitOptions(**kwargs) if options is None else replace(options, **kwargs)
    pool = ThreadPoolExecutor(max_workers=o.n_jobs or os.cpu_count() or 1)
    try:
        fit = _SegmentFit(packed, records, free, scales, o, pool)
        r_init = fit.resid(fit.theta0)
        lo = np.array([f.lower for f in free])
        hi = np.array([f.upper for f in free])
        x0 = np.array([f.prior if f.start is None else f.start for f in free]) if o.start is None \
            else np.asarray(o.start, float)
        sol = least_squares(fit.resid, np.clip(x0, lo, hi), jac=fit.jac, method="trf", x_scale=fit.sig0,
                            max_nfev=o.max_nfev, bounds=(lo, hi), loss=o.loss, f_scale=o.f_scale)
    finally:
        pool.shutdown()
    return _result(free, sol, 0.5 * float(r_init @ r_init), fit.record_rows())
