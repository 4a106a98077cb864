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
from mmg.ship import ParameterCovariance, Ship

__all__ = ["parameter_covariance", "ship_values", "draw", "WIND_FACTOR_NAMES"]

WIND_FACTOR_NAMES = ("wind_scale", "wind_sway_factor", "wind_yaw_factor")
"""Parameters of a covariance that are factors on the records' wind loads (1: the ship as it is)."""


def ship_values(ship: Ship, names) -> np.ndarray:
    """The ship's own values of the parameters ``names`` (in the fit's units), for a covariance without values."""
    from mmg.nondim import inertia_scale, mass_scale

    pa, out = ship.particulars, []
    for n in names:
        if n in ship.hull.names:
            out.append(ship.hull.value(n))
        elif n == "w_P0":
            out.append(ship.propeller.w_P0[0])
        elif n == "Y_P_astern":
            out.append(ship.propeller.Y_P_astern)
        elif n in ("m_x", "m_y"):
            out.append(getattr(ship.mass, f"{n}_prime") * mass_scale(pa.rho, pa.L, pa.T))
        elif n == "J_z":
            out.append(ship.mass.J_z_prime * inertia_scale(pa.rho, pa.L, pa.T))
        elif n == "rudder_offset":
            off = ship.effect_set().get("rudder_offset")
            out.append(np.radians(off["offset_deg"]) if off else 0.0)
        elif n in WIND_FACTOR_NAMES:     # factors on the records' wind loads: 1 is the ship as it is
            out.append(1.0)
        elif hasattr(ship.rudder, n):
            out.append(getattr(ship.rudder, n))
        else:
            raise InputError("covariance", n, f"not a parameter of {ship.name} (a hull coefficient or one of "
                                              f"w_P0, epsilon, kappa, gamma_R_pos, gamma_R_neg, l_R_prime, "
                                              f"rudder_offset, Y_P_astern, m_x, m_y, J_z)")
    return np.asarray(out, dtype=float)


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
            raise InputError("samples", ship.name, "the ship config has no covariance: section (mmg identify "
                                                   "writes one into DIR/ship.yaml) and none was given")
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
