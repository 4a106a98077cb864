"""The ship's parameters sampled from their covariance, the standard manoeuvres run per sample.

The covariance is the ship config's ``covariance:`` section (:class:`mmg.ship.ParameterCovariance`:
``mmg identify`` writes it into ``DIR/ship.yaml``) or one given.  Samples are drawn from the
multivariate normal with that covariance (correlations kept) about the values it gives, written
into the ship by name (:func:`trials.measured.identify.ship_with_values`), and every manoeuvre of
the plan is run per sample.  The wind-load scale is left out (the standard's manoeuvres are in calm
water: it changes nothing) and the others keep their joint distribution (the marginal of a normal).

Where the samples run is an *executor*: a function ``executor(func, tasks) -> list`` returning
``[func(t) for t in tasks]`` in order (``func`` and the tasks are picklable).  The default,
:func:`local_executor`, is :func:`trials.files.sweep.run_sweep` on this machine's cores (joblib's
process pool); a distributed one (Dask, a cluster) plugs in the same way.

Summaries (:func:`summarise`): the median, the 90 % interval (5th to 95th percentile) and the
probability of meeting the limit (the share of samples at or below it); a sample whose manoeuvre
does not give the criterion (a turn that never reaches 180 deg, a zigzag whose heading never turns
back) counts as not meeting it and as +inf in the percentiles.  Verdict: ``"pass"`` when the
probability is at least 0.95, ``"fail"`` when at most 0.05, ``"undecided"`` between.
"""
from __future__ import annotations

import numpy as np

from mmg.ship import Ship

from ..measured.draws import WIND_FACTOR_NAMES, draw, parameter_covariance
from ..measured.draws import ship_values as _ship_values  # noqa: F401  (bench/imo_coverage.py, tests)
from .standard import Plan, criteria, criterion_values, run_manoeuvres

__all__ = ["covariance_of", "draw", "sample_tasks", "run_samples", "local_executor", "summarise", "convergence",
           "PASS_PROBABILITY", "FAIL_PROBABILITY", "INTERVAL", "NOT_SAMPLED"]

PASS_PROBABILITY = 0.95
"""Verdict ``"pass"``: the probability of meeting the limit is at least this."""
FAIL_PROBABILITY = 0.05
"""Verdict ``"fail"``: the probability of meeting the limit is at most this."""
INTERVAL = (5.0, 95.0)
"""The percentiles bounding the reported 90 % interval."""
NOT_SAMPLED = WIND_FACTOR_NAMES
"""Parameters of a covariance left out of the sampling: the wind-load scale and shape factors do nothing
in calm water."""


def covariance_of(ship: Ship, cov=None) -> tuple[list[str], np.ndarray, np.ndarray, list[str]]:
    """The parameters to sample: (names, mean, covariance, notes); :func:`trials.measured.draws.parameter_covariance`
    (``cov``: default the ship config's ``covariance:`` section; a mapping with ``names``, ``matrix`` and
    optionally ``values``; a DataFrame) with :data:`NOT_SAMPLED` left out, a note for each."""
    names, mean, matrix, out = parameter_covariance(ship, cov, leave_out=NOT_SAMPLED)
    return names, mean, matrix, [f"{x} not sampled: no wind in the standard's calm-water manoeuvres" for x in out]


def _one_sample(p: Plan, names, row) -> dict:
    """Criterion values of one parameter sample (all None, with the reason, when its run fails)."""
    from ..measured.identify import ship_with_values

    try:
        ship = ship_with_values(p.ship, dict(zip(names, (float(x) for x in row))))
        return {"values": criterion_values(p, run_manoeuvres(p, ship)), "error": None}
    except Exception as e:                  # noqa: BLE001 - one odd sample must not end a run of thousands: counted, named
        return {"values": {c.name: None for c in criteria(p.L_over_V)}, "error": f"{type(e).__name__}: {e}"}


def _chunk_task(task) -> list[dict]:
    """Worker: the criterion values of each sample of one chunk ``(plan, names, rows)``."""
    p, names, rows = task
    return [_one_sample(p, names, r) for r in rows]


def sample_tasks(p: Plan, names, samples: np.ndarray, chunks: int) -> list:
    """The samples cut into ``chunks`` picklable tasks ``(plan, names, rows)`` for :func:`_chunk_task`."""
    parts = np.array_split(np.asarray(samples), max(1, min(int(chunks), len(samples))))
    return [(p, list(names), part) for part in parts if len(part)]


def local_executor(jobs: int | None = None, progress: bool = False, backend: str = "loky", client=None):
    """The default executor: :func:`trials.files.sweep.run_sweep` on ``jobs`` local processes (default
    every usable core), one progress line per finished chunk when ``progress``; ``backend="dask"``
    sends the chunks to the workers of ``client`` (default: the current ``distributed.Client``),
    ``"serial"`` runs them here, the same numbers either way."""
    from ..files.sweep import run_sweep

    def run(func, tasks):
        return run_sweep(func, tasks, backend=backend, n_jobs=jobs, progress=progress, client=client,
                         labels=[f"{len(t[2])} samples" for t in tasks])

    return run


def run_samples(p: Plan, names, samples: np.ndarray, executor=None, chunks: int | None = None) -> list[dict]:
    """Run every manoeuvre of plan ``p`` for each parameter sample (rows of ``samples``, columns ``names``).

    Parameters
    ----------
    p : Plan
    names : list of str
    samples : (N, len(names)) array
    executor : callable, optional
        ``executor(func, tasks) -> list`` (module docstring); default :func:`local_executor`.
    chunks : int, optional
        Tasks to cut the samples into (default 8 per usable core, at most N).

    Returns
    -------
    list of dict
        Per sample, in order: ``values`` (criterion name -> value or None) and ``error`` (None, or why
        the sample's runs failed).
    """
    from ..files.sweep import default_jobs

    executor = executor or local_executor()
    tasks = sample_tasks(p, names, samples, chunks or 8 * default_jobs())
    return [r for part in executor(_chunk_task, tasks) for r in part]


def summarise(values, limit: float) -> dict:
    """Median, 90 % interval, probability of meeting ``limit`` and verdict of one criterion's samples.

    ``values``: one per sample, None or NaN where the sample did not give it (counted as not meeting
    the limit, +inf in the percentiles; a percentile at +inf is returned as None).
    """
    v = np.array([np.inf if (x is None or not np.isfinite(x)) else float(x) for x in values], dtype=float)
    if v.size == 0:
        return {"median": None, "interval": None, "probability": None, "verdict": "undecided", "missing": 0}
    prob = float(np.mean(v <= limit))
    q = np.percentile(v, [50.0, *INTERVAL], method="linear") if np.all(np.isfinite(v)) else \
        np.percentile(v, [50.0, *INTERVAL], method="inverted_cdf")

    def num(x):
        return float(x) if np.isfinite(x) else None

    verdict = "pass" if prob >= PASS_PROBABILITY else ("fail" if prob <= FAIL_PROBABILITY else "undecided")
    return {"median": num(q[0]), "interval": [num(q[1]), num(q[2])], "probability": prob, "verdict": verdict,
            "missing": int(np.sum(~np.isfinite(v)))}


def convergence(values, limit: float, fractions=(0.125, 0.25, 0.5, 1.0)) -> list[dict]:
    """:func:`summarise` of the first N/8, N/4, N/2 and N samples (each with ``n``): how the figures settle."""
    out = []
    for f in fractions:
        k = max(1, int(round(f * len(values))))
        out.append({"n": k, **summarise(list(values)[:k], limit)})
    return out
