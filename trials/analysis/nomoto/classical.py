"""Nomoto's (1960) classical first-order K, T from a zigzag, eqs. (10)-(12), per half-cycle.

Works on a recorded zigzag (:class:`~trials.analysis.nomoto.zigzag.ZigzagData`) or a
simulated one (:class:`~trials.analysis.nomoto.simulation.ZigzagSimulation`, whose exact
states are then used).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mmg.errors import InputError
from trials.analysis.nomoto.models import NomotoModel, first_order
from trials.analysis.nomoto.simulation import ZigzagSimulation

__all__ = ["ClassicalResult", "classical_first_order"]


@dataclass(frozen=True)
class ClassicalResult:
    """Nomoto (1960) first-order K, T from a zigzag, per half-cycle and averaged.

    Attributes
    ----------
    K, T : float
        Averages over the half-cycles used [-]: K of eq. (10); T of the
        counter-rudder variant, eq. (12), or, when no half-cycle has a next
        counter-rudder, of the zero-crossing form, eq. (11).
    rows : tuple of dict
        Per half-cycle k: K (from OS_k), T_zero (eq. 11, heading zero crossing
        after OS_k), T_cr (eq. 12, counter-rudder CR_k+1), and the
        overshoot-to-overshoot form K_os, T_os (see :func:`classical_first_order`).
    K_os, T_os : float
        Averages of the overshoot-to-overshoot form.
    """

    K: float
    T: float
    rows: tuple
    K_os: float = float("nan")
    T_os: float = float("nan")

    @property
    def model(self) -> NomotoModel:
        """As a first-order :class:`NomotoModel`."""
        return first_order(self.K, self.T, name="classical")

    def to_dict(self) -> dict:
        """JSON-ready dict with the per-half-cycle rows."""
        return {"K": float(self.K), "T": float(self.T), "K_overshoot_to_overshoot": float(self.K_os),
                "T_overshoot_to_overshoot": float(self.T_os), "half_cycles": [dict(r) for r in self.rows]}

    def to_pandas(self):
        """Per-half-cycle DataFrame."""
        import pandas as pd

        return pd.DataFrame(list(self.rows))


def classical_first_order(z, n_half: int = 3) -> ClassicalResult:
    """First-order K, T by Nomoto's two-point method, eqs. (10)-(12).

    From the integrated model (7), T omega' + psi = K Delta, with origin at the
    execute (zero initial state):

    * K_k = psi_OSk / Delta_OSk  (eq. 10, omega' = 0 at an overshoot);
    * T_k = (K_k Delta_Zk - psi_Zk) / omega'_Zk at the heading zero crossing
      after OS_k (eq. 11, psi_Z = 0), and
    * T_k = (K_k Delta_CRk+1 - psi_CRk+1) / omega'_CRk+1 at the next counter-rudder
      (eq. 12, Artyszuk's economical variant).

    Also reported, the overshoot-to-overshoot form (model (7) integrated from
    OS_k-1, where omega' = 0, to OS_k; OS_0 = execute):
    K_os = (psi_OSk - psi_OSk-1) / (Delta_OSk - Delta_OSk-1) and
    T_os = (K_os (Delta_CRk - Delta_OSk-1) - (psi_CRk - psi_OSk-1)) / (omega'_CRk - omega'_OSk-1)
    at the counter-rudder CR_k inside that half-cycle.  It does not depend on the
    state at the execute.

    The averages use the first ``n_half`` half-cycles (as is usual, at most three).

    Parameters
    ----------
    z : ZigzagData or ZigzagSimulation
        Dimensionless zigzag with s_cr, s_os and (for eq. 11) the heading zero
        crossings ``s_z`` (found here for a simulation, whose exact states are used).
    n_half : int
        Maximum number of half-cycles to average.

    Returns
    -------
    ClassicalResult
        Averages and the per-half-cycle rows.

    Raises
    ------
    InputError
        No overshoot in the zigzag.
    """
    def at(s):
        return z.state_at(s) if isinstance(z, ZigzagSimulation) else z.at(s)

    zs = getattr(z, "s_z", None)
    if zs is None:  # simulation: zero crossings of heading after each overshoot
        zs = []
        for so in z.s_os:
            m = np.where(z.s > so)[0]
            for q in m[:-1]:
                if z.psi[q] * z.psi[q + 1] <= 0 and z.psi[q] != 0:
                    zs.append(float(z.s[q] - z.psi[q] * (z.s[q + 1] - z.s[q]) / (z.psi[q + 1] - z.psi[q])))
                    break
    rows = []
    prev = {"psi": 0.0, "Delta": 0.0, "omega": 0.0}
    for k in range(min(n_half, len(z.s_os))):
        os_ = at(z.s_os[k])
        K = os_["psi"] / os_["Delta"]
        Kos = (os_["psi"] - prev["psi"]) / (os_["Delta"] - prev["Delta"])
        row = {"half_cycle": k + 1, "s_OS": os_["s"], "K": K, "T_zero": np.nan, "T_cr": np.nan,
               "K_os": Kos, "T_os": np.nan}
        if k < len(zs):
            zz = at(zs[k])
            row["T_zero"] = (K * zz["Delta"] - zz["psi"]) / zz["omega"]
        if k + 1 < len(z.s_cr):
            cr = at(z.s_cr[k + 1])
            row["T_cr"] = (K * cr["Delta"] - cr["psi"]) / cr["omega"]
        # overshoot-to-overshoot: K over [OS_k-1, OS_k], T at the counter-rudder inside it
        if k < len(z.s_cr):
            cr = at(z.s_cr[k])
            row["T_os"] = ((Kos * (cr["Delta"] - prev["Delta"]) - (cr["psi"] - prev["psi"]))
                           / (cr["omega"] - prev["omega"]))
        rows.append(row)
        prev = {"psi": os_["psi"], "Delta": os_["Delta"], "omega": 0.0}
    if not rows:
        raise InputError(getattr(z, "name", "zigzag"), "heading", "no overshoot found: not a zigzag")
    K = float(np.nanmean([r["K"] for r in rows]))
    T = float(np.nanmean([r["T_cr"] for r in rows])) if any(np.isfinite(r["T_cr"]) for r in rows) \
        else float(np.nanmean([r["T_zero"] for r in rows]))
    Kos = float(np.nanmean([r["K_os"] for r in rows]))
    Tos = float(np.nanmean([r["T_os"] for r in rows]))
    return ClassicalResult(K=K, T=T, rows=tuple(rows), K_os=Kos, T_os=Tos)


