"""Kijima et al. (1990) regression formulas for the hull derivatives (even keel).

Given the particulars (L, B, T, C_b) and the added mass m_x', they predict the
linear and nonlinear sway/yaw derivatives of the Kijima hull model (terms in beta
and r').  Rhee & Kim's Table 2 is these formulas evaluated for the Esso Osaka
(apart from Y_0, N_0 which come from trials); :func:`compare` shows how close.
Formulas as collected in the project's physics fact sheet (section 1), k = 2T/L.
"""
from __future__ import annotations

from .ship import Ship


def kijima_derivatives(L: float, B: float, T: float, C_b: float, m_x_prime: float) -> dict[str, float]:
    """Kijima (1990) hull derivatives, named as in the ship configs.

    Parameters
    ----------
    L, B, T : float
        Length between perpendiculars, breadth, draught [m].
    C_b : float
        Block coefficient.
    m_x_prime : float
        Surge added mass (1/2 rho L^2 T); enters Y_r = m' + m_x' - 1.5 C_b B/L with m' = 2 C_b B/L.
    """
    k = 2.0 * T / L
    cbl = C_b * B / L
    tb = T / B
    m_prime = 2.0 * cbl
    return {
        "Y_beta": 0.5 * 3.141592653589793 * k + 1.4 * cbl,
        "Y_r": m_prime + m_x_prime - 1.5 * cbl,
        "Y_bb": 2.5 * tb * (1 - C_b) + 0.5,
        "Y_rr": 0.343 * tb * C_b - 0.07,
        "Y_bbr": 1.5 * tb * C_b - 0.65,
        "Y_brr": 5.95 * tb * (1 - C_b),
        "N_beta": k,
        "N_r": -0.54 * k + k * k,
        "N_bb": 0.066 - 0.96 * tb * (1 - C_b),
        "N_rr": 0.5 * cbl - 0.09,
        "N_bbr": -(57.5 * cbl**2 - 18.4 * cbl + 1.6),
        "N_brr": 0.05 - 0.5 * tb * C_b,
    }


def compare(ship: Ship) -> list[dict]:
    """Rows (name, kijima, config value, relative difference %) for the ship's hull coefficients."""
    p = ship.particulars
    pred = kijima_derivatives(p.L, p.B, p.T, p.C_b, ship.mass.m_x_prime)
    rows = []
    for name, kij in pred.items():
        if name in ship.hull.names:
            val = ship.hull.value(name)
            rows.append({"coefficient": name, "kijima": kij, "config": val,
                         "difference_pct": 100.0 * (kij - val) / abs(val)})
    return rows
