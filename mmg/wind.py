"""Wind forces on a ship from the relative (apparent) wind: Fujiwara et al. regression.

Coefficient set
---------------
Fujiwara, T., Ueno, M. & Nimura, T. (1998), *Estimation of wind forces and moments
acting on ships*, J. Soc. Naval Architects of Japan 183, 77-90 (the same regression
was presented again by Fujiwara, Ueno & Nimura in 2001). The coefficients are the
Fourier-type regression

    C_X = X0 + X1 cos a + X3 cos 3a + X5 cos 5a
    C_Y = Y1 sin a + Y3 sin 3a + Y5 sin 5a
    C_N = N1 sin a + N2 sin 2a + N3 sin 3a

whose amplitudes X0..N3 are linear in non-dimensional geometry groups of the
above-water body (A_T, A_L, A_OD, L_oa, B, H_BR, x_AL, z_AL, x_AOD). The regression
constants used here (``_FUJIWARA``) were transcribed from the MATLAB routine
``wind_EO.m`` of the Osaka University NAOE group that published the FRT-DS-ESSO data
set (the routine quotes them as "from Prof. T. Fujiwara paper"); they could not be
checked against the printed paper here. The routine's flag ``ss`` (number of
superstructures) is 1, i.e. every term is kept.

Geometry of the 3 m Esso Osaka model (:data:`ESSO_OSAKA_MODEL`): A_T = 0.135 m^2 and
A_L = 0.520 m^2 are the data set's values; A_OD, x_AL, z_AL, x_AOD and H_BR are the
values the same routine attributes to "Miyauchi and Dimas" for this model (their
A_T = 0.13544 m^2 and A_L = 0.52038 m^2 agree with the data set). L_oa is taken as
L = 3.0 m (the routine does the same), B = 0.489 m (the routine used 0.5 m).

Conventions (module-wide)
-------------------------
* Ship axes at midship: x forward, y to starboard, z down; N positive turns the bow
  to starboard; moments are about midship.
* ``angle`` (the relative wind angle of attack, gamma) is the direction the apparent
  wind comes FROM, measured from the bow, positive towards starboard (clockwise seen
  from above): 0 = head wind, +pi/2 = wind from starboard beam, pi = following wind.
  This is the convention of the FRT-DS-ESSO column ``wind_dir_relative_mid``
  (established from the data, see ``docs/wind.md``) up to the wrap range.
* Earth frame of the data set: x north, y east, heading psi clockwise from x;
  ``wind_dir_true`` is the direction the true wind comes FROM, clockwise from x,
  in [0, 2 pi).
* The regression's own angle ``a`` is positive for wind from PORT (so that its
  positive C_Y pushes to starboard); here a = -gamma, so in this module
  C_Y(gamma) = -(Y1 sin g + Y3 sin 3g + Y5 sin 5g), C_N likewise, and C_X is even.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "WindParticulars",
    "ESSO_OSAKA_MODEL",
    "RHO_AIR",
    "fujiwara_amplitudes",
    "fujiwara_coefficients",
    "fujiwara_series",
    "amplitude_vector",
    "AMPLITUDES",
    "WindShape",
    "wind_forces",
    "coefficient_loads",
    "angle_from_dataset",
    "true_wind_from_relative",
    "relative_wind_from_true",
    "apparent_air_velocity",
]

RHO_AIR = 1.225
"""Air density at 15 deg C, sea level [kg/m^3]."""


@dataclass(frozen=True)
class WindParticulars:
    """Above-water geometry needed by the Fujiwara et al. (1998) wind regression.

    Parameters
    ----------
    A_T : float
        Transverse (frontal) projected area above water [m^2].
    A_L : float
        Lateral projected area above water [m^2].
    L : float
        Length overall L_oa [m] (also the moment arm of ``N = q A_L L C_N``).
    B : float
        Breadth [m].
    A_OD : float
        Lateral projected area of the superstructure and deck houses over the deck [m^2].
    H_BR : float
        Height of the top of the superstructure (bridge) above the waterline [m].
    x_AL : float
        Longitudinal position of the centroid of A_L, from midship, positive forward [m].
    z_AL : float
        Height of the centroid of A_L above the waterline [m].
    x_AOD : float
        Longitudinal position of the centroid of A_OD, from midship, positive forward [m].
    """

    A_T: float
    A_L: float
    L: float
    B: float
    A_OD: float
    H_BR: float
    x_AL: float
    z_AL: float
    x_AOD: float

    def __post_init__(self):
        for name in ("A_T", "A_L", "L", "B", "A_OD", "H_BR", "z_AL"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"WindParticulars.{name} must be finite and > 0, got {v!r}")
        for name in ("x_AL", "x_AOD"):
            if not np.isfinite(getattr(self, name)):
                raise ValueError(f"WindParticulars.{name} must be finite")


ESSO_OSAKA_MODEL = WindParticulars(
    A_T=0.135, A_L=0.520, L=3.0, B=0.489,
    A_OD=0.14230, H_BR=0.2940, x_AL=-0.01299, z_AL=0.10359, x_AOD=-1.23339,
)
"""The 3 m Esso Osaka free-running model of FRT-DS-ESSO (see the module docstring)."""

# Fujiwara, Ueno & Nimura (1998) regression constants, as transcribed (see module doc).
_FUJIWARA = {
    "X0": (-0.330, 0.293, 0.0193, 0.682),
    "X1": (-1.353, 1.700, 2.870, -0.463, -0.570, -6.640, -0.0123, 0.0202),
    "X3": (0.830, -0.413, -0.0827, -0.563, 0.804, -5.670, 0.0401, -0.132),
    "X5": (0.0372, -0.0075, -0.103, 0.0921),
    "Y1": (0.684, 0.717, -3.220, 0.0281, 0.0661, 0.298),
    "Y3": (-0.400, 0.282, 0.307, 0.0519, 0.0526, -0.0814, 0.0582),
    "Y5": (0.122, -0.166, -0.0054, -0.0481, -0.0136, 0.0864, -0.0297),
    "N1": (0.299, 1.710, 0.183, -1.090, -0.0442, -0.289, 4.240, -0.0646, 0.0306),
    "N2": (0.117, 0.123, -0.323, 0.0041, -0.166, -0.0109, 0.174, 0.214, -1.060),
    "N3": (0.0230, 0.0385, -0.0339, 0.0023),
}


def _groups(p: WindParticulars) -> dict[str, tuple[float, ...]]:
    """Non-dimensional geometry groups multiplying each regression constant (1 = constant)."""
    L, B = p.L, p.B
    return {
        "X0": (1.0, B * p.H_BR / p.A_T, p.x_AL / p.z_AL, p.A_OD / L**2),
        "X1": (1.0, p.A_L / (L * B), L * p.z_AL / p.A_L, L * p.H_BR / p.A_L, p.A_OD / p.A_L,
               p.A_T / (L * B), L**2 / p.A_T, L / p.z_AL),
        "X3": (1.0, p.A_L / (L * p.H_BR), p.A_L / p.A_T, L * p.z_AL / p.A_L, p.A_OD / p.A_L,
               p.A_OD / L**2, p.x_AL / p.z_AL, p.x_AOD / L),
        "X5": (1.0, p.A_L / p.A_OD, p.x_AOD / L, p.A_L / (L * B)),
        "Y1": (1.0, p.x_AOD / L, p.x_AL / L, p.A_L / p.A_OD, p.x_AL / p.z_AL, p.A_T / (B * p.H_BR)),
        "Y3": (1.0, p.A_L / (L * B), L * p.z_AL / p.A_L, p.x_AOD / L, B / p.H_BR, p.A_OD / p.A_L,
               p.A_T / (B * p.H_BR)),
        "Y5": (1.0, p.A_L / (L * B), L / p.H_BR, p.x_AOD / L, B**2 / p.A_T, p.x_AL / L,
               L * p.z_AL / p.A_L),
        "N1": (1.0, p.x_AL / L, L * p.z_AL / p.A_L, p.A_T / p.A_L, p.x_AL / p.z_AL, p.A_L / (L * B),
               p.A_T / L**2, B**2 / p.A_T, p.x_AOD / L),
        "N2": (1.0, p.x_AOD / L, p.x_AL / L, p.A_L / p.A_OD, p.A_T / B**2, L / p.H_BR,
               p.A_T / (B * p.H_BR), p.A_L / (L * B), p.A_L / L**2),
        "N3": (1.0, p.x_AOD / L, p.A_T / (B * p.H_BR), p.A_L / p.A_T),
    }


def fujiwara_amplitudes(particulars: WindParticulars = ESSO_OSAKA_MODEL) -> dict[str, float]:
    """Fourier amplitudes X0, X1, X3, X5, Y1, Y3, Y5, N1, N2, N3 of the Fujiwara regression.

    Parameters
    ----------
    particulars : WindParticulars
        Above-water geometry of the ship.

    Returns
    -------
    dict of str to float
        The ten amplitudes, in the regression's own sign convention (angle positive
        for wind from port; see the module docstring).
    """
    g = _groups(particulars)
    return {k: float(np.dot(_FUJIWARA[k], g[k])) for k in _FUJIWARA}


def fujiwara_coefficients(angle, particulars: WindParticulars = ESSO_OSAKA_MODEL):
    """Wind coefficients C_X, C_Y, C_N at a relative wind angle of attack.

    Parameters
    ----------
    angle : array_like
        Relative wind angle gamma [rad]: the direction the apparent wind comes FROM,
        from the bow, positive towards starboard. Any real value (periodic in 2 pi).
    particulars : WindParticulars
        Above-water geometry of the ship.

    Returns
    -------
    C_X, C_Y, C_N : ndarray
        Coefficients in ship axes (x forward, y starboard, N bow to starboard) with
        ``X = q A_T C_X``, ``Y = q A_L C_Y``, ``N = q A_L L C_N`` and ``q = rho V^2 / 2``.
        C_X is even in gamma, C_Y and C_N are odd; head wind gives C_X < 0 and wind
        from starboard gives C_Y < 0.
    """
    a = np.asarray(angle, dtype=float)
    return fujiwara_series(np.cos(a), np.sin(a), amplitude_vector(particulars))


AMPLITUDES = ("X0", "X1", "X3", "X5", "Y1", "Y3", "Y5", "N1", "N2", "N3")
"""Order of the amplitudes in :func:`amplitude_vector` and :func:`fujiwara_series`."""


def amplitude_vector(particulars: WindParticulars = ESSO_OSAKA_MODEL, sway_factor: float = 1.0,
                     yaw_factor: float = 1.0, yaw_sin: float = 0.0) -> np.ndarray:
    """The ten Fujiwara amplitudes as an array in the order of :data:`AMPLITUDES`, with the shape terms.

    The one place the wind effect's shape terms act (:class:`mmg.effects.Wind`): the sway amplitudes
    Y1, Y3, Y5 times ``sway_factor`` and the yaw amplitudes N1, N2, N3 times ``yaw_factor`` (the series
    is linear in them, so C_Y and C_N are the published ones times the factors at every angle; C_X
    unchanged), and ``yaw_sin`` sin(gamma) added to C_N (in N1: the lateral load's centre moved along
    the ship by about ``yaw_sin`` / |C_Y| of L, aft when positive: the bow turned towards the wind).  Used by :func:`wind_forces` (the replay's loads from the measured wind) and by the
    simulator's steady wind (the ``P_WIND_AMP`` slots of :mod:`mmg.model`, written by
    :meth:`mmg.effects.Wind.pack`).

    Parameters
    ----------
    particulars : WindParticulars
        Above-water geometry of the ship.
    sway_factor, yaw_factor : float
        Factors on the sway force and the yaw moment (1: as published).
    yaw_sin : float
        Yaw-moment coefficient added times sin(gamma) (0: as published).

    Returns
    -------
    ndarray, shape (10,)
    """
    A = fujiwara_amplitudes(particulars)
    f = {"Y": float(sway_factor), "N": float(yaw_factor)}
    out = np.array([A[k] * f.get(k[0], 1.0) for k in AMPLITUDES])
    out[AMPLITUDES.index("N1")] -= float(yaw_sin)            # C_N = -(N1 sin g + ...): the regression's angle is -g
    return out


def fujiwara_series(c, s, A):
    """The Fujiwara Fourier series C_X, C_Y, C_N from cos gamma and sin gamma.

    The one definition of the series, used by :func:`fujiwara_coefficients` (arrays) and,
    compiled, by the simulator's steady-wind loads (:func:`mmg.model.wind_loads`, real or complex
    scalars).  The multiple angles are written as polynomials in ``c = cos gamma`` and
    ``s = sin gamma`` (cos 3g = 4c^3 - 3c, cos 5g = 16c^5 - 20c^3 + 5c, sin 2g = 2sc,
    sin 3g = 3s - 4s^3, sin 5g = s (16c^4 - 12c^2 + 1)), so the loads follow from the components
    of the apparent wind without an arctangent and stay analytic for complex-step derivatives.

    Parameters
    ----------
    c, s : float, complex or ndarray
        cos and sin of the relative wind angle gamma (comes FROM, from the bow, + to starboard).
    A : sequence of 10 floats
        :func:`amplitude_vector`.

    Returns
    -------
    C_X, C_Y, C_N
        As :func:`fujiwara_coefficients`.
    """
    c2 = c * c
    s2 = s * s
    cx = A[0] + A[1] * c + A[2] * (4.0 * c2 - 3.0) * c + A[3] * ((16.0 * c2 - 20.0) * c2 + 5.0) * c
    # The regression angle is -gamma; sin is odd, cos even.
    cy = -(A[4] * s + A[5] * (3.0 - 4.0 * s2) * s + A[6] * ((16.0 * c2 - 12.0) * c2 + 1.0) * s)
    cn = -(A[7] * s + A[8] * 2.0 * s * c + A[9] * (3.0 - 4.0 * s2) * s)
    return cx, cy, cn


@dataclass(frozen=True)
class WindShape:
    """The wind effect's shape terms on the published loads (:func:`amplitude_vector`; all neutral by default).

    Attributes
    ----------
    sway_factor : float
        Factor on the sway force [-] (1: as published).
    yaw_factor : float
        Factor on the yaw moment [-] (1: as published).
    yaw_sin : float
        Yaw-moment coefficient [-] added times sin(gamma) (0: as published).
    """

    sway_factor: float = 1.0
    yaw_factor: float = 1.0
    yaw_sin: float = 0.0


def wind_forces(V_rel, angle_rel, particulars: WindParticulars = ESSO_OSAKA_MODEL,
                rho_air: float = RHO_AIR, scale: float = 1.0, shape: WindShape | None = None):
    """Wind surge force, sway force and yaw moment about midship from the relative wind.

    Parameters
    ----------
    V_rel : array_like
        Relative (apparent) wind speed [m/s], >= 0.
    angle_rel : array_like
        Relative wind angle gamma [rad]: direction the apparent wind comes FROM, from
        the bow, positive towards starboard (use :func:`angle_from_dataset` for the
        FRT-DS-ESSO column ``wind_dir_relative_mid``). Broadcast against ``V_rel``.
    particulars : WindParticulars
        Above-water geometry (default: the 3 m Esso Osaka model).
    rho_air : float
        Air density [kg/m^3].
    scale : float
        Overall factor on all three loads (1 = as published).
    shape : WindShape, optional
        Further factors on the sway force and the yaw moment alone and the added sin(gamma) yaw term
        (:func:`amplitude_vector`); default: as published.

    Returns
    -------
    X, Y, N : ndarray
        Surge force [N] (x forward), sway force [N] (y to starboard) and yaw moment
        about midship [N m] (positive bow to starboard).

    Examples
    --------
    >>> X, Y, N = wind_forces(2.0, 0.0)         # head wind: drag
    >>> bool(X < 0)
    True
    >>> X, Y, N = wind_forces(2.0, np.pi / 2)   # from starboard: pushed to port
    >>> bool(Y < 0)
    True
    """
    V = np.asarray(V_rel, dtype=float)
    if np.any(V < 0):
        raise ValueError("V_rel must be >= 0")
    p = particulars
    a = np.asarray(angle_rel, dtype=float)
    sh = WindShape() if shape is None else shape
    cx, cy, cn = fujiwara_series(np.cos(a), np.sin(a), amplitude_vector(p, sh.sway_factor, sh.yaw_factor, sh.yaw_sin))
    return coefficient_loads(V, cx, cy, cn, p, rho_air, scale)


def coefficient_loads(V_rel, cx, cy, cn, particulars: WindParticulars, rho_air: float = RHO_AIR,
                      scale: float = 1.0):
    """Wind loads from their non-dimensional coefficients: X = q A_T C_X, Y = q A_L C_Y, N = q A_L L C_N.

    Parameters
    ----------
    V_rel : array_like
        Apparent wind speed [m/s].
    cx, cy, cn : array_like
        Surge, sway and yaw-moment coefficients [-] at the relative wind angle.
    particulars : WindParticulars
        Its ``A_T``, ``A_L`` [m^2] and ``L`` [m] (the moment's arm).
    rho_air : float
        Air density [kg/m^3].
    scale : float
        Factor on all three loads (1 = as the coefficients give).

    Returns
    -------
    X, Y, N : float or ndarray
        Surge force [N], sway force [N] and yaw moment about midship [N m], q = rho_air V_rel^2 / 2.
    """
    q = 0.5 * rho_air * np.asarray(V_rel, dtype=float) ** 2 * scale
    p = particulars
    return q * p.A_T * cx, q * p.A_L * cy, q * p.A_L * p.L * cn


def angle_from_dataset(dir_rel):
    """Map FRT-DS-ESSO ``wind_dir_relative_mid`` [rad, 0..2 pi] to this module's gamma.

    The data set logs the direction the apparent wind comes FROM, from the bow,
    clockwise (towards starboard), in [0, 2 pi); this is the module convention, so the
    map only wraps to (-pi, pi].

    Parameters
    ----------
    dir_rel : array_like
        ``wind_dir_relative_mid`` [rad].

    Returns
    -------
    ndarray
        gamma in (-pi, pi] [rad].
    """
    d = np.asarray(dir_rel, dtype=float)
    g = np.mod(d + np.pi, 2 * np.pi) - np.pi
    return np.where(g == -np.pi, np.pi, g)


def true_wind_from_relative(V_rel, dir_rel, u, v, psi):
    """True wind (over ground) from the apparent wind measured on board.

    Parameters
    ----------
    V_rel : array_like
        Apparent wind speed at the anemometer (midship) [m/s].
    dir_rel : array_like
        Apparent wind direction [rad]: comes FROM, from the bow, clockwise
        (``wind_dir_relative_mid``; gamma of this module, any wrap).
    u, v : array_like
        Surge and sway velocity over ground of the anemometer point (midship) [m/s],
        x forward, y to starboard (``u_velo``, ``vm_velo``).
    psi : array_like
        Heading [rad], clockwise from the earth x axis (north), ``psi_hat``.

    Returns
    -------
    V_true : ndarray
        True wind speed [m/s].
    dir_true : ndarray
        True wind direction [rad] in [0, 2 pi): comes FROM, clockwise from the earth x
        axis (north), the convention of ``wind_dir_true``.
    """
    Vr = np.asarray(V_rel, dtype=float)
    g = np.asarray(dir_rel, dtype=float)
    psi = np.asarray(psi, dtype=float)
    # air velocity over ground in ship axes = air velocity relative to ship + ship velocity
    ax = -Vr * np.cos(g) + np.asarray(u, dtype=float)
    ay = -Vr * np.sin(g) + np.asarray(v, dtype=float)
    wn = ax * np.cos(psi) - ay * np.sin(psi)
    we = ax * np.sin(psi) + ay * np.cos(psi)
    return np.hypot(wn, we), np.mod(np.arctan2(-we, -wn), 2 * np.pi)


def relative_wind_from_true(V_true, dir_true, u, v, psi):
    """Apparent wind on board from the true wind (inverse of :func:`true_wind_from_relative`).

    Parameters
    ----------
    V_true : array_like
        True wind speed [m/s].
    dir_true : array_like
        True wind direction [rad]: comes FROM, clockwise from the earth x axis (north).
    u, v : array_like
        Surge and sway velocity over ground of the point considered [m/s].
    psi : array_like
        Heading [rad], clockwise from north.

    Returns
    -------
    V_rel : ndarray
        Apparent wind speed [m/s].
    angle_rel : ndarray
        Apparent wind angle gamma [rad] in (-pi, pi]: comes FROM, from the bow,
        positive towards starboard.
    """
    rel = np.asarray(dir_true, dtype=float) - np.asarray(psi, dtype=float)
    ax, ay = apparent_air_velocity(np.asarray(V_true, dtype=float), rel, np.asarray(u, dtype=float),
                                   np.asarray(v, dtype=float))
    return np.hypot(ax, ay), angle_from_dataset(np.arctan2(-ay, -ax))


def apparent_air_velocity(V_true, rel, u, v):
    """The air's velocity relative to the ship, in ship axes [m/s]: the true wind's minus the ship's.

    The one definition of the apparent wind: :func:`relative_wind_from_true` and the simulator's
    steady-wind loads (:func:`mmg.model.wind_loads`, which compiles this function) use it.

    Parameters
    ----------
    V_true : float or array
        True wind speed [m/s].
    rel : float or array
        True wind direction (comes FROM, clockwise from north) minus the heading [rad].
    u, v : float or array
        The ship's velocity over ground in ship axes [m/s] (x forward, y to starboard).

    Returns
    -------
    ax, ay : float or array
        Apparent air velocity [m/s], x forward, y to starboard (the wind blows along it: it comes
        from the direction of -(ax, ay)).
    """
    return -V_true * np.cos(rel) - u, -V_true * np.sin(rel) - v
