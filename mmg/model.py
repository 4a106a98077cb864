"""The 3-DOF MMG model: forces and equations of motion as small compiled functions.

State vector (SI), index constants below::

    x = [u, v, r, x0, y0, psi, delta, n]

u, v    surge and sway velocity of midship through the water [m/s]
r       yaw rate [rad/s]
x0, y0  position of midship over ground, north and east [m]
psi     heading [rad], delta rudder angle [rad] (+ to starboard), n propeller revolutions [rps]

Forces follow Rhee & Kim (1999) eqs. (1)-(20) with the MMG rudder and propeller
model of Yasukawa & Yoshimura (2015); the equations of motion are written about
midship with the centre of gravity at x_G (x_G = 0 gives Rhee & Kim eqs. 1-3).
Outside the first quadrant (propeller astern, ship moving astern) the thrust is the Wageningen
B4-70 four-quadrant curve anchored to the ship's K_T(J) (:func:`thrust_coefficient`,
:mod:`mmg.fourquadrant`) and the rudder takes reversed inflow (:func:`rudder`).

The ship is packed once into a flat parameter vector ``p`` (layout below), a
polynomial table ``poly`` and the hull's term tables, so every function here
compiles with numba and runs on real or complex numbers (complex-step
derivatives for the estimator use the same code).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from ._jit import njit

from ._inlining import hot_loops_only
from .nondim import force_scale, inertia_scale, mass_scale, moment_scale, r_prime
from .fourquadrant import N_HARMONICS, atan2_of, b4_70_coefficients, ct_from_kt, fourier_ct, pitch_angle
from .terms import AXES, TERMS, V_PARITY, sabs, term_value
from .wind import apparent_air_velocity, fujiwara_series

_fujiwara_series = njit(cache=True, error_model="numpy", inline="always")(fujiwara_series)
_apparent_air_velocity = njit(cache=True, error_model="numpy", inline="always")(apparent_air_velocity)

# state indices
U_, V_, R_, X_, Y_, PSI_, DELTA_, N_ = range(8)
STATE_NAMES = ("u", "v", "r", "x", "y", "psi", "delta", "n")
STATE_UNITS = ("m/s", "m/s", "rad/s", "m", "m", "rad", "rad", "rps")

# parameter-vector layout
(
    P_RHO, P_L, P_T, P_XG, P_M, P_MX, P_MY, P_IZ, P_JZ,
    P_D, P_XP, P_WAKE, P_CWAKE, P_C1, P_C2POS, P_C2NEG, P_KQSCALE,
    P_AR, P_FALPHA, P_EPS, P_KAPPA, P_ETA, P_TR, P_AH, P_XH, P_XR, P_GPOS, P_GNEG, P_LR,
    P_TE, P_RATE, P_DMAX,
    P_ENGINE, P_POWER, P_SHAFT_I,
    P_CUR_SPEED, P_CUR_DIR, P_RUDDER_OFFSET, P_EXT_X, P_EXT_Y, P_EXT_N,
    P_ULOW,
    P_WIND_V, P_WIND_FROM, P_WIND_Q, P_WIND_AT, P_WIND_AL, P_WIND_ALL, P_WIND_AMP,
) = range(49)
N_WIND_AMP = 10
"""Slots P_WIND_AMP .. P_WIND_AMP + 9: the Fujiwara amplitudes (:func:`mmg.wind.amplitude_vector`)."""
P_FQ_SCALE = P_WIND_AMP + N_WIND_AMP
"""Factor on the B4-70 C_T* series: the config's bollard K_T(0) over the series' (:func:`thrust_coefficient`)."""
P_FQ_BLEND = P_FQ_SCALE + 1
"""C_T* added at beta_p = :data:`BETA_ANCHOR`, faded out by 90 deg (:func:`thrust_coefficient`)."""
P_FQ_A = P_FQ_BLEND + 1
"""Slots P_FQ_A .. + 2 N_HARMONICS - 1: the A_k then the B_k of the ship's B4-70 series (:mod:`mmg.fourquadrant`)."""
P_YP_ASTERN = P_FQ_A + 2 * N_HARMONICS
"""Lateral force coefficient of the propeller running astern, Y_P / (rho n^2 D^4) for n < 0
(:func:`propeller_lateral`; the config's ``propeller.Y_P_astern``)."""
P_HULL_ASTERN = P_YP_ASTERN + 1
"""1 where the hull's terms act astern as the ship moving ahead turned end for end, 0 where each acts as
written for ahead (the config's ``hull.astern``; :func:`astern_factor`)."""
N_PARAMS = P_HULL_ASTERN + 1

LOW_SPEED_FROUDE = 0.01
"""Froude number below which the hull's speed scale is floored (:func:`kinematics`): U_low =
0.01 sqrt(g L): 0.054 m/s for the 3 m model, 0.57 m/s (1.1 kn) for the 325 m ship, below the 0.75 m/s
the Esso Osaka keeps in the steady phase of its 35 deg turn (so every full-scale trial stays above it)."""
J_MAX = 1.2
"""Largest advance ratio the ship's own K_T(J) polynomial is evaluated at (:func:`propeller`): the
first quadrant up to J_MAX is the config's K_T, everything else the four-quadrant curve
(:func:`thrust_coefficient`)."""
BETA_ANCHOR = float(np.arctan(J_MAX / (0.7 * np.pi)))
"""Hydrodynamic pitch angle [rad] of J = J_MAX (28.6 deg): below it C_T* is the config's K_T(J)."""
G = 9.80665

# polynomial table rows
POLY_KT, POLY_KQ, POLY_TP, POLY_WP0 = range(4)

ENGINE_CONSTANT_POWER, ENGINE_CONSTANT_RPM = 0, 1
WAKE_KIJIMA, WAKE_MMG2015 = 0, 1


@dataclass(frozen=True)
class PackedShip:
    """A ship in the arrays the compiled code reads (see module docstring)."""

    p: np.ndarray
    poly: np.ndarray
    hull_axis: np.ndarray
    hull_term: np.ndarray
    hull_coef: np.ndarray

    def args(self):
        """Positional arguments of the compiled functions after the state."""
        return self.p, self.poly, self.hull_axis, self.hull_term, self.hull_coef


def _poly_table(rows) -> np.ndarray:
    """The polynomials as the rows of one table, zero-padded to the longest (Horner over a
    padded zero is exact, so the width only sets the work of :func:`polyval`)."""
    out = np.zeros((len(rows), max(1, max(len(c) for c in rows))))
    for i, c in enumerate(rows):
        out[i, : len(c)] = c
    return out


def pack(ship: "mmg.ship.Ship", engine_power_W: float = 0.0) -> PackedShip:
    """Pack a :class:`~mmg.ship.Ship` into arrays.

    Parameters
    ----------
    ship : Ship
    engine_power_W : float
        Delivered power P_0 [W] for a constant-power engine (from the approach
        condition, see :func:`mmg.equilibrium.engine_power`).
    """
    pa, ms, pr, ru, st, en = ship.particulars, ship.mass, ship.propeller, ship.rudder, ship.steering, ship.engine
    p = np.zeros(N_PARAMS)
    p[P_RHO], p[P_L], p[P_T], p[P_XG] = pa.rho, pa.L, pa.T, pa.x_G
    # the Python bodies: compiling a specialisation for two products of four floats would cost
    # a cold start a second or two (same IEEE operations, same values)
    ms_ = mass_scale.py_func(pa.rho, pa.L, pa.T)
    is_ = inertia_scale.py_func(pa.rho, pa.L, pa.T)
    p[P_M], p[P_MX], p[P_MY] = ms.m_prime * ms_, ms.m_x_prime * ms_, ms.m_y_prime * ms_
    p[P_IZ], p[P_JZ] = ms.I_zG_prime * is_, ms.J_z_prime * is_
    p[P_D], p[P_XP] = pr.D, pr.x_P_prime
    p[P_WAKE] = WAKE_KIJIMA if pr.wake_model == "kijima" else WAKE_MMG2015
    p[P_CWAKE], p[P_C1], p[P_C2POS], p[P_C2NEG], p[P_KQSCALE] = pr.C_wake, pr.C_1, pr.C_2_pos, pr.C_2_neg, pr.K_Q_scale
    p[P_AR], p[P_FALPHA], p[P_EPS], p[P_KAPPA], p[P_ETA] = ru.A_R, ru.f_alpha, ru.epsilon, ru.kappa, ru.eta
    p[P_TR], p[P_AH], p[P_XH], p[P_XR] = ru.t_R, ru.a_H, ru.x_H_prime * pa.L, ru.x_R_prime * pa.L
    p[P_GPOS], p[P_GNEG], p[P_LR] = ru.gamma_R_pos, ru.gamma_R_neg, ru.l_R_prime
    p[P_TE], p[P_RATE], p[P_DMAX] = st.T_E, st.rate_max, st.delta_max
    p[P_ENGINE] = ENGINE_CONSTANT_POWER if en.mode == "constant_power" else ENGINE_CONSTANT_RPM
    p[P_POWER] = engine_power_W
    p[P_SHAFT_I] = en.shaft_inertia_coefficient * pr.D**5
    p[P_ULOW] = LOW_SPEED_FROUDE * np.sqrt(G * pa.L)
    p[P_FQ_SCALE], p[P_FQ_BLEND], p[P_FQ_A:P_YP_ASTERN] = four_quadrant_slots(pr.K_T, pr.P_D)
    p[P_YP_ASTERN] = pr.Y_P_astern
    if ship.hull.astern not in ("as_ahead", "end_for_end"):
        raise ValueError(f"hull.astern {ship.hull.astern!r}: expected as_ahead or end_for_end")
    p[P_HULL_ASTERN] = 1.0 if ship.hull.astern == "end_for_end" else 0.0
    poly = _poly_table([pr.K_T, pr.K_Q, pr.t_P, pr.w_P0])
    h = ship.hull
    return PackedShip(
        p=p,
        poly=poly,
        hull_axis=np.array([AXES[a] for a in h.axes], dtype=np.int64),
        hull_term=np.array([TERMS[t] for t in h.terms], dtype=np.int64),
        hull_coef=np.array(h.values, dtype=np.float64),
    )


def four_quadrant_slots(K_T, P_D):
    """(scale, blend, series) of :func:`thrust_coefficient` for a propeller of open-water K_T(J)
    (coefficients lowest power first) and pitch ratio P_D (None: :data:`mmg.fourquadrant.PD_DEFAULT`).

    series: the A_k then the B_k of the B4-70 C_T* curve at P_D (:func:`mmg.fourquadrant.b4_70_coefficients`);
    scale = C_T*(0) of K_T over the series' (the bollard anchor, so beta_p = 0 = 360 deg joins);
    blend = C_T* of K_T at J_MAX minus scale x the series there (added at BETA_ANCHOR, faded out by 90 deg)."""
    a, b = b4_70_coefficients(P_D)
    series = np.concatenate([a, b])
    kt = np.polynomial.polynomial.polyval
    fourier = fourier_ct.py_func
    scale = ct_from_kt.py_func(kt(0.0, K_T), 0.0) / fourier(0.0, series, 0, N_HARMONICS)
    blend = ct_from_kt.py_func(kt(J_MAX, K_T), J_MAX) - scale * fourier(BETA_ANCHOR, series, 0, N_HARMONICS)
    return scale, blend, series


# --------------------------------------------------------------------------- force components


@njit(cache=True, inline="always")
def polyval(poly, row, x):
    """Polynomial ``poly[row]`` (coefficients lowest power first) at ``x`` (Horner).

    Indexes the table in place: a row view ``poly[row]`` would be a new array reference (a
    reference-count increment and decrement) at every evaluation."""
    w = poly.shape[1]
    acc = poly[row, w - 1] + 0.0 * x
    for i in range(w - 2, -1, -1):
        acc = acc * x + poly[row, i]
    return acc


@njit(cache=True, error_model="numpy", inline=hot_loops_only)
def kinematics(u, v, r, p):
    """Speed U [m/s], the hull's speed scale U_h [m/s], drift angle beta [rad], v' and r' at midship.

    Above U_low = ``p[P_ULOW]`` (:data:`LOW_SPEED_FROUDE` sqrt(g L)) this is the textbook set:
    U_h = U, beta = atan(-v/u), v' = v/U, r' = r L/U.  Below it, where beta and r' lose their
    meaning (every measured record starts at rest), the speed scale is floored smoothly,
    U_h = (U^2 + U_low^2) / (2 U_low) (equal to U, with equal slope, at U_low; U_low/2 at rest),
    and v' = v/U_h, r' = r L/U_h, beta = atan(-v / sqrt(U_h^2 - v^2)), all bounded at U = 0.
    Going astern (u < 0, outside the Kijima polynomials' range) beta is atan(-v/|u|), the flow
    along the hull as if ahead; with the config's ``hull.astern: end_for_end`` :func:`astern_factor` then
    turns the terms that change sign with the direction of motion (the Munk moment, the sway force of
    yawing), and in either case :func:`forces_of` turns the
    surge force with the motion (factor clip(u / U_low, -1, 1)).  The
    hull forces are the primed forces times 1/2 rho L T U U_h (:func:`hull_scales`), so they fall
    to zero at rest, the quadratic resistance turning linear in U below U_low (a laminar-like
    floor), and the manoeuvring derivatives act as linear damping there, Y = 1/2 rho L T Y_v' v U_h.
    The choice keeps every result above U_low (all of the full-scale trials) bit for bit.
    """
    U = np.sqrt(u * u + v * v)
    ul = p[P_ULOW]
    if U.real >= ul:
        au = u if u.real >= 0.0 else -u          # astern: beta of the flow along the hull, so sway stays damped
        return U, U, np.arctan(-v / au), v / U, r_prime(r, p[P_L], U)
    Uh = (U * U + ul * ul) / (2.0 * ul)
    uh = np.sqrt(Uh * Uh - v * v)
    return U, Uh, np.arctan(-v / uh), v / Uh, r_prime(r, p[P_L], Uh)


@njit(cache=True, error_model="numpy", inline=hot_loops_only)
def hull_primed(beta, vp, rp, hull_axis, hull_term, hull_coef):
    """Primed hull forces (X_H', Y_H', N_H') = sum of coefficient x term per axis, each term as written
    (ahead; astern with ``hull.astern: as_ahead``; :func:`hull_primed_at` chooses)."""
    X = 0.0 * beta
    Y = 0.0 * beta
    N = 0.0 * beta
    for i in range(hull_coef.shape[0]):
        X, Y, N = _on_axis(hull_axis[i], hull_coef[i] * term_value(hull_term[i], beta, vp, rp), X, Y, N)
    return X, Y, N


@njit(cache=True, error_model="numpy", inline="always")
def _on_axis(a, val, X, Y, N):
    """(X, Y, N) with ``val`` added to axis ``a`` (0 X, 1 Y, 2 N)."""
    if a == 0:
        return X + val, Y, N
    if a == 1:
        return X, Y + val, N
    return X, Y, N + val


@njit(cache=True, error_model="numpy", inline="always")
def hull_primed_at(beta, vp, rp, u, p, hull_axis, hull_term, hull_coef):
    """Primed hull forces at the surge velocity u [m/s]: :func:`hull_primed`, or moving astern with the
    config's ``hull.astern: end_for_end`` (``p[P_HULL_ASTERN]``) :func:`hull_primed_astern`."""
    if p[P_HULL_ASTERN] != 0.0 and u.real < 0.0:
        return hull_primed_astern(beta, vp, rp, u, p, hull_axis, hull_term, hull_coef)
    return hull_primed(beta, vp, rp, hull_axis, hull_term, hull_coef)


@njit(cache=True, error_model="numpy")
def hull_primed_astern(beta, vp, rp, u, p, hull_axis, hull_term, hull_coef):
    """:func:`hull_primed` moving astern (u < 0 [m/s]) with ``hull.astern: end_for_end``: each term times
    its :func:`astern_factor`."""
    X = 0.0 * beta
    Y = 0.0 * beta
    N = 0.0 * beta
    for i in range(hull_coef.shape[0]):
        a = hull_axis[i]
        val = hull_coef[i] * term_value(hull_term[i], beta, vp, rp) * astern_factor(a, hull_term[i], u, p)
        X, Y, N = _on_axis(a, val, X, Y, N)
    return X, Y, N


@njit(cache=True, error_model="numpy", inline="always")
def astern_factor(axis, tid, u, p):
    """Factor on hull term ``tid`` of axis ``axis`` (0 X, 1 Y, 2 N) at the surge velocity u [m/s].

    The hull's terms are written for the ship moving ahead.  Moving astern with sway v and yaw rate r,
    the flow about the hull is that of the ship moving ahead with sway -v and the same r, turned end
    for end: (X, Y, N)(u, v, r) = (-X, -Y, N)(|u|, -v, r) for a hull alike at both ends.
    :func:`kinematics` gives beta and v' of the motion as if ahead (the flow along the hull), so a term
    even in v (:data:`mmg.terms.V_PARITY`) changes sign astern on Y, an odd one on N: the Munk
    moment N_v v' and the lift Y_r r' take the sign of u, the damping Y_v and N_r keep theirs.  This
    is the low-speed hull model of Yoshimura (Y_v v|u| + Y_r r u, N_v v u + N_r r|u|), which the Osaka
    group fits to this 3 m model.  X's even terms turn with the motion through :func:`surge_sign`
    (the resistance opposes it); its odd terms (X_vr v r) keep their sign, so this factor turns them back.

    Where the config's ``hull.astern`` is ``as_ahead`` (``p[P_HULL_ASTERN]`` 0, the default) the factor
    is 1 everywhere: each term acts astern as written for ahead in the flow along the hull.  With
    ``end_for_end`` it is 1 for u >= 0, so nothing changes ahead.  On Y's even and N's odd terms it runs
    from 1 at u = 0 linearly to -1 at u = -U_low (``p[P_ULOW]``) and stays there: continuous in u.  On
    X's odd terms it is -1 for u < 0 (their product with :func:`surge_sign` is continuous, 0 at u = 0).
    """
    if u.real >= 0.0 or p[P_HULL_ASTERN] == 0.0:
        return 1.0 + 0.0 * u
    par = V_PARITY[tid]
    if axis == 0:
        return (-1.0 if par == -1 else 1.0) + 0.0 * u
    if (axis == 1 and par == 1) or (axis == 2 and par == -1):
        ul = p[P_ULOW]
        return (-1.0 + 0.0 * u) if u.real <= -ul else 1.0 + 2.0 * u / ul
    return 1.0 + 0.0 * u


@njit(cache=True, error_model="numpy", inline=hot_loops_only)
def one_minus_wake(u, beta, rp, p, poly):
    """(1 - w_P) in manoeuvring: Kijima exp(-C beta_P^2) or MMG 2015 form, beta_P = beta - x_P' r'."""
    w0 = polyval(poly, POLY_WP0, u)
    bp = beta - p[P_XP] * rp
    if p[P_WAKE] == WAKE_KIJIMA:
        return 1.0 - w0 * np.exp(-p[P_CWAKE] * bp * bp)
    c2 = p[P_C2POS] if bp.real > 0.0 else p[P_C2NEG]
    return (1.0 - w0) * (1.0 + (1.0 - np.exp(-p[P_C1] * sabs(bp))) * (c2 - 1.0))


@njit(cache=True, error_model="numpy", inline=hot_loops_only)
def thrust_coefficient(beta, p, poly):
    """C_T*(beta_p) of the ship's propeller at hydrodynamic pitch angle beta_p [rad] in [0, 2 pi).

    Up to :data:`BETA_ANCHOR` (first quadrant, J <= J_MAX) the config's own K_T(J), J = 0.7 pi tan(beta_p)
    (:func:`mmg.fourquadrant.ct_from_kt`).  Elsewhere the Wageningen B4-70 four-quadrant curve at the
    propeller's P/D (:mod:`mmg.fourquadrant`: van Lammeren et al. 1969, Fourier series of Roddy, Hess &
    Faller 2006) times ``p[P_FQ_SCALE]``, the config's bollard C_T*(0) over the series' (1.156 for the
    Esso Osaka: its K_T(0) = 0.349 against the B4-70's 0.302 at P/D 0.715), so the curve joins the
    config's at beta_p = 0 = 360 deg; between BETA_ANCHOR and 90 deg the gap left at J_MAX
    (``p[P_FQ_BLEND]``) is added with a weight cos^2 going from 1 to 0, so the curve is continuous there too.
    """
    if beta.real <= BETA_ANCHOR:
        J = 0.7 * np.pi * np.tan(beta)
        return ct_from_kt(polyval(poly, POLY_KT, J), J)
    c = p[P_FQ_SCALE] * fourier_ct(beta, p, P_FQ_A, N_HARMONICS)
    if beta.real < 0.5 * np.pi:
        w = np.cos(0.5 * np.pi * (beta - BETA_ANCHOR) / (0.5 * np.pi - BETA_ANCHOR))
        c = c + p[P_FQ_BLEND] * w * w
    return c


@njit(cache=True, error_model="numpy", inline="always")
def slipstream_weight(beta):
    """Share of the propeller's thrust loading that accelerates the flow onto the rudder, by the
    hydrodynamic pitch angle beta_p [rad]: 1 in the first quadrant up to :data:`BETA_ANCHOR`, falling
    as cos^2 to 0 at n = 0 (90 deg; 270 deg through the fourth quadrant, ship astern with the
    propeller ahead: cos^2 beta_p), 0 with the propeller astern (90-270 deg: its race goes forward,
    away from the rudder).  Continuous, so the rudder force is continuous as n crosses 0."""
    if beta.real <= BETA_ANCHOR:
        return 1.0 + 0.0 * beta
    if beta.real < 0.5 * np.pi:
        w = np.cos(0.5 * np.pi * (beta - BETA_ANCHOR) / (0.5 * np.pi - BETA_ANCHOR))
        return w * w
    if beta.real > 1.5 * np.pi:
        c = np.cos(beta)
        return c * c
    return 0.0 * beta


@njit(cache=True, error_model="numpy", inline=hot_loops_only)
def propeller(u, n, one_minus_wP, p, poly):
    """Advance ratio J_P, surge force X_P [N] (eq. 12) and the slipstream's thrust loading [m^2/s^2].

    First quadrant with J <= :data:`J_MAX`: the config's K_T(J), X_P = (1 - t_P) rho n^2 D^4 K_T, as
    ever.  Everywhere else the four-quadrant form T = C_T*(beta_p) 1/2 rho (V_A^2 + (0.7 pi n D)^2)
    pi D^2/4 (:func:`thrust_coefficient`, :mod:`mmg.fourquadrant`), which is bounded and continuous
    across n = 0 and V_A = 0 and zero at rest.  V_A = u (1 - w_P) ahead (0 where a wake polynomial
    extrapolated far past its speeds gives 1 - w_P < 0: the bollard J = 0 the model always took there);
    going astern (u < 0) the propeller meets the flow before the hull, V_A = u (no wake), t_P = t_P(0).
    The loading returned is 8 T / (pi rho D^2) = C_T* (V_A^2 + (0.7 pi n D)^2) (= 8 K_T (n D)^2 / pi)
    times :func:`slipstream_weight`, what the rudder's slipstream sees (:func:`rudder`).  J_P (for
    the shaft's torque, :func:`shaft_acceleration`) is J_MAX beyond it ahead and 0 astern, as before.
    """
    D = p[P_D]
    ahead = u.real >= 0.0
    uP = (u * one_minus_wP if one_minus_wP.real >= 0.0 else 0.0 * u) if ahead else u
    tP = polyval(poly, POLY_TP, u if ahead else 0.0 * u)
    if n.real >= 0.0 and uP.real >= 0.0 and (n * D).real * J_MAX > uP.real:
        J = uP / (n * D)
        KT = polyval(poly, POLY_KT, J)
        XP = (1.0 - tP) * p[P_RHO] * n * n * D ** 4 * KT
        nD = n * D
        return J, XP, 8.0 * KT * nD * nD / np.pi
    x07 = 0.7 * np.pi * n * D
    beta = pitch_angle(uP, x07)
    TL = thrust_coefficient(beta, p, poly) * (uP * uP + x07 * x07)
    XP = (1.0 - tP) * 0.125 * np.pi * p[P_RHO] * D * D * TL
    J = J_MAX + 0.0 * uP if (n.real >= 0.0 and uP.real >= 0.0) else 0.0 * uP
    return J, XP, TL * slipstream_weight(beta)


@njit(cache=True, error_model="numpy", inline="always")
def propeller_lateral(n, p):
    """Sway force [N] and yaw moment about midship [N m] of a propeller running astern (n < 0): the
    transverse thrust ("propeller walk") of a single screw whose race, thrown forward, strikes the
    stern quarters unevenly (a right-handed screw walks the stern to port: Y_P < 0, bow to starboard).

    Y_P = Y_P* rho n^2 D^4 with Y_P* = ``p[P_YP_ASTERN]`` (the config's ``propeller.Y_P_astern``, 0 by
    default: no force), acting at the propeller, N_P = x_P' L Y_P; 0 for n >= 0.  One constant, as the
    Osaka group's low-speed MMG writes the reversing propeller's lateral force over n^2 D^4 (there a
    function of the advance ratio from captive tests; none exists for this propeller, so the constant
    is the identification's to fit).  Zero with zero slope at n = 0, so the forces stay continuous
    (and smooth) as the propeller reverses."""
    if n.real >= 0.0:
        return 0.0 * n, 0.0 * n
    Y = p[P_YP_ASTERN] * p[P_RHO] * n * n * p[P_D] ** 4
    return Y, p[P_XP] * p[P_L] * Y


@njit(cache=True, error_model="numpy", inline="always")
def rudder_axial_speed(uP, TL, p):
    """Signed axial inflow speed at the rudder [m/s] (> 0: from the leading edge) for any signs of
    u_P and the slipstream loading TL [m^2/s^2] (:func:`propeller`).

    The propeller race adds dq = sqrt(u_P^2 + TL) - |u_P| to the axial speed behind the disc (the
    MMG slipstream, kappa dq of it at the rudder: a_s = u_P + kappa dq), and the rudder's mean
    axial speed is the signed root of the momentum-weighted mean eta a_s|a_s| + (1 - eta) u_P|u_P|,
    times epsilon.  For u_P >= 0 this is the MMG u_R = epsilon sqrt(eta a_s^2 + (1 - eta) u_P^2);
    it goes through 0 continuously when the mean flow reverses (ship astern, race not strong enough)."""
    s2 = uP * uP + TL
    au = sabs(uP)
    dq = (np.sqrt(s2) if s2.real > 0.0 else 0.0 * s2) - au
    a_s = uP + p[P_KAPPA] * dq
    m = p[P_ETA] * a_s * sabs(a_s) + (1.0 - p[P_ETA]) * uP * au
    q = np.sqrt(sabs(m))
    return p[P_EPS] * (q if m.real >= 0.0 else -q)


@njit(cache=True, error_model="numpy", inline=hot_loops_only)
def rudder(u, U, beta, rp, delta, n, one_minus_wP, TL, p):
    """MMG rudder forces (X_R, Y_R, N_R) [N, N, N m] and the normal force F_N [N], in all four quadrants.

    Ahead with the propeller ahead (u, n >= 0) the MMG rudder as ever: the slipstream speed
    u_P sqrt(1 + 8 K_T / (pi J^2)) written sqrt(u_P^2 + TL), TL = 8 K_T (n D)^2 / pi (:func:`propeller`),
    defined as u_P or n go to zero; beta, r' are those of :func:`kinematics`, so v_R = U gamma_R beta_R
    stays bounded at rest.  Otherwise (the propeller astern, or the ship moving astern, where
    u_P = u) the signed axial inflow of :func:`rudder_axial_speed`; the angle of attack
    alpha_R = delta - atan2(v_R, u_R) then measures the flow from the trailing edge when it comes from
    behind (u_R < 0), so F_N = 1/2 rho A_R (u_R^2 + v_R^2) f_alpha sin(alpha_R) reverses with the
    flow, continuously (through the cross flow at u_R = 0).  This is the reversed-inflow form of the
    Osaka group's low-speed MMG model of the Esso Osaka (u_R = u astern, alpha_R from atan2); the lift
    slope f_alpha is kept for reversed flow, as there: no published reduction was found to use.
    """
    d = delta + p[P_RUDDER_OFFSET]
    bR = beta - p[P_LR] * rp
    g = p[P_GPOS] if bR.real >= 0.0 else p[P_GNEG]
    vR = U * g * bR
    if n.real >= 0.0 and u.real >= 0.0:
        uP = u * one_minus_wP
        q2 = uP * uP + TL
        q = np.sqrt(q2) if q2.real > 0.0 else 0.0 * q2
        uPs = (1.0 - p[P_KAPPA]) * uP + p[P_KAPPA] * q            # u_P s
        uR = p[P_EPS] * np.sqrt(p[P_ETA] * uPs * uPs + (1.0 - p[P_ETA]) * uP * uP)
        if uR.real > 1e-12:
            alpha = d - np.arctan(vR / uR)
        else:                                                   # no inflow along the blade
            alpha = d - (np.pi / 2 if vR.real > 0.0 else -np.pi / 2 if vR.real < 0.0 else 0.0) + 0.0 * uR
    else:
        uR = rudder_axial_speed(u * one_minus_wP if u.real >= 0.0 else u, TL, p)
        alpha = d - atan2_of(vR, uR)
    FN = 0.5 * p[P_RHO] * p[P_AR] * (uR * uR + vR * vR) * p[P_FALPHA] * np.sin(alpha)
    cd = np.cos(d)
    XR = -(1.0 - p[P_TR]) * FN * np.sin(d)
    YR = -(1.0 + p[P_AH]) * FN * cd
    NR = -(p[P_XR] + p[P_AH] * p[P_XH]) * FN * cd
    return XR, YR, NR, FN


@njit(cache=True, error_model="numpy", inline=hot_loops_only)
def steering_rate(delta_cmd, delta, p):
    """Steering gear, Rhee & Kim eq. (20): rudder rate [rad/s] towards the clipped order."""
    dmax = p[P_DMAX]
    c = min(max(delta_cmd, -dmax), dmax)
    err = c - delta
    if abs(err.real) <= p[P_TE] * p[P_RATE]:
        return err / p[P_TE]
    return (p[P_RATE] if err.real > 0.0 else -p[P_RATE]) + 0.0 * err


@njit(cache=True, error_model="numpy", inline=hot_loops_only)
def shaft_acceleration(u, n, J, p, poly):
    """dn/dt [rps/s] of the shaft, eq. (15): 2 pi (I+J) dn/dt = Q_P + Q_E (constant power)."""
    if p[P_ENGINE] != ENGINE_CONSTANT_POWER:
        return 0.0 * n
    D = p[P_D]
    KQ = p[P_KQSCALE] * polyval(poly, POLY_KQ, J)
    QP = -p[P_RHO] * n * n * D ** 5 * KQ
    QE = p[P_POWER] / (2.0 * np.pi * n)
    return (QP + QE) / (2.0 * np.pi * p[P_SHAFT_I])


@njit(cache=True, error_model="numpy", inline="always")
def hull_scales(U, Uh, p):
    """Dimensional scales of the primed hull forces (X_H', Y_H', N_H') at speed U [m/s] with the
    hull's speed scale Uh [m/s] (:func:`kinematics`; Uh = U above the low-speed floor):
    (1/2 rho L T U Uh, 1/2 rho L T U Uh, 1/2 rho L^2 T U Uh) [N, N, N m]."""
    k = U * Uh
    fs = force_scale(p[P_RHO], p[P_L], p[P_T], 1.0) * k
    ms = moment_scale(p[P_RHO], p[P_L], p[P_T], 1.0) * k
    return fs, fs, ms


@njit(cache=True, error_model="numpy", inline="always")
def surge_sign(u, p):
    """Factor on the hull's surge force: 1 for u >= U_low, u / U_low between -U_low and U_low, -1
    below (the resistance opposes the motion astern too and is 0 at u = 0; :func:`kinematics`)."""
    ul = p[P_ULOW]
    if u.real >= ul:
        return 1.0 + 0.0 * u
    if u.real <= -ul:
        return -1.0 + 0.0 * u
    return u / ul


@njit(cache=True, error_model="numpy")
def forces(x, p, poly, hull_axis, hull_term, hull_coef):
    """Total surge and sway force [N] and yaw moment [N m] about midship, and J_P."""
    return forces_of(x[U_], x[V_], x[R_], x[DELTA_], x[N_], p, poly, hull_axis, hull_term, hull_coef)


@njit(cache=True, error_model="numpy", inline="always")
def forces_of(u, v, r, delta, n, p, poly, hull_axis, hull_term, hull_coef):
    """:func:`forces` of the states u, v [m/s], r [rad/s], delta [rad], n [rps] as scalars, each
    real or complex (a complex step in one of them leaves the parts that do not depend on it real)."""
    U, Uh, beta, vp, rp = kinematics(u, v, r, p)
    XHp, YHp, NHp = hull_primed_at(beta, vp, rp, u, p, hull_axis, hull_term, hull_coef)
    sX, sY, sN = hull_scales(U, Uh, p)
    owp = one_minus_wake(u, beta, rp, p, poly)
    J, XP, TL = propeller(u, n, owp, p, poly)
    XR, YR, NR, FN = rudder(u, U, beta, rp, delta, n, owp, TL, p)
    YP, NP = propeller_lateral(n, p)
    X = XHp * sX * surge_sign(u, p) + XP + XR + p[P_EXT_X]
    Y = YHp * sY + YR + YP + p[P_EXT_Y]
    N = NHp * sN + NR + NP + p[P_EXT_N]
    return X, Y, N, J


@njit(cache=True, error_model="numpy", inline="always")
def wind_loads(u, v, psi, p):
    """Loads (X, Y [N], N [N m] about midship) of a steady true wind on the ship at u, v [m/s] through
    the water and heading psi [rad]; (0, 0, 0) unless the ``wind`` effect gives a true wind speed.

    The true wind of speed ``p[P_WIND_V]`` [m/s] comes FROM ``p[P_WIND_FROM]`` [rad, clockwise from
    north]; the apparent wind is the true one minus the ship's velocity over ground (through the
    water plus the current; the anemometer is at midship: :func:`mmg.wind.apparent_air_velocity`,
    compiled) and acts through the Fujiwara series (:func:`mmg.wind.fujiwara_series`, the one
    definition the replay's measured-wind loads also use):
    X = q A_T C_X, Y = q A_L C_Y, N = q A_L L_oa C_N, q = 1/2 rho_air V_rel^2 times the effect's scale
    (``p[P_WIND_Q]`` = 1/2 rho_air scale).  Real or complex states (complex-step derivatives)."""
    Vt = p[P_WIND_V]
    if Vt == 0.0:
        z = 0.0 * u
        return z, z, z
    rel = p[P_WIND_FROM] - psi
    cur = p[P_CUR_DIR] - psi
    ax, ay = _apparent_air_velocity(Vt, rel, u, v)               # relative to the water: minus the current's
    ax = ax - p[P_CUR_SPEED] * np.cos(cur)
    ay = ay - p[P_CUR_SPEED] * np.sin(cur)
    V2 = ax * ax + ay * ay
    if V2.real < 1e-18:
        z = 0.0 * u
        return z, z, z
    V = np.sqrt(V2)
    cx, cy, cn = _fujiwara_series(-ax / V, -ay / V, p[P_WIND_AMP:P_WIND_AMP + N_WIND_AMP])
    q = p[P_WIND_Q] * V2
    return q * p[P_WIND_AT] * cx, q * p[P_WIND_AL] * cy, q * p[P_WIND_ALL] * cn


@njit(cache=True, error_model="numpy", inline="always")
def with_steady_wind(fx, fy, fn, u, v, psi, p):
    """External loads fx, fy [N], fn [N m] plus those of a steady true wind (:func:`wind_loads`) when
    the ``wind`` effect gives one (``p[P_WIND_V]`` != 0; else unchanged): the one steady-wind branch
    of the simulator's right-hand side (:func:`rhs_of`) and the replay's (:mod:`mmg.replay`)."""
    if p[P_WIND_V] != 0.0:
        wx, wy, wn = wind_loads(u, v, psi, p)
        return fx + wx, fy + wy, fn + wn
    return fx, fy, fn


@njit(cache=True, error_model="numpy", inline="always")
def force_accelerations(X, Y, N, p):
    """du/dt, dv/dt, dr/dt [m/s^2, m/s^2, rad/s^2] an added load X, Y [N], N [N m] about midship
    gives: the affine part of :func:`accelerations` (the inverse mass matrix times the load)."""
    m, mx, xG = p[P_M], p[P_MX], p[P_XG]
    a11 = m + p[P_MY]
    a12 = xG * m
    a22 = p[P_IZ] + xG * xG * m + p[P_JZ]
    det = a11 * a22 - a12 * a12
    return X / (m + mx), (Y * a22 - a12 * N) / det, (a11 * N - a12 * Y) / det


@njit(cache=True, error_model="numpy", inline="always")
def accelerations(X, Y, N, u, v, r, p, out):
    """The equations of motion about midship: du/dt, dv/dt, dr/dt into out[U_], out[V_], out[R_].

    X, Y [N], N [N m] the total forces (:func:`forces`), u, v [m/s], r [rad/s]; see :func:`rhs`.
    Affine in (X, Y, N): with u = v = r = 0 it is the force-to-acceleration map (the inverse
    mass matrix, :func:`inverse_mass`).
    """
    out[U_], out[V_], out[R_] = accelerations_of(X, Y, N, u, v, r, p)


@njit(cache=True, error_model="numpy", inline="always")
def accelerations_of(X, Y, N, u, v, r, p):
    """:func:`accelerations` as values: (du/dt, dv/dt, dr/dt)."""
    m, mx, my, xG = p[P_M], p[P_MX], p[P_MY], p[P_XG]
    return force_accelerations(X + (m + my) * v * r + xG * m * r * r,
                               Y - (m + mx) * u * r, N - xG * m * u * r, p)


@njit(cache=True, error_model="numpy", inline=hot_loops_only)
def rhs(x, delta_cmd, p, poly, hull_axis, hull_term, hull_coef, out):
    """Time derivative of the state, written into ``out`` (MMG equations of motion).

    (m+m_x) du/dt - (m+m_y) v r - x_G m r^2 = X
    (m+m_y) dv/dt + x_G m dr/dt + (m+m_x) u r = Y
    (I_zG + x_G^2 m + J_z) dr/dt + x_G m (dv/dt + u r) = N

    Made of three parts, each a function of only the states it is given:
    :func:`dynamics` (u, v, r, n from u, v, r, delta, n), :func:`track` (x0, y0, psi from u, v,
    r, psi) and the steering gear (delta from delta and the order); nothing depends on x0, y0.
    """
    (out[U_], out[V_], out[R_], out[X_], out[Y_], out[PSI_], out[DELTA_],
     out[N_]) = rhs_of(x[U_], x[V_], x[R_], x[PSI_], x[DELTA_], x[N_], delta_cmd, p, poly,
                       hull_axis, hull_term, hull_coef)


@njit(cache=True, error_model="numpy", inline="always")
def rhs_of(u, v, r, psi, delta, n, delta_cmd, p, poly, hull_axis, hull_term, hull_coef):
    """:func:`rhs` of the states as scalars (x0 and y0 enter nothing), returned as values in the
    state order (du/dt, dv/dt, dr/dt, dx0/dt, dy0/dt, dpsi/dt, ddelta/dt, dn/dt): a loop that
    holds its state in scalars (the simulator's RK4 loop) keeps it in registers."""
    X, Y, N, J = forces_of(u, v, r, delta, n, p, poly, hull_axis, hull_term, hull_coef)
    X, Y, N = with_steady_wind(X, Y, N, u, v, psi, p)     # a steady true wind: loads depend on the heading
    du, dv, dr = accelerations_of(X, Y, N, u, v, r, p)
    dn = shaft_acceleration(u, n, J, p, poly)
    dx, dy, dpsi = track_of(u, v, r, psi, p)
    return du, dv, dr, dx, dy, dpsi, steering_rate(delta_cmd, delta, p), dn


@njit(cache=True, error_model="numpy", inline="always")
def dynamics(u, v, r, delta, n, p, poly, hull_axis, hull_term, hull_coef, out):
    """du/dt, dv/dt, dr/dt and dn/dt of :func:`rhs` into out[U_], out[V_], out[R_], out[N_].

    The states as scalars (u, v [m/s], r [rad/s], delta [rad], n [rps]), each real or complex.
    """
    X, Y, N, J = forces_of(u, v, r, delta, n, p, poly, hull_axis, hull_term, hull_coef)
    accelerations(X, Y, N, u, v, r, p, out)
    out[N_] = shaft_acceleration(u, n, J, p, poly)


@njit(cache=True, error_model="numpy", inline="always")
def track(u, v, r, psi, p, out):
    """dx0/dt, dy0/dt [m/s] (over ground, with the current) and dpsi/dt [rad/s] of :func:`rhs`
    into out[X_], out[Y_], out[PSI_]; u, v [m/s], r [rad/s], psi [rad] scalars, real or complex.
    The current's velocity (constant) is added only when there is one: in still water the
    trigonometry of its direction is not evaluated at every call (same values either way)."""
    out[X_], out[Y_], out[PSI_] = track_of(u, v, r, psi, p)


@njit(cache=True, error_model="numpy", inline="always")
def track_of(u, v, r, psi, p):
    """:func:`track` as values: (dx0/dt, dy0/dt, dpsi/dt)."""
    c, s = np.cos(psi), np.sin(psi)
    dx = u * c - v * s
    dy = u * s + v * c
    cs = p[P_CUR_SPEED]
    if cs != 0.0:
        dx += cs * np.cos(p[P_CUR_DIR])
        dy += cs * np.sin(p[P_CUR_DIR])
    return dx, dy, r


@njit(cache=True, error_model="numpy")
def hull_regressors(x, p, hull_axis, hull_term, idx, out):
    """d(X, Y, N) / d hull_coef[idx[j]] at the (real) state x into out[:, j] (out (3, m)).

    The hull forces are linear in their coefficients (:func:`hull_primed`, :func:`forces`):
    coefficient i adds its term's value times its axis's scale (:func:`hull_scales`) to that
    axis [N or N m per unit coefficient] and nothing elsewhere.
    """
    U, Uh, beta, vp, rp = kinematics(x[U_], x[V_], x[R_], p)
    sX, sY, sN = hull_scales(U, Uh, p)
    sX = sX * surge_sign(x[U_], p)
    for j in range(idx.shape[0]):
        i = idx[j]
        a = hull_axis[i]
        val = term_value(hull_term[i], beta, vp, rp) * astern_factor(a, hull_term[i], x[U_], p)
        out[0, j] = val * sX if a == 0 else 0.0
        out[1, j] = val * sY if a == 1 else 0.0
        out[2, j] = val * sN if a == 2 else 0.0


@njit(cache=True, error_model="numpy")
def inverse_mass(p, work):
    """The force-to-acceleration map of :func:`accelerations` (the inverse mass matrix about
    midship): (du/dX, du/dY, du/dN, dv/dX, dv/dY, dv/dN, dr/dX, dr/dY, dr/dN); work: real (8,) scratch."""
    accelerations(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, p, work)
    m0u, m0v, m0r = work[U_], work[V_], work[R_]
    accelerations(0.0, 1.0, 0.0, 0.0, 0.0, 0.0, p, work)
    m1u, m1v, m1r = work[U_], work[V_], work[R_]
    accelerations(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, p, work)
    m2u, m2v, m2r = work[U_], work[V_], work[R_]
    return m0u, m1u, m2u, m0v, m1v, m2v, m0r, m1r, m2r


@njit(cache=True, error_model="numpy")
def rhs_hull_jacobian(x, p, hull_axis, hull_term, idx, minv, out):
    """d(du/dt, dv/dt, dr/dt) / d hull_coef[idx[j]] of :func:`rhs` at the (real) state x, analytically.

    out (3, m): rows u, v, r (no other component of :func:`rhs` depends on the hull
    coefficients); minv: :func:`inverse_mass` of the ship.  The accelerations are affine in the
    forces (:func:`accelerations`) and the forces linear in the coefficients
    (:func:`hull_regressors`), so column j is the force-to-acceleration map applied to
    coefficient j's regressor.
    """
    hull_regressors(x, p, hull_axis, hull_term, idx, out)
    uX, uY, uN, vX, vY, vN, rX, rY, rN = minv
    for j in range(idx.shape[0]):
        fx, fy, fn = out[0, j], out[1, j], out[2, j]
        out[0, j] = uX * fx + uY * fy + uN * fn
        out[1, j] = vX * fx + vY * fy + vN * fn
        out[2, j] = rX * fx + rY * fy + rN * fn
