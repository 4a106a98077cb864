"""Nested cross-validation of ``mmg identify``: every choice made inside the training folds.

A plain k-fold cross-validation (:func:`trials.measured.identify.cross_validate`) scores one
procedure.  When the procedure has a choice to make (the hull form, a free set, a prior width, a
weighting), choosing it by that same cross-validation's figure fits the choice to the kept-out
records, and the figure is no longer a held-out one.  :func:`nested_cross_validate` keeps the
kept-out records out of the choice too:

* outer folds: the records are dealt into ``folds`` folds (:func:`~trials.measured.identify.fold_of`:
  a record and its cut copies share a fold), each kept out once;
* inside each outer training set, an inner cross-validation over the training records only
  (``inner_folds`` folds) fits every :class:`Candidate` on each inner training set and replays the
  inner kept-out records; the candidate with the fewest diverged inner replays, then the lowest mean
  inner held-out heading RMS, is the fold's choice (:func:`choose`);
* the choice is then fitted on the whole outer training set and the outer kept-out records are
  replayed open loop with it and with the initial (Froude-scaled) model.

Every fit goes through :func:`fit_model` (one place a test can watch).  A replay that goes
non-finite is reported as a divergence with its time and state (:func:`replay_scores`), never as a
bare NaN.  :func:`select_candidate` is the inner step alone, on all the given records: what
``mmg identify --hull auto`` uses to choose the form it then fits.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from mmg.ship import Ship
from mmg.errors import InputError

from .predict import MeasuredRun, replay_record

__all__ = ["BandSpec", "Candidate", "NestedCV", "Selection", "nested_cross_validate", "select_candidate", "choose",
           "replay_scores", "fit_model", "check_choosable", "HULL_FORMS", "hull_candidates", "HORIZON_S", "SCORE_NAMES",
           "band_scores", "band_sections", "band_summary", "band_ship", "MODEL_FORMS", "split_folds", "json_ready"]

HULL_FORMS = {"kijima": "", "crossflow": "_crossflow"}
"""The hull forms ``mmg identify --hull`` knows, by the suffix of their bundled config's name after the
Kijima one's (``esso_osaka_3m`` and ``esso_osaka_3m_crossflow``: the same ship, the hull rewritten in
the low-speed cross-flow form of :mod:`mmg.terms`)."""
HORIZON_S = 60.0
"""The short-horizon window [s] of the scores (the first minute: what a berthing pilot looks at)."""
SCORE_NAMES = ("heading_rms_deg", "yaw_rate_rms_degps", "speed_rms_mps", "final_position_error_L")
"""The scores reported per record, over the whole record and over the first :data:`HORIZON_S`."""


@dataclass(frozen=True)
class Candidate:
    """One procedure among which a nested cross-validation chooses.

    Attributes
    ----------
    name : str
        Its label in the choices reported.
    ship : Ship
        The prior the fit starts from (its hull form is the model form).
    options : dict
        :func:`trials.measured.identify.identify` keyword arguments of this candidate on top of the
        common ones (a free set ``free``, ``prior_rel_std``, ``record_weighting``, ...).
    path : str, optional
        The ship's config file (where ``mmg identify`` reads the YAML it writes the fitted values into).
    """

    name: str
    ship: Ship
    options: dict = field(default_factory=dict)
    path: object = None


def hull_candidates(ship_name: str, forms=("kijima", "crossflow")) -> dict[str, Candidate]:
    """The candidates of ``mmg identify --hull``: the bundled configs of ``ship_name``'s hull forms
    (:data:`HULL_FORMS`; ``ship_name`` may name either form).  Raises :class:`mmg.errors.InputError`
    naming ``--hull`` for a form whose config is not bundled."""
    from mmg.errors import InputError
    from mmg.resources import ship_path
    from mmg.ship import load_ship

    base = str(ship_name)
    for suffix in HULL_FORMS.values():
        if suffix and base.endswith(suffix):
            base = base[: -len(suffix)]
    out = {}
    for f in forms:
        if f not in HULL_FORMS:
            raise InputError("--hull", f, f"one of auto, {', '.join(HULL_FORMS)}")
        name = base + HULL_FORMS[f]
        try:
            path = ship_path(name)
            out[f] = Candidate(f, load_ship(path), path=path)
        except InputError:
            raise InputError("--hull", f, f"no bundled ship config {name!r} for the {f} hull form of "
                                          f"{ship_name!r} (--hull needs --ship to name a bundled ship "
                                          f"whose forms are {', '.join(base + s for s in HULL_FORMS.values())})"
                             ) from None
    return out


def fit_model(ship: Ship, runs: list[MeasuredRun], **kw):
    """Every fit of the nested cross-validation: :func:`trials.measured.identify.identify` (quiet)."""
    from .identify import identify

    kw.setdefault("say", lambda m: None)
    return identify(ship, runs, **kw)


def replay_scores(rep, horizon_s: float = HORIZON_S, ship: Ship | None = None) -> dict:
    """Scores of one replay (:class:`trials.measured.predict.Replayed`): :data:`SCORE_NAMES` over the whole
    record, the same with the suffix ``_60s`` (``horizon_s``) over its first minute, and ``divergence``
    (:attr:`~trials.measured.predict.Replayed.divergence`: time and state, None when it stayed finite).
    A window the divergence falls in has NaN scores and the divergence says why.

    With ``ship`` (the model that made ``rep``) also ``window_heading_rms_deg`` [deg] and
    ``window_final_position_error_L`` [L]: the means over the 60 s windows every 30 s restarted from the
    measured state (:func:`trials.measured.window.window_scores` of ``rep.run``, so with the same wind
    loads and effects as ``rep``)."""
    whole, first = rep.scores(), rep.scores(until_s=horizon_s)
    tag = f"_{horizon_s:g}s"
    out = {k: whole[k] for k in SCORE_NAMES}
    out.update({k + tag: first[k] for k in SCORE_NAMES})
    if ship is not None:
        from .window import window_scores

        w = window_scores(ship, rep.run)
        out.update({"window_heading_rms_deg": w.mean("heading_rms_deg"),
                    "window_final_position_error_L": w.mean("position_error_L")})
    out["divergence"] = rep.divergence
    return out


def _inner_task(task) -> list[dict]:
    """One inner fit: candidate fitted on an inner training set, its inner kept-out records replayed."""
    outer, inner, cand, train, tests, initial, kw = task
    ident = fit_model(cand.ship, train, initial=initial, **{**kw, **cand.options})
    out = []
    for r in tests:
        rep = ident.replay(r)
        out.append({"outer": outer, "inner": inner, "candidate": cand.name, "name": r.name,
                    "heading_rms_deg": rep.scores()["heading_rms_deg"], "divergence": rep.divergence})
    return out


def band_sections(ident) -> tuple:
    """(covariance, run spread) the bands of ``ident``'s predictions draw from: what ``mmg identify`` would
    write into ship.yaml (an empty covariance where it is not finite)."""
    from .identify import identification_covariance, run_spread

    cov = identification_covariance(ident)
    return (cov if cov is not None else {"names": [], "matrix": []}), run_spread(ident)


def band_scores(ident, run, samples: int, seed: int = 0, sections: tuple | None = None,
                support: str = "physical", ship: Ship | None = None) -> dict:
    """The 90 % heading band of ``run`` (a record as loaded for the initial ship; the band varies about it as
    ``ident`` replays it, with its fitted wind factors and effects: :func:`trials.measured.identify.fitted_run`)
    predicted by the identified model ``ident`` (its ship drawn from the
    covariance ``mmg identify`` would write, each start from the training records' run-to-run spread:
    :func:`trials.measured.bands.prediction_bands`; ``sections``: :func:`band_sections` of ``ident``, made
    once for several runs): ``samples`` (the record's), ``inside`` (of them in the band), ``coverage90``,
    ``median_width_deg``, ``unbounded_share``, ``draws``, ``diverged_draws``, ``rejected_draws`` (candidate
    ships outside the ``support``, not replayed: :func:`trials.measured.bands.prediction_bands`), and of the
    position band ``position_inside`` (samples whose logged position lies in it) and ``median_radius_m``; ``ship``:
    ``ident.ship`` with the sections it carries (a model-form term: :func:`band_ship`), ``ident.ship`` by default."""
    from .bands import prediction_bands
    from .identify import fitted_run

    cov, spread = band_sections(ident) if sections is None else sections
    run = fitted_run(ident.ship, ident.fit.values(), run)
    b = prediction_bands(ident.ship if ship is None else ship, run, samples, seed, covariance=cov, run_spread=spread,
                         jobs=1, support=support)
    n = len(b.t)
    bounded = int(round((1.0 - b.unbounded_share) * n))
    inside_b = int(round(b.coverage90_where_bounded * bounded)) if bounded else 0
    return {"samples": n, "inside": int(round(b.coverage90 * n)), "coverage90": b.coverage90,
            "bounded": bounded, "inside_bounded": inside_b, "median_width_deg": b.median_width_deg,
            "unbounded_share": b.unbounded_share, "draws": b.draws, "diverged_draws": b.diverged,
            "rejected_draws": b.rejected, "position_inside": int(round(b.position_coverage90 * n)),
            "median_radius_m": b.median_radius_m}


def band_summary(records: list[dict]) -> dict:
    """The kept-out records' 90 % heading bands pooled (where the records carry them, :func:`band_scores`):
    ``band_coverage90`` (samples inside over all samples; a sample where the band is unbounded counts as
    inside), ``band_unbounded_share`` (samples where it is, over all), ``band_coverage90_where_bounded``
    (inside over the bounded samples), ``band_median_width_deg`` (the median over the records of each
    record's median width), ``band_records``, ``band_rejected_share`` (candidate ships rejected outside the
    support over all candidates, pooled over the records); where every record carries them also
    ``band_position_coverage90`` (samples inside the position band over all samples) and
    ``band_median_radius_m`` (the median over the records of each one's median radius [m]); {} where none
    carries a band; ``band_refused_records`` counts the records whose band ``mmg predict --samples`` would
    refuse (their fold's covariance admits no ship in the support: ``band_refused``), left out of the rest."""
    refused = sum(1 for r in records if r.get("band_refused"))
    b = [r["band"] for r in records if r.get("band")]
    if not b:
        return {"band_refused_records": refused} if refused else {}
    n = sum(x["samples"] for x in b)
    nb = sum(x.get("bounded", x["samples"]) for x in b)
    return {"band_coverage90": sum(x["inside"] for x in b) / n, "band_refused_records": refused,
            "band_median_width_deg": float(np.median([x["median_width_deg"] for x in b])), "band_records": len(b),
            "band_unbounded_share": 1.0 - nb / n,
            "band_coverage90_where_bounded": (sum(x.get("inside_bounded", x["inside"]) for x in b) / nb) if nb else
            float("nan"),
            "band_rejected_share": sum(x.get("rejected_draws", 0) for x in b)
            / max(sum(x.get("draws", 0) + x.get("rejected_draws", 0) for x in b), 1),
            **({"band_position_coverage90": sum(x["position_inside"] for x in b) / n,
                "band_median_radius_m": float(np.median([x["median_radius_m"] for x in b]))}
               if all("position_inside" in x for x in b) else {})}


@dataclass(frozen=True)
class BandSpec:
    """The 90 % heading bands :func:`nested_cross_validate` gives each kept-out record (:func:`band_scores`).

    Attributes
    ----------
    samples : int
        Draws of the fold's model per record; 0: no bands.
    support : {"none", "bounds", "physical"}
        Where the bands' ship draws are truncated (:data:`trials.measured.draws.SUPPORTS`,
        :func:`trials.measured.bands.prediction_bands`).
    model_form : {"training", "kept-out", "none"}
        The model-form term the fold's model carries (:func:`trials.measured.identify.model_form`), as
        ``mmg identify`` writes it: from the fold's training replays (default, as without ``--cv``), from
        the kept-out replays of a cross-validation inside the fold's training set (as with ``--cv``:
        ``folds`` more fits per fold, dealt by ``folds_by``), or none.
    folds : int, optional
        Folds of that inner cross-validation (:func:`nested_cross_validate`'s ``inner_folds`` when None).
    folds_by : str, optional
        How it deals the records (:func:`~trials.measured.identify.fold_of`; the nested cross-validation's
        ``folds_by`` when None).

    Raises
    ------
    ValueError
        A negative ``samples``, a ``support`` not in :data:`~trials.measured.draws.SUPPORTS` or a
        ``model_form`` not in :data:`MODEL_FORMS`.
    """

    samples: int = 0
    support: str = "physical"
    model_form: str = "training"
    folds: int | None = None
    folds_by: str | None = None

    def __post_init__(self):
        from .draws import SUPPORTS

        if int(self.samples) != self.samples or self.samples < 0:
            raise ValueError(f"BandSpec.samples must be a whole number >= 0, got {self.samples!r}")
        if self.support not in SUPPORTS:
            raise ValueError(f"BandSpec.support must be one of {SUPPORTS}, got {self.support!r}")
        if self.model_form not in MODEL_FORMS:
            raise ValueError(f"BandSpec.model_form must be one of {MODEL_FORMS}, got {self.model_form!r}")


MODEL_FORMS = ("training", "kept-out", "none")
"""Where the bands' model-form term comes from (:class:`BandSpec`)."""


def band_ship(ident, spec: BandSpec, initial: Ship | None = None, kw: dict | None = None) -> Ship:
    """``ident``'s ship with the model-form term ``spec.model_form`` says (:class:`BandSpec`), as ``mmg
    identify`` would write it into its ship.yaml; ``initial`` and ``kw`` (the fit's options) make the
    inner cross-validation of ``"kept-out"``."""
    from .identify import cross_validate, model_form
    from .modelform import model_form_of

    if spec.model_form == "none":
        return replace(ident.ship, model_form=None)
    cv = None
    if spec.model_form == "kept-out":
        kw = {**(kw or {}), "say": lambda m: None}
        cv = cross_validate(ident.prior or ident.initial, ident.runs, folds=spec.folds or 3, initial=initial,
                            folds_by=spec.folds_by or "order", **kw)
    return replace(ident.ship, model_form=model_form_of(model_form(ident, cv)[0]))


def _outer_task(task) -> list[dict]:
    """One outer fit: the fold's choice fitted on the whole outer training set, the kept-out records scored
    (with ``bands.samples`` > 0 also their 90 % heading bands, :func:`band_scores`)."""
    outer, cand, train, tests, initial, kw, horizon_s, bands = task
    ident = fit_model(cand.ship, train, initial=initial, **{**kw, **cand.options})
    values = {k: float(v) for k, v in ident.fit.values().items()}
    out = [{"name": r.name, "fold": outer, "choice": cand.name,
            "scaled": replay_scores(replay_record(initial, r), horizon_s, initial),
            "identified": replay_scores(ident.replay(r), horizon_s, ident.ship), "ship": ident.ship, "values": values}
           for r in tests]
    if bands.samples:
        sections = band_sections(ident)                # one covariance and run spread per fold
        ship = band_ship(ident, bands, initial, {**kw, **cand.options})
        for rec, r in zip(out, tests):
            try:
                rec["band"] = band_scores(ident, r, bands.samples, seed=outer, sections=sections,
                                          support=bands.support, ship=ship)
            except InputError as e:                # the fold's covariance admits no ship to draw
                rec["band_refused"] = str(e)
    return out


def choose(rows: list[dict], names) -> tuple[str, dict]:
    """The candidate an inner cross-validation chooses and each candidate's inner figures.

    ``rows``: one per inner kept-out record and candidate (``candidate``, ``heading_rms_deg``,
    ``divergence``).  Per candidate: ``n`` records, ``diverged`` replays, ``mean_heading_rms_deg``
    over the finite ones.  Chosen: fewest divergences (a model that diverges on records like its
    training set is not the better predictor), then the lowest mean, then the order of ``names``."""
    table = {}
    for c in names:
        mine = [r for r in rows if r["candidate"] == c]
        h = [r["heading_rms_deg"] for r in mine if r["divergence"] is None and np.isfinite(r["heading_rms_deg"])]
        table[c] = {"n": len(mine), "diverged": len(mine) - len(h),
                    "mean_heading_rms_deg": float(np.mean(h)) if h else float("inf")}
    best = min(names, key=lambda c: (table[c]["diverged"], table[c]["mean_heading_rms_deg"], list(names).index(c)))
    return best, table


def json_ready(v, drop=()):
    """``v`` (dicts, lists, tuples, numbers) as JSON takes it: keys as text, a dict's keys in ``drop`` left
    out at every depth, the values as :func:`trials.files.output.json_safe` makes them (a non-finite float as
    None, numpy scalars and arrays as Python numbers and lists)."""
    from ..files.output import json_safe

    if isinstance(v, dict):
        return {str(k): json_ready(x, drop) for k, x in v.items() if k not in drop}
    if isinstance(v, (list, tuple)):
        return [json_ready(x, drop) for x in v]
    return json_safe(v)


def split_folds(runs, folds: int, folds_by: str) -> tuple[int, list]:
    """(folds made, [(training records, kept-out records) per fold]): ``runs`` dealt into at most ``folds``
    folds by ``folds_by`` (:func:`~trials.measured.identify.fold_of`; a record and its cut copies share one)."""
    from .identify import cv_folds, fold_of

    k = cv_folds(runs, folds)
    f = fold_of(runs, k, folds_by)
    return k, [([r for r, g in zip(runs, f) if g != j], [r for r, g in zip(runs, f) if g == j]) for j in range(k)]


def _inner_tasks(outer, candidates, train, inner_folds, folds_by, initial, kw):
    try:
        _, splits = split_folds(train, inner_folds, folds_by)
    except ValueError as e:
        where = "the records" if outer is None else f"outer fold {outer}'s training set"
        raise ValueError(f"no choice can be made on {where}: the inner {e}") from None
    return [(outer, j, c, tr, te, initial, kw) for j, (tr, te) in enumerate(splits) for c in candidates.values()]


def check_choosable(candidates: dict, runs: list[MeasuredRun], inner_folds: int, folds: int | None = None,
                    folds_by: str = "order") -> None:
    """Raise ValueError, before any fit, where a choice among ``candidates`` cannot be made: on ``runs``
    (:func:`select_candidate`) and, with ``folds``, on each outer training set (:func:`nested_cross_validate`),
    an inner cross-validation needs 2 or more independent records."""
    _inner_tasks(None, candidates, runs, inner_folds, folds_by, None, {})
    if folds:
        for k, (tr, _) in enumerate(split_folds(runs, folds, folds_by)[1]):
            _inner_tasks(k, candidates, tr, inner_folds, folds_by, None, {})


def _sweep(func, tasks, labels, backend, client, n_jobs):
    from ..files.sweep import run_sweep

    return run_sweep(func, tasks, backend=backend, client=client, n_jobs=n_jobs, labels=labels)


@dataclass(frozen=True)
class Selection:
    """:func:`select_candidate`'s result: ``choice`` and per candidate its inner figures (``table``)."""

    choice: str
    table: dict
    folds: int
    rows: list

    def lines(self) -> list[str]:
        """One line per candidate: its inner held-out mean heading RMS and divergences, the choice marked."""
        return [f"{c}: mean held-out heading RMS {t['mean_heading_rms_deg']:.2f} deg over {t['n'] - t['diverged']} "
                f"records, {t['diverged']} diverged{' (chosen)' if c == self.choice else ''}"
                for c, t in self.table.items()]


def select_candidate(candidates: dict, runs: list[MeasuredRun], folds: int = 3, initial: Ship | None = None,
                     folds_by: str = "order", backend: str = "serial", client=None, n_jobs=None, **kw) -> Selection:
    """Choose among ``candidates`` (:class:`Candidate` by name) by a ``folds``-fold cross-validation on
    ``runs`` (:func:`choose`); ``kw``: :func:`~trials.measured.identify.identify`'s common options."""
    initial = _initial(candidates, initial)
    if len(candidates) == 1:
        (name,) = candidates
        return Selection(name, {name: {"n": 0, "diverged": 0, "mean_heading_rms_deg": float("nan")}}, 0, [])
    tasks = _inner_tasks(None, candidates, runs, folds, folds_by, initial, kw)
    parts = _sweep(_inner_task, tasks, [f"choice: inner fold {t[1] + 1}, {t[2].name}" for t in tasks],
                   backend, client, n_jobs)
    rows = [r for p in parts for r in p]
    choice, table = choose(rows, list(candidates))
    return Selection(choice, table, len({t[1] for t in tasks}), rows)


def _initial(candidates: dict, initial: Ship | None) -> Ship:
    from ..files.shipcheck import check_same_ship

    if not candidates:
        raise ValueError("no candidate to fit")
    first = next(iter(candidates.values())).ship
    ref = first if initial is None else initial
    for c in candidates.values():
        check_same_ship(ref, c.ship, option="--hull")
    return ref


def nested_cross_validate(candidates: dict, runs: list[MeasuredRun], folds: int = 4, inner_folds: int = 3,
                          initial: Ship | None = None, folds_by: str = "order", backend: str = "serial",
                          client=None, n_jobs=None, horizon_s: float = HORIZON_S,
                          bands: BandSpec = BandSpec(), **kw) -> NestedCV:
    """Nested cross-validation (module docstring) of the procedure "choose among ``candidates`` by an
    inner ``inner_folds``-fold cross-validation, then fit the choice".

    Parameters
    ----------
    candidates : dict of str to Candidate
        The procedures to choose among (one: no inner cross-validation, a plain one).
    runs : list of MeasuredRun
        Every record (a record and its cut copies count once: they share a fold).
    folds, inner_folds : int
        Outer and inner fold counts (fewer when there are fewer independent records).
    initial : Ship, optional
        The model every kept-out record is also replayed with ("scaled"); the first candidate's prior
        when omitted.
    folds_by : str
        How records are dealt into folds, outer and inner (:func:`~trials.measured.identify.fold_of`).
    backend, client, n_jobs
        Where the fits run (:func:`trials.files.sweep.run_sweep`): the inner fits of every outer fold
        in one sweep, then the outer fits in another; the same numbers on every backend.
    horizon_s : float
        The short-horizon window [s] of the scores.
    bands : BandSpec
        With ``bands.samples`` > 0, each kept-out record's 90 % heading band from that many draws of its
        fold's model, truncated to ``bands.support`` (:func:`band_scores`; records' ``band``); none by default.
    **kw
        :func:`~trials.measured.identify.identify`'s options common to every candidate.
    """
    initial = _initial(candidates, initial)
    n_out, splits = split_folds(runs, folds, folds_by)
    bands = replace(bands, folds=inner_folds if bands.folds is None else bands.folds,
                    folds_by=folds_by if bands.folds_by is None else bands.folds_by)
    choices, tables, inner_rows = {}, {}, []
    if len(candidates) > 1:
        tasks = [t for k, (tr, _) in enumerate(splits)
                 for t in _inner_tasks(k, candidates, tr, inner_folds, folds_by, initial, kw)]
        parts = _sweep(_inner_task, tasks, [f"outer fold {t[0] + 1}/{n_out}: inner fold {t[1] + 1}, {t[2].name}"
                                            for t in tasks], backend, client, n_jobs)
        inner_rows = [r for p in parts for r in p]
        for k in range(n_out):
            choices[k], tables[k] = choose([r for r in inner_rows if r["outer"] == k], list(candidates))
    else:
        choices = dict.fromkeys(range(n_out), next(iter(candidates)))
    tasks = [(k, candidates[choices[k]], tr, te, initial, kw, horizon_s, bands)
             for k, (tr, te) in enumerate(splits)]
    parts = _sweep(_outer_task, tasks, [f"outer fold {k + 1}/{n_out}: fit {choices[k]} on {len(t[2])} records"
                                        for k, t in enumerate(tasks)], backend, client, n_jobs)
    folds_info = [{"fold": k, "choice": choices[k], "inner": tables.get(k, {}),
                   "train": [r.name for r in tr], "test": [r.name for r in te]} for k, (tr, te) in enumerate(splits)]
    return NestedCV(records=[r for p in parts for r in p], folds=folds_info, inner=inner_rows,
                    candidates=list(candidates), horizon_s=horizon_s)


@dataclass(frozen=True)
class NestedCV:
    """:func:`nested_cross_validate`'s result.

    Attributes
    ----------
    records : list of dict
        Per kept-out record: ``name``, ``fold``, ``choice`` (the candidate its fold chose), ``scaled``
        and ``identified`` (:func:`replay_scores` of the initial and the identified model), ``ship``
        (the model identified without it), ``values`` (its fitted values by name: the fold's fit).
    folds : list of dict
        Per outer fold: ``fold``, ``choice``, ``inner`` (:func:`choose`'s table), ``train``, ``test`` (names).
    inner : list of dict
        Every inner kept-out replay (``outer``, ``inner``, ``candidate``, ``name``, ``heading_rms_deg``,
        ``divergence``).
    candidates : list of str
    horizon_s : float
    """

    records: list
    folds: list
    inner: list
    candidates: list
    horizon_s: float = HORIZON_S

    def summary(self) -> dict:
        """``mean_scaled``, ``mean_identified`` heading RMS [deg] over the records both replays kept finite,
        their ``ratio``, ``better`` (identified finite and lower, or the scaled one diverged and it did not)
        of ``n``; ``diverged``: ``[(record, "scaled" | "identified", divergence)]``."""
        both, better, div = [], 0, []
        for r in self.records:
            a, b = r["scaled"], r["identified"]
            for who, s in (("scaled", a), ("identified", b)):
                if s["divergence"] is not None:
                    div.append((r["name"], who, s["divergence"]))
            fa, fb = a["divergence"] is None, b["divergence"] is None
            if fa and fb:
                both.append((a["heading_rms_deg"], b["heading_rms_deg"]))
            better += int(fb and (not fa or b["heading_rms_deg"] < a["heading_rms_deg"]))
        x = float(np.mean([p[0] for p in both])) if both else float("nan")
        y = float(np.mean([p[1] for p in both])) if both else float("nan")
        return {"mean_scaled": x, "mean_identified": y, "ratio": x / y if both else float("nan"),
                "better": better, "n": len(self.records), "n_both_finite": len(both), "diverged": div,
                **band_summary(self.records)}

    def to_pandas(self):
        """One row per kept-out record: ``fold``, ``choice``, ``scaled_<score>`` and ``identified_<score>``
        (:data:`SCORE_NAMES` and their first-minute ``_60s`` versions), ``<model>_diverged_at_s``."""
        import pandas as pd

        rows = []
        for r in self.records:
            row = {"name": r["name"], "fold": r["fold"], "choice": r["choice"]}
            for who in ("scaled", "identified"):
                s = r[who]
                row.update({f"{who}_{k}": v for k, v in s.items() if k != "divergence"})
                row[f"{who}_diverged_at_s"] = None if s["divergence"] is None else s["divergence"]["t_s"]
            rows.append(row)
        return pd.DataFrame(rows).set_index("name")

    def to_json(self) -> dict:
        """Everything but the identified ships, JSON-ready (NaN as None: :func:`json_ready`)."""
        return json_ready({"candidates": self.candidates, "horizon_s": self.horizon_s, "folds": self.folds,
                           "records": self.records, "inner": self.inner, "summary": self.summary()}, drop=("ship",))
