"""``shallow_water``: depth corrections of the hull coefficients, ``depth_to_draft`` = H / T.

Method: the shallow-water corrections collected by Tang et al. (2020, Ocean Eng. 196, 106679)
for MMG models: the linear sway/yaw derivatives from the Yoshimura & Masumoto (2012) estimates
with the effective aspect ratio k_e(q) = k / (T/(2H) + ((pi T/(2H)) cot(pi T/(2H)))^q), k = 2T/L,
applied here as the *ratio* shallow/deep of those estimates to the ship's own derivatives
(Y_v: q = 2.3, Y_r, N_r: q = 0.7, N_v: q = 1.7; the Kijima beta-derivatives take the factors of
the v-derivatives: Y_beta = -Y_v, N_beta = -N_v); the nonlinear drift-yaw terms N_bbr, N_brr
times 1 + 6 (T/H)^2.5 and the resistance (the hull's resistance coefficients,
:meth:`mmg.ship.HullModel.resistance_names`: X_uu of the Kijima form, X_0 of the MMG standard
method) times 1 + 0.388 (T/H)^2 (Furukawa et al. 2016);
the added masses m_x, m_y and J_z times the factors ((H/T-1)^a + ...)/(H/T-1)^a of the same
collection; the wake (1 - w_P0) times cos(1.4 C_b T/H).  Deep water is depth_to_draft -> inf.

A coefficient effect: it changes the packed ship (:meth:`ShallowWater.pack`).  Fitted as
h = T/H in [0, 0.85] (0: deep), reported as depth_to_draft = 1/h.  With the hull coefficients
free it is nearly collinear with them (it *is* a change of coefficients); only the added-mass and
wake parts are distinct, so the workflow can name it only when the depth is small.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .. import model as M
from .base import Effect, Parameter


def _ke(k, h, q):
    if h <= 0.0:
        return k
    a = math.pi * h / 2.0
    return k / (h / 2.0 + (a / math.tan(a)) ** q)


def factors(ship, h: float) -> dict:
    """Multiplying factors of the corrected quantities at h = T / H (0 deep), by hull coefficient name
    (the resistance by the ship's own names of it), ``m_x``, ``m_y``, ``J_z`` and ``one_minus_w``."""
    pa = ship.particulars
    L, B, T, Cb = pa.L, pa.B, pa.T, pa.C_b
    k = 2.0 * T / L
    if h <= 0.0:
        return {}
    yv = (0.5 * math.pi * _ke(k, h, 2.3) + 1.4 * Cb * B / L) / (0.5 * math.pi * k + 1.4 * Cb * B / L)
    yr = _ke(k, h, 0.7) / k
    nv = _ke(k, h, 1.7) / k
    ke7 = _ke(k, h, 0.7)
    nr = (0.54 * ke7 - ke7 ** 2) / (0.54 * k - k ** 2)
    c = 1.0 / h - 1.0
    mx = (c ** 1.3 + 3.77 + 1.14 * B / T - 0.233 * L / T - 3.43 * Cb) / c ** 1.3
    my = (c ** 0.82 + 0.413 + 0.0320 * B / T + 0.129 * (B / T) ** 2) / c ** 0.82
    jz = (c ** 0.82 + 0.413 + 0.0192 * B / T + 0.00554 * (B / T) ** 2) / c ** 0.82
    return {"Y_beta": yv, "Y_v": yv, "Y_r": yr, "N_beta": nv, "N_v": nv, "N_r": nr,
            "N_bbr": 1 + 6 * h ** 2.5, "N_brr": 1 + 6 * h ** 2.5, "N_vvr": 1 + 6 * h ** 2.5, "N_vrr": 1 + 6 * h ** 2.5,
            **dict.fromkeys(ship.hull.resistance_names(), 1 + 0.388 * h ** 2), "m_x": max(mx, 1.0), "m_y": my, "J_z": jz,
            "one_minus_w": math.cos(1.4 * Cb * h)}


class ShallowWater(Effect):
    name = "shallow_water"
    kind = "coefficients"
    description = "shallow-water corrections of the hull coefficients, added masses and wake"
    parameters = (Parameter("depth_to_draft", "1", math.inf, 1.15, math.inf, math.inf, "water depth over draft H/T"),)
    affects = ("u", "v", "r", "heading", "position")
    measured_by = "the water depth from a chart or an echo sounder"
    magnitude_unit = "T/H"
    detection_size = (0.5, "1")
    """T/H 0.5 (H/T 2, where the hull derivatives have changed by tens of per cent)."""

    @classmethod
    def magnitude(cls, values, L):
        """Draught over depth T/H (0 in deep water)."""
        h = float(values["depth_to_draft"])
        return 0.0 if not math.isfinite(h) or h <= 0 else 1.0 / h

    @classmethod
    def values(cls, given=None, owner=None):
        return super().values(given, owner)

    @classmethod
    def fit_parameters(cls):
        return (Parameter("draft_to_depth", "1", 0.0, 0.0, 0.85, 0.5, "T/H (0: deep water)", 0.2),)

    @classmethod
    def from_fit(cls, theta):
        h = float(theta[0])
        return {"depth_to_draft": (1.0 / h) if h > 1e-9 else math.inf}

    @classmethod
    def changed_coefficients(cls, ship) -> tuple:
        f = factors(ship, 0.5)                      # the keys only: which quantities the depth corrects
        wake = ("w_P0",) if "one_minus_w" in f else ()
        return tuple(n for n in ship.hull.names if n in f) + tuple(n for n in ("m_x", "m_y", "J_z") if n in f) + wake

    @classmethod
    def pack(cls, packed, values, ship=None):
        if ship is None:
            raise ValueError("shallow_water needs the ship (its particulars and hull names)")
        H = float(values["depth_to_draft"])
        h = 0.0 if not math.isfinite(H) else 1.0 / H
        f = factors(ship, h)
        if not f:
            return packed
        coef = packed.hull_coef.copy()
        for i, nm in enumerate(ship.hull.names):
            if nm in f:
                coef[i] *= f[nm]
        p = packed.p.copy()
        p[M.P_MX] *= f["m_x"]
        p[M.P_MY] *= f["m_y"]
        p[M.P_JZ] *= f["J_z"]
        poly = packed.poly.copy()
        w0 = poly[M.POLY_WP0][0]
        poly[M.POLY_WP0][0] = 1.0 - (1.0 - w0) * f["one_minus_w"]
        return replace(packed, p=p, poly=poly, hull_coef=coef)
