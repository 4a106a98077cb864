"""Ships drawn from the covariance of their identified parameters (``mmg imo --samples``, ``mmg predict --samples``).

The covariance is the ship config's ``covariance:`` section (:class:`mmg.ship.ParameterCovariance`:
``mmg identify`` writes it into ``DIR/ship.yaml``) or one given.  :func:`parameter_covariance` reads
and checks it (names, mean, matrix), :func:`draw` samples the multivariate normal with that
covariance (correlations kept) about those values, and
:func:`trials.measured.identify.ship_with_values` writes a sample into the ship by name.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from mmg.errors import InputError
from mmg.parameters import WIND_COLUMNS
from mmg.ship import ParameterCovariance, Ship

__all__ = ["parameter_covariance", "ship_values", "draw", "WIND_FACTOR_NAMES"]

WIND_FACTOR_NAMES = tuple(WIND_COLUMNS)
"""Parameters of a covariance that are factors on the records' wind loads (1: the ship as it is)."""


def ship_values(ship: Ship, names) -> np.ndarray:
    """The ship's own values of the parameters ``names`` (in the fit's units, :mod:`mmg.parameters`), for a
    covariance without values; a wind factor is 1 (the ship as it is)."""
    from mmg.parameters import CONSTANTS, ship_value

    out = []
    for n in names:
        try:
            out.append(ship_value(ship, n))
        except KeyError:
            raise InputError("covariance", n, f"not a parameter of {ship.name} (a hull coefficient or one of "
                                              f"{', '.join(CONSTANTS)})") from None
    return np.asarray(out, dtype=float)


NO_COVARIANCE = ("the ship config has no covariance: section to draw samples from: run `mmg identify` on the "
                 "ship's records (it writes one into DIR/ship.yaml) and give that DIR/ship.yaml, or drop --samples")
"""What to do about a ship without a covariance when samples are asked for."""


def parameter_covariance(ship: Ship, cov=None, leave_out=()) -> tuple[list[str], np.ndarray, np.ndarray, list[str]]:
    """The parameters to sample: (names, mean, covariance, the names left out), the covariance's names in
    ``leave_out`` left out (the others keep their joint distribution: the marginal of a normal).

    Parameters
    ----------
    ship : Ship
    cov : ParameterCovariance, mapping or pandas.DataFrame, optional
        Default the ship config's ``covariance:`` section.  A mapping has ``names`` and ``matrix``
        (and optionally ``values``); a DataFrame is indexed and labelled by the names.  Without
        values the mean is the ship's own.

    Raises
    ------
    mmg.errors.InputError
        No covariance, a matrix of the wrong shape, not symmetric or not positive semi-definite, a
        name that is no parameter of the ship.
    """
    if cov is None:
        cov = ship.covariance
        if cov is None:
            raise InputError("samples", ship.name, NO_COVARIANCE)
    if isinstance(cov, ParameterCovariance):
        names, values, matrix = list(cov.names), cov.values, cov.matrix
    elif isinstance(cov, Mapping):
        names, values, matrix = list(cov["names"]), cov.get("values"), cov["matrix"]
    else:                                                  # a DataFrame
        names, values, matrix = [str(x) for x in cov.index], None, cov.to_numpy()
    matrix = np.asarray(matrix, dtype=float)
    n = len(names)
    if matrix.shape != (n, n) or not np.all(np.isfinite(matrix)):
        raise InputError("covariance", "matrix", f"expected a finite {n} x {n} matrix, got shape {matrix.shape}")
    if not np.allclose(matrix, matrix.T, rtol=1e-9, atol=1e-12 * max(np.abs(matrix).max(), 1e-300)):
        raise InputError("covariance", "matrix", "not symmetric")
    if np.linalg.eigvalsh(matrix).min() < -1e-9 * max(np.abs(np.diag(matrix)).max(), 1e-300):
        raise InputError("covariance", "matrix", "not positive semi-definite: not a covariance")
    mean = ship_values(ship, names) if values is None else np.asarray(values, dtype=float)
    keep = [i for i, x in enumerate(names) if x not in leave_out]
    return [names[i] for i in keep], mean[keep], matrix[np.ix_(keep, keep)], [x for x in names if x in leave_out]


def draw(mean, matrix, n: int, seed: int | None = None) -> np.ndarray:
    """``n`` samples (rows) of the normal with ``mean`` and covariance ``matrix`` (correlations kept)."""
    rng = np.random.default_rng(seed)
    return rng.multivariate_normal(np.asarray(mean, float), np.asarray(matrix, float), size=int(n), method="eigh")
