"""Identify a ship model from measured records (``mmg identify``) and cross-validate it.

:func:`identify` reads the training records (every layout :func:`trials.files.logio.read_record`
reads, checked against the ship's length), skips a record it cannot use with one line naming it
and why, and fits the hull coefficients and the model-scale constants jointly over all of them
with their measured inputs (:func:`ekf.identify.identify_segments`: segment-wise output error with
a prior).  :func:`write_identification` writes ``ship.yaml`` (the ship config with the fitted
values: usable by every other command) and ``report.md`` (values, standard errors, correlations,
training fits).  :func:`cross_validate` keeps each record out once (k folds) and compares the
open-loop replay of the kept-out records with the initial and the identified model.

Freed by default (:data:`DEFAULT_FREE`): every hull coefficient, the constants Y_0, N_0 included
(the single-screw model's port-starboard asymmetry: with the wind scale freed and 16+ records of
both rudder signs they are no longer confounded with the wind; freeing them took the four-fold
cross-validated heading RMS of the Kijima 3 m model from 17.1 to 15.5 deg with wind), the wake
fraction's constant term ``w_P0`` (the model-scale wake is the largest scale effect, see the 3 m
config), the rudder inflow ratio ``epsilon`` and the slipstream share ``kappa`` (at model scale
the propeller runs heavily loaded, so how much of its slipstream reaches the rudder sets the
rudder force: the Osaka set has kappa = 0.20 against the ship's 0.595), the rudder's flow
straightening ``gamma_R_pos``, ``gamma_R_neg`` (the inflow angle at the rudder), the wind-load
scale, and the propeller's walk astern ``Y_P_astern`` (:func:`mmg.model.propeller_lateral`; no
information and so its prior, 0, on records that never run the screw astern; with it the nested
cross-validation over the 35 shared records went from 1.56x to 1.63x in heading and 1.02x to 1.33x in
yaw rate, docs/benchmark_frt.md).  The rudder's lever ``l_R_prime`` stays at its config value (it can be freed): fits that
freed it ran it to its bound (-2.0, twice the textbook 2 x_R'), and with folds that keep a run
together keeping it fixed predicts the kept-out records as well or better in all four
cross-validations (wind on / off, folds in file order / by revolutions; docs/identify_cv.md).  Each training record counts alike
(:data:`DEFAULT_WEIGHTING` ``"equal"``): with every sample alike a 400 s turn outweighed a
140 s zigzag three times.
The propeller curve, masses and rudder geometry stay at the config values: the records (n
constant over most of each run) cannot separate them from the freed ones.

The hull form is the prior's: ``esso_osaka_3m`` (Kijima polynomials in beta) or
``esso_osaka_3m_crossflow`` (the low-speed cross-flow form, :mod:`mmg.terms`), whose fitted
values stay physical (w_P0 0.61 as the Osaka identification's 0.614, N_r within 10 % of its prior)
where the Kijima ones do not (Y_bb changes sign, N_r falls to a fifth); ``initial=`` scores the
fit against another model (the Kijima ship the cross-flow prior was converted from).

Each record's start state (:data:`DEFAULT_INITIAL_STATE` ``"fit"``): the open-loop replay of a record
starts from its first sample, and that one sample's noise (on the 3 m model r is logged to about
+-0.002 rad/s) drifts the whole replay; the shared parameters then absorb the drift and the residuals
are correlated over the record (tau ~ 20 samples on synthetic records; docs/imo.md).  So the offsets
of u, v, r and the heading of each record's first sample are fitted as per-record nuisance parameters
(:func:`ekf.identify.start_parameters`), prior 0 with a std of twice the record's noise level
(:func:`start_noise`: the first sample's error has the noise's std; twice it lets the data decide), an
offset whose std is below 1 % of its residual scale left out (:data:`START_MIN_SCALE`: smoothed channels).
Fitted rather than smoothed: a local polynomial over the first seconds estimates the state at the
window's *end* point, whose variance a low-degree fit barely reduces (a quadratic's end-point
variance is 9/N of the noise's: 10 samples gain nothing) and whose bias is largest where a
record starts with the rudder going over (a zigzag); the fit uses the whole record through the
model, and its covariance accounts for the offsets (the shared parameters' block of the joint
inverse is their marginal).  ``initial_state="sample"`` replays from the raw first sample as before.

The covariance written into ship.yaml (:func:`identification_covariance`) is the sum of two parts.
The linearised posterior cov = (J_d^T J_d / (s_d^2 tau) + diag(1 / sigma_prior^2))^-1: the data rows'
information scaled by their own residual variance s_d^2 and the prior's kept at its stated std
(:func:`ekf.identify._result` scales the whole inverse, prior rows included, by s^2, so a good fit
would shrink the prior's std too), inflated by the fit's residuals' integrated autocorrelation time tau
where it is above 1 (N correlated residuals carry about N / tau independent ones; tau as ``mmg
diagnose`` takes it: the mean over u, v, r, heading of the median over the records).  And the
run-to-run part: the delete-one-run jackknife over the independent runs
(:func:`ekf.identify.run_jackknife_covariance`), which counts how far the fit moves from one group of
records to the next; on real records (a model form that is not the ship's, a rudder zero or a drift
that differs from run to run) it is many times the posterior.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from mmg.errors import InputError
from mmg.model import pack
from mmg.ship import Ship

from ..predict import MeasuredRun, measured_run, replay_record

__all__ = ["identify", "IdentifyOptions", "cross_validate", "cv_folds", "load_runs", "Identification",
           "ship_with_values", "DEFAULT_FREE", "DEFAULT_WEIGHTING", "DEFAULT_MAX_NFEV", "stage_description",
           "start_noise", "DEFAULT_INITIAL_STATE", "INITIAL_STATES", "fold_of", "manoeuvre_class", "goes_astern",
           "ASTERN_SHARE", "FOLD_ASSIGNMENTS", "fitted_run"]


DEFAULT_FREE = ("hull", "w_P0", "epsilon", "kappa", "gamma_R_pos", "gamma_R_neg", "wind_scale", "Y_P_astern")
DEFAULT_MAX_NFEV = 30
"""Default limit of the residual evaluations of each fit stage (:func:`identify`'s ``max_nfev``)."""
DEFAULT_INITIAL_STATE = "fit"
"""Default start state of each record's replay in the fit (:func:`identify`'s ``initial_state``)."""
INITIAL_STATES = ("fit", "sample")
"""``"fit"``: each record's start state offsets fitted as nuisance parameters (module docstring);
``"sample"``: the raw first sample."""
DEFAULT_WEIGHTING = "equal"
"""Default weighting of the training records in the fit (:func:`ekf.identify.record_weights`)."""
DEFAULT_SEGMENTS_L = (52.0, np.inf)
"""Segment lengths of the successive fits, in units of sqrt(L/g): 29 s for a 3 m model, 300 s at
325 m (about one zigzag half-period: short enough that a poor start does not diverge), then the
whole record open-loop from the first fit's values (the objective the replay is judged by)."""


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def load_runs(ship: Ship, paths, wind: bool | None = None, say=_log, names=None) -> list[MeasuredRun]:
    """Read and prepare each record; one that cannot be used is skipped with one line saying why, but one
    of another ship (:func:`trials.files.shipcheck.check_record_ship`) raises its :class:`~trials.files.shipcheck.ShipMismatch`.
    Each is named after its file (:func:`trials.files.output.record_labels`: ``ST35``, or ``day1/ST35``
    and ``day2/ST35`` for two files of one stem), as the report and ship.yaml name it; ``names``:
    the names to give instead (labels made over the training and test records together)."""
    from dataclasses import replace

    from ...files.output import record_labels
    from ...files.shipcheck import ShipMismatch, read_for_ship

    paths = list(paths)
    runs = []
    for p, label in zip(paths, record_labels(paths) if names is None else names):
        try:
            rec = read_for_ship(p, ship)
            runs.append(replace(measured_run(ship, rec, wind=wind), name=label))
        except ShipMismatch:              # a record of another ship: the call is wrong, not the record
            raise
        except InputError as e:
            say(f"skipped: {e}")
    return runs


def _free_names(ship: Ship, free) -> list[str]:
    names = []
    for f in free:
        if f == "hull-except-constants":
            names += [n for n, t in zip(ship.hull.names, ship.hull.terms) if t != "1"]
        elif f == "hull":
            names += list(ship.hull.names)
        else:
            names.append(f)
    return names


def _scales(runs: list[MeasuredRun], L: float, velocity_weight: float = 1.0):
    """Residual scales: 5 % of the records' median speed for u and v (and that over L for r), 2 deg for
    the heading; the velocities' residuals multiplied by ``velocity_weight`` (their scales divided by
    it, their squares' weight in the cost ``velocity_weight**2``)."""
    from ekf.identify import Scales

    U = float(np.median(np.concatenate([np.hypot(r.meas[:, 0], r.meas[:, 1]) for r in runs])))
    k = 1.0 / velocity_weight
    return Scales(u=0.05 * U * k, v=0.05 * U * k, r=0.05 * U / L * k, psi=np.radians(2.0))


@dataclass(frozen=True)
class Identification:
    """The identified model: the ship with fitted values, the fit, the training records and scores."""

    ship: Ship
    initial: Ship
    fit: object
    runs: list
    segment_s: float
    prior: Ship | None = None
    """The prior (starting) model when it is not ``initial`` (another hull form of it)."""
    record_weighting: str = DEFAULT_WEIGHTING
    """How the training records counted (:func:`ekf.identify.record_weights`)."""
    velocity_weight: float = 1.0
    """How much the u, v, r residuals counted beside the heading's (:func:`identify`)."""
    tau: float = 1.0
    """The fit's residuals' integrated autocorrelation time [samples at the fit's stride] (module docstring)."""
    initial_state: str = DEFAULT_INITIAL_STATE
    """How each record's start state was taken (:data:`INITIAL_STATES`)."""
    record_nuisance: tuple = ()
    """The :mod:`mmg.effects` fitted once per training record as a nuisance (:class:`IdentifyOptions`)."""
    stages: tuple = ()
    """One dict per fit stage, in order: ``segment_s`` (segment length [s]; ``inf``: the whole record,
    no cut), ``description`` (:func:`stage_description`), ``evaluations`` (residual evaluations used),
    ``max_nfev`` (the limit), ``cost_initial``, ``cost_final``, ``status``, ``message`` (scipy's)."""

    def scores(self, runs=None, model: str = "identified") -> list[dict]:
        """Open-loop replay scores (:meth:`trials.measured.predict.Replayed.scores`) of ``runs`` (the training
        records when omitted) with the identified or the initial model."""
        return [{"name": r.name, **self.replay(r, model).scores()} for r in (runs or self.runs)]

    def fit_residuals(self, stride: int = 1) -> list[np.ndarray]:
        """Each training record's residuals in the fit's own whole-record replay (its fitted start state
        and per-record nuisances, the fit's free parameters at their fitted values), unscaled: one array
        (n_k, 4) of u, v [m/s], r [rad/s] and heading [rad] at every ``stride``-th sample; NaN where that
        replay failed.  What no prediction of an unseen record can have: the in-sample bound
        (``bench/identify_ceiling.py``)."""
        from ekf.identify import FAILED_RESIDUAL

        prior = self.prior or self.initial
        nu = _nuisance_effects(self.record_nuisance) or None
        res, sc = _whole_record_residuals((prior, pack(prior), self.runs, self.fit.free, nu), self.fit.theta,
                                          self.velocity_weight, stride)
        unit = np.array([sc.u, sc.v, sc.r, sc.psi])
        return [np.where(d[:, :4] == FAILED_RESIDUAL, np.nan, d[:, :4] * unit) for d in res]

    def physical_check(self):
        """:func:`trials.measured.physical.physical_check` of the identified model against its prior
        over the training records: the energy balance unpowered, and every record's replay (made once,
        then kept: the report and the console both read it)."""
        return self._physical

    @cached_property
    def _physical(self):
        from ..physical import physical_check

        return physical_check(self.ship, self.prior or self.initial, self.runs, [self.replay(r) for r in self.runs])

    def replay(self, run: MeasuredRun, model: str = "identified"):
        """:func:`trials.measured.predict.replay_record` of ``run`` with the identified (its wind scale too) or
        initial model; made once per record and model, then kept (the scores, the physical check and the
        report all read the same replays)."""
        key = (id(run), model)
        hit = self._replays.get(key)
        if hit is not None and hit[0] is run:
            return hit[1]
        if model == "identified":
            rep = replay_fitted(self.ship, self.fit.values(), run)
        else:
            rep = replay_record(self.initial, run)
        self._replays[key] = (run, rep)
        return rep

    @cached_property
    def _replays(self) -> dict:
        return {}


def replay_fitted(ship: Ship, values: dict, run: MeasuredRun):
    """:func:`trials.measured.predict.replay_record` of ``run`` with an identified ``ship`` and its fitted
    ``values`` (:meth:`ekf.identify.IdentifyResult.values`): the record's wind loads scaled by the fitted
    wind factors, the ship's own effects applied."""
    return replay_record(ship, fitted_run(ship, values, run))


def fitted_run(ship: Ship, values: dict, run: MeasuredRun) -> MeasuredRun:
    """``run`` as the identified ``ship`` with its fitted ``values`` replays it: its wind loads (made with
    another ship's wind section, e.g. the initial one) scaled by the fitted wind factors, the ship's own
    effects applied.  What :func:`replay_fitted` replays, and what a band of that fit varies about."""
    return with_ship_effects(with_fitted_wind(run, values), ship)


def with_ship_effects(run: MeasuredRun, ship: Ship) -> MeasuredRun:
    """``run`` with the effects of ``ship``'s config other than the wind (in the run's loads) added, as
    :func:`trials.measured.predict.measured_run` of that ship would have them (a fitted ``rudder_offset``)."""
    from dataclasses import replace

    own = ship.effect_set().without("wind")
    if not own.items:
        return run
    es = own if run.effects is None else run.effects.merged(own)
    return replace(run, effects=es)


def with_fitted_wind(run: MeasuredRun, values: dict) -> MeasuredRun:
    """``run`` with its wind loads scaled by a fitted ``wind_scale`` and shape factors ``wind_sway_factor``,
    ``wind_yaw_factor`` (as the identified ship computes them)."""
    from dataclasses import replace

    from ekf.identify import wind_scaled

    if run.inputs.ext is None or not any(k in values for k in _wind_keys()):
        return run
    return replace(run, inputs=wind_scaled(run.inputs, values.get("wind_scale", 1.0),
                                           values.get("wind_sway_factor", 1.0), values.get("wind_yaw_factor", 1.0)))


def ship_with_values(ship: Ship, values: dict) -> Ship:
    """``ship`` with fitted parameter values (by their ``mmg identify --free`` names, in the fit's units:
    :func:`mmg.parameters.unit_of`) written in through the parameter table (:mod:`mmg.parameters`); a wind
    value multiplies the ship's; names not in the table (a record's own nuisances) are left out."""
    from mmg.parameters import with_value

    hull = {k: v for k, v in values.items() if k in ship.hull.names}
    s = ship.with_hull(hull) if hull else ship                # the hull in one step
    for k, v in values.items():
        if k not in hull:
            s = with_value(s, k, v)
    return s


def _wind_keys() -> dict:
    """``mmg identify --free`` name of a fitted wind value -> the key of the ship's ``wind:`` section (and of
    its ``wind`` effect) it multiplies (:data:`mmg.parameters.WIND_COLUMNS`): the records' loads were computed
    with the ship's values, so the fitted ones are factors on them."""
    from mmg.parameters import WIND_COLUMNS

    return {k: key for k, (key, _) in WIND_COLUMNS.items()}


_ship_with = ship_with_values


def without_fit_sections(ship: Ship) -> Ship:
    """``ship`` without the sections an identification writes about its own fit (``covariance:``,
    ``run_spread:``, ``model_form:``, ``identification:``): a ship identified again from an identified
    ship.yaml does not carry its prior's uncertainty as its own."""
    return replace(ship, covariance=None, run_spread=None, model_form=None, identification=None)


def stage_description(segment_s: float) -> str:
    """What a fit stage with segments of ``segment_s`` [s] fits, in words (an infinite length: the
    whole record, not cut)."""
    if not np.isfinite(segment_s):
        return "whole-record fit: each record replayed open-loop from its first sample (not cut into segments)"
    return f"segment-wise fit: {segment_s:.3g} s segments, each restarted from the measured state"


@dataclass(frozen=True)
class IdentifyOptions:
    """How :func:`identify` fits (each field also a keyword argument of it).

    Attributes
    ----------
    segment_s : float or sequence of float, optional
        Segment length(s) [s] of successive fits; :data:`DEFAULT_SEGMENTS_L` when omitted.
    wind : bool, optional
        Override the ship config's wind switch.
    max_nfev : int
        Most evaluations of the residuals in each stage (:func:`scipy.optimize.least_squares`'s
        ``max_nfev``; ``mmg identify --max-nfev``); a stage that reaches it stops there
        (:attr:`Identification.stages`: its ``status`` 0).
    progress : callable, optional
        ``progress(iteration, cost, stage)`` after each Jacobian; ``stage`` names the stage:
        ``"stage 1/2: segment-wise fit: ..."`` (:func:`stage_description`).
    say : callable
        Where a skipped record's one line goes.
    prior_rel_std : float
        Prior std of each freed coefficient relative to its config value (:func:`ekf.identify.free_parameters`).
    initial : Ship, optional
        The model the identified one is compared with in the scores and the report ("initial");
        ``ship`` (the prior) when omitted.  Given when the prior is the initial model rewritten in
        another hull form (e.g. ``esso_osaka_3m_crossflow`` for the Kijima ``esso_osaka_3m``).
    record_weighting : str
        How each training record's residuals count in every stage (:func:`ekf.identify.record_weights`):
        ``"samples"`` (each sample alike: long records count more), ``"equal"`` (each record alike),
        ``"relative"`` (each record alike, relative to its own misfit at the stage's start).
    loss, f_scale : str, float
        Robust loss of the last (whole-record) stage (:func:`scipy.optimize.least_squares`): ``"linear"``
        (least squares), ``"soft_l1"``, ``"cauchy"``; ``f_scale`` in units of the scaled residuals.
    record_nuisance : sequence of str
        Effects of :mod:`mmg.effects` (e.g. ``("current",)``) fitted once per training record, as a
        nuisance: each record gets its own values (a pond's wind-driven drift differs from run to run),
        so the shared parameters need not absorb one record's disturbance.  They are not part of the
        identified ship: a record it has not seen is predicted without them.
    velocity_weight : float
        Factor on the u, v and r residuals beside the heading's (1: their scales are 5 % of the
        median speed, the heading's 2 deg; 0.1: their squares weigh a hundredth in the cost, so the
        fit follows the heading, the score a replay is judged by).  docs/identify_cv.md: 0.1
        predicts the kept-out records better without wind and worse with it.
    initial_state : str
        ``"fit"`` (default): each record's start state (u, v, r, heading of its first sample) moved by
        offsets fitted as per-record nuisance parameters; ``"sample"``: the raw first sample
        (module docstring).
    """

    segment_s: object = None
    wind: bool | None = None
    max_nfev: int = DEFAULT_MAX_NFEV
    progress: object = None
    say: object = _log
    prior_rel_std: float = 0.5
    initial: Ship | None = None
    record_weighting: str = DEFAULT_WEIGHTING
    loss: str = "linear"
    f_scale: float = 1.0
    record_nuisance: tuple = ()
    velocity_weight: float = 1.0
    initial_state: str = DEFAULT_INITIAL_STATE


def _check_velocity_weight(velocity_weight) -> None:
    try:
        ok = bool(np.isfinite(float(velocity_weight)) and float(velocity_weight) > 0)
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"velocity_weight: a positive finite number, got {velocity_weight!r}")


def _training_runs(ship: Ship, paths_or_runs, o: IdentifyOptions) -> list[MeasuredRun]:
    """The given runs, then the records read from the given paths (unusable ones skipped with one line)."""
    items = list(paths_or_runs)
    runs = [r for r in items if isinstance(r, MeasuredRun)]
    paths = [r for r in items if not isinstance(r, MeasuredRun)]
    runs += load_runs(ship, paths, wind=o.wind, say=o.say) if paths else []
    if not runs:
        raise InputError("--train", "", "no usable training record")
    return runs


def _bounded_wind(ship: Ship, fp: list) -> list:
    """``fp`` with the bounds of each fitted factor divided by the config value it multiplies (its
    parameter-table entry's :attr:`~mmg.parameters.ShipParameter.multiplies`: the wind values, factors on the
    records' loads, which carry the config's; ship.yaml writes their product, which must stay within the
    config's range: scale 0-10, shape factors 0.2-3)."""
    from dataclasses import replace

    from mmg.parameters import CONSTANTS

    if ship.wind is None:
        return fp
    out = []
    for f in fp:
        entry = CONSTANTS.get(f.name)
        c = entry.multiplies(ship) if entry is not None and entry.multiplies is not None else 1.0
        out.append(replace(f, lower=f.lower / c, upper=f.upper / c) if c > 0 and c != 1.0 else f)
    return out


def _nuisance_effects(names) -> list:
    """The :mod:`mmg.effects` classes of ``record_nuisance`` names (an unknown name is refused there)."""
    import mmg.effects as E

    return [E.get(n, "record_nuisance") for n in names]


def _free_of(ship: Ship, packed, runs, free, o: IdentifyOptions):
    """(free parameters, the per-record nuisance effects or None)."""
    from ekf.identify import free_parameters

    names = _free_names(ship, free)
    if not any(r.inputs.ext is not None for r in runs):
        names = [n for n in names if n not in _wind_keys()]     # no wind loads to scale
    if "Y_P_astern" in names and not any(goes_astern(r) for r in runs):
        names = [n for n in names if n != "Y_P_astern"]       # nothing to fit it on: it stays the config's
        o.say(f"Y_P_astern not fitted: no record runs its propeller astern on {ASTERN_SHARE:.0%} of its samples")
    fp = _bounded_wind(ship, free_parameters(packed, ship.hull.names, names, o.prior_rel_std,
                                                  hull_terms=ship.hull.terms))
    if o.initial_state == "fit":
        from ekf.identify import start_parameters

        fp = fp + start_parameters(_start_sigmas(ship, runs, o), names=[r.name for r in runs])
    if not o.record_nuisance:
        return fp, None
    from ekf.identify import record_effect_parameters

    nuisance = _nuisance_effects(o.record_nuisance)
    return fp + record_effect_parameters(nuisance, len(runs), names=[r.name for r in runs]), nuisance


def start_noise(run: MeasuredRun) -> np.ndarray:
    """The noise level (std) of each logged state of ``run`` (u, v, r, x, y, psi; NaN where the record does
    not log it: v of a speed-only record): the robust (MAD) std of the second difference over sqrt(6),
    white noise on a smooth signal; where the MAD is 0 (a quantised channel) the plain std."""
    m = np.asarray(run.meas, float).copy()
    m[:, 5] = np.unwrap(m[:, 5])
    d2 = np.diff(m, 2, axis=0)
    d2 = d2[np.all(np.isfinite(d2), axis=1)]
    if len(d2) < 3:
        return np.full(6, np.nan)
    mad = np.median(np.abs(d2 - np.median(d2, axis=0)), axis=0) * 1.4826
    out = np.where(mad > 0, mad, np.std(d2, axis=0)) / np.sqrt(6.0)
    if run.speed_only:
        out[1] = np.nan
    return out


START_MIN_SCALE = 0.01
"""A start offset whose prior std is below this share of its residual scale (:func:`_scales`) is not fitted:
it could not move the fit, and its finite-difference step (1e-6 of the std) would be at round-off."""


def _start_sigmas(ship: Ship, runs, o: IdentifyOptions) -> np.ndarray:
    """Prior std (n_records, 6) of each record's start offsets: twice its noise level (:func:`start_noise`);
    NaN (not fitted) where below :data:`START_MIN_SCALE` of the residual scale (smoothed channels, whose
    second difference shows no noise) and for x, y (not in the residuals)."""
    sc = _scales(runs, ship.particulars.L, o.velocity_weight)
    floor = START_MIN_SCALE * np.array([sc.u, sc.v, sc.r, np.nan, np.nan, sc.psi])
    sig = np.array([start_noise(r) for r in runs]) * 2.0
    with np.errstate(invalid="ignore"):
        return np.where(sig >= floor, sig, np.nan)


def _segmented(runs, seg: float):
    from ekf.identify import Segmented, segment_resets

    return [Segmented(r.name, r.meas, r.inputs, segment_resets(r.t, seg), fixed=r.effects, speed_only=r.speed_only)
            for r in runs]


def _whole_record_residuals(problem: tuple, theta, velocity_weight: float, stride: int):
    """(each record's scaled residuals of its whole-record replay at ``theta``, the scales): the last stage's
    residuals; problem = (ship, packed ship, runs, free parameters, nuisance effects or None)."""
    from ekf.identify import record_residuals

    ship, packed, runs, fp, nuisance = problem
    sc = _scales(runs, ship.particulars.L, velocity_weight)
    return record_residuals(packed, _segmented(runs, np.inf), fp, theta, sc, stride=stride, effects=nuisance,
                            ship=ship), sc


def _residual_tau(problem: tuple, fit, o: IdentifyOptions, stride: int = 2) -> float:
    """The integrated autocorrelation time [samples at ``stride``] of the last stage's residuals: each
    channel's (u, v, r, heading) median over the records, the mean over the channels (as ``mmg diagnose``)."""
    from ..diagnose import _tau

    res, _ = _whole_record_residuals(problem, fit.theta, o.velocity_weight, stride)
    taus = [np.median([_tau(d[:, j]) for d in res]) for j in range(4)]
    return float(np.mean(taus))


def _fit_stage(problem: tuple, seg: float, label: str, last: bool, fit, o: IdentifyOptions):
    """One stage of :func:`identify`: every record cut into ``seg`` [s] segments, fitted from ``fit``'s values
    (the priors when None); problem = (ship, packed ship, runs, free parameters, nuisance effects or None)."""
    from ekf.identify import identify_segments, record_residual_rms, record_weights

    ship, packed, runs, fp, nuisance = problem
    stage_progress = None if o.progress is None else (lambda i, c, _l=label: o.progress(i, c, _l))
    segs = _segmented(runs, seg)
    sc = _scales(runs, ship.particulars.L, o.velocity_weight)
    theta = np.array([f.prior for f in fp]) if fit is None else fit.theta
    rms = (record_residual_rms(packed, segs, fp, theta, sc, effects=nuisance, ship=ship)
           if o.record_weighting == "relative" else None)
    return identify_segments(packed, segs, fp, sc, max_nfev=o.max_nfev, progress=stage_progress, effects=nuisance,
                             ship=ship, start=None if fit is None else fit.theta,
                             weights=record_weights(segs, o.record_weighting, rms=rms),
                             loss=o.loss if last else "linear", f_scale=o.f_scale)


def identify(ship: Ship, paths_or_runs, free=DEFAULT_FREE, options: IdentifyOptions | None = None,
             **kwargs) -> Identification:
    """Identify ``free`` jointly over the training records (module docstring).

    Parameters
    ----------
    ship : Ship
        The initial model (the prior).
    paths_or_runs : list of paths or of MeasuredRun
    free : sequence of str
        Hull coefficient names, ``"hull-except-constants"``, ``"hull"`` (every hull coefficient),
        ``"w_P0"``, ``"epsilon"``, ``"kappa"``, ``"wind_scale"``.
    options : IdentifyOptions, optional
        How to fit; defaults when omitted.
    **kwargs
        Any :class:`IdentifyOptions` field by name (``segment_s``, ``wind``, ``max_nfev``,
        ``progress``, ``say``, ``prior_rel_std``, ``initial``, ``record_weighting``, ``loss``,
        ``f_scale``, ``record_nuisance``, ``velocity_weight``), over ``options``.
    """
    o = IdentifyOptions(**kwargs) if options is None else replace(options, **kwargs)
    _check_velocity_weight(o.velocity_weight)                # before any record is read
    if o.initial_state not in INITIAL_STATES:
        raise ValueError(f"initial_state {o.initial_state!r}: one of {INITIAL_STATES}")
    if o.initial is not None:                                 # the same ship's, before any record is read
        from ...files.shipcheck import check_same_ship

        check_same_ship(ship, o.initial)
    runs = _training_runs(ship, paths_or_runs, o)
    L = ship.particulars.L
    stages = DEFAULT_SEGMENTS_L if o.segment_s is None else np.atleast_1d(o.segment_s) / np.sqrt(L / 9.80665)
    packed = pack(ship)
    fp, nuisance = _free_of(ship, packed, runs, free, o)
    fit = None
    done = []
    for k, st in enumerate(stages):
        seg = float(st) * float(np.sqrt(L / 9.80665))
        label = f"stage {k + 1}/{len(stages)}: {stage_description(seg)}"
        fit = _fit_stage((ship, packed, runs, fp, nuisance), seg, label, k == len(stages) - 1, fit, o)
        done.append({"segment_s": seg, "description": stage_description(seg), "evaluations": fit.iterations,
                     "max_nfev": int(o.max_nfev), "cost_initial": fit.cost_initial, "cost_final": fit.cost_final,
                     "status": fit.status, "message": fit.message})
    tau = _residual_tau((ship, packed, runs, fp, nuisance), fit, o)
    return Identification(ship=_ship_with(without_fit_sections(ship), fit.values()), initial=ship if o.initial is None else o.initial,
                          fit=fit, runs=runs, segment_s=seg, prior=None if o.initial is None else ship,
                          record_weighting=o.record_weighting, velocity_weight=float(o.velocity_weight),
                          stages=tuple(done), tau=tau, initial_state=o.initial_state,
                          record_nuisance=tuple(o.record_nuisance))


FOLD_ASSIGNMENTS = ("order", "revolutions", "manoeuvre")
"""How :func:`cross_validate` deals the records into folds (:func:`fold_of`)."""


def cv_folds(runs: list[MeasuredRun], folds: int) -> int:
    """The number of folds a cross-validation of ``runs`` uses: ``folds``, or fewer when there are
    fewer independent runs (:func:`same_run_groups`: a record and its cuts count once), since a fold
    with nothing to keep out would only repeat the fit on all records.  Raises ValueError below two
    runs, where nothing can be kept out and still leave a training set."""
    n = len(set(same_run_groups(runs)))
    if n < 2:
        raise ValueError(f"cross-validation needs 2 or more independent records, got {n}")
    return min(int(folds), n)


def fold_of(runs: list[MeasuredRun], folds: int, by: str = "order") -> np.ndarray:
    """The fold (0 .. folds-1) of each record.

    ``"order"``: record i in fold i mod k, in the order given.  ``"revolutions"``: stratified by the
    record's median propeller revolutions: the records sorted by them (ties by order) are dealt
    round-robin, so every fold's training set spans the revolutions of all the records and a kept-out
    record is not outside its training set's operating range by the luck of the file order (with
    "order" over the sorted FRT files, the 16.7 and 15 rps zigzags fell into one fold, whose training
    set then held one zigzag above 12 rps).  ``"manoeuvre"``: stratified by :func:`manoeuvre_class`
    (astern, zigzag, or a turn to one side, then the revolutions), dealt alike, so that records of
    one class fall into different folds (with "order" the FRT set's only two 20 deg port turns at
    10 rps shared fold 0, whose training set then had no port turn at that angle)."""
    if by not in FOLD_ASSIGNMENTS:
        raise ValueError(f"fold assignment {by!r}: one of {FOLD_ASSIGNMENTS}")
    group = same_run_groups(runs)
    firsts = sorted(set(group))                           # a group's first record stands for it
    if by == "order":
        key = {g: g for g in firsts}
    elif by == "manoeuvre":
        key = {g: (*manoeuvre_class(runs[g]), g) for g in firsts}
    else:
        rps = {g: float(np.nanmedian(np.abs(runs[g].inputs.n))) for g in firsts}
        key = {g: (rps[g], g) for g in firsts}
    deal = {g: k % folds for k, g in enumerate(sorted(firsts, key=lambda g: key[g]))}
    return np.array([deal[g] for g in group], dtype=int)


ASTERN_SHARE = 0.02
"""Share of a record's samples with the propeller astern (n < 0) from which :func:`manoeuvre_class`
calls it an astern record: a sustained astern phase, not one noisy sample (the FRT random and
berthing records run astern for 12-36 % of their samples, its turns and zigzags for none)."""


def goes_astern(run: MeasuredRun) -> bool:
    """Whether a record runs its propeller astern (n < 0) on at least :data:`ASTERN_SHARE` of its
    samples: the one test of an astern record (:func:`manoeuvre_class`; the propeller walk is fitted
    only where a record is one)."""
    return bool(np.mean(np.asarray(run.inputs.n, float) < 0) >= ASTERN_SHARE)


def manoeuvre_class(run: MeasuredRun) -> tuple:
    """The manoeuvre of a record, for stratified folds (:func:`fold_of`).

    A turn holds one side: over the samples with the rudder beyond 2 deg, |sum delta| / sum |delta|
    >= 0.5 (side +1 starboard, -1 port; the FRT turns, steered on the approach with up to 24 deg the
    other way, give 0.7 or more; their zigzags, equal angles both ways, under 0.35).  Otherwise a
    zigzag (side 0).

    Parameters
    ----------
    run : MeasuredRun
        The record (its logged revolutions and rudder angle).

    Returns
    -------
    tuple
        (class, rudder side, median |revolutions| [rps]): class 0 a turn, 1 a zigzag, 2 a record with
        the propeller astern for at least :data:`ASTERN_SHARE` of its samples (whatever its rudder),
        3 a straight run (no rudder beyond 2 deg); side 0 but for turns.
    """
    n = np.asarray(run.inputs.n, float)
    rps = float(np.nanmedian(np.abs(n)))
    if goes_astern(run):
        return (2, 0, rps)
    d = np.asarray(run.inputs.delta, float)
    big = d[np.abs(d) > np.radians(2.0)]
    if not len(big):
        return (3, 0, rps)
    lean = float(np.sum(big) / np.sum(np.abs(big)))
    if abs(lean) < 0.5:
        return (1, 0, rps)
    return (0, 1 if lean > 0 else -1, rps)


def same_run_groups(runs: list[MeasuredRun]) -> list[int]:
    """For each record, the index of the first record of the same run: a record whose first measured
    sample (position, heading, velocities) is a sample of an earlier one is a copy or a cut of it
    (the FRT set's ``turn_cut_*`` files are the first minutes of another file).  Cross-validation keeps
    a run's records in one fold: a kept-out record must not be in its own training set."""
    out = list(range(len(runs)))
    for j in range(len(runs)):
        s0 = runs[j].meas[0]
        for i in range(j):
            if out[i] != i:
                continue
            m = runs[i].meas
            if m.shape[1] == s0.shape[0] and np.any(np.all(np.abs(m - s0) <= 1e-9 * (1.0 + np.abs(s0)), axis=1)):
                out[j] = i
                break
    return out


def _fold(task) -> list[dict]:
    """One cross-validation fold: identify on its training records, replay its kept-out ones."""
    ship, ref, train, tests, k, kw = task
    ident = identify(ship, train, **kw)
    values = {n: float(v) for n, v in ident.fit.values().items()}
    return [{"name": r.name, "fold": k, "initial": replay_record(ref, r).scores(),
             "identified": ident.replay(r).scores(), "ship": ident.ship, "values": values} for r in tests]


def cross_validate(ship: Ship, runs: list[MeasuredRun], folds: int = 4, progress=None, initial: Ship | None = None,
                   folds_by: str = "order", backend: str = "serial", client=None, n_jobs: int | None = None,
                   **kw) -> list[dict]:
    """k-fold cross-validation: each record kept out once; per record the open-loop heading RMS [deg]
    (and the other scores) of the initial model (``initial``, the prior ``ship`` when omitted) and of
    the model identified from ``ship`` without it (``kw``: :func:`identify`'s options); ``folds_by``:
    how records are dealt into folds (:func:`fold_of`).  Each record's dict also holds ``"ship"``,
    the model identified without it (for further replays of the kept-out record), and ``"values"``, that
    fit's values by name (:mod:`trials.measured.foldspread`).

    The folds are independent: ``backend`` ``"serial"`` (default: one after the other, ``progress(k,
    folds)`` after each), ``"loky"`` (``n_jobs`` local processes) or ``"dask"`` (the workers of
    ``client``) run them through :func:`trials.files.sweep.run_sweep`, one progress line per fold, the
    same numbers either way."""
    ref = ship if initial is None else initial
    if initial is not None:
        from ...files.shipcheck import check_same_ship

        check_same_ship(ship, initial)
    idx = np.arange(len(runs))
    folds = cv_folds(runs, folds)
    fold = fold_of(runs, folds, folds_by)
    tasks = [(ship, ref, [runs[i] for i in idx if fold[i] != k], [runs[i] for i in idx if fold[i] == k], k, kw)
             for k in range(folds)]
    if backend == "serial":
        out = []
        for k, t in enumerate(tasks):
            out += _fold(t)
            if progress:
                progress(k + 1, folds)
        return out
    from ...files.sweep import run_sweep

    parts = run_sweep(_fold, tasks, backend=backend, client=client, n_jobs=n_jobs,
                      labels=[f"cross-validation fold {k + 1}/{folds}" for k in range(folds)])
    return [r for part in parts for r in part]
