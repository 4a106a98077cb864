"""Ships drawn from the covariance of their identified parameters (``mmg imo --samples``, ``mmg predict --samples``).

The covariance is the ship config's ``covariance:`` section (:class:`mmg.ship.ParameterCovariance`:
``mmg identify`` writes it into ``DIR/ship.yaml``) or one given.  :func:`parameter_covariance` reads
and checks it (names, mean, matrix), :func:`draw` samples the multivariate normal with that
covariance (correlations kept) about those values, and
:func:`trials.measured.identify.ship_with_values` writes a sample into the ship by name.

:func:`support_of` gives the ships a draw may be (:class:`Support`): the values the fit itself can return
(its hard bounds, :func:`ekf.identify.free_parameters`) and, where the covariance states the range of
the states its training records log (``state_range``), a hull that does not gain energy unpowered over
that range (:func:`mmg.dissipation.power_check` on the grid :func:`mmg.dissipation.state_box` spans: the
check ``mmg identify`` makes of the fitted ship, :func:`trials.measured.physical.physical_check`).  The
covariance is the linearisation of the fit about its estimate; truncated to this support it is that
normal conditioned on the ship being one the estimator and the physics admit.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from mmg.errors import InputError
from mmg.parameters import WIND_COLUMNS
from mmg.ship import ParameterCovariance, Ship

__all__ = ["parameter_covariance", "ship_values", "draw", "WIND_FACTOR_NAMES", "Support", "support_of",
           "support_bounds", "SUPPORTS"]

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


def support_bounds(ship: Ship, names) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) of each parameter ``names``: the hard bounds a fit of ``ship`` holds it to
    (:func:`ekf.identify.free_parameters`: the straight-ahead resistance negative, w_P0, epsilon, kappa,
    the gamma_R, l_R', Y_P_astern and the effects' parameters within theirs, an added mass within
    0 to 3 times the ship's value, a wind factor's divided by the
    config value it multiplies as the fit's are); -inf/inf where a parameter has none."""
    from ekf.identify import free_parameters
    from mmg.model import pack

    from .identify.fit import _bounded_wind

    free = _bounded_wind(ship, free_parameters(pack(ship), ship.hull.names, list(names), hull_terms=ship.hull.terms))
    return np.array([f.lower for f in free], float), np.array([f.upper for f in free], float)


def _state_range(cov) -> tuple:
    """((u_min, u_max), (v_min, v_max), (r_min, r_max)) of a covariance, () where it gives none."""
    if isinstance(cov, ParameterCovariance):
        return tuple(cov.state_range)
    if isinstance(cov, Mapping) and cov.get("state_range"):
        d = cov["state_range"]
        try:
            out = tuple((float(d[k][0]), float(d[k][1])) for k in ("u_mps", "v_mps", "r_radps"))
        except (KeyError, IndexError, TypeError, ValueError):
            raise InputError("covariance", "state_range", "expected u_mps, v_mps, r_radps each [min, max]") from None
        if not all(np.isfinite(a) and np.isfinite(b) and a <= b for a, b in out):
            raise InputError("covariance", "state_range", "expected finite [min, max] ranges")
        return out
    return ()


@dataclass(frozen=True)
class Support:
    """The ships a draw may be (module docstring).

    Attributes
    ----------
    names : tuple of str
        The drawn parameters.
    lower, upper : ndarray
        Each one's hard bounds (:func:`support_bounds`).
    states : tuple of ndarray or None
        (u [m/s], v [m/s], r [rad/s]) of the grid a drawn ship must not gain energy on; None: no energy check.
    note : str
        What the support is (for a band's notes where draws were rejected).
    caveat : str
        Why the energy check is left out though the covariance gives a range to check over; empty otherwise.
    """

    names: tuple
    lower: np.ndarray
    upper: np.ndarray
    states: tuple | None
    note: str
    caveat: str = ""

    def contains(self, ship: Ship, row) -> bool:
        """Whether the draw ``row`` (values of :attr:`names`) of ``ship`` lies in the support: every value
        within its bounds and, with :attr:`states`, the ship with those values gaining no energy there."""
        row = np.asarray(row, float)
        if np.any(row < self.lower) or np.any(row > self.upper):
            return False
        if self.states is None:
            return True
        from mmg.dissipation import gains_no_energy

        from .identify import ship_with_values

        s = ship_with_values(ship, {n: float(v) for n, v in zip(self.names, row) if n not in WIND_FACTOR_NAMES})
        return gains_no_energy(s, *self.states)


def _dissipative_states(ship: Ship, states) -> tuple:
    """The states of ``states`` (u, v, r arrays) where ``ship`` gains no energy unpowered (within
    :data:`mmg.dissipation.POWER_TOLERANCE` of :func:`mmg.dissipation.power_scale`)."""
    from mmg.dissipation import POWER_TOLERANCE, relative_power

    rel, _ = relative_power(ship, *states)
    with np.errstate(invalid="ignore"):
        keep = rel <= POWER_TOLERANCE
    return tuple(np.asarray(a)[keep] for a in states)


SUPPORTS = ("none", "bounds", "physical")
"""The supports a band's ship draws may be truncated to: none (the covariance's normal as it is), the
fit's hard bounds, or those and the energy check (:func:`support_of`)."""


def support_of(ship: Ship, names, cov, energy: bool = True) -> Support:
    """The :class:`Support` of draws of ``names`` about ``ship`` from the covariance ``cov``: the fit's
    bounds, and (with ``energy``) the energy check over the grid spanning the covariance's ``state_range`` (where it has
    one), at the grid's states where ``ship`` itself gains none: the support holds the estimate it is about,
    and a state where the estimate (and, as a rule, its prior: the hull polynomial at large r' = r L / U)
    gains energy is one the hull form does not describe (said in :attr:`Support.caveat`)."""
    from mmg.dissipation import state_box

    lower, upper = support_bounds(ship, names)
    rng = _state_range(cov)
    bounds = "within the fit's hard bounds"
    if not energy:
        return Support(tuple(names), lower, upper, None, bounds)
    if not rng:
        return Support(tuple(names), lower, upper, None, f"{bounds} (the covariance has no state_range: no energy check)",
                       "support 'physical' without the energy check: the covariance states no state_range, so the "
                       "draws are truncated to the fit's hard bounds alone")
    grid = state_box(*(np.array(r) for r in rng))
    states = _dissipative_states(ship, grid)
    n, m = len(states[0]), len(grid[0])
    caveat = (f"drawn ships checked for energy at {n} of the {m} states spanning the covariance's state_range: "
              "the identified ship itself gains energy unpowered at the others") if n < m else ""
    if not n:
        return Support(tuple(names), lower, upper, None, bounds, caveat)
    return Support(tuple(names), lower, upper, states,
                   f"{bounds} and gaining no energy unpowered over the covariance's state_range", caveat)
