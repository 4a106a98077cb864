"""How far apart are the fits of a cross-validation's folds?  A check of the stated uncertainty.

``mmg identify`` writes a covariance for its fit (:func:`trials.measured.identify.identification_covariance`):
the noise of one model fitted to all the records, the residuals' correlation counted.  A K-fold
cross-validation fits the same model K times, each time leaving one group of records out.  Were the
parameters set by what the records share, those K fits would differ by about what the covariance says;
where the records differ from one another in ways the model does not carry (a pond's wind-driven drift,
a rudder zero that moves, a model form that is not the ship's), the fits move further, and the written
covariance (and every interval drawn from it, ``mmg imo --samples``) is too sure by that much.

The yardstick is the delete-a-group jackknife: from the K leave-one-group-out estimates theta_i, the
standard error of the estimate on all the records is sqrt((K - 1) / K * sum_i (theta_i - mean theta)^2).
With groups of equal size and an estimate that is a mean, it is exactly the standard error of the mean
of the group means (``tests/test_bench_measured_limits.py``).  Four folds give a rough figure (3 degrees
of freedom): a ratio of 2 says little, a ratio of 10 on every parameter says the covariance misses most of
the variation (docs/benchmark_frt.md, "Why held out falls short of in sample").
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["jackknife_se", "fold_values", "FoldSpread", "fold_spread"]


def jackknife_se(theta) -> float:
    """Delete-a-group jackknife standard error from the K leave-one-group-out estimates ``theta``."""
    theta = np.asarray(theta, float)
    k = len(theta)
    return float(np.sqrt((k - 1) / k * np.sum((theta - theta.mean()) ** 2)))


def fold_values(records: list[dict]) -> tuple[list[str], list[dict]]:
    """Each fold's choice and fitted shared values, in fold order.

    Parameters
    ----------
    records : list of dict
        Kept-out records carrying ``fold``, ``values`` and optionally ``choice``
        (:func:`trials.measured.identify.cross_validate`'s, a nested cross-validation's ``records``).

    Returns
    -------
    choices : list of str
        Each fold's candidate (``""`` where the records name none).
    values : list of dict
        Each fold's fitted values by name; a record's own values (names with ``[``: start offsets,
        per-record nuisances) are left out.
    """
    by_fold = {}
    for r in records:
        shared = {k: float(v) for k, v in r["values"].items() if "[" not in k}
        by_fold.setdefault(r["fold"], (r.get("choice", ""), shared))
    folds = sorted(by_fold)
    return [by_fold[f][0] for f in folds], [by_fold[f][1] for f in folds]


@dataclass(frozen=True)
class FoldSpread:
    """Per parameter: the folds' fitted values, their jackknife standard error and the stated one.

    Attributes
    ----------
    names : tuple of str
        The parameters every fold fitted.
    values : ndarray
        (n_folds, n_parameters) fitted values.
    jackknife : ndarray
        Jackknife standard error of each (NaN when the folds chose different candidates).
    stated : ndarray
        The stated standard error of each (the written covariance's; NaN where it has none).
    choices : tuple of str
        Each fold's candidate (``""`` where the records name none).
    """

    names: tuple
    values: np.ndarray
    jackknife: np.ndarray
    stated: np.ndarray
    choices: tuple = ()

    @property
    def same_choice(self) -> bool:
        """Whether every fold fitted the same candidate (the jackknife needs it)."""
        return len(set(self.choices)) <= 1

    @property
    def ratio(self) -> np.ndarray:
        """Jackknife over stated standard error (NaN where the stated one is not positive)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.stated > 0, self.jackknife / self.stated, np.nan)

    @property
    def sign_differs(self) -> np.ndarray:
        """Whether the folds' values of a parameter have both signs."""
        return np.any(self.values > 0, axis=0) & np.any(self.values < 0, axis=0)

    def median_ratio(self) -> float:
        """The median ratio over the parameters that have one (NaN when none)."""
        r = self.ratio[np.isfinite(self.ratio)]
        return float(np.median(r)) if r.size else float("nan")

    def to_pandas(self):
        """One row per parameter: each fold's value, ``jackknife_se``, ``stated_se``, ``ratio``, ``sign_differs``."""
        import pandas as pd

        df = pd.DataFrame(self.values.T, index=list(self.names), columns=[f"fold {k}" for k in range(len(self.values))])
        return df.assign(jackknife_se=self.jackknife, stated_se=self.stated, ratio=self.ratio,
                         sign_differs=self.sign_differs)

    def to_json(self) -> dict:
        """The figures as plain lists (NaN as None)."""
        def clean(a):
            return [None if not np.isfinite(x) else float(x) for x in np.ravel(a)]

        return {"names": list(self.names), "values": [clean(v) for v in self.values], "jackknife_se": clean(self.jackknife),
                "stated_se": clean(self.stated), "choices": list(self.choices)}


def fold_spread(records: list[dict], stated: dict | None = None) -> FoldSpread:
    """How far apart the folds' fits are, against stated standard errors.

    Parameters
    ----------
    records : list of dict
        A cross-validation's kept-out records (:func:`fold_values`).
    stated : dict, optional
        {name: standard error}, e.g. the written covariance's; NaN ratios without it.

    Returns
    -------
    FoldSpread
        Over the parameters every fold fitted.

    Raises
    ------
    ValueError
        Below two folds.
    """
    choices, values = fold_values(records)
    if len(values) < 2:
        raise ValueError(f"a fold spread needs 2 or more folds, got {len(values)}")
    names = tuple(n for n in values[0] if all(n in v for v in values))
    th = np.array([[v[n] for n in names] for v in values])
    same = len(set(choices)) == 1
    jk = np.array([jackknife_se(th[:, j]) if same else np.nan for j in range(len(names))])
    st = np.array([(stated or {}).get(n, np.nan) for n in names], float)
    return FoldSpread(names, th, jk, st, tuple(choices))
