"""The run-to-run covariance of a fit's parameters: how far the estimate moves from one independent group of
records to the next (:func:`run_jackknife_covariance`), beside the Gauss-Newton covariance of
:func:`ekf.identify.identify_segments`."""
from __future__ import annotations

import numpy as np

__all__ = ["run_jackknife_covariance"]


def run_jackknife_covariance(result, groups) -> np.ndarray:
    """Delete-one-group jackknife covariance of a fit's parameters over its independent records.

    For each group g of records (a run and its cut copies: one group), the fit without it is taken
    one Gauss-Newton step from the solution: ``delta_g = (H - H_g)^-1 s_g``, H the fit's information
    (data rows' J^T J plus the prior's diag(1 / sigma^2)), H_g and s_g the group's own J^T J and
    score J^T r (:attr:`ekf.identify.IdentifyResult.record_info`, :attr:`~ekf.identify.IdentifyResult.record_scores`).  The
    covariance is ``(G - 1) / G * sum_g (delta_g - mean)(delta_g - mean)^T``: how far the estimate
    moves from one group of records to the next, whatever the residuals' correlation within a record
    or a model form the records share.  The prior does not move with the records, so a parameter the
    records do not inform gets none of its variance here.

    Parameters
    ----------
    result : ekf.identify.IdentifyResult
        A fit made by :func:`ekf.identify.identify_segments` (its per-record scores and information).
    groups : sequence of int
        Each record's group label, in the fit's record order.

    Returns
    -------
    ndarray
        (n, n) over every free parameter (a record's own ones included).

    Raises
    ------
    ValueError
        Without per-record scores, a label per record, or with fewer than two groups.
    """
    if result.record_scores is None or result.record_info is None:
        raise ValueError("run jackknife: the fit carries no per-record scores (made by identify_segments?)")
    groups = np.asarray(groups)
    if len(groups) != len(result.record_scores):
        raise ValueError(f"run jackknife: {len(groups)} group labels for {len(result.record_scores)} records")
    labels = list(dict.fromkeys(groups.tolist()))
    if len(labels) < 2:
        raise ValueError(f"run jackknife: needs two or more independent groups of records, got {len(labels)}")
    sig = np.array([f.sigma for f in result.free], float)
    H = result.record_info.sum(axis=0) + np.diag(1.0 / sig ** 2)
    deltas = []
    for g in labels:
        m = groups == g
        deltas.append(np.linalg.solve(H - result.record_info[m].sum(axis=0), result.record_scores[m].sum(axis=0)))
    d = np.array(deltas)
    d -= d.mean(axis=0)
    G = len(labels)
    return (G - 1) / G * d.T @ d
