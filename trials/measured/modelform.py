"""The model-form term of a prediction band: the heading error a replay gains with elapsed time.

A band drawn from the identified parameters' covariance and the run spread alone carries the doubt of
the fit, not the error of the model's form: on real records a replay strays from the record further than
its parameters' doubt explains (``docs/prediction_bands.md``).  This module measures how far, as a
function of the time elapsed since the replay's start:

* :func:`heading_error_curves` takes replays of records (:class:`trials.measured.predict.Replayed`) and
  gives each one's elapsed time [s] and heading error (predicted minus logged, unwrapped) [deg];
* :func:`heading_error_growth` pools them into bins of elapsed Froude time t / sqrt(L/g) (edges
  :data:`ELAPSED_EDGES`) and gives, per bin that at least :data:`MIN_RECORDS` records reach, the
  :data:`QUANTILE` quantile of the absolute error, made non-decreasing with time: the ``model_form:``
  section of the ship YAML (:class:`mmg.ship.ModelForm`);
* :func:`heading_half_width` evaluates it at the elapsed times of another record (linear between the
  nodes, from zero at the start, held beyond the last node).

Which replays are measured sets what the term means.  The kept-out replays of a cross-validation
(``mmg identify --cv K``) are errors on records the fit did not see: what a new record will meet.  The
fit's own training replays are in sample: their errors are smaller, a lower bound, and the section's
``source`` says so.
"""
from __future__ import annotations

import numpy as np

from mmg.model import G
from mmg.ship import ModelForm

__all__ = ["ELAPSED_EDGES", "MIN_RECORDS", "QUANTILE", "heading_error_curves", "heading_error_growth",
           "heading_half_width", "model_form_section"]

ELAPSED_EDGES = (0.0, 10.0, 20.0, 40.0, 80.0, 160.0, 320.0, 640.0, 1280.0, 2560.0, 5120.0)
"""Bin edges of elapsed time in sqrt(L/g) (a 3 m model: 0.55 s; a 320 m ship: 5.7 s)."""
MIN_RECORDS = 3
"""A bin counts only where at least this many records reach it (fewer: the previous node is held)."""
QUANTILE = 0.9
"""The quantile of the absolute heading error given at each node (the band's half-width)."""


def heading_error_curves(replays) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per replay, (elapsed time from its first sample [s], predicted minus logged heading [deg]); both
    headings unwrapped, NaN where the replay diverged.

    Parameters
    ----------
    replays : iterable of Replayed
        :class:`trials.measured.predict.Replayed` (``run.t``, ``run.meas``, ``pred``).

    Returns
    -------
    list of (ndarray, ndarray)
    """
    out = []
    for rep in replays:
        t = np.asarray(rep.run.t, float)
        with np.errstate(invalid="ignore"):
            e = np.degrees(np.unwrap(rep.pred[:, 5]) - np.unwrap(rep.run.meas[:, 5]))
        e = e - 360.0 * np.round((e[0] if np.isfinite(e[0]) else 0.0) / 360.0)     # the same turn at the start
        out.append((t - t[0], e))
    return out


def heading_error_growth(curves, L: float, g: float = G) -> tuple[np.ndarray, np.ndarray, int]:
    """The :data:`QUANTILE` quantile of the absolute heading error per bin of elapsed Froude time.

    Parameters
    ----------
    curves : list of (ndarray, ndarray)
        :func:`heading_error_curves`: elapsed time [s] and heading error [deg] per record.
    L : float
        Ship length [m] (the Froude time unit is sqrt(L / g)).
    g : float
        Gravity [m/s^2].

    Returns
    -------
    elapsed : ndarray
        Each kept bin's end (the last elapsed time reached, for the last bin) [sqrt(L/g)].
    q90 : ndarray
        The quantile of the absolute error in the bin [deg] (a diverged sample counts as an infinite
        error), made non-decreasing with time.
    records : int
        Records measured.
    """
    unit = np.sqrt(L / g)
    ts = [np.asarray(t, float) / unit for t, _ in curves]
    es = [np.where(np.isfinite(e), np.abs(e), np.inf) for _, e in curves]
    reach = max((t[-1] for t in ts if len(t)), default=0.0)
    nodes, q = [], []
    for lo, hi in zip(ELAPSED_EDGES[:-1], ELAPSED_EDGES[1:]):
        sel = [(t >= lo) & (t < hi) for t in ts]
        if sum(bool(s.any()) for s in sel) < MIN_RECORDS:
            continue
        v = np.concatenate([e[s] for e, s in zip(es, sel)])
        nodes.append(min(hi, reach))
        q.append(float(np.quantile(v, QUANTILE, method="higher")))
    q = np.maximum.accumulate(np.array(q)) if q else np.zeros(0)
    return np.array(nodes), q, len(curves)


def model_form_section(curves, L: float, source: str) -> dict | None:
    """The ``model_form:`` section of the ship YAML (:class:`mmg.ship.ModelForm`) from the error ``curves``
    (:func:`heading_error_growth`), with ``source`` saying which replays they are; None where no bin is
    reached by :data:`MIN_RECORDS` records or an error is not finite (a replay that diverged early)."""
    nodes, q, n = heading_error_growth(curves, L)
    if not len(nodes) or not np.all(np.isfinite(q)):
        return None
    six = lambda a: [float(f"{x:.6g}") for x in a]          # noqa: E731
    return {"elapsed_froude": six(nodes), "heading_q90_deg": six(q),
            "records": int(n), "source": source}


def heading_half_width(model_form: ModelForm, elapsed_s, L: float, g: float = G) -> np.ndarray:
    """The model-form term's 90 % half-width [deg] at elapsed times ``elapsed_s`` [s] of a ship of length
    ``L`` [m]: linear in elapsed Froude time between zero at the start and the nodes, held beyond the last."""
    t = np.asarray(elapsed_s, float) / np.sqrt(L / g)
    return np.interp(t, np.r_[0.0, model_form.elapsed_froude], np.r_[0.0, model_form.heading_q90_deg])
