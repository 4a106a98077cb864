"""The hull moving astern (:func:`mmg.model.astern_factor`, the config's ``hull.astern``).

With ``end_for_end``, two checks that do not read the factor's own rule:

* the low-speed cross-flow hull of Yoshimura, in the form the Osaka group fits to the 3 m Esso Osaka
  (X = X_0 u|u| + X_vr v r L, Y = Y_v v|u| + Y_r r L u - C_D int, N = N_v v u + N_r r L|u| - C_D int;
  the u without bars carry the direction of motion), written out here, with its strip integrals
  summed numerically, against the simulator's hull forces ahead and astern;
* the end-for-end symmetry of any hull form: moving astern with (u, v, r) is moving ahead with
  (-u, -v, r) turned end for end, so (X, Y, N) -> (-X, -Y, N).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dataclasses import replace

from mmg import model as M
from mmg.errors import InputError
from mmg.ship import load_ship, ship_from_dict
from mmg.ship.yamlfile import read_yaml

from .conftest import CONFIGS


def _end_for_end(name):
    return load_ship(name).with_hull_astern("end_for_end")


def _hull_forces(pk, u, v, r):
    """The simulator's hull surge and sway force [N] and yaw moment [N m] at (u, v, r)."""
    p = pk.p
    U, Uh, beta, vp, rp = M.kinematics(u, v, r, p)
    X, Y, N = M.hull_primed_at(beta, vp, rp, u, p, pk.hull_axis, pk.hull_term, pk.hull_coef)
    sX, sY, sN = M.hull_scales(U, Uh, p)
    return X * sX * M.surge_sign(u, p), Y * sY, N * sN


def _strips(v, rL, weight_x: bool) -> float:
    """Integral over x' in [-1/2, 1/2] of [x'] |v + x' r L| (v + x' r L), by the trapezoid rule."""
    x = np.linspace(-0.5, 0.5, 20001)
    w = v + x * rL
    f = np.abs(w) * w * (x if weight_x else 1.0)
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)))


def _yoshimura(ship, u, v, r):
    """Yoshimura's low-speed hull [N, N, N m] from the cross-flow config's coefficients."""
    c = dict(zip(ship.hull.names, ship.hull.values))
    pa = ship.particulars
    L, T, rho = pa.L, pa.T, pa.rho
    U2, s = u * u + v * v, math.copysign(1.0, u)
    q = 0.5 * rho * L * T
    X = q * (c["X_uu"] * u * abs(u) + c["X_vr"] * v * r * L)
    Y = q * (c["Y_0"] * U2 * s + c["Y_v"] * v * abs(u) + c["Y_r"] * r * L * u + c["Y_CD"] * _strips(v, r * L, False))
    N = q * L * (c["N_0"] * U2 + c["N_v"] * v * u + c["N_r"] * r * L * abs(u) + c["N_CD"] * _strips(v, r * L, True))
    return X, Y, N


@pytest.mark.parametrize("u", [0.25, -0.25, 0.12, -0.12])
@pytest.mark.parametrize("v, r", [(0.03, 0.0), (-0.05, 0.02), (0.02, -0.04), (0.0, 0.03)])
def test_the_cross_flow_hull_astern_is_yoshimuras(u, v, r):
    ship = _end_for_end("esso_osaka_3m_crossflow")
    pk = M.pack(ship)
    got = _hull_forces(pk, u, v, r)
    want = _yoshimura(ship, u, v, r)
    scale = max(abs(w) for w in want)
    for g, w in zip(got, want):
        assert abs(g - w) <= 1e-6 * scale + 1e-9, (got, want)


@pytest.mark.parametrize("name", ["esso_osaka_3m", "esso_osaka_3m_crossflow", "kvlcc2_l7"])
@settings(max_examples=60, deadline=None)
@given(a=st.floats(1.05, 6.0), v=st.floats(-1.0, 1.0), r=st.floats(-1.0, 1.0))
def test_moving_astern_is_moving_ahead_turned_end_for_end(name, a, v, r):
    """Beyond U_low astern (a = |u| / U_low); v and r scaled to the ship's speed and length."""
    pk = M.pack(_end_for_end(name))
    ul, L = pk.p[M.P_ULOW], pk.p[M.P_L]
    u, v, r = -a * ul, v * a * ul, r * a * ul / L
    Xa, Ya, Na = _hull_forces(pk, u, v, r)
    Xf, Yf, Nf = _hull_forces(pk, -u, -v, r)
    scale = max(abs(Xf), abs(Yf), abs(Nf) / L, 1e-12)
    assert abs(Xa + Xf) <= 1e-9 * scale
    assert abs(Ya + Yf) <= 1e-9 * scale
    assert abs(Na - Nf) <= 1e-9 * scale * L


@pytest.mark.parametrize("name", ["esso_osaka_3m", "esso_osaka_3m_crossflow"])
@pytest.mark.parametrize("v, r", [(0.03, 0.01), (-0.05, 0.02), (0.02, -0.04)])
def test_as_ahead_the_default_acts_astern_as_the_flow_along_the_hull(name, v, r):
    """Without ``hull.astern`` every term acts astern as ahead in the flow along the hull: the sway
    force and yaw moment at (-|u|, v, r) are those at (|u|, v, r), the surge force turned."""
    ship = load_ship(name)
    assert ship.hull.astern == "as_ahead"
    pk = M.pack(ship)
    Xa, Ya, Na = _hull_forces(pk, -0.25, v, r)
    Xf, Yf, Nf = _hull_forces(pk, 0.25, v, r)
    assert (Xa, Ya, Na) == pytest.approx((-Xf, Yf, Nf), rel=1e-12, abs=1e-15)


def test_an_unknown_astern_rule_is_refused_naming_the_field():
    data = read_yaml(CONFIGS / "ships" / "esso_osaka_3m.yaml")
    data["hull"]["astern"] = "mirrored"
    with pytest.raises(InputError, match="hull.astern"):
        ship_from_dict(data, "bad.yaml")


@pytest.mark.parametrize("name", ["esso_osaka_3m", "esso_osaka_3m_crossflow"])
def test_the_estimators_hull_jacobian_astern_is_the_complex_step_of_rhs(name):
    """d rhs / d c moving astern with ``end_for_end``: the analytic regressors (mmg.model.hull_regressors,
    which the filters and the fits use) equal a complex step of the model's own right-hand side."""
    pk = M.pack(_end_for_end(name))
    p, poly, ha, ht, hc = pk.args()
    idx = np.arange(len(hc))
    ul = p[M.P_ULOW]
    for u in (-3.0 * ul, -0.5 * ul):
        x = np.array([u, 0.4 * ul, 0.02, 0.0, 0.0, 0.3, 0.1, 0.0])
        B = np.empty((3, len(idx)))
        M.rhs_hull_jacobian(x, p, ha, ht, idx, M.inverse_mass(p, np.empty(8)), B)
        out = np.empty(8, dtype=complex)
        for j in idx:
            c = hc.astype(complex)
            c[j] += 1e-30j
            M.rhs(x.astype(complex), x[6], p, poly, ha, ht, c, out)
            d = out.imag / 1e-30
            np.testing.assert_allclose(B[:, j], d[[M.U_, M.V_, M.R_]], rtol=1e-12, atol=1e-12 * np.abs(d).max())


def test_the_parity_table_is_the_terms_own():
    """Each registered term evaluated at (-beta, -v', r') against (beta, v', r') at two generic points:
    the ratio is the table's parity, so a term added without its right parity fails here."""
    from mmg.terms import TERMS, V_PARITY, term_value

    assert len(V_PARITY) == len(TERMS)
    for key, tid in TERMS.items():
        for b, v, r in ((0.31, -0.27, 0.43), (-0.12, 0.4, -0.77), (0.05, 0.05, 0.6)):   # the last: |v'| < |r'|/2
            a, m = term_value(tid, b, v, r), term_value(tid, -b, -v, r)
            assert a != 0.0, key
            assert m == pytest.approx(V_PARITY[tid] * a, rel=1e-12), key


def test_a_mismatch_ship_keeps_its_hulls_astern_rule():
    """The mismatch family perturbs the coefficients, not how the hull acts astern."""
    from trials.measured.mismatch import mismatch_ship

    ship = _end_for_end("esso_osaka_3m")
    assert mismatch_ship(ship, np.random.default_rng(3)).hull.astern == "end_for_end"
    with pytest.raises(ValueError, match="hull.astern"):
        M.pack(replace(ship, hull=replace(ship.hull, astern="mirrored")))
