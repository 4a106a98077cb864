"""Output-error fit: the second-order model driven by the recorded rudder, fitted to the heading.

Beyond the paper.  Only heading and rudder enter the misfit, so errors of the
differentiated omega', eps' cannot bias the parameters.  Starting points come
from the least-squares, four-point and classical methods.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
from scipy import optimize

from mmg.errors import InputError
from trials.analysis.nomoto.classical import classical_first_order
from trials.analysis.nomoto.fourpoint import four_point
from trials.analysis.nomoto.least_squares import FitResult, _delta_method, fit_least_squares
from trials.analysis.nomoto.models import NomotoModel, _params_from_x
from trials.analysis.nomoto.response import simulate_response
from trials.analysis.nomoto.zigzag import ZigzagData

__all__ = ["fit_output_error"]


def _starts(z: ZigzagData, fit_bias: bool) -> list:
    """Starting models: the least-squares fit, the four-point result and the classical first-order
    K, T with T2 = T3 = 0.1 |T| (those that could be had)."""
    starts = [fit_least_squares(z, fit_bias=fit_bias).model]
    try:
        starts.append(four_point(z.points(2)).model)
    except InputError:
        pass
    try:  # the robust first-order estimate, with a small T2 and T3 = T2
        cl = classical_first_order(z)
        starts.append(NomotoModel(cl.K, cl.T, 0.1 * abs(cl.T), 0.1 * abs(cl.T)))
    except InputError:
        pass
    return starts


def _best_of(resid, q0s, name: str):
    """The lowest-cost optimum of ``resid`` from the starting points q0s (several: the heading misfit is
    not convex in these parameters); InputError when every start fails."""
    sol = None
    for q0 in q0s:
        try:
            with np.errstate(all="ignore"):
                cand = optimize.least_squares(resid, q0, x_scale="jac", max_nfev=300)
        except (ValueError, np.linalg.LinAlgError):
            continue
        if np.isfinite(cand.cost) and (sol is None or cand.cost < sol.cost):
            sol = cand
    if sol is None:
        raise InputError(name, "heading", "output-error fit failed from every starting point")
    return sol


def fit_output_error(z: ZigzagData, start: Optional[NomotoModel] = None, fit_bias: bool = True) -> FitResult:
    """Output-error fit: the 2nd-order ODE driven by the recorded rudder, fitted to the heading.

    The model is simulated exactly
    (:func:`~trials.analysis.nomoto.response.simulate_response`) from the execute;
    K, T1, T2, T3, the state (psi, omega', eps') at the execute (and a neutral
    rudder angle) minimise the heading residual over the whole zigzag
    (``scipy.optimize.least_squares`` over K, T1 T2, T1 + T2, T3, unconstrained,
    so a course-unstable ship with T1 < 0 or complex T1, T2 can be fitted).
    Records longer than 4000 samples are decimated to 2000-3999.  Only heading
    and rudder enter, so errors in the derived yaw rate and acceleration do not
    bias the parameters (they only give the starting guess of the initial
    state).  95 % intervals from sigma^2 (J^T J)^-1 at the optimum (optimistic
    if residuals are correlated).

    Parameters
    ----------
    z : ZigzagData
        Dimensionless zigzag.
    start : NomotoModel, optional
        Starting point.  Default: each of the least-squares fit, the four-point
        result and the classical K, T with T2 = T3 = 0.1 |T| (those that are
        finite with |T1 T2| > 1e-6, else K, T1, T2, T3 = 2, 3, 0.3, 1), keeping
        the best optimum.
    fit_bias : bool
        Also fit a neutral rudder angle [rad].

    Returns
    -------
    FitResult
        Method "output_error", with the extra attribute ``initial_state``,
        the fitted (psi, omega', eps') at the execute.

    Raises
    ------
    InputError
        The optimiser failed from every starting point.
    """
    s = z.s
    # decimate long records for speed (the ODE is smooth; 2000 samples are plenty)
    step = max(1, len(s) // 2000)
    idx = np.arange(0, len(s), step)
    ss, dd, pp = s[idx], (z.delta + z.delta_e)[idx], (z.psi if z.psi_raw is None else z.psi_raw)[idx]
    starts = _starts(z, fit_bias) if start is None else [start]
    starts = [m for m in starts if np.isfinite([m.K, m.T1, m.T2, m.T3]).all() and abs(m.T1 * m.T2) > 1e-6] \
        or [NomotoModel(2.0, 3.0, 0.3, 1.0)]
    nb = 1 if fit_bias else 0

    # parameters q = (K, x1 = T1 T2, x2 = T1 + T2, T3[, delta_bias], psi_0, omega'_0, eps'_0): no bounds,
    # so unstable ships (T1 < 0) and complex T1, T2 are reachable; the state at the execute is fitted too
    def resid(q):
        return simulate_response((q[0], q[1], q[2], q[3]), ss, dd, q[4 + nb], q[5 + nb], q[6 + nb],
                                 q[4] if fit_bias else 0.0) - pp

    sol = _best_of(resid, [np.array([st.K, st.T1 * st.T2, st.T1 + st.T2, st.T3] + ([0.0] if fit_bias else [])
                                    + [0.0, z.omega_e, z.eps_e]) for st in starts], z.name)
    q = sol.x
    J = _jac(resid, q)
    r = sol.fun
    n, p = len(r), len(q)
    s2 = r @ r / max(n - p, 1)
    cov = s2 * np.linalg.pinv(J.T @ J)

    def to_params(th):
        K, T1, T2, T3, _ = _params_from_x(np.array([th[1], th[2], -th[0], -th[0] * th[3]]))
        return np.array([K, T1, T2, T3] + ([th[4]] if fit_bias else []), float)

    par = to_params(q)
    names = ["K", "T1", "T2", "T3"] + (["delta_bias"] if fit_bias else [])
    ci = _delta_method(q, cov, to_params, names)
    note = "" if sol.success else f"optimiser: {sol.message}"
    if not np.isfinite(par[1]):
        note = (note + "; " if note else "") + f"T1, T2 not real (T1 T2 = {q[1]:.4g}, T1 + T2 = {q[2]:.4g})"
    db = par[4] if fit_bias else 0.0
    ini = q[4 + nb:7 + nb]
    res = FitResult("output_error", float(par[0]), float(par[1]), float(par[2]), float(par[3]), ci, float(db),
                    float(np.sqrt(np.mean(r ** 2))), n, note)
    object.__setattr__(res, "initial_state", tuple(float(v) for v in ini))
    return res


def _jac(fun, q):
    """Central-difference Jacobian of a vector function."""
    from mmg.numdiff import central_jacobian

    return central_jacobian(fun, q, 1e-4)


