"""The model-form term of a prediction band: the heading and position error a replay gains with elapsed time.

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
* :func:`position_error_curves` and the same binning give the distance between the predicted and the
  logged position, in ship lengths (``position_q90_L``);
* :func:`heading_half_width` and :func:`position_half_width` evaluate them at the elapsed times of another
  record (linear between the nodes, from zero at the start, held beyond the last node, or unbounded beyond
  it where the replays that made it diverged: :func:`unbounded_after`).

Which replays are measured sets what the term means.  The kept-out replays of a cross-validation
(``mmg identify --cv K``) are errors on records the fit did not see: what a new record will meet.  The
fit's own training replays are in sample: their errors are smaller, a lower bound, and the section's
``source`` says so.
"""
from __future__ import annotations

from statistics import NormalDist

import numpy as np

from mmg.model import G
from mmg.ship import ModelForm

__all__ = ["ELAPSED_EDGES", "MIN_RECORDS", "QUANTILE", "Z90", "R90", "heading_error_curves", "heading_error_growth",
           "position_error_curves", "heading_half_width", "position_half_width", "model_form_section",
           "model_form_of", "measured_until", "unbounded_from", "unbounded_after"]

ELAPSED_EDGES = (0.0, 10.0, 20.0, 40.0, 80.0, 160.0, 320.0, 640.0, 1280.0, 2560.0, 5120.0)
"""Bin edges of elapsed time in sqrt(L/g) (a 3 m model: 0.55 s; a 320 m ship: 5.7 s)."""
MIN_RECORDS = 3
"""A bin counts only where at least this many records reach it (fewer: the previous node is held)."""
QUANTILE = 0.9
"""The quantile of the absolute heading error given at each node (the band's half-width)."""
Z90 = NormalDist().inv_cdf(0.5 + QUANTILE / 2)
"""The normal quantile of :data:`QUANTILE`'s central interval (1.645): a normal error of standard deviation s
has a :data:`QUANTILE` half-width Z90 s."""
R90 = float(np.sqrt(-2.0 * np.log(1.0 - QUANTILE)))
"""The :data:`QUANTILE` quantile of the distance from the centre of a circular two-dimensional normal of
standard deviation 1 per axis (2.146; the Rayleigh distribution's)."""


def _elapsed_curves(replays, error) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per replay, (elapsed time from its first sample [s], ``error(replay)``)."""
    return [(np.asarray(rep.run.t, float) - float(rep.run.t[0]), error(rep)) for rep in replays]


def heading_error_curves(replays) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per replay (:class:`trials.measured.predict.Replayed`: ``run.t``, ``run.meas``, ``pred``), (elapsed
    time from its first sample [s], predicted minus logged heading [deg]); both headings unwrapped, put on
    the same turn at the start, NaN where the replay diverged."""
    def error(rep):
        with np.errstate(invalid="ignore"):
            e = np.degrees(np.unwrap(rep.pred[:, 5]) - np.unwrap(rep.run.meas[:, 5]))
        return e - 360.0 * np.round((e[0] if np.isfinite(e[0]) else 0.0) / 360.0)

    return _elapsed_curves(replays, error)


def position_error_curves(replays, L: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per replay (as :func:`heading_error_curves`), (elapsed time from its first sample [s], distance
    between the predicted and the logged position [ship lengths ``L`` in m]); NaN where it diverged."""
    return _elapsed_curves(replays, lambda rep: np.hypot(rep.pred[:, 3] - rep.run.meas[:, 3],
                                                         rep.pred[:, 4] - rep.run.meas[:, 4]) / L)


def heading_error_growth(curves, L: float, g: float = G) -> tuple[np.ndarray, np.ndarray, int]:
    """The :data:`QUANTILE` quantile of the absolute error per bin of elapsed Froude time: of the heading
    [deg] for :func:`heading_error_curves`, of the position [ship lengths] for :func:`position_error_curves`.

    The samples of a bin are pooled over the records (a longer record counts more, as in the share of
    samples the bands are judged by); a bin counts where :data:`MIN_RECORDS` records reach it.

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
        Each kept bin's node: its end, or the last elapsed time any record reaches where that is earlier
        [sqrt(L/g)], to 6 significant figures; a bin whose node would not lie after the previous one is left out.
    q90 : ndarray
        The quantile of the absolute error in the bin [deg] (a diverged sample counts as an infinite
        error), made non-decreasing with time.
    records : int
        Records measured.
    """
    unit = np.sqrt(L / g)
    ts = [np.asarray(t, float) / unit for t, _ in curves]
    es = [np.where(np.isfinite(e), np.abs(e), np.inf) for _, e in curves]
    reach = max((float(t[-1]) for t in ts if len(t)), default=0.0)
    nodes, q = [], []
    for lo, hi in zip(ELAPSED_EDGES[:-1], ELAPSED_EDGES[1:]):
        sel = [(t >= lo) & (t < hi) for t in ts]
        if sum(bool(s.any()) for s in sel) < MIN_RECORDS:
            continue
        node = float(f"{min(hi, reach):.6g}")
        if node <= (nodes[-1] if nodes else 0.0):
            continue
        nodes.append(node)
        q.append(float(np.quantile(np.concatenate([e[s] for e, s in zip(es, sel)]), QUANTILE, method="higher")))
    q = np.maximum.accumulate(np.array(q)) if q else np.zeros(0)
    return np.array(nodes), q, len(curves)


def model_form_section(curves, L: float, source: str, position_curves=None) -> tuple[dict | None, str]:
    """(the ``model_form:`` section of the ship YAML, :class:`mmg.ship.ModelForm`, or None; what limits it)
    from the heading error ``curves`` and, where given, the ``position_curves`` of the same replays
    (:func:`heading_error_growth`), with ``source`` saying which replays they are.

    Where replays diverged, the section ends before the first bin whose quantile they make infinite, and is
    unbounded from its last node on (``unbounded_from_froude``; its ``source`` says why); None where no bin
    is left, the second item saying why."""
    nodes, q, n = heading_error_growth(curves, L)
    if not len(nodes):
        return None, f"fewer than {MIN_RECORDS} records reach any elapsed time"
    qp = None
    if position_curves is not None:
        pnodes, qp, _ = heading_error_growth(position_curves, L)
        if not np.array_equal(pnodes, nodes):
            raise ValueError("model_form_section: the position curves do not reach the heading curves' elapsed "
                             "times (they must be of the same replays)")
    bad = ~np.isfinite(q) | (~np.isfinite(qp) if qp is not None else False)
    why = ""
    if bad.any():
        which = " and ".join(name for name, x in (("heading", q), ("position", qp))
                             if x is not None and not np.isfinite(x).all())
        why = (f"replays diverged: the {which} error is unbounded in the bin ending at {nodes[bad][0]:.6g} "
               "sqrt(L/g), so the term is unbounded from the last finite node on (unbounded_from_froude)")
    keep = np.cumsum(bad) == 0
    if not keep.any():
        return None, why
    six = lambda a: [float(f"{x:.6g}") for x in a]          # noqa: E731
    out = {"elapsed_froude": six(nodes[keep]), "heading_q90_deg": six(q[keep])}
    if qp is not None:
        out["position_q90_L"] = six(qp[keep])
    if bad.any():
        out["unbounded_from_froude"] = out["elapsed_froude"][-1]
    return out | {"records": int(n), "source": source + (f"; {why}" if why else "")}, why


def model_form_of(section: dict | None) -> ModelForm | None:
    """A ``model_form:`` section (:func:`model_form_section`) as the :class:`mmg.ship.ModelForm` a ship carries."""
    if section is None:
        return None
    pos = section.get("position_q90_L")
    return ModelForm(tuple(section["elapsed_froude"]), tuple(section["heading_q90_deg"]), int(section["records"]),
                     section["source"], None if pos is None else tuple(pos), section.get("unbounded_from_froude"))


def _along(model_form: ModelForm, values, elapsed_s, L: float, g: float) -> np.ndarray:
    """``values`` (one per node) at elapsed times ``elapsed_s`` [s] of a ship of length ``L`` [m]: linear in
    elapsed Froude time between zero at the start and the nodes, held beyond the last."""
    t = np.asarray(elapsed_s, float) / np.sqrt(L / g)
    return np.interp(t, np.r_[0.0, model_form.elapsed_froude], np.r_[0.0, values])


def heading_half_width(model_form: ModelForm, elapsed_s, L: float, g: float = G) -> np.ndarray:
    """The model-form term's 90 % half-width [deg] at elapsed times ``elapsed_s`` [s] of a ship of length
    ``L`` [m]: linear in elapsed Froude time between zero at the start and the nodes, held beyond the last."""
    return _along(model_form, model_form.heading_q90_deg, elapsed_s, L, g)


def position_half_width(model_form: ModelForm, elapsed_s, L: float, g: float = G) -> np.ndarray | None:
    """The model-form term's 90 % position radius [m] at elapsed times ``elapsed_s`` [s] of a ship of length
    ``L`` [m] (as :func:`heading_half_width`); None where the section has no ``position_q90_L``."""
    if model_form.position_q90_L is None:
        return None
    return L * _along(model_form, model_form.position_q90_L, elapsed_s, L, g)


def unbounded_from(model_form: ModelForm, L: float, g: float = G) -> float:
    """The elapsed time [s] of a ship of length ``L`` [m] from which the term is unbounded
    (``unbounded_from_froude``); infinite where it has none."""
    u = model_form.unbounded_from_froude
    return float("inf") if u is None else float(u * np.sqrt(L / g))


def unbounded_after(model_form: ModelForm, elapsed_s, L: float, g: float = G) -> np.ndarray:
    """Where (bool per elapsed time [s] of a ship of length ``L`` [m]) the term is unbounded: beyond
    :func:`unbounded_from`."""
    return np.asarray(elapsed_s, float) > unbounded_from(model_form, L, g)


def measured_until(model_form: ModelForm, L: float, g: float = G) -> float:
    """The elapsed time [s] of a ship of length ``L`` [m] up to which the term was measured (its last node)."""
    return float(model_form.elapsed_froude[-1] * np.sqrt(L / g))
