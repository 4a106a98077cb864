"""Propeller thrust in all four quadrants of (n, V_A): the Wageningen B4-70 C_T*(beta_p) curves.

The open-water thrust of a propeller of diameter D turning at n [rps] with advance speed V_A [m/s]
is written with the hydrodynamic pitch angle at 0.7 R, beta_p = atan2(V_A, 0.7 pi n D) in [0, 2 pi),
and the thrust coefficient on the relative velocity there (van Lammeren, van Manen & Oosterveld 1969):

    T = C_T*(beta_p) 1/2 rho (V_A^2 + (0.7 pi n D)^2) pi D^2 / 4.

Quadrants: [0, 90 deg) ahead and ahead (n > 0, V_A >= 0), [90, 180) ship ahead and propeller astern
(crash stop), [180, 270) both astern, [270, 360) ship astern and propeller ahead.  T is well posed
everywhere: bounded by |C_T*| times the relative speed squared, continuous across n = 0 and V_A = 0
(C_T* is a periodic Fourier series, so continuous across 0 = 360 deg) and zero at n = V_A = 0.
First quadrant: C_T* = 8 K_T(J) / (pi (J^2 + (0.7 pi)^2)), J = V_A / (n D) = 0.7 pi tan(beta_p).

Constants: the Fourier series C_T*(beta) = sum_k A_k cos(k beta) + B_k sin(k beta), k = 0..30, of the
four-quadrant open-water tests of the Wageningen B4-70 propellers at P/D = 0.6, 0.8 and 1.0 (4 blades,
A_E/A_0 = 0.70), as tabulated (coefficients times 100, as listed below) by Roddy, Hess & Faller (2006),
"Neural network predictions of the 4-quadrant Wageningen propeller series", NSWCCD-50-TR-2006/004,
David Taylor Model Basin, from the measurements of van Lammeren, van Manen & Oosterveld (1969), "The
Wageningen B-screw series", Trans. SNAME 77.  The tables were read from a public transcription
(the ShipSIM Modelica library's ``WageningenB_4Q_Matrix``, which cites that report); the test checks
them independently: near beta = 0 they give the K_T(J) of the Oosterveld & van Oossanen (1975)
B-series polynomial for the same propellers within 0.01 (tests/test_four_quadrant.py).

A ship's propeller of pitch ratio P/D takes the curve interpolated linearly in P/D between the two
tabulated ones around it (P/D clipped to 0.6-1.0; 0.7 when the config gives no pitch):
:func:`b4_70_coefficients`.  The Esso Osaka (P/D = 0.7154, 4 blades, A_E/A_0 about 0.7) is between
the 0.6 and 0.8 curves.  How the curve is anchored to a ship's own first-quadrant K_T(J) is
:mod:`mmg.model` (:func:`mmg.model.thrust_coefficient`).
"""
from __future__ import annotations

import numpy as np

from ._jit import njit

__all__ = ["B4_70", "N_HARMONICS", "b4_70_coefficients", "atan2_of", "pitch_angle", "fourier_ct", "ct_from_kt",
           "PD_DEFAULT"]

N_HARMONICS = 31
"""Terms k = 0..30 of the tabulated series."""

PD_DEFAULT = 0.7
"""P/D taken when a ship config gives no propeller pitch."""

# (A_k, B_k) x 100, k = 0..30: Roddy, Hess & Faller (2006), B4-70 series (module docstring)
_B4_70_PD06 = (
    (3.8804, 0.0), (8.3653, -79.381), (-0.85859, -1.3907), (2.3607, 11.251), (-1.0596, -0.78851),
    (-4.1596, 4.2391), (0.46247, 0.94902), (3.333, -0.43077), (-0.37098, -0.90581), (-1.9768, 1.6585),
    (-0.11972, 0.86297), (1.757, -0.079001), (0.027679, -0.60216), (-0.43212, 0.80185), (0.028939, 0.34344),
    (0.78009, -0.16327), (-0.0080617, -0.003006), (0.19424, 0.44053), (0.12056, 0.054953), (0.35168, -0.40025),
    (-0.067099, -0.176), (0.12167, 0.13029), (0.16065, -0.0014661), (0.18555, -0.30406), (-0.052739, -0.17165),
    (-0.038986, -0.031444), (-0.085151, 0.022516), (0.020961, -0.10705), (-0.051549, -0.095616),
    (-0.083052, -0.071008), (-0.038942, 0.05025),
)
_B4_70_PD08 = (
    (2.8757, 0.0), (13.007, -77.762), (0.62869, -1.3032), (2.8104, 10.58), (-1.6832, -1.0413),
    (-4.4894, 4.5769), (0.37703, 1.4296), (3.1647, -0.39612), (-0.13492, -0.9917), (-1.9905, 2.0759),
    (0.17576, 0.90153), (1.975, -0.029877), (-0.11063, -0.56354), (-0.069828, 0.94773), (0.25665, 0.23681),
    (0.80681, -0.53204), (-0.18781, -0.071537), (0.29821, 0.52768), (0.48643, 0.0174), (0.33893, -0.68105),
    (-0.26851, -0.204), (0.096098, 0.14086), (0.2145, -0.057914), (0.06644, -0.44898), (-0.1321, -0.11454),
    (0.016378, -0.012005), (0.012367, -0.11932), (-0.16113, -0.24427), (-0.10536, 0.049882),
    (-0.041139, 0.063587), (-0.0089569, -0.073611),
)
_B4_70_PD10 = (
    (2.6617, 0.0), (17.802, -74.797), (1.3828, -1.3632), (2.7871, 10.246), (-1.624, -1.0865),
    (-5.3084, 4.7346), (0.1918, 1.1355), (3.8318, -0.9318), (-0.22892, -0.72471), (-1.8656, 2.3747),
    (0.349, 0.86208), (2.2321, 0.0070224), (-0.35976, -0.36422), (0.13606, 0.91758), (0.47192, 0.089383),
    (0.87235, -0.59364), (-0.35748, -0.070954), (0.35955, 0.48825), (0.52896, -0.090587), (0.21045, -0.81163),
    (-0.27057, -0.056659), (0.10509, 0.12011), (0.27733, -0.13042), (-0.11596, -0.48187), (-0.1745, 0.045412),
    (0.040782, -0.019469), (0.099247, -0.21858), (-0.3465, -0.16314), (-0.12357, 0.14865),
    (0.063929, 0.10185), (0.061933, -0.16735),
)
B4_70 = {0.6: _B4_70_PD06, 0.8: _B4_70_PD08, 1.0: _B4_70_PD10}
"""P/D -> ((A_k, B_k) x 100 for k = 0..30): the tabulated B4-70 thrust series."""


def b4_70_coefficients(P_D: float | None) -> tuple[np.ndarray, np.ndarray]:
    """(A_k, B_k), k = 0..30 (as fractions, not x 100) of the B4-70 C_T* series at pitch ratio ``P_D``.

    Linear in P/D between the tabulated curves around it (0.6, 0.8, 1.0); clipped to that range,
    :data:`PD_DEFAULT` when None."""
    pd = PD_DEFAULT if P_D is None else min(max(float(P_D), 0.6), 1.0)
    keys = sorted(B4_70)
    lo = max(k for k in keys if k <= pd + 1e-12)
    hi = min(k for k in keys if k >= pd - 1e-12)
    a_lo, a_hi = np.array(B4_70[lo]) / 100.0, np.array(B4_70[hi]) / 100.0
    w = 0.0 if hi == lo else (pd - lo) / (hi - lo)
    c = (1.0 - w) * a_lo + w * a_hi
    return c[:, 0].copy(), c[:, 1].copy()


@njit(cache=True, error_model="numpy", inline="always")
def atan2_of(y, x):
    """atan2(y, x) in (-pi, pi] for real or complex y, x (quadrant from the real parts; the ratio
    written so its magnitude stays <= 1: no division by a vanishing number, complex steps stay
    analytic).  0 at y = x = 0."""
    if abs(x.real) >= abs(y.real):
        if x.real == 0.0:
            return 0.0 * (x + y)
        a = np.arctan(y / x)
        if x.real > 0.0:
            return a
        return a + np.pi if y.real >= 0.0 else a - np.pi
    a = np.arctan(x / y)
    return (0.5 * np.pi - a) if y.real > 0.0 else (-0.5 * np.pi - a)


@njit(cache=True, error_model="numpy", inline="always")
def pitch_angle(VA, x07):
    """Hydrodynamic pitch angle beta_p = atan2(V_A, 0.7 pi n D) [rad] in [0, 2 pi); ``x07`` = 0.7 pi n D [m/s]."""
    b = atan2_of(VA, x07)
    return b + 2.0 * np.pi if b.real < 0.0 else b


@njit(cache=True, error_model="numpy", inline="always")
def fourier_ct(beta, c, i0, n):
    """C_T*(beta) = sum_k A_k cos(k beta) + B_k sin(k beta), k < n, with A_k = c[i0 + k] and
    B_k = c[i0 + n + k] (the harmonics by the angle-addition recurrence: two trigonometric calls for
    any number of terms; real or complex beta)."""
    c1 = np.cos(beta)
    s1 = np.sin(beta)
    ck = 1.0 + 0.0 * beta
    sk = 0.0 * beta
    acc = c[i0] * ck
    for k in range(1, n):
        ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1
        acc += c[i0 + k] * ck + c[i0 + n + k] * sk
    return acc


@njit(cache=True, error_model="numpy", inline="always")
def ct_from_kt(KT, J):
    """C_T* of the first quadrant from K_T at advance ratio J: 8 K_T / (pi (J^2 + (0.7 pi)^2))."""
    return 8.0 * KT / (np.pi * (J * J + (0.7 * np.pi) ** 2))
