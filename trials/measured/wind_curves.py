"""Wind-load curves of another shape than the model's: a truncated Fourier series in the relative wind angle.

The diagnosis's wind candidate (:class:`mmg.effects.Wind`) is the Fujiwara, Ueno & Nimura (1998)
regression with a scale and three shape terms (``sway_factor``, ``yaw_factor``, ``yaw_sin``).  A real
ship's wind loads are measured curves of their own; a family of ships whose loads all follow the
candidate's own curve would never show what a diagnosis leaves behind when they do not.  This module
gives the mismatch family (:mod:`trials.measured.mismatch`) such other curves, their coefficients
independent of :mod:`mmg.wind` (the loads from the coefficients: :func:`mmg.wind.coefficient_loads`):

    C_X(gamma) = sum_k a_k cos(k gamma),   k = 0 .. K
    C_Y(gamma) = sum_k b_k sin(k gamma),   k = 1 .. K
    C_N(gamma) = sum_k c_k sin(k gamma),   k = 1 .. K

(the Isherwood-type harmonic form of a wind-load table: C_X even, C_Y and C_N odd in gamma, a
port-starboard symmetric ship), with X = q A_T C_X, Y = q A_L C_Y, N = q A_L L C_N about midship,
q = rho_air V_rel^2 / 2, gamma the direction the apparent wind comes FROM, from the bow, positive
towards starboard (the convention of :mod:`mmg.wind`; x forward, y to starboard, N bow to starboard).

The loaded-tanker curve (:data:`TANKER_LOADED`) is a least-squares fit of order 4 to the loaded
VLCC wind coefficients of OCIMF (1994), *Prediction of Wind and Current Loads on VLCCs*, 2nd ed.,
figs 2.3 (lateral force at the forward and aft perpendiculars, C_YF, C_YA) and 2.4 (longitudinal
force, C_X), as digitised at 12 angles (0 to 180 deg) in a public spreadsheet ("OCIMF Calculation",
scribd document 663684986; read there, not checked against the printed book).  The lateral force
is C_Y = -(C_YA + C_YF) and the moment about midship C_N = (C_YA - C_YF) / 2 (the perpendiculars
L/2 either side, wind from starboard pushing to port).  The fit leaves 0.024 (C_X), 0.012 (C_Y) and
0.003 (C_N) rms at the table's angles.  Its shape differs from Fujiwara's: the side force has a
sin 2 gamma part (the bow and stern are not alike), and the yaw moment turns the bow into the wind
at every angle (the accommodation aft: C_N about 0.10 at the beam), where Fujiwara's regression on
the Esso Osaka geometry gives a moment of a few hundredths that changes sign near 73 deg.  OCIMF's
coefficients refer to the wind 10 m above the water; here they act on the anemometer's wind.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mmg.wind import RHO_AIR, coefficient_loads

__all__ = ["TANKER_LOADED", "WIND_CURVES", "HarmonicWindCurve"]

WIND_CURVES = ("fujiwara", "harmonic", "mixed")
"""The mismatch family's wind-curve options: every member's loads on the model's own (Fujiwara) curve,
every member's on a drawn :class:`HarmonicWindCurve`, or half of the members (at random places) each."""

@dataclass(frozen=True)
class HarmonicWindCurve:
    """Wind-load coefficients as truncated Fourier series in the relative wind angle.

    Attributes
    ----------
    a : tuple of float
        a_0 .. a_K of C_X = sum a_k cos(k gamma) [-].
    b : tuple of float
        b_1 .. b_K of C_Y = sum b_k sin(k gamma) [-].
    c : tuple of float
        c_1 .. c_K of C_N = sum c_k sin(k gamma) [-].
    """

    a: tuple
    b: tuple
    c: tuple

    def coefficients(self, gamma):
        """C_X, C_Y, C_N at relative wind angles ``gamma`` [rad] (comes FROM, from the bow, + to starboard)."""
        g = np.asarray(gamma, dtype=float)
        cx = sum(ak * np.cos(k * g) for k, ak in enumerate(self.a))
        cy = sum(bk * np.sin((k + 1) * g) for k, bk in enumerate(self.b))
        cn = sum(ck * np.sin((k + 1) * g) for k, ck in enumerate(self.c))
        return cx + 0.0 * g, cy + 0.0 * g, cn + 0.0 * g

    def loads(self, V_rel, gamma, particulars, rho_air: float = RHO_AIR):
        """Surge force X [N], sway force Y [N] and yaw moment N [N m] about midship.

        Parameters
        ----------
        V_rel : array_like
            Apparent wind speed [m/s].
        gamma : array_like
            Relative wind angle [rad].
        particulars : mmg.wind.WindParticulars
            Its ``A_T``, ``A_L`` [m^2] and ``L`` [m] (the moment's arm) only.
        rho_air : float
            Air density [kg/m^3].
        """
        return coefficient_loads(V_rel, *self.coefficients(gamma), particulars, rho_air)

    def drawn(self, rng: np.random.Generator, half_width: float) -> "HarmonicWindCurve":
        """A curve of the same form, every coefficient times its own 1 + u, u uniform in [-half_width, half_width].

        Parameters
        ----------
        rng : numpy.random.Generator
            The draws' source (one uniform number per coefficient, in the order a, b, c).
        half_width : float
            The largest relative change of a coefficient [-] (0.3: each within 30 % of its value).

        Returns
        -------
        HarmonicWindCurve
            The drawn curve; the same number of harmonics as this one.
        """
        f = lambda xs: tuple(float(x * (1.0 + rng.uniform(-half_width, half_width))) for x in xs)  # noqa: E731
        return HarmonicWindCurve(f(self.a), f(self.b), f(self.c))

    def to_dict(self) -> dict:
        """``{"kind": "harmonic", "a": [...], "b": [...], "c": [...]}`` (JSON)."""
        return {"kind": "harmonic", "a": list(self.a), "b": list(self.b), "c": list(self.c)}

    @classmethod
    def from_dict(cls, d: dict) -> "HarmonicWindCurve":
        """The curve of :meth:`to_dict`'s mapping."""
        return cls(tuple(d["a"]), tuple(d["b"]), tuple(d["c"]))


TANKER_LOADED = HarmonicWindCurve(a=(-0.0271, -0.7829, -0.0550, -0.0687, 0.0031),
                                  b=(-0.7319, 0.0502, -0.0199, 0.0304),
                                  c=(0.1310, -0.0611, 0.0300, -0.0067))
"""A loaded VLCC's wind loads (OCIMF 1994, fitted; module docstring).  Head wind C_X = -0.93, following
wind +0.77, beam wind C_Y = -0.71 and C_N = +0.10 (bow into the wind)."""
