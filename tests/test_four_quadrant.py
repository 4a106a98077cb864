"""Four quadrants: propeller thrust and rudder force for any sign of n and u, hull forces at
any drift angle (``mmg.fourquadrant``, ``mmg.model.propeller`` / ``rudder`` / ``kinematics``).

* the published B4-70 four-quadrant series, evaluated here by a plain sum of cosines and sines,
  agree near beta_p = 0 with an independent published source, the Oosterveld & van Oossanen (1975)
  K_T(J, P/D, A_E/A_0, Z) polynomial of the same propellers (written out below);
* thrust and rudder force are continuous across n = 0 and u = 0 from both sides, and across the
  end of the config's K_T(J) (J = J_MAX): a numeric limit check;
* signs: astern revolutions at rest push aft, by the B4-70's astern-to-ahead bollard ratio; ahead
  revolutions with the ship moving astern push ahead, harder than at the bollard; astern revolutions
  with the ship ahead brake harder than at the bollard; a locked propeller drags; reversed inflow
  reverses the rudder force;
* first quadrant (u, n > 0, J <= J_MAX): the textbook X_P = (1 - t_P) rho n^2 D^4 K_T(J) to rounding;
* hull forces are defined and continuous over beta in [0, 360 deg) and fall to zero as U -> 0;
* (hypothesis) every force is finite for any finite state in a wide box.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mmg import model as M
from mmg.fourquadrant import B4_70, b4_70_coefficients, fourier_ct, pitch_angle
from mmg.ship import load_ship

# Oosterveld & van Oossanen (1975), Int. Shipbuilding Progress 22(251): K_T = sum C J^s (P/D)^t (A_E/A_0)^u Z^v
_OO_KT = (
    (0.00880496, 0, 0, 0, 0), (-0.204554, 1, 0, 0, 0), (0.166351, 0, 1, 0, 0), (0.158114, 0, 2, 0, 0),
    (-0.147581, 2, 0, 1, 0), (-0.481497, 1, 1, 1, 0), (0.415437, 0, 2, 1, 0), (0.0144043, 0, 0, 0, 1),
    (-0.0530054, 2, 0, 0, 1), (0.0143481, 0, 1, 0, 1), (0.0606826, 1, 1, 0, 1), (-0.0125894, 0, 0, 1, 1),
    (0.0109689, 1, 0, 1, 1), (-0.133698, 0, 3, 0, 0), (0.00638407, 0, 6, 0, 0), (-0.00132718, 2, 6, 0, 0),
    (0.168496, 3, 0, 1, 0), (-0.0507214, 0, 0, 2, 0), (0.0854559, 2, 0, 2, 0), (-0.0504475, 3, 0, 2, 0),
    (0.010465, 1, 6, 2, 0), (-0.00648272, 2, 6, 2, 0), (-0.00841728, 0, 3, 0, 1), (0.0168424, 1, 3, 0, 1),
    (-0.00102296, 3, 3, 0, 1), (-0.0317791, 0, 3, 1, 1), (0.018604, 1, 0, 2, 1), (-0.00410798, 0, 2, 2, 1),
    (-0.000606848, 0, 0, 0, 2), (-0.0049819, 1, 0, 0, 2), (0.0025983, 2, 0, 0, 2), (-0.000560528, 3, 0, 0, 2),
    (-0.00163652, 1, 2, 0, 2), (-0.000328787, 1, 6, 0, 2), (0.000116502, 2, 6, 0, 2), (0.000690904, 0, 0, 1, 2),
    (0.00421749, 0, 3, 1, 2), (0.0000565229, 3, 6, 1, 2), (-0.00146564, 0, 3, 2, 2),
)


def oosterveld_kt(J, pd, area=0.70, z=4):
    return sum(c * J ** s * pd ** t * area ** u * z ** v for c, s, t, u, v in _OO_KT)


def series_ct(beta, table):
    """C_T* of a published table ((A_k, B_k) x 100), summed term by term."""
    return sum(a * math.cos(k * beta) + b * math.sin(k * beta) for k, (a, b) in enumerate(table)) / 100.0


@pytest.mark.parametrize("pd", [0.6, 0.8, 1.0])
@pytest.mark.parametrize("J", [0.0, 0.2, 0.4, 0.6])
def test_published_series_match_the_b_series_polynomial(pd, J):
    beta = math.atan2(J, 0.7 * math.pi)
    kt = series_ct(beta, B4_70[pd]) * math.pi / 8.0 * (J * J + (0.7 * math.pi) ** 2)
    assert abs(kt - oosterveld_kt(J, pd)) < 0.012


def test_code_series_is_the_table_interpolated():
    a, b = b4_70_coefficients(0.7)
    c = np.concatenate([a, b])
    for beta in np.linspace(0.0, 2 * math.pi, 37):
        want = 0.5 * (series_ct(beta, B4_70[0.6]) + series_ct(beta, B4_70[0.8]))
        assert fourier_ct.py_func(beta, c, 0, a.size) == pytest.approx(want, abs=1e-12)
    assert pitch_angle.py_func(-1.0, 1e-30) == pytest.approx(1.5 * math.pi)


# ----------------------------------------------------------------------------- helpers


@pytest.fixture(scope="module", params=["esso_osaka_3m", "esso_osaka_3m_crossflow", "esso_osaka"])
def pk(request):
    return M.pack(load_ship(request.param))


def scales(pk):
    """(speed [m/s], revolutions [rps], force [N]) of the ship's service condition."""
    L, D, rho = pk.p[M.P_L], pk.p[M.P_D], pk.p[M.P_RHO]
    u0 = 0.15 * math.sqrt(9.81 * L)
    n0 = u0 / (0.5 * D)
    return u0, n0, rho * n0 * n0 * D ** 4


def parts(pk, u, v, r, delta, n):
    """X_P [N] and the rudder's (X_R, Y_R [N], N_R / L [N]) of a state, through the model's own functions."""
    p, poly = pk.p, pk.poly
    U, Uh, beta, vp, rp = M.kinematics(u, v, r, p)
    owp = M.one_minus_wake(u, beta, rp, p, poly)
    _, XP, TL = M.propeller(u, n, owp, p, poly)
    XR, YR, NR, _ = M.rudder(u, U, beta, rp, delta, n, owp, TL, p)
    return np.array([XP, XR, YR, NR / p[M.P_L]])


def limit_gap(f, eps):
    """|f(+eps) - f(-eps)| (vector) for the step eps."""
    return np.abs(np.asarray(f(eps)) - np.asarray(f(-eps)))


# ----------------------------------------------------------------------------- continuity


@pytest.mark.parametrize("u_frac", [-0.6, -0.05, 0.05, 0.6])
def test_continuous_as_n_crosses_zero(pk, u_frac):
    u0, n0, F = scales(pk)
    for v, r, d in ((0.0, 0.0, 0.35), (0.1 * u0, -0.2 * u0 / pk.p[M.P_L], -0.2)):
        f = lambda e: parts(pk, u_frac * u0, v, r, d, e * n0)  # noqa: E731
        big, small = limit_gap(f, 1e-5), limit_gap(f, 1e-8)
        assert np.all(small <= 1e-6 * F), small
        assert np.all(small <= big + 1e-12 * F)


@pytest.mark.parametrize("n_frac", [-1.0, -0.1, 0.1, 1.0])
def test_continuous_as_u_crosses_zero(pk, n_frac):
    u0, n0, F = scales(pk)
    for v, r, d in ((0.0, 0.0, 0.35), (0.05 * u0, 0.1 * u0 / pk.p[M.P_L], -0.5)):
        f = lambda e: parts(pk, e * u0, v, r, d, n_frac * n0)  # noqa: E731
        big, small = limit_gap(f, 1e-5), limit_gap(f, 1e-8)
        assert np.all(small <= 1e-5 * F), small
        assert np.all(small <= big + 1e-12 * F)


def test_continuous_at_the_end_of_the_config_kt(pk):
    """J = J_MAX: the config's K_T(J) hands over to the four-quadrant curve."""
    u0, n0, F = scales(pk)
    p, poly = pk.p, pk.poly
    for u in (0.3 * u0, u0):
        owp = M.one_minus_wake(u, 0.0, 0.0, p, poly)
        n_edge = u * owp / (M.J_MAX * p[M.P_D])
        f = lambda e: parts(pk, u, 0.0, 0.0, 0.2, n_edge * (1.0 + e))  # noqa: E731
        assert np.all(limit_gap(f, 1e-9) <= 1e-6 * F)


def test_zero_at_rest_and_bounded_at_zero_speed(pk):
    u0, n0, F = scales(pk)
    assert np.all(parts(pk, 0.0, 0.0, 0.0, 0.3, 0.0) == 0.0)
    for n in (-n0, n0):
        x = parts(pk, 0.0, 0.0, 0.0, 0.3, n)
        assert np.all(np.isfinite(x)) and np.all(np.abs(x) < 10 * F)


# ----------------------------------------------------------------------------- signs against physics


def test_astern_revolutions_at_rest_push_aft_by_the_b_series_ratio():
    pk = M.pack(load_ship("esso_osaka_3m"))
    _, n0, _ = scales(pk)
    ahead = parts(pk, 0.0, 0.0, 0.0, 0.0, n0)[0]
    astern = parts(pk, 0.0, 0.0, 0.0, 0.0, -n0)[0]
    assert ahead > 0.0 > astern
    # C_T*(180 deg) / C_T*(0) of the B4-70 at P/D 0.7154, from the published tables
    w = (0.7154 - 0.6) / 0.2
    ct = lambda b: (1 - w) * series_ct(b, B4_70[0.6]) + w * series_ct(b, B4_70[0.8])  # noqa: E731
    assert -astern / ahead == pytest.approx(-ct(math.pi) / ct(0.0), rel=1e-3)
    assert 0.5 < -astern / ahead < 0.8          # a fixed-pitch propeller astern: 50-80 % of ahead


def test_thrust_signs_in_each_quadrant(pk):
    u0, n0, _ = scales(pk)
    X = lambda u, n: parts(pk, u, 0.0, 0.0, 0.0, n)[0]  # noqa: E731
    bollard = X(0.0, n0)
    assert X(-0.3 * u0, n0) > bollard > 0.0          # ship astern, propeller ahead: thrust ahead, above bollard
    # crash stop at speed (beta_p ~ 160 deg): brakes harder than the astern bollard pull of the same revolutions
    assert X(u0, -0.3 * n0) < X(0.0, -0.3 * n0) < 0.0
    assert X(0.5 * u0, 0.0) < 0.0 < X(-0.5 * u0, 0.0)       # locked propeller: drag against the motion


def test_first_quadrant_is_the_textbook_thrust(pk):
    u0, n0, _ = scales(pk)
    p, poly = pk.p, pk.poly
    rng = np.random.default_rng(7)
    for _ in range(200):
        u, n = rng.uniform(0.01, 1.5) * u0, rng.uniform(0.3, 2.0) * n0
        owp = M.one_minus_wake(u, 0.0, 0.0, p, poly)
        J = u * owp / (n * p[M.P_D])
        if J > M.J_MAX:
            continue
        kt = np.polynomial.polynomial.polyval(J, poly[M.POLY_KT])
        tp = np.polynomial.polynomial.polyval(u, poly[M.POLY_TP])
        want = (1 - tp) * p[M.P_RHO] * n * n * p[M.P_D] ** 4 * kt
        assert M.propeller(u, n, owp, p, poly)[1] == pytest.approx(want, rel=1e-13, abs=1e-13 * abs(want) + 1e-300)


def test_reversed_inflow_reverses_the_rudder_force():
    pk = M.pack(load_ship("esso_osaka_3m"))
    u0, n0, _ = scales(pk)
    d = math.radians(20.0)
    for n in (0.0, -n0):
        ahead = parts(pk, 0.5 * u0, 0.0, 0.0, d, n)[2]
        astern = parts(pk, -0.5 * u0, 0.0, 0.0, d, n)[2]
        assert ahead < 0.0 < astern          # Y_R: starboard rudder pushes the stern to port ahead, to starboard astern
    # ship astern slowly with a strong ahead kick: the race wins and the rudder works as ahead
    assert parts(pk, -0.05 * u0, 0.0, 0.0, d, 2 * n0)[2] < 0.0


# ----------------------------------------------------------------------------- hull at any drift angle


@pytest.mark.parametrize("astern", ["as_ahead", "end_for_end"])
@pytest.mark.parametrize("name", ["esso_osaka_3m", "esso_osaka_3m_crossflow"])
def test_hull_forces_continuous_over_all_drift_angles(name, astern):
    pk = M.pack(load_ship(name).with_hull_astern(astern))
    p, L = pk.p, pk.p[M.P_L]
    U = 0.3
    betas = np.radians(np.arange(0.0, 360.0, 0.05))
    for r in (0.0, 0.05, -0.1):
        F = []
        for b in betas:
            u, v = U * math.cos(b), -U * math.sin(b)
            Uk, Uh, beta, vp, rp = M.kinematics(u, v, r, p)
            X, Y, N = M.hull_primed_at(beta, vp, rp, u, p, pk.hull_axis, pk.hull_term, pk.hull_coef)
            sX, sY, sN = M.hull_scales(Uk, Uh, p)
            F.append((X * sX * M.surge_sign(u, p), Y * sY, N * sN / L))
        F = np.array(F)
        assert np.all(np.isfinite(F))
        scale = np.abs(F).max()
        jumps = np.abs(np.diff(np.vstack([F, F[:1]]), axis=0)).max()
        assert jumps < 0.01 * scale, (r, jumps, scale)


@pytest.mark.parametrize("name", ["esso_osaka_3m", "esso_osaka_3m_crossflow"])
def test_hull_forces_vanish_at_zero_speed(name):
    pk = M.pack(load_ship(name))
    p = pk.p
    for U in (1e-3, 1e-6):
        for b in np.radians([0, 45, 90, 135, 180, 225, 270, 315]):
            X, Y, N, _ = M.forces_of(U * math.cos(b), -U * math.sin(b), 0.0, 0.0, 0.0, *pk.args())
            assert max(abs(X), abs(Y), abs(N)) < 50 * U      # linear in U below the floor (a few N per m/s)


# ----------------------------------------------------------------------------- finite everywhere


_PK3 = None


def _pk3():
    global _PK3
    if _PK3 is None:
        _PK3 = M.pack(load_ship("esso_osaka_3m"))
    return _PK3


@settings(max_examples=300, deadline=None)
@given(u=st.floats(-2.0, 2.0), v=st.floats(-2.0, 2.0), r=st.floats(-1.0, 1.0),
       d=st.floats(-0.7, 0.7), n=st.floats(-40.0, 40.0))
def test_forces_finite_for_any_finite_state(u, v, r, d, n):
    assert np.all(np.isfinite(M.forces_of(u, v, r, d, n, *_pk3().args())))


def test_complex_step_derivative_in_other_quadrants():
    """The estimators differentiate the forces by complex steps: they hold outside the first quadrant."""
    pk = _pk3()
    for u, n in ((-0.2, 8.0), (0.3, -8.0), (-0.2, -8.0), (0.3, 1.0)):
        h = 1e-30
        for k in (0, 4):                           # d/du and d/dn
            x = [u, 0.02, 0.01, 0.2, n]
            xc = list(x)
            xc[k] = x[k] + 1j * h
            cs = np.array(M.forces_of(*xc, *pk.args())[:3]).imag / h
            e = 1e-6
            xp, xm = list(x), list(x)
            xp[k] += e
            xm[k] -= e
            fd = (np.array(M.forces_of(*xp, *pk.args())[:3]) - np.array(M.forces_of(*xm, *pk.args())[:3])) / (2 * e)
            assert np.allclose(cs, fd, rtol=1e-4, atol=1e-6 * (1 + np.abs(fd).max()))


# ----------------------------------------------------------------------------- propeller walk astern


def _walking(c=-0.02):
    """The 3 m model with a transverse force of its propeller astern, Y_P = c rho n^2 D^4."""
    from dataclasses import replace

    s = load_ship("esso_osaka_3m")
    return s, M.pack(replace(s, propeller=replace(s.propeller, Y_P_astern=c)))


def test_propeller_walk_is_the_stated_force_at_the_propeller():
    """n < 0: Y = c rho n^2 D^4 at x_P (written out here from the ship's own particulars), N = x_P Y;
    n >= 0: nothing (the forces of the ship without it, to the last bit)."""
    s, pk = _walking(-0.02)
    base = M.pack(s)
    D, L, rho, xp = s.propeller.D, s.particulars.L, s.particulars.rho, s.propeller.x_P_prime
    for u, n in ((0.3, -12.0), (-0.1, -5.0), (0.0, -20.0)):
        f1 = np.array(M.forces_of(u, 0.01, 0.02, 0.1, n, *pk.args())[:3])
        f0 = np.array(M.forces_of(u, 0.01, 0.02, 0.1, n, *base.args())[:3])
        Y = -0.02 * rho * n * n * D ** 4
        assert f1 - f0 == pytest.approx([0.0, Y, xp * L * Y], rel=1e-9, abs=1e-12)
    for n in (0.0, 3.0, 12.0):
        assert np.array_equal(M.forces_of(0.3, 0.01, 0.02, 0.1, n, *pk.args()),
                              M.forces_of(0.3, 0.01, 0.02, 0.1, n, *base.args()))


def test_a_right_handed_screw_astern_turns_the_bow_to_starboard():
    """The seaman's rule: going astern, a right-handed screw walks the stern to port (Y_P < 0 with
    the propeller aft, x_P < 0), so the bow swings to starboard: a positive yaw moment."""
    s, pk = _walking(-0.02)
    base = M.pack(s)
    dN = M.forces_of(0.0, 0.0, 0.0, 0.0, -10.0, *pk.args())[2] - M.forces_of(0.0, 0.0, 0.0, 0.0, -10.0, *base.args())[2]
    assert s.propeller.x_P_prime < 0 and dN > 0


def test_propeller_walk_continuous_and_smooth_as_n_reverses():
    """Zero with zero slope at n = 0: the forces' jump and their n-derivative's jump vanish there."""
    _, pk = _walking(-0.05)
    f = lambda n: np.array(M.propeller_lateral(n, pk.p))  # noqa: E731
    assert np.all(np.abs(f(-1e-8) - f(1e-8)) < 1e-12)
    h = 1e-7
    slope = lambda n: (f(n + h) - f(n - h)) / (2 * h)  # noqa: E731
    assert np.all(np.abs(slope(-1e-4)) < 1e-3 * np.abs(slope(-1.0)))


def test_complex_step_derivative_in_n_with_propeller_walk():
    _, pk = _walking(-0.05)
    for n in (-8.0, -0.5):
        cs = np.array(M.forces_of(0.2, 0.0, 0.0, 0.0, n + 1e-30j, *pk.args())[:3]).imag / 1e-30
        e = 1e-6
        fd = (np.array(M.forces_of(0.2, 0.0, 0.0, 0.0, n + e, *pk.args())[:3])
              - np.array(M.forces_of(0.2, 0.0, 0.0, 0.0, n - e, *pk.args())[:3])) / (2 * e)
        assert np.allclose(cs, fd, rtol=1e-5, atol=1e-9)
