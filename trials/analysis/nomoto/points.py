"""Motion values at the characteristic abscissas of a zigzag (CR1, OS1, CR2, OS2, ...).

:class:`ZigzagPoints` is what the four-point method (:mod:`trials.analysis.nomoto.fourpoint`)
consumes; simulations (:mod:`trials.analysis.nomoto.simulation`) and records
(:mod:`trials.analysis.nomoto.zigzag`) both produce it.  Imports nothing from the other
:mod:`trials.analysis.nomoto` modules.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ZigzagPoints"]


@dataclass(frozen=True)
class ZigzagPoints:
    """Motion values at the characteristic abscissas (one row per point).

    Attributes
    ----------
    names : tuple of str
        e.g. ("CR1", "OS1", "CR2", "OS2").
    s, eps, omega, Delta, delta, psi : ndarray
        s' [-], eps' [-], omega' [-], Delta [rad], delta [rad], psi [rad] per point.
        From a record (:meth:`trials.analysis.nomoto.zigzag.ZigzagData.points`) eps' and
        omega' are increments from the execute.
    """

    names: tuple
    s: np.ndarray
    eps: np.ndarray
    omega: np.ndarray
    Delta: np.ndarray
    delta: np.ndarray
    psi: np.ndarray

    @classmethod
    def from_rows(cls, names, rows):
        """Build from a list of dicts with keys s, eps, omega, Delta, delta, psi."""
        return cls(tuple(names), *(np.array([r[k] for r in rows], float)
                                   for k in ("s", "eps", "omega", "Delta", "delta", "psi")))

    def scaled(self, **factors) -> "ZigzagPoints":
        """A copy with values multiplied, e.g. ``scaled(eps={'CR1': 1.1})`` or ``scaled(omega=1.05)``."""
        kw = {}
        for k in ("s", "eps", "omega", "Delta", "delta", "psi"):
            v = getattr(self, k).copy()
            f = factors.get(k)
            if isinstance(f, dict):
                for nm, fac in f.items():
                    v[self.names.index(nm)] *= fac
            elif f is not None:
                v *= f
            kw[k] = v
        return ZigzagPoints(self.names, **kw)

    def to_dict(self) -> dict:
        """{name: {s, eps, omega, Delta, delta, psi, psi_deg}}."""
        return {n: {"s": float(self.s[i]), "eps": float(self.eps[i]), "omega": float(self.omega[i]),
                    "Delta": float(self.Delta[i]), "delta": float(self.delta[i]), "psi": float(self.psi[i]),
                    "psi_deg": float(np.degrees(self.psi[i]))} for i, n in enumerate(self.names)}

    def to_pandas(self):
        """The points as a DataFrame (Artyszuk's Table 1 layout)."""
        import pandas as pd

        return pd.DataFrame.from_dict(self.to_dict(), orient="index")


