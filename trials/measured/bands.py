"""Prediction bands of a replayed record: heading and position, 90 %, from the ship's and the run's uncertainty.

:func:`prediction_bands` replays one record (:func:`trials.measured.predict.replay_record`) ``samples``
times, each replay with

* a ship drawn from the covariance of its identified parameters (the ship config's ``covariance:``
  section, :func:`trials.measured.draws.parameter_covariance`, written in by name with
  :func:`trials.measured.identify.ship_with_values`; a wind-load factor scales the record's measured
  wind loads, relative to the covariance's own value), truncated (``support``, default) to the ships
  the estimator and the physics admit (:func:`trials.measured.draws.support_of`: within the fit's hard
  bounds, and not gaining energy unpowered over the training records' range of states): a candidate
  outside is never replayed but rejected and the next one drawn (:attr:`Bands.rejected`,
  ``rejected_draws``), and
* the record's start state (and a per-record effect) offset by a zero-mean normal draw of the
  between-run spread of a run's own disturbance (the ``run_spread:`` section, :class:`mmg.ship.RunSpread`,
  written by ``mmg identify``: ``start.u``, ``start.v``, ``start.r``, ``start.psi`` added to the first
  logged state; ``<effect>.<parameter>`` a per-record effect the run does not already have), and
* the model-form term of the ship's ``model_form:`` section (:class:`mmg.ship.ModelForm`,
  :mod:`trials.measured.modelform`): on the heading a zero-mean normal error, one draw per replay from the
  third stream of ``seed``, whose 90 % half-width grows with the elapsed time as the section says; on the
  position (where the section has ``position_q90_L``) a circular normal offset, one draw per replay from
  the fourth stream, whose 90 % radius grows so.

At every sample of the record the band is the 5 % and 95 % quantiles over the draws (numpy's default
linear interpolation) of

* the heading, unwrapped (:func:`numpy.unwrap`) and put on the same turn as the record's unwrapped
  logged heading at the first sample, in degrees: directly comparable with the unwrapped record
  sample by sample (:attr:`Bands.coverage90`: the share of the record's samples inside the band);
* the distance of the predicted position from the draws' median track (the per-sample median of x and
  of y): ``radius`` is its 90 % quantile, a disc about the median track that holds 90 % of the draws
  (:attr:`Bands.position_coverage90`: the share of samples whose logged position lies inside it).

A draw whose replay diverges still counts: from its divergence on its heading is taken as -inf for the
lower and +inf for the upper quantile, and its distance from the median track as +inf, so divergences
widen the band (to unbounded where more than 5 % of the draws, 10 % for the position, have diverged),
never narrow it; a draw inside the support that diverges counts so too.  The draws are made from ``seed``
alone (the ship's and the run's from two streams, in batches of ``samples`` candidates, a rejected
ship's run draw dropped with it: where none is rejected, the draws of the untruncated normal),
and the replays run on threads (the compiled replay releases the GIL): the same numbers for any
number of threads.
"""
from __future__ import annotations

import os
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace

import numpy as np

from mmg.errors import InputError
from mmg.replay import STATE
from mmg.ship import RunSpread, Ship

from .draws import SUPPORTS, WIND_FACTOR_NAMES, parameter_covariance, support_of
from .predict import MeasuredRun, Replayed, measured_run, replay_record

__all__ = ["Bands", "prediction_bands", "BAND_KEYS", "QUANTILES", "SAMPLE_TRACKS"]

QUANTILES = (0.05, 0.95)
"""The quantiles bounding the 90 % heading band."""
POSITION_QUANTILE = 0.90
"""The quantile of the distance from the median track that bounds the position band."""
SAMPLE_TRACKS = 12
"""How many of the drawn tracks a :class:`Bands` keeps for its figure."""
MAX_CANDIDATES = 50
"""At most this many candidates per asked-for draw are tried for the support (fewer draws are said in the notes)."""
BAND_KEYS = ("draws", "diverged_draws", "rejected_draws", "heading_band_deg", "coverage90",
             "heading_band_median_width_deg", "heading_band_unbounded_share", "coverage90_where_bounded",
             "position_band_m", "position_coverage90", "position_band_median_radius_m")
"""The keys :meth:`Bands.to_json` gives (``mmg predict --samples`` adds them to each run)."""


@dataclass(frozen=True)
class Bands:
    """The 90 % bands of one record's prediction (module docstring); angles in degrees, lengths in metres.

    Attributes
    ----------
    nominal : Replayed
        The replay with the ship as given and the record's own start state (the band's centre line).
    t : ndarray (N,)
        The record's sample times [s].
    heading_deg : ndarray (N,)
        The record's logged heading, unwrapped [deg].
    lo, hi : ndarray (N,)
        The band's 5 % and 95 % quantiles of the predicted heading [deg] (``-inf``/``inf`` where
        diverged draws leave it unbounded, or the model-form term is), on the record's turn.
    nominal_deg : ndarray (N,)
        The nominal replay's heading on the record's turn [deg].
    x_median, y_median : ndarray (N,)
        The draws' median track [m] (over the draws still finite there).
    radius : ndarray (N,)
        The 90 % quantile of the draws' distance from the median track [m].
    tracks : ndarray (k, N, 2)
        The first :data:`SAMPLE_TRACKS` drawn tracks, x and y [m] (for the figure; the replays themselves,
        without the model-form position offset the band's radius carries).
    draws, diverged : int
        Replays made, and how many of them diverged somewhere in the record.
    notes : tuple of str
        What was and was not drawn (the support, no covariance, no run spread, an effect not applied).
    rejected : int
        Candidate ships drawn outside the support (:func:`trials.measured.draws.support_of`) and not
        replayed: ``rejected / (draws + rejected)`` is the share of the covariance's normal outside it.
    """

    nominal: Replayed
    t: np.ndarray
    heading_deg: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    nominal_deg: np.ndarray
    x_median: np.ndarray
    y_median: np.ndarray
    radius: np.ndarray
    tracks: np.ndarray
    draws: int
    diverged: int
    notes: tuple = ()
    rejected: int = 0

    @property
    def coverage90(self) -> float:
        """The share of the record's samples whose unwrapped logged heading lies in [lo, hi]."""
        return float(np.mean((self.heading_deg >= self.lo) & (self.heading_deg <= self.hi)))

    @property
    def position_coverage90(self) -> float:
        """The share of the record's samples whose logged position lies within ``radius`` of the median track
        (inside where the band is unbounded)."""
        m = self.nominal.run.meas
        with np.errstate(invalid="ignore"):
            inside = np.hypot(m[:, 3] - self.x_median, m[:, 4] - self.y_median) <= self.radius
        return float(np.mean(inside | (self.radius == np.inf)))        # unbounded: every draw diverged there too

    @property
    def unbounded_share(self) -> float:
        """The share of the record's samples where the heading band is unbounded (diverged draws, or the
        model-form term unbounded there; inside it, whatever the record does: read :attr:`coverage90` with this)."""
        return float(np.mean(~(np.isfinite(self.lo) & np.isfinite(self.hi))))

    @property
    def coverage90_where_bounded(self) -> float:
        """:attr:`coverage90` over the samples where the heading band is bounded alone (NaN where it is nowhere)."""
        ok = np.isfinite(self.lo) & np.isfinite(self.hi)
        h = self.heading_deg[ok]
        return float(np.mean((h >= self.lo[ok]) & (h <= self.hi[ok]))) if ok.any() else float("nan")

    @property
    def empty(self) -> bool:
        """Whether every draw replayed the same track (nothing was drawn: no covariance and no run spread,
        :attr:`notes`): a band of no width (to 1e-9 deg and m), whose coverages say nothing of the prediction's uncertainty."""
        with np.errstate(invalid="ignore"):
            return bool(np.all(np.abs(self.hi - self.lo) <= 1e-9) and np.all(self.radius <= 1e-9))

    @property
    def median_width_deg(self) -> float:
        """The median over the samples of the heading band's width hi - lo [deg] (inf where unbounded)."""
        return float(np.median(self.hi - self.lo))

    @property
    def median_radius_m(self) -> float:
        """The median over the samples of the position band's radius [m]."""
        return float(np.median(self.radius))

    def to_json(self) -> dict:
        """The run's band keys (:data:`BAND_KEYS`): ``heading_band_deg`` ``{"t_s", "lo", "hi"}``,
        ``position_band_m`` ``{"t_s", "x_median", "y_median", "radius"}`` at every sample, the coverages,
        median width [deg] and radius [m], the share of samples where the heading band is unbounded and the
        coverage over the others, the
        draws, how many diverged and how many candidates were rejected outside the support (unbounded values:
        null; the coverages null for an :attr:`empty` band)."""
        lst = lambda a: [float(x) for x in a]          # noqa: E731
        cov = lambda x: None if self.empty else x      # noqa: E731
        t = lst(self.t)
        return {"draws": int(self.draws), "diverged_draws": int(self.diverged), "rejected_draws": int(self.rejected),
                "heading_band_deg": {"t_s": t, "lo": lst(self.lo), "hi": lst(self.hi)},
                "coverage90": cov(self.coverage90), "heading_band_median_width_deg": self.median_width_deg,
                "heading_band_unbounded_share": self.unbounded_share,
                "coverage90_where_bounded": cov(self.coverage90_where_bounded),
                "position_band_m": {"t_s": t, "x_median": lst(self.x_median), "y_median": lst(self.y_median),
                                    "radius": lst(self.radius)},
                "position_coverage90": cov(self.position_coverage90),
                "position_band_median_radius_m": self.median_radius_m}

    def to_pandas(self):
        """Per sample (index ``t`` [s]): ``heading_deg`` (the record, unwrapped), ``nominal_deg``, ``lo_deg``,
        ``hi_deg``, ``x_median_m``, ``y_median_m``, ``radius_m``."""
        import pandas as pd

        return pd.DataFrame({"heading_deg": self.heading_deg, "nominal_deg": self.nominal_deg, "lo_deg": self.lo,
                             "hi_deg": self.hi, "x_median_m": self.x_median, "y_median_m": self.y_median,
                             "radius_m": self.radius}, index=pd.Index(self.t, name="t"))

    def plot(self, pyplot: bool = True):
        """The replay figure (:func:`trials.measured.predict_plots.replay_figure`) with the bands drawn in."""
        from .predict_plots import replay_figure

        return replay_figure(self.nominal, pyplot=pyplot, bands=self)


def _spread_of(spread, src: str) -> tuple[list[str], np.ndarray]:
    """(names, std) of a ``run_spread`` (:class:`mmg.ship.RunSpread` or a mapping with ``names``, ``std``),
    each name checked (``start.<u|v|r|psi>`` or ``<effect>.<fit parameter>``)."""
    import mmg.effects as E

    if isinstance(spread, RunSpread):
        names, std = list(spread.names), np.asarray(spread.std, float)
    else:
        names, std = list(spread["names"]), np.asarray(spread["std"], float)
    if std.shape != (len(names),) or not np.all(np.isfinite(std)) or np.any(std < 0):
        raise InputError(src, "run_spread.std", f"expected {len(names)} finite non-negative standard deviations")
    for i, n in enumerate(names):
        kind, _, q = n.partition(".")
        ok = q in ("u", "v", "r", "psi") if kind == "start" else False
        if kind != "start":
            try:
                ok = _effect_slot(E.get(kind, "run_spread"), q) is not None
            except InputError:
                ok = False
        if not ok:
            raise InputError(src, f"run_spread.names.{i}", f"{n!r} is not start.<u|v|r|psi> nor <effect>.<parameter>")
    return names, std


def _effect_slot(effect, q: str):
    """(position in ``effect``'s fit parameters, factor from SI to its unit) of quantity ``q`` (``..._rad`` for
    a parameter in degrees), or None."""
    for j, p in enumerate(effect.fit_parameters()):
        if p.name == q:
            return j, 1.0
        if p.unit == "deg" and p.name.endswith("_deg") and q == p.name[:-4] + "_rad":
            return j, 180.0 / np.pi
    return None


def _disturbed(run: MeasuredRun, names, row, notes: set) -> MeasuredRun:
    """``run`` with its first logged state offset by the ``start.*`` draws and the drawn per-record effects
    added (one the run already has is left as it is, noted in ``notes``)."""
    import mmg.effects as E

    off, eff = np.zeros(6), {}
    for n, v in zip(names, row):
        kind, _, q = n.partition(".")
        if kind == "start":
            off[STATE.index(q)] += v
        else:
            eff.setdefault(kind, []).append((q, v))
    meas = run.meas
    if np.any(off):
        meas = meas.copy()
        meas[0] += off
    es = run.effects
    for name, qs in eff.items():
        if es is not None and es.get(name) is not None:
            notes.add(f"{name} not drawn: the ship config has it already")
            continue
        e = E.get(name, "run_spread")
        vec = [p.default for p in e.fit_parameters()]
        for q, v in qs:
            j, k = _effect_slot(e, q)
            vec[j] += k * v
        add = E.EffectSet(((e, e.from_fit(vec)),))
        es = add if es is None else es.merged(add)
    return replace(run, meas=meas, effects=es)


def _fit_doubts(ship: Ship, names, covariance) -> list:
    """A note when the ship is drawn from the covariance its own ``identification:`` section doubts: a fit
    that stopped before converging (the covariance is not about an optimum) or that replays its training
    records worse than the initial model."""
    ident = ship.identification
    if covariance is not None or not len(names) or ident is None:
        return []
    why = ([] if ident.converged else ["did not converge (a fit stage stopped at its evaluation limit)"]) + (
        [f"replays {len(ident.training_replays_worse)} training record(s) worse than the initial model"]
        if ident.training_replays_worse else [])
    return [f"ship drawn from the covariance of an identification that {' and '.join(why)}: the band is not "
            "the uncertainty of a finished fit"] if why else []


def _candidates(ship: Ship, covariance, notes: list, support: str):
    """(names, mean, matrix, support) of the ship's draws; no support with ``support`` "none" or without a
    covariance (no names then)."""
    cov = ship.covariance if covariance is None else covariance
    if cov is None:
        notes.append("ship not drawn: the ship config has no covariance: section (the band is the run spread's alone)")
        return [], np.zeros(0), np.zeros((0, 0)), None
    names, mean, matrix, _ = parameter_covariance(ship, cov)
    if not len(names) or support == "none":
        return names, mean, matrix, None
    sup = support_of(ship, names, cov, energy=support == "physical")
    notes += [sup.caveat] if sup.caveat else []
    return names, mean, matrix, sup


def _draws(ship: Ship, covariance, std, samples: int, seed: int, notes: list, support: str):
    """(names, ship rows (k, n), mean, run rows (k, len(std)), rejected): ``samples`` draws of the ship inside
    its support (:func:`_candidates`) each with its run draw, batches of ``samples`` candidates from the
    two streams of ``seed``, at most :data:`MAX_CANDIDATES` times ``samples`` candidates."""
    names, mean, matrix, support = _candidates(ship, covariance, notes, support)
    ship_rng, run_rng = np.random.default_rng(seed), np.random.default_rng([int(seed), 1])
    rows, runs, tried = [], [], 0
    while len(rows) < samples and tried < MAX_CANDIDATES * samples:
        cand = (ship_rng.multivariate_normal(mean, matrix, samples, method="eigh") if len(names)
                else np.zeros((samples, 0)))
        run_rows = run_rng.normal(0.0, 1.0, (samples, len(std))) * std
        for a, b in zip(cand, run_rows):
            if len(rows) == samples:
                break
            tried += 1
            if support is None or support.contains(ship, a):
                rows.append(a)
                runs.append(b)
    if not rows:
        raise InputError(ship.source or ship.name, "covariance.matrix",
                         f"none of {tried} ships drawn lies in the support ({support.note}): the covariance puts next "
                         "to no weight on an admissible ship")
    if tried > len(rows):
        notes.append(f"{tried - len(rows)} of {tried} ships drawn from the covariance rejected, not replayed: "
                     f"outside the support ({support.note}); the band is the normal truncated to it")
    if len(rows) < samples:
        notes.append(f"only {len(rows)} of {samples} draws inside the support after {tried} candidates")
    return names, np.array(rows), mean, np.array(runs), tried - len(rows)


def _one_replay(ship: Ship, run: MeasuredRun, names, row, mean, sp_names, sp_row, notes: set) -> np.ndarray:
    """The predicted x, y [m] and heading [rad] (N, 3) of one draw: the ship's parameters ``row`` (``names``), the
    run spread's ``sp_row``."""
    from .identify import ship_with_values, with_fitted_wind, with_ship_effects

    values = {n: float(v) for n, v in zip(names, row)}
    wind = {n: values.pop(n) / m for n, m in zip(names, mean) if n in WIND_FACTOR_NAMES and m != 0}
    s = ship_with_values(ship, values) if values else ship
    r = with_fitted_wind(run, wind) if wind else run
    r = with_ship_effects(r, s) if "rudder_offset" in values else r
    r = _disturbed(r, sp_names, sp_row, notes) if len(sp_names) else r
    return replay_record(s, r).pred[:, 3:6]


def _model_form_errors(ship: Ship, run: MeasuredRun, samples: int, seed: int, notes: list) -> np.ndarray | float:
    """Each draw's model-form heading error [deg] (draws, N): a zero-mean normal, one per draw and whole along
    the record, whose 90 % half-width is the ship's ``model_form:`` term at each sample's elapsed time
    (:func:`trials.measured.modelform.heading_half_width`), from the third stream of ``seed``; 0 without one."""
    mf = ship.model_form
    if mf is None:
        notes.append("no model-form term drawn (none in the ship config, or left out): the band is the "
                     "parameters' and the run's doubt alone, narrower than a new record's error")
        return 0.0
    from .modelform import Z90, heading_half_width, measured_until, unbounded_from

    L = ship.particulars.L
    hw = heading_half_width(mf, run.t - run.t[0], L)
    z = np.random.default_rng([int(seed), 2]).standard_normal(samples)
    span, last = run.t[-1] - run.t[0], measured_until(mf, L)
    cut = unbounded_from(mf, L)
    notes.append(f"model-form heading error added to each draw ({mf.source or 'model_form: section'}; "
                 f"{hw[-1]:.1f} deg 90 % half-width at the record's end" + (", where the term is unbounded)"
                                                                        if span > cut else ")"))
    if span > last and cut > last:
        notes.append(f"the model-form term was measured up to {last:.4g} s of elapsed time and is held at its last "
                     f"value beyond{'' if span <= cut else f' up to {cut:.4g} s'} (a longer record's error may grow "
                     "further)")
    if span > cut:
        notes.append(f"the model-form term is unbounded from {cut:.4g} s of elapsed time (replays that made it "
                     "diverged in the bin after its last node): the bands are unbounded beyond")
    return z[:, None] * (hw / Z90)[None, :]


def _model_form_offsets(ship: Ship, run: MeasuredRun, samples: int, seed: int, notes: list) -> np.ndarray | float:
    """Each draw's model-form position offset [m] (draws, N, 2): a circular normal, one per draw and whole
    along the record, whose 90 % radius is the ship's ``model_form:`` position term at each sample's elapsed
    time (:func:`trials.measured.modelform.position_half_width`), from the fourth stream of ``seed``; 0
    without one."""
    from .modelform import R90, position_half_width

    mf = ship.model_form
    hw = None if mf is None else position_half_width(mf, run.t - run.t[0], ship.particulars.L)
    if hw is None:
        if mf is not None:
            notes.append("no model-form position term (the model_form: section has no position_q90_L): the "
                         "position band is the draws' alone, narrower than a new record's error")
        return 0.0
    z = np.random.default_rng([int(seed), 3]).standard_normal((samples, 2))
    notes.append(f"model-form position offset added to each draw ({hw[-1]:.3g} m 90 % radius at the record's end)")
    return z[:, None, :] * (hw / R90)[None, :, None]


def _unwrapped_deg(psi: np.ndarray, first: float) -> np.ndarray:
    """Headings (..., N) [rad] unwrapped along the last axis, put on the turn of ``first`` [rad], in degrees."""
    u = np.unwrap(psi, axis=-1)
    k = np.round((first - u[..., :1]) / (2 * np.pi))
    return np.degrees(u + 2 * np.pi * np.nan_to_num(k))


def _quantile_bounds(x: np.ndarray, q=QUANTILES) -> tuple[np.ndarray, np.ndarray]:
    """Per column of ``x`` (draws, N): the ``q`` quantiles with a NaN (a diverged draw) as -inf for the
    lower and +inf for the upper one."""
    with np.errstate(invalid="ignore"):
        lo = np.quantile(np.where(np.isnan(x), -np.inf, x), q[0], axis=0)
        hi = np.quantile(np.where(np.isnan(x), np.inf, x), q[1], axis=0)
    return np.where(np.isnan(lo), -np.inf, lo), np.where(np.isnan(hi), np.inf, hi)   # inf - inf in the interpolation


def _position_band(xy: np.ndarray):
    """(x median, y median, radius) per sample of the drawn tracks ``xy`` (draws, N, 2) (module docstring)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)        # a sample where every draw diverged: NaN
        xm, ym = np.nanmedian(xy[:, :, 0], axis=0), np.nanmedian(xy[:, :, 1], axis=0)
    d = np.hypot(xy[:, :, 0] - xm, xy[:, :, 1] - ym)
    with np.errstate(invalid="ignore"):
        r = np.quantile(np.where(np.isnan(d), np.inf, d), POSITION_QUANTILE, axis=0)
    return xm, ym, np.where(np.isnan(r), np.inf, r)


def prediction_bands(ship: Ship, run, samples: int, seed: int = 0, covariance=None, run_spread=None,
                     jobs: int | None = None, support: str = "physical") -> Bands:
    """The 90 % heading and position bands of one record's prediction (module docstring).

    Parameters
    ----------
    ship : Ship
        The (identified) ship; its ``covariance:`` and ``run_spread:`` sections are the defaults.
    run : MeasuredRun or TrialRecord
        The record (a :class:`~trials.files.records.TrialRecord` is made ready with :func:`measured_run`).
    samples : int
        Replays to draw (1 or more).
    seed : int
        Seed of the draws.
    covariance : ParameterCovariance, mapping or DataFrame, optional
        The parameters' covariance (:func:`trials.measured.draws.parameter_covariance`); default the
        ship's; the ship is not drawn where neither is (said in :attr:`Bands.notes`).
    run_spread : RunSpread or mapping, optional
        ``names`` and ``std`` of the run's own disturbance; default the ship's; none drawn where
        neither is.
    jobs : int, optional
        Threads (default every core).
    support : {"physical", "bounds", "none"}
        Where the ship's draws are truncated (:data:`trials.measured.draws.SUPPORTS`): to the fit's hard
        bounds and no energy gained unpowered over the covariance's ``state_range`` (default,
        :func:`~trials.measured.draws.support_of`), to the bounds alone, or nowhere (the covariance's normal:
        a diverging draw widens the band, to unbounded).  The parameters' doubt alone under-covers new
        records; the ship's ``model_form:`` term adds what a replay's heading and position stray beyond it
        (``docs/prediction_bands.md``).

    Returns
    -------
    Bands
    """
    if support not in SUPPORTS:
        raise InputError("prediction_bands", "support", f"must be one of {', '.join(SUPPORTS)}, got {support!r}")
    if isinstance(samples, bool) or int(samples) != samples or samples < 1:
        raise InputError("samples", "", f"must be a whole number of 1 or more, got {samples!r}")
    samples = int(samples)
    run = run if isinstance(run, MeasuredRun) else measured_run(ship, run)
    src = ship.source or ship.name
    notes: list = []
    spread = ship.run_spread if run_spread is None else run_spread
    sp_names, std = _spread_of(spread, src) if spread is not None else ([], np.zeros(0))
    names, rows, mean, sp_rows, rejected = _draws(ship, covariance, std, samples, seed, notes, support)
    notes += _fit_doubts(ship, names, covariance)
    if spread is None:
        notes.append("start state not drawn: the ship config has no run_spread: section")
    samples = len(rows)
    seen: set = set()
    with ThreadPoolExecutor(max_workers=jobs or os.cpu_count() or 1) as pool:
        preds = list(pool.map(lambda k: _one_replay(ship, run, names, rows[k], mean, sp_names, sp_rows[k], seen),
                              range(samples)))
    P = np.stack(preds)                                              # (draws, N, 3): x, y, psi
    nominal = replay_record(ship, run)
    first = float(np.unwrap(run.meas[:, 5])[0])
    lo, hi = _quantile_bounds(_unwrapped_deg(P[:, :, 2], first) + _model_form_errors(ship, run, samples, seed, notes))
    xm, ym, radius = _position_band(P[:, :, :2] + _model_form_offsets(ship, run, samples, seed, notes))
    if ship.model_form is not None:                   # beyond where the term's own replays diverged
        from .modelform import unbounded_after

        out = unbounded_after(ship.model_form, run.t - run.t[0], ship.particulars.L)
        lo, hi, radius = np.where(out, -np.inf, lo), np.where(out, np.inf, hi), np.where(out, np.inf, radius)
    return Bands(nominal=nominal, t=np.asarray(run.t, float), heading_deg=np.degrees(np.unwrap(run.meas[:, 5])),
                 lo=lo, hi=hi, nominal_deg=_unwrapped_deg(nominal.pred[:, 5], first), x_median=xm, y_median=ym,
                 radius=radius, tracks=P[:SAMPLE_TRACKS, :, :2].copy(), draws=samples,
                  diverged=int(np.sum(~np.isfinite(P).all(axis=(1, 2)))), notes=tuple(notes + sorted(seen)),
                 rejected=rejected)
