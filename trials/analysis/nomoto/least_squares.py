"""Least-squares (equation-error) fit of the second-order model to every sample of a zigzag.

Also home of :class:`FitResult`, the result of every whole-record fit (this one
and :func:`trials.analysis.nomoto.output_error.fit_output_error`), and of the helpers
both fits share: the map from x1..x4 of eq. (16) to K, T1, T2, T3 (eq. 23) and
the delta-method 95 % intervals.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import cumulative_trapezoid

from trials.analysis.nomoto.models import NomotoModel, _params_from_x
from trials.analysis.nomoto.zigzag import ZigzagData

__all__ = ["Z95", "FitResult", "fit_least_squares"]

Z95 = 1.959963984540054
"""Two-sided 95 % quantile of the standard normal distribution."""


@dataclass(frozen=True)
class FitResult:
    """A 2nd-order model fitted to a whole record, with 95 % confidence intervals.

    Attributes
    ----------
    method : str
        "least_squares" (equation error of eq. 15 integrated twice, the default
        of :func:`fit_least_squares`), "least_squares_integrated" (integrated
        once), "least_squares_eq15" (eq. 15 itself) or "output_error" (heading,
        :func:`trials.analysis.nomoto.output_error.fit_output_error`).
    K, T1, T2, T3 : float
        Parameters [-] (T1, T2 NaN if not real).
    ci95 : dict
        {name: (low, high)} 95 % intervals for K, T1, T2, T3 (and delta_bias).
    delta_bias : float
        Fitted neutral rudder angle [rad] (0 if not fitted).
    rms : float
        RMS residual [rad]: of the fitted equation (heading units) for least
        squares, of the heading for the output-error fit.
    n : int
        Number of samples fitted (the output-error fit decimates long records).
    note : str
        Remarks (e.g. complex roots, optimiser trouble).

    Notes
    -----
    The output-error fit also attaches ``initial_state``, the fitted
    (psi, omega', eps') at the execute, as an extra attribute.
    """

    method: str
    K: float
    T1: float
    T2: float
    T3: float
    ci95: dict
    delta_bias: float
    rms: float
    n: int
    note: str = ""

    @property
    def model(self) -> NomotoModel:
        """As a :class:`NomotoModel`."""
        return NomotoModel(self.K, self.T1, self.T2, self.T3, name=self.method)

    def to_dict(self) -> dict:
        """JSON-ready dict (NaN as None) with ``K_ci95`` ... keys as [low, high], angles in degrees."""
        f = lambda v: None if not np.isfinite(v) else float(v)  # noqa: E731
        d = {"K": f(self.K), "T1": f(self.T1), "T2": f(self.T2), "T3": f(self.T3)}
        for k, (lo, hi) in self.ci95.items():
            d[f"{k}_ci95"] = [f(lo), f(hi)]
        d.update({"delta_bias_deg": float(np.degrees(self.delta_bias)), "rms_residual_deg": float(np.degrees(self.rms)),
                  "n_samples": int(self.n), "note": self.note})
        return d

    def to_pandas(self):
        """One-row DataFrame."""
        import pandas as pd

        return pd.DataFrame([self.to_dict()])


def _regression_eq15(z: ZigzagData, fit_bias: bool):
    """(regressors, dependent variable, theta -> K, T1, T2, T3 (, delta_bias)) of eq. (15) as it stands."""
    one = np.ones_like(z.s)
    cols = [z.eps, z.omega, z.Delta, z.delta, one] + ([z.s] if fit_bias else [])
    b = -z.psi

    def to_params(th):  # th = x1..x4, c0 (, K delta_bias)
        K, T1, T2, T3, _ = _params_from_x(th[:4])
        return np.array([K, T1, T2, T3] + ([th[5] / K] if fit_bias else []), float)
    return cols, b, to_params


def _regression_integrated(z: ZigzagData, fit_bias: bool):
    """The same for eq. (15) integrated once more from the execute."""
    one = np.ones_like(z.s)
    psi = z.psi if z.psi_raw is None else z.psi_raw
    Psi = cumulative_trapezoid(psi, z.s, initial=0.0)
    DD = cumulative_trapezoid(z.Delta, z.s, initial=0.0)
    # x1 omega' + x2 psi + Psi + x3 DD + x4 Delta + c0 + c1 s' + c2 s'^2 = 0, solved for the
    # measured heading so that its noise is in the dependent variable, not in a regressor
    cols = [Psi, z.omega, DD, z.Delta, one, z.s] + ([z.s ** 2] if fit_bias else [])

    def to_params(th):
        x2 = -1.0 / th[0]
        x = np.array([-th[1] * x2, x2, -th[2] * x2, -th[3] * x2])
        K, T1, T2, T3, _ = _params_from_x(x)
        return np.array([K, T1, T2, T3] + ([2.0 * (-th[6] * x2) / K] if fit_bias else []), float)
    return cols, psi, to_params


def _regression_integrated2(z: ZigzagData, fit_bias: bool):
    """The same for eq. (15) integrated twice more (only the recorded heading and rudder enter)."""
    one = np.ones_like(z.s)
    psi = z.psi if z.psi_raw is None else z.psi_raw
    Psi = cumulative_trapezoid(psi, z.s, initial=0.0)
    PP = cumulative_trapezoid(Psi, z.s, initial=0.0)
    DD = cumulative_trapezoid(z.Delta, z.s, initial=0.0)
    DDD = cumulative_trapezoid(DD, z.s, initial=0.0)
    # x1 psi + x2 Psi + PP + x3 DDD + x4 DD + c0 + c1 s' + c2 s'^2 (+ c3 s'^3) = 0, solved for psi
    cols = [PP, Psi, DDD, DD, one, z.s, z.s ** 2] + ([z.s ** 3] if fit_bias else [])

    def to_params(th):
        x1 = -1.0 / th[0]
        x = np.array([x1, -th[1] * x1, -th[2] * x1, -th[3] * x1])
        K, T1, T2, T3, _ = _params_from_x(x)
        return np.array([K, T1, T2, T3] + ([6.0 * (-th[7] * x1) / K] if fit_bias else []), float)
    return cols, psi, to_params


_REGRESSIONS = {"eq15": _regression_eq15, "integrated": _regression_integrated, "integrated2": _regression_integrated2}


def fit_least_squares(z: ZigzagData, form: str = "integrated2", fit_bias: bool = True) -> FitResult:
    """Least-squares fit of eq. (15) over every sample of the zigzag, with 95 % intervals.

    ``form="eq15"`` regresses eq. (15) as it stands,
    -psi = x1 eps' + x2 omega' + x3 Delta + x4 delta + c0 (+ c1 s'),
    with x1 = T1 T2, x2 = T1 + T2, x3 = -K, x4 = -K T3 (eq. 16); c0 absorbs the
    state at the execute and c1 = K delta_bias a neutral rudder angle.

    ``form="integrated"`` fits the same equation integrated once more
    from the execute:
    x1 omega' + x2 psi + int psi ds' + x3 int Delta ds' + x4 Delta + c0 + c1 s' (+ c2 s'^2) = 0,
    (c0, c1 absorb the unknown omega', eps' at the execute, c2 = K delta_bias / 2),
    solved for the recorded heading psi (its noise then sits in the dependent
    variable, not in a regressor, so it causes no attenuation bias).
    Same parameters, but the regressors are heading and yaw rate instead of
    yaw rate and yaw acceleration.  Why: in eq. (15) the error of eps' is
    multiplied by T1 T2 and that of omega' by T1 + T2; with eps' differentiated
    twice from a heading with 0.05 deg noise this errors-in-variables bias
    pulls T1 down by tens of percent, whereas psi is measured and omega' is
    only differentiated once (see the extended Table 8 of ``mmg nomoto-paper``).

    ``form="integrated2"`` (default) integrates twice more, so only the recorded
    heading and rudder enter (no derivative at all):
    x1 psi + x2 int psi + intint psi + x3 intint Delta + x4 int Delta + cubic(s') = 0,
    solved for psi; the cubic absorbs the state at the execute and the neutral
    rudder (c3 = K delta_bias / 6).  On the eq. (24) record with 0.05 deg heading
    noise it keeps K, T1 within about 3 %, where the once-integrated form
    scatters to 4 % and eq. (15) itself is 20-40 % low.

    The 95 % intervals propagate sigma^2 (A^T A)^-1 through eq. (23) by the
    delta method.  Residuals of a record are autocorrelated, so the intervals
    are optimistic: they reflect the scatter, not the differentiator or model bias.

    Parameters
    ----------
    z : ZigzagData
        Dimensionless zigzag (:func:`trials.analysis.nomoto.zigzag.zigzag_data`).
    form : {"integrated2", "integrated", "eq15"}
        Which equation error to minimise.
    fit_bias : bool
        Also fit a neutral rudder angle.

    Returns
    -------
    FitResult
        Method "least_squares", "least_squares_integrated" or
        "least_squares_eq15" according to ``form``.

    Raises
    ------
    ValueError
        Unknown ``form``.
    """
    regression = _REGRESSIONS.get(form)
    if regression is None:
        raise ValueError(f"unknown form {form!r}")
    cols, b, to_params = regression(z, fit_bias)
    A = np.column_stack(cols)
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    ths, *_ = np.linalg.lstsq(A / scale, b, rcond=None)
    th = ths / scale
    res = b - A @ th
    n, p = A.shape
    s2 = res @ res / max(n - p, 1)
    cov = s2 * np.linalg.pinv(A.T @ A)
    par = to_params(th)
    K, T1, T2, T3 = par[:4]
    db = float(par[4]) if fit_bias else 0.0
    ci = _delta_method(th, cov, to_params, ["K", "T1", "T2", "T3"] + (["delta_bias"] if fit_bias else []))
    note = "" if np.isfinite(T1) else "T1, T2 not real ((T1+T2)^2 < 4 T1 T2)"
    method = {"integrated2": "least_squares", "integrated": "least_squares_integrated",
              "eq15": "least_squares_eq15"}[form]
    return FitResult(method, float(K), float(T1), float(T2), float(T3), ci, db,
                     float(np.sqrt(np.mean(res ** 2))), n, note)


def _delta_method(th, cov, g, names):
    """95 % intervals of g(th) from the covariance of th (numerical Jacobian of g)."""
    from mmg.numdiff import central_jacobian

    g0 = g(th)
    J = central_jacobian(g, th, 1e-8, g0)
    sd = np.sqrt(np.abs(np.diag(J @ cov @ J.T)))
    return {nm: (float(v - Z95 * e), float(v + Z95 * e)) for nm, v, e in zip(names, g0, sd)}


