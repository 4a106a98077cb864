"""Artyszuk's four-point identification of the second-order Nomoto model.

Eq. (17), [eps' omega' Delta delta] x = -psi at four abscissas, solved by
Cramer's rule (the determinants of his Table 7), then eq. (23) for K, T1, T2,
T3.  A singular matrix (exact first-order data) gives the minimum-norm
solution with T2 = T3 indeterminate.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mmg.errors import InputError
from trials.analysis.nomoto.models import NomotoModel, _params_from_x
from trials.analysis.nomoto.points import ZigzagPoints

__all__ = ["FourPointResult", "four_point"]


@dataclass(frozen=True)
class FourPointResult:
    """Result of the four-point 2nd-order identification (eqs. 16-18, 23).

    Attributes
    ----------
    K, T1, T2, T3 : float
        Model parameters [-]; T1, T2 are NaN when x2^2 - 4 x1 < 0 (no real
        roots, Artyszuk's Table 6 case).
    x : ndarray
        x1 = T1 T2, x2 = T1 + T2, x3 = -K, x4 = -K T3, eq. (16).
    W : float
        Main determinant of eq. (17)/(18).
    Wx : ndarray
        Cramer determinants W_x1..W_x4 (x_i = W_xi / W), Table 7.
    discriminant : float
        x2^2 - 4 x1 under the square roots of eq. (23).
    real : bool
        True when T1, T2 are real.
    cond : float
        Condition number of the 4x4 matrix.
    rank_deficient : bool
        The matrix is singular to working precision (first-order data): x is the
        minimum-norm solution, T2 = T3 is then indeterminate (Artyszuk, Table 4).
    """

    K: float
    T1: float
    T2: float
    T3: float
    x: np.ndarray
    W: float
    Wx: np.ndarray
    discriminant: float
    real: bool
    cond: float
    rank_deficient: bool = False

    @property
    def model(self) -> NomotoModel:
        """As a :class:`NomotoModel` (NaN T1, T2 if not real)."""
        return NomotoModel(self.K, self.T1, self.T2, self.T3, name="four-point")

    def note(self) -> str:
        """Plain-words remark for reports ('' when all is well)."""
        if self.rank_deficient:
            return ("four-point matrix singular (first-order behaviour): T2 = T3 indeterminate, "
                    "minimum-norm solution reported")
        if not self.real:
            return (f"T1, T2 not real: (T1+T2)^2 - 4 T1 T2 = {self.discriminant:.4g} < 0 "
                    f"(T1 T2 = {self.x[0]:.4g}, T1 + T2 = {self.x[1]:.4g})")
        return ""

    def to_dict(self) -> dict:
        """JSON-ready dict (NaN parameters as None) with the determinants and the note."""
        f = lambda v: None if not np.isfinite(v) else float(v)  # noqa: E731
        return {"K": f(self.K), "T1": f(self.T1), "T2": f(self.T2), "T3": f(self.T3),
                "T1T2": float(self.x[0]), "T1_plus_T2": float(self.x[1]), "real_T1_T2": bool(self.real),
                "discriminant": float(self.discriminant), "W": float(self.W),
                "W_x": [float(v) for v in self.Wx], "condition_number": float(self.cond),
                "rank_deficient": bool(self.rank_deficient), "note": self.note()}

    def to_pandas(self):
        """One-row DataFrame."""
        import pandas as pd

        return pd.DataFrame([self.to_dict()])


def four_point(points: ZigzagPoints) -> FourPointResult:
    """Artyszuk's four-point identification of the 2nd-order model.

    Solves eq. (17) (with the corrected right-hand side -psi_#4),
    [eps' omega' Delta delta] x = -psi at four abscissas, by Cramer's rule so
    that the determinants of Table 7 are reported, then eq. (23).

    Parameters
    ----------
    points : ZigzagPoints
        Exactly four points (e.g. CR1, OS1, CR2, OS2).

    Returns
    -------
    FourPointResult
        K, T1, T2, T3 with the determinants; NaN T1, T2 when they are not real.

    Raises
    ------
    ValueError
        Not exactly four points.
    InputError
        Non-finite input values.
    """
    if len(points.names) != 4:
        raise ValueError("the four-point method needs exactly four points")
    A = np.column_stack([points.eps, points.omega, points.Delta, points.delta])
    b = -points.psi
    if not np.all(np.isfinite(A)) or not np.all(np.isfinite(b)):
        raise InputError("four-point", "", "non-finite input values")
    W = float(np.linalg.det(A))
    Wx = np.empty(4)
    for i in range(4):
        Ai = A.copy()
        Ai[:, i] = b
        Wx[i] = np.linalg.det(Ai)
    # relative size of W against Hadamard's bound tells a rank-deficient matrix, which is
    # what exact first-order data give (eps' = (K delta - omega')/T is a combination of
    # the other columns): then T2 = T3 is indeterminate and the minimum-norm solution is
    # returned (it has T1 = T and T2 = T3 exactly).
    hadamard = float(np.prod(np.linalg.norm(A, axis=0)))
    rank_deficient = hadamard == 0 or abs(W) < 1e-9 * hadamard
    if rank_deficient:
        x = np.linalg.lstsq(A, b, rcond=1e-9)[0]
    else:
        x = Wx / W
    disc = x[1] ** 2 - 4 * x[0]
    K, T1, T2, T3, real = _params_from_x(x)
    return FourPointResult(K=float(K), T1=float(T1), T2=float(T2), T3=float(T3),
                           x=x, W=W, Wx=Wx, discriminant=float(disc), real=bool(real),
                           cond=float(np.linalg.cond(A)), rank_deficient=bool(rank_deficient))


