"""The low-speed cross-flow hull terms (mmg.terms.crossflow_Y, crossflow_N) against independent
references: numerical quadrature of the strip integrals, finite differences of their complex-step
derivatives, the symmetries of a fore-aft symmetric strip hull, the small-drift agreement of the
cross-flow 3 m config with the Kijima one it was converted from, and finite forces down to rest."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

import mmg
from mmg.model import P_ULOW, forces_of, pack
from mmg.terms import TERMS, crossflow_N, crossflow_Y, term_value

# (v', r') covering both branches: cross-flow of one sign along the hull (|v'| >= |r'|/2), a sign
# change inside the hull, the boundary |v'| = |r'|/2 itself, pure drift, pure yaw and rest
CASES = [(0.3, 0.2), (0.1, 0.8), (-0.05, 0.9), (0.0, 0.5), (0.2, 0.0), (-0.4, -0.3), (0.02, -1.2),
         (0.25, 0.5), (-0.25, 0.5), (0.7, -1.4), (1.0, 0.0), (0.0, -2.0), (0.0, 0.0), (-0.6, 2.5)]


def _strip(a, b, moment):
    """The strip integral by adaptive quadrature, split where the cross-flow a + b x changes sign."""
    f = (lambda x: x * abs(a + b * x) * (a + b * x)) if moment else (lambda x: abs(a + b * x) * (a + b * x))
    pts = [-a / b] if b != 0.0 and abs(a / b) < 0.5 else None
    return quad(f, -0.5, 0.5, points=pts, epsabs=1e-14, epsrel=1e-12)[0]


@pytest.mark.parametrize("a,b", CASES)
def test_closed_forms_equal_the_quadrature_of_the_strip_integrals(a, b):
    assert crossflow_Y(a, b) == pytest.approx(_strip(a, b, False), rel=1e-10, abs=1e-14)
    assert crossflow_N(a, b) == pytest.approx(_strip(a, b, True), rel=1e-10, abs=1e-14)


@pytest.mark.parametrize("a,b", [(0.0, 5e-217), (1e-200, -3e-190), (0.0, -1e-170), (2e-170, 1e-163)])
def test_tiny_yaw_rates_give_finite_integrals(a, b):
    """b^2 underflows to 0 here; the integrals are then 0 to double precision, not 0/0."""
    assert crossflow_Y(a, b) == pytest.approx(0.0, abs=1e-300)
    assert crossflow_N(a, b) == pytest.approx(0.0, abs=1e-300)


def test_random_states_against_quadrature():
    rng = np.random.default_rng(7)
    for a, b in zip(rng.uniform(-1.5, 1.5, 200), rng.uniform(-3.0, 3.0, 200)):
        assert crossflow_Y(a, b) == pytest.approx(_strip(a, b, False), rel=1e-9, abs=1e-13)
        assert crossflow_N(a, b) == pytest.approx(_strip(a, b, True), rel=1e-9, abs=1e-13)


def test_terms_are_registered_and_evaluated_through_term_value():
    a, b = 0.13, -0.61
    beta = np.arctan(-a / np.sqrt(1 - a * a))
    assert term_value(TERMS["int(|v+x*r|*(v+x*r))"], beta, a, b) == pytest.approx(_strip(a, b, False), rel=1e-10)
    assert term_value(TERMS["int(x*|v+x*r|*(v+x*r))"], beta, a, b) == pytest.approx(_strip(a, b, True), rel=1e-10)
    assert term_value(TERMS["v*cos(beta)"], beta, a, b) == pytest.approx(a * np.sqrt(1 - a * a), rel=1e-12)
    assert term_value(TERMS["r*cos(beta)"], beta, a, b) == pytest.approx(b * np.sqrt(1 - a * a), rel=1e-12)


def test_symmetries_of_a_fore_aft_symmetric_strip_hull():
    rng = np.random.default_rng(3)
    for a, b in zip(rng.uniform(-1, 1, 50), rng.uniform(-2, 2, 50)):
        # reversing the flow reverses force and moment; mirroring x -> -x (b -> -b) keeps the force
        # and reverses the moment; swapping the sign of a alone mirrors it port-starboard
        assert crossflow_Y(-a, -b) == pytest.approx(-crossflow_Y(a, b), abs=1e-15)
        assert crossflow_N(-a, -b) == pytest.approx(-crossflow_N(a, b), abs=1e-15)
        assert crossflow_Y(a, -b) == pytest.approx(crossflow_Y(a, b), abs=1e-15)
        assert crossflow_N(a, -b) == pytest.approx(-crossflow_N(a, b), abs=1e-15)
    # pure drift: the drag of the whole hull; pure yaw: no side force, the moment of two half-hulls
    assert crossflow_Y(0.4, 0.0) == pytest.approx(0.16) and crossflow_N(0.4, 0.0) == 0.0
    assert crossflow_Y(0.0, 0.8) == 0.0
    assert crossflow_N(0.0, 0.8) == pytest.approx(2 * 0.8 ** 2 * quad(lambda x: x ** 3, 0, 0.5)[0])


@pytest.mark.parametrize("fn", [crossflow_Y, crossflow_N])
@pytest.mark.parametrize("a,b", [c for c in CASES if c != (0.0, 0.0)])
def test_complex_step_derivatives_match_finite_differences(fn, a, b):
    h, eps = 1e-30, 1e-6
    for da, db in ((1.0, 0.0), (0.0, 1.0)):
        cs = fn(complex(a, h * da), complex(b, h * db)).imag / h
        fd = (fn(a + eps * da, b + eps * db) - fn(a - eps * da, b - eps * db)) / (2 * eps)
        assert cs == pytest.approx(fd, rel=1e-6, abs=1e-8), (a, b, da, db)


def test_crossflow_config_agrees_with_the_kijima_one_at_small_drift():
    """The cross-flow 3 m config is converted from the Kijima one to agree at small drift: the hull
    forces differ by the quadratic terms only (both ships have the same propeller and rudder)."""
    kij, cf = pack(mmg.load_ship("esso_osaka_3m")), pack(mmg.load_ship("esso_osaka_3m_crossflow"))
    U, n, delta = 0.4, 10.0, 0.0
    for beta, rp in ((0.005, 0.0), (0.0, 0.005), (-0.004, 0.003)):
        u, v, r = U * np.cos(beta), -U * np.sin(beta), rp * U / 3.0
        fk = np.array(forces_of(u, v, r, delta, n, *kij.args())[:3])
        fc = np.array(forces_of(u, v, r, delta, n, *cf.args())[:3])
        fs = 0.5 * 1000 * 3.0 * 0.201 * U ** 2 * np.array([1.0, 1.0, 3.0])
        # the linear parts agree; what is left is quadratic in the 0.5 % perturbation (< 1e-4 primed)
        assert np.all(np.abs(fk - fc) / fs < 1e-4), (beta, rp, (fk - fc) / fs)


def test_crossflow_hull_is_well_posed_down_to_rest():
    """Below the low-speed floor the primed terms stay bounded (v', r' on the floored speed scale),
    so the forces stay finite and fall continuously to zero as the ship comes to rest (propeller
    stopped), whatever the direction of the motion and with the ship still turning."""
    pk = pack(mmg.load_ship("esso_osaka_3m_crossflow"))
    ul = pk.p[P_ULOW]
    for ang in np.radians([0.0, 30.0, 90.0, 150.0, -120.0]):
        out = []
        for U in (2 * ul, ul, 0.3 * ul, 1e-3 * ul, 1e-6 * ul, 0.0):
            u, v = U * np.cos(ang), -U * np.sin(ang)
            out.append(forces_of(u, v, 0.02, 0.1, 0.0, *pk.args())[:3])
        out = np.array(out)
        assert np.all(np.isfinite(out))
        scale = np.abs(out[0]).max()
        assert np.all(np.abs(out[-2]) < 1e-5 * scale) and np.all(out[-1] == 0.0)
