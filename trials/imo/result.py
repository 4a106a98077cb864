"""``mmg.imo``: the IMO manoeuvring standards checked on a ship, with their uncertainty.

Source of the criteria: IMO Resolution MSC.137(76) (2002), *Standards for Ship Manoeuvrability*,
Annex section 5.3, with the explanatory notes MSC/Circ.1053 (2002); the limits are defined once in
:mod:`trials.analysis.metrics`, the manoeuvres and criteria in :mod:`trials.imo.standard`, the
sampling in :mod:`trials.imo.sampling`.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mmg.errors import InputError
from mmg.ship import Ship, load_ship

from ..analysis.metrics import IMO_STANDARD
from . import sampling as S
from .doubts import IdentificationDoubts, identification_doubts
from .standard import MAX_RUN_LENGTHS_L, STOPPING, STOPPING_RUN, Criterion, approach_speed, criteria, \
    criterion_values, plan, run_manoeuvres

__all__ = ["imo", "ImoResult", "VERDICTS"]

VERDICTS = ("pass", "fail", "undecided")
"""A criterion's verdict: met, not met, or not decided by the samples (probability between
:data:`~trials.imo.sampling.FAIL_PROBABILITY` and :data:`~trials.imo.sampling.PASS_PROBABILITY`)."""


@dataclass(frozen=True)
class ImoResult:
    """The IMO criteria of one ship: values, limits, verdicts and, with samples, their uncertainty.

    Returned by :func:`imo`.  Read it with :meth:`rows` (what ``imo.json`` holds), :meth:`to_pandas`,
    :meth:`to_json` and :meth:`plot`.

    Attributes
    ----------
    ship : str
        The ship's name.
    speed : str
        The approach speed as given (``"10 kn"``); ``u0`` the same in m/s; ``L_over_V`` L / V [s].
    criteria : tuple of Criterion
        One per side of each manoeuvre, the stopping test last.
    nominal : dict
        Criterion name -> value with the ship's own parameters (None where not available).
    samples : dict or None
        Criterion name -> one value per parameter sample (None: no samples).
    parameters : dict or None
        With samples: ``names``, ``mean``, ``cov`` (the sampled parameters), ``draws`` (N x names), ``seed``.
    notes : tuple of str
        What a reader should know (effects left out, failed samples, the stopping test).
    doubts : IdentificationDoubts
        The identified ship's own warnings (its ``identification:`` section) and, where its fit did not
        finish, why no criterion is reported as passed (:mod:`trials.imo.doubts`).
    own_warnings : tuple of str
        This check's own doubts: samples that failed to run, criteria a manoeuvre did not give.
    runs : dict
        The nominal runs: run name -> (TrialRun, metrics) (for the figures; not in the JSON).
    """

    ship: str
    speed: str
    u0: float
    L_over_V: float
    L: float
    B: float
    criteria: tuple
    nominal: dict
    samples: dict | None = None
    parameters: dict | None = None
    notes: tuple = ()
    doubts: IdentificationDoubts = IdentificationDoubts()
    own_warnings: tuple = ()
    runs: dict = field(default_factory=dict, repr=False, compare=False)
    sample_runs: dict = field(default_factory=dict, repr=False, compare=False)
    """With samples: the turning circles of the samples with the smallest, the median and the largest
    tactical diameter on each side, ``"turning circle, starboard: median sample"`` -> (TrialRun, metrics)."""
    scaling: dict | None = None
    """Scaled from a model (``scale_to``): ``model``, ``lambda``, ``u_model``, ``re_model``, ``re_ship``,
    ``cf_model``, ``cf_ship``, ``form_factor``, ``corrections`` (name -> (quantity, model value, ship
    value)), ``rel_std`` (:data:`trials.imo.scaling.EFFECTS` -> relative std); None otherwise."""
    samples_without_scaling: dict | None = None
    """Scaled with samples: the same model draws with the scale-effect uncertainties off (criterion name ->
    values), so :meth:`interval_widths` can say how much of each interval the scaling assumptions make."""

    @property
    def warnings(self) -> list[str]:
        """The identification's warnings, then this check's own (``imo.json``'s ``warnings``)."""
        return list(self.doubts.warnings) + list(self.own_warnings)

    @property
    def n_samples(self) -> int:
        """The number of parameter samples (0 without uncertainty)."""
        return 0 if self.samples is None else len(next(iter(self.samples.values())))

    def _row(self, c: Criterion) -> dict:
        if self.samples is None:
            v = self.nominal[c.name]
            verdict = "fail" if v is None or v > c.limit else "pass"   # a turn or zigzag that never gets there fails
            row = {"name": c.name, "value": v, "unit": c.unit, "limit": c.limit, "interval": None,
                   "probability": None, "verdict": verdict}
        else:
            s = S.summarise(self.samples[c.name], c.limit)
            row = {"name": c.name, "value": s["median"], "unit": c.unit, "limit": c.limit, "interval": s["interval"],
                   "probability": s["probability"], "verdict": s["verdict"]}
        shown = self.doubts.verdict(row["verdict"])
        if shown != row["verdict"]:
            row.update(verdict=shown, note=f"would pass, but {self.doubts.reason}")
        return row

    def rows(self) -> list[dict]:
        """One dict per criterion, exactly the ``imo.json`` entries: ``name``, ``value`` (the median of the
        samples with uncertainty, else the ship's own), ``unit``, ``limit``, ``interval`` ([5 %, 95 %]
        percentiles, None without samples), ``probability`` (of meeting the limit, None without samples),
        ``verdict`` (:data:`VERDICTS`); and ``note`` where a pass is reported ``"undecided"`` because the
        identification is in doubt (:attr:`doubts`), saying why."""
        return [self._row(c) for c in self.criteria]

    def as_dict(self) -> dict:
        """``{"ship": ..., "warnings": [...], "criteria": [...]}``: what ``imo.json`` holds (:attr:`warnings`,
        an empty list when there are none)."""
        return {"ship": self.ship, "warnings": self.warnings, "criteria": self.rows()}

    def to_json(self, path: str | os.PathLike | None = None) -> str:
        """The JSON of :meth:`as_dict` (written to ``path`` when given); NaN and inf never appear (None)."""
        text = json.dumps(self.as_dict(), indent=2, allow_nan=False)
        if path is not None:
            Path(path).write_text(text + "\n")
        return text

    def to_pandas(self):
        """One row per criterion (indexed by name): value, unit, limit, interval_low, interval_high,
        probability, verdict and ``nominal`` (the ship's own value)."""
        import pandas as pd

        rows = []
        for r in self.rows():
            lo, hi = r["interval"] if r["interval"] else (None, None)
            rows.append({"name": r["name"], "value": r["value"], "unit": r["unit"], "limit": r["limit"],
                         "interval_low": lo, "interval_high": hi, "probability": r["probability"],
                         "verdict": r["verdict"], "nominal": self.nominal.get(r["name"])})
        return pd.DataFrame(rows).set_index("name")

    def convergence(self, name: str) -> list[dict]:
        """How the figures of criterion ``name`` settle with the number of samples (N/8, N/4, N/2, N)."""
        if self.samples is None:
            raise ValueError("no samples: imo(ship, samples=N) gives the convergence")
        c = next(c for c in self.criteria if c.name == name)
        return S.convergence(self.samples[name], c.limit)

    def interval_widths(self) -> list[dict]:
        """Scaled with samples: per criterion the 90 % interval's width with all the uncertainty
        (``width``), with the identified covariance only (``width_identified``: scale effects fixed at
        their nominal corrections) and the share of the width the scaling assumptions add
        (``scaling_share`` = 1 - width_identified / width).  Empty otherwise."""
        if self.samples is None or self.samples_without_scaling is None:
            return []
        out = []
        for c in self.criteria:
            a = S.summarise(self.samples[c.name], c.limit)["interval"]
            b = S.summarise(self.samples_without_scaling[c.name], c.limit)["interval"]
            w = None if None in a else a[1] - a[0]
            w0 = None if None in b else b[1] - b[0]
            share = None if (w is None or w0 is None or w <= 0) else 1.0 - w0 / w
            out.append({"name": c.name, "unit": c.unit, "width": w, "width_identified": w0, "scaling_share": share})
        return out

    def plot(self, kind: str = "tracks", ax=None, pyplot: bool = True):
        """A figure: ``"tracks"`` (the turning circles with ship outlines), ``"zigzags"`` (heading and rudder
        histories), ``"stopping"`` (the full-astern stopping track with ship outlines and its speed and
        revolutions) or ``"distributions"`` (the sampled criteria with their limits).  Returns the Figure."""
        from . import plots

        draw = {"tracks": plots.tracks_figure, "zigzags": plots.zigzags_figure, "stopping": plots.stopping_figure,
                "distributions": plots.distributions_figure}.get(kind)
        if draw is None:
            raise ValueError(f"unknown plot kind {kind!r}: tracks, zigzags, stopping or distributions")
        return draw(self, pyplot=pyplot)

    def __repr__(self) -> str:
        verdicts = [r["verdict"] for r in self.rows()]
        count = ", ".join(f"{verdicts.count(v)} {v}" for v in VERDICTS if verdicts.count(v))
        unc = f", {self.n_samples} samples" if self.samples is not None else ""
        return f"ImoResult({self.ship!r}, {self.speed}{unc}: {count})"


def _ship(ship) -> Ship:
    if isinstance(ship, Ship):
        return ship
    if not isinstance(ship, (str, os.PathLike)):
        raise InputError("ship", repr(ship)[:40], "expected a Ship, a bundled ship name or a ship YAML path")
    return load_ship(ship)


def imo(ship, speed: str | None = None, samples: int = 0, cov=None, seed: int | None = 0, executor=None,
        scale_to=None):
    """Check the IMO manoeuvring standards on ``ship``, with their uncertainty when ``samples`` > 0.

    The criteria of IMO Resolution MSC.137(76) (2002) with MSC/Circ.1053 (turning, initial turning, the
    10/10 and 20/20 zigzags to either side and the stopping test, the engine ordered astern along
    :class:`mmg.engine_order.AsternOrder`), their limits as :mod:`trials.imo.standard` states them.

    Parameters
    ----------
    ship : Ship, str or os.PathLike
        A Ship, a bundled ship name (``"esso_osaka"``) or a ship YAML path (``mmg identify``'s
        ``DIR/ship.yaml``, with its ``covariance:`` section).
    speed : str, optional
        Approach speed with its unit (``"10 kn"``); default the one of the ship's bundled trials (with
        ``scale_to``: the full-scale ship's speed and trials).
    samples : int, default 0
        Parameter samples; 0: the ship's own parameters only (no interval, no probability).
    cov : ParameterCovariance, mapping or DataFrame, optional
        The parameters' covariance (:func:`trials.imo.sampling.covariance_of`); default the ship's.
    seed : int or None, default 0
        Seed of the parameter samples.
    executor : callable, optional
        ``executor(func, tasks) -> list`` that runs the samples (:mod:`trials.imo.sampling`); default
        this machine's cores.
    scale_to : Ship, str or os.PathLike, optional
        The full-scale ship (same hull form) ``ship``, a model, is Froude-scaled to
        (:mod:`trials.imo.scaling`): the model's primed hull coefficients and flow constants (identified
        or its config's) with the scale-effect corrections (friction line, wake, rudder inflow), the
        full-scale ship's geometry, mass, propeller, engine and steering.  With samples the corrections'
        uncertainties (:class:`~trials.imo.scaling.ScaleEffects`) are sampled with the model's
        covariance, and the same model draws are run again with the corrections fixed
        (:meth:`ImoResult.interval_widths`: how much of each interval the scaling makes; twice the runs).

    Returns
    -------
    ImoResult
        With samples each criterion's value is the median of the samples, its interval the 5th-95th
        percentiles, its probability the share of samples meeting the limit; verdict ``"pass"`` if that
        probability is >= 0.95, ``"fail"`` if <= 0.05, else ``"undecided"``.  Without samples the verdict
        is the value against the limit (a manoeuvre that does not give its figure fails, with a note).
        On a ship whose ``identification:`` section says its fit did not converge or replays training
        records worse than the initial model, a pass is ``"undecided"`` with a ``note``
        (:mod:`trials.imo.doubts`); the section's warnings are the result's :attr:`ImoResult.warnings`.

    Raises
    ------
    mmg.errors.InputError
        An unknown ship, a bad speed (or none known), a negative sample count, a bad covariance, a
        ``scale_to`` of another hull form or not larger than the model.
    """
    sh = _ship(ship)
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 0:
        raise InputError("samples", repr(samples), "expected a whole number of samples, 0 or more")
    target = sh if scale_to is None else _ship(scale_to)
    notes = []
    if speed is None:
        speed, files = approach_speed(target)
        notes.append(f"approach speed {speed} from the bundled trials {', '.join(files)}")
    sc, scaled = _scale(sh, target, speed) if scale_to is not None else (None, None)
    p = plan(sh if sc is None else sc.ship(sh), speed)
    notes += ([] if sc is None else [_scale_note(sc)]) + list(p.notes)
    runs = run_manoeuvres(p)
    nominal = criterion_values(p, runs)
    crit = tuple(criteria(p.L_over_V))
    own = [f"{c.name}: the manoeuvre does not give it (no 180 deg of turn, no overshoot, no stop) within "
           f"{MAX_RUN_LENGTHS_L:g} L/V: it fails" for c in crit if nominal[c.name] is None]
    notes += own
    sampled = without = params = None
    if samples:
        sampled, without, params = _sampled(p, sh, sc, (samples, cov, seed), executor, (notes, own))
    notes.append(stopping_note(runs[STOPPING_RUN]))
    pa = p.ship.particulars
    extremes = _extreme_turns(p, params, sampled) if samples else {}
    return ImoResult(ship=sh.name if sc is None else sc.base.name, speed=str(speed), u0=p.u0,
                     L_over_V=p.L_over_V, L=pa.L, B=pa.B, criteria=crit, nominal=nominal, samples=sampled,
                     parameters=params, notes=tuple(notes), doubts=identification_doubts(sh),
                     own_warnings=tuple(own), runs=runs, sample_runs=extremes, scaling=scaled,
                     samples_without_scaling=without)


def _scale(model: Ship, full: Ship, speed: str):
    """(:class:`~trials.imo.scaling.Scaling`, its summary for :attr:`ImoResult.scaling`)."""
    from . import scaling as SC
    from .standard import _parse_speed

    sc = SC.scaling(model, full, _parse_speed(speed))
    e = sc.effects
    return sc, {"model": model.name, "ship": full.name, "lambda": sc.lam, "u_model": sc.u_model, "u_ship": sc.u_ship,
                "re_model": sc.re_model, "re_ship": sc.re_ship, "cf_model": sc.cf_model, "cf_ship": sc.cf_ship,
                "form_factor": e.form_factor, "delta_CF": e.delta_CF, "t_model": sc.t_model,
                "corrections": sc.corrections(model), "rel_std": dict(zip(SC.EFFECTS, e.stds().tolist()))}


def _scale_note(sc) -> str:
    return (f"Froude-scaled from {sc.model_name} (lambda = {sc.lam:.4g}, model speed {sc.u_model:.4g} m/s): the "
            f"model's primed hull coefficients and flow constants with the scale-effect corrections, the ship's "
            f"geometry, mass, propeller, engine and steering (trials.imo.scaling)")


def _run(p, names, rows, executor, notes: tuple) -> dict:
    """Criterion name -> one value per row of ``rows`` (:func:`trials.imo.sampling.run_samples`); a note on
    failures appended to each list of ``notes`` (the report's notes, the check's own warnings)."""
    out = S.run_samples(p, names, rows, executor)
    bad = [o["error"] for o in out if o["error"]]
    if bad:
        for n in notes:
            n.append(f"{len(bad)} of {len(out)} samples failed to run (counted as not meeting any criterion), "
                     f"e.g. {bad[0]}")
    return {c.name: [o["values"][c.name] for o in out] for c in criteria(p.L_over_V)}


def _sampled(p, sh: Ship, sc, how: tuple, executor, notes: tuple):
    """(samples, samples with the scale effects fixed or None, parameters) of :func:`imo`; ``how`` =
    (number of samples, covariance or None, seed); ``notes`` = (the report's notes, the check's own warnings)."""
    from .scaling import EFFECTS, full_scale_draws

    n, cov, seed = how
    if sc is None or cov is not None or sh.covariance is not None:
        names, mean, mat, more = S.covariance_of(p.ship if sc is None else sh, cov)
        notes[0].extend(more)
        draws = S.draw(mean, mat, n, seed)
    else:
        names, mean, mat, draws = [], np.zeros(0), np.zeros((0, 0)), np.zeros((n, 0))
        notes[0].append(f"{sh.name} has no covariance: only the scale-effect corrections are sampled")
    params = {"names": names, "mean": mean, "cov": mat, "draws": draws, "seed": seed}
    if sc is None:
        return _run(p, names, draws, executor, notes), None, params
    rng = np.random.default_rng(None if seed is None else [int(seed), 28])
    xi = rng.standard_normal((n, len(EFFECTS))) * sc.effects.stds()
    fnames, rows = full_scale_draws(sc, sh, names, draws, xi)
    nominal = sc.values(sh)
    full = {"names": fnames, "mean": np.array([nominal[k] for k in fnames]),
            "cov": np.cov(rows.T) if n > 1 else np.zeros((len(fnames),) * 2), "draws": rows, "seed": seed,
            "model": params, "scale_effects": xi}
    sampled = _run(p, fnames, rows, executor, notes)
    without = None
    if names:
        _, rows0 = full_scale_draws(sc, sh, names, draws, np.zeros_like(xi))
        without = _run(p, fnames, rows0, executor, ())
    return sampled, without, full


def stopping_note(run_metrics) -> str:
    """What the report says of the stopping test: the engine order, the definition of stopped, the
    head reach, lateral deviation and time to stop of the ship's own parameters."""
    run, m = run_metrics
    o = run.trial.astern_order()
    head = ("" if not m.get("stopped") else
            f"; track reach {m['track_reach_L']:.2f} L, head reach {m['head_reach_L']:.2f} L, lateral deviation {m['lateral_deviation_L']:+.2f} L "
            f"(+ starboard), heading change {m['heading_change_deg']:+.1f} deg, stopped after "
            f"{m['time_to_stop_s']:.0f} s ({m['time_to_stop_s'] / 60:.1f} min)")
    return (f"{STOPPING}: rudder midships, full astern ordered at t = 0 from the approach revolutions "
            f"{m['approach_rpm']:.1f} rpm: a linear ramp to {o.astern_ratio:g} of them astern "
            f"({-o.astern_ratio * m['approach_rpm']:.1f} rpm) in {_ramp_text(o.ramp_s, run.trial.ship)} "
            f"(mmg.engine_order.AsternOrder, "
            f"revolutions prescribed: no propeller torque needed; thrust from the four-quadrant B4-70 curve, "
            f"mmg.fourquadrant); stopped = surge speed down to 1 % of the "
            f"approach speed{head}.  Limit 15 L; the Administration may accept up to 20 L for ships of large "
            f"displacement")


def _ramp_text(ramp_s: float, ship: Ship) -> str:
    """The stopping ramp [s] and where it comes from: the full-scale reversal time, Froude-scaled on a model."""
    from mmg.engine_order import REVERSAL_TIME_S, reversal_time

    lam = ship.froude_scale
    if not math.isclose(ramp_s, reversal_time(lam), rel_tol=1e-9):
        return f"{ramp_s:.3g} s"
    if lam == 1.0:
        return f"{ramp_s:.3g} s (the full-scale reversal time)"
    return (f"{ramp_s:.3g} s (the full-scale {REVERSAL_TIME_S:g} s Froude-scaled to this model: "
            f"{REVERSAL_TIME_S:g} s / sqrt(lambda), lambda = {lam:.4g})")


def _extreme_turns(p, params: dict, sampled: dict) -> dict:
    """The turning circles of the samples with the smallest, median and largest tactical diameter per side
    (run again: a few runs, not kept from the pool)."""
    from dataclasses import replace

    from ..measured.identify import ship_with_values

    out = {}
    for side in ("starboard", "port"):
        name = f"turning circle, {side}"
        v = np.array([np.nan if x is None else x for x in sampled[f"tactical diameter, {side}"]], dtype=float)
        ok = np.flatnonzero(np.isfinite(v))
        if ok.size == 0:
            continue
        order = ok[np.argsort(v[ok])]
        one = replace(p, trials={name: p.trials[name]})
        for label, k in (("smallest", order[0]), ("median", order[len(order) // 2]), ("largest", order[-1])):
            ship = ship_with_values(p.ship, dict(zip(params["names"], (float(x) for x in params["draws"][k]))))
            out[f"{name}: {label} sample"] = run_manoeuvres(one, ship)[name]
    return out


SOURCE = IMO_STANDARD
