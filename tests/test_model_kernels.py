"""The small compiled pieces the speed work touched, against formulas written out here.

* :func:`mmg.model.polyval` reads row ``row`` of the packed polynomial table in place;
  the table is zero-padded to its longest polynomial (:func:`mmg.model.pack`);
* :func:`mmg.model.track` adds the current only when there is one, and the same velocity
  either way;
* :func:`mmg.integrate.simulate_kernel` (no reference counting, caller's work arrays) gives
  the states of a step of RK4 written out with :func:`mmg.model.rhs`.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from mmg import model as M
from mmg.integrate import CommandLaw, integrate
from mmg.effects import effect_set
from mmg.ship import load_ship
from mmg.simulation import prepare
from mmg.units import DEG, KNOT


def test_polyval_reads_the_table_row():
    poly = np.array([[1.0, -2.0, 0.5, 0.0], [0.25, 0.0, 0.0, 0.0], [3.0, 1.0, -1.0, 2.0]])
    for x in (0.0, 0.3, -1.7, 12.0):
        for row in range(3):
            want = sum(c * x**k for k, c in enumerate(poly[row]))
            assert math.isclose(M.polyval(poly, row, x), want, rel_tol=1e-14, abs_tol=1e-15)
    z = M.polyval(poly, 2, 0.3 + 1e-20j)             # complex step: the derivative in the imaginary part
    assert math.isclose(z.imag / 1e-20, 1.0 - 2.0 * 0.3 + 6.0 * 0.3**2, rel_tol=1e-13)


def test_pack_pads_the_polynomials_to_the_longest():
    ship = load_ship("esso_osaka")
    pk = M.pack(ship)
    pr = ship.propeller
    rows = {M.POLY_KT: pr.K_T, M.POLY_KQ: pr.K_Q, M.POLY_TP: pr.t_P, M.POLY_WP0: pr.w_P0}
    assert pk.poly.shape == (4, max(len(c) for c in rows.values()))
    for r, c in rows.items():
        assert list(pk.poly[r, : len(c)]) == list(c) and not pk.poly[r, len(c):].any()


def test_track_adds_the_current_velocity():
    p = np.zeros(M.N_PARAMS)
    out = np.zeros(8)
    u, v, r, psi = 5.0, -0.3, 0.01, 0.7
    M.track(u, v, r, psi, p, out)
    still = out.copy()
    assert math.isclose(still[M.X_], u * math.cos(psi) - v * math.sin(psi))
    assert math.isclose(still[M.Y_], u * math.sin(psi) + v * math.cos(psi))
    assert still[M.PSI_] == r
    p[M.P_CUR_SPEED], p[M.P_CUR_DIR] = 0.5, math.radians(30.0)
    M.track(u, v, r, psi, p, out)
    assert math.isclose(out[M.X_] - still[M.X_], 0.5 * math.cos(math.radians(30.0)), rel_tol=1e-12)
    assert math.isclose(out[M.Y_] - still[M.Y_], 0.5 * math.sin(math.radians(30.0)), rel_tol=1e-12)


@pytest.mark.parametrize("ship_name, effects", [
    ("esso_osaka", None),
    # the cross-flow hull terms, a steady wind and a current: every branch the kernel inlines
    ("esso_osaka_3m_crossflow", {"wind": {"true_speed_mps": 1.8, "true_from_deg": 60.0},
                                 "current": {"speed_mps": 0.05, "direction_deg": 200.0}}),
])
def test_simulate_kernel_is_rk4_of_rhs(ship_name, effects):
    """The kernel inlines the model (mmg._inlining); the called rhs, stepped here, must agree."""
    ship = load_ship(ship_name)
    es = effect_set(effects) if effects else None
    u0 = 10 * KNOT * math.sqrt(ship.particulars.L / 325.0)
    pk, eq = prepare(ship, u0, effects=es)
    if effects:
        assert pk.p[M.P_WIND_V] > 0.0 and pk.p[M.P_CUR_SPEED] > 0.0
    law = CommandLaw.schedule([0.0, 100.0], [35 * DEG, 35 * DEG])
    dt = 0.5 * math.sqrt(ship.particulars.L / 325.0)
    _, states, _, done = integrate(pk, eq.state(), law, 8 * dt, dt)
    assert done
    x = np.array(eq.state(), float)
    for i in range(1, states.shape[0]):
        k = [np.zeros(8) for _ in range(4)]
        M.rhs(x, 35 * DEG, *pk.args(), k[0])
        M.rhs(x + 0.5 * dt * k[0], 35 * DEG, *pk.args(), k[1])
        M.rhs(x + 0.5 * dt * k[1], 35 * DEG, *pk.args(), k[2])
        M.rhs(x + dt * k[2], 35 * DEG, *pk.args(), k[3])
        x = x + dt / 6.0 * (k[0] + 2.0 * k[1] + 2.0 * k[2] + k[3])
        np.testing.assert_allclose(states[i], x, rtol=1e-13, atol=1e-12)
    assert abs(states[-1, M.R_]) > 0.0                 # the run turned: the rudder and hull terms acted


def test_inlining_cost_model_names_only_the_hot_loops():
    from types import SimpleNamespace

    from mmg._inlining import HOT_LOOPS, hot_loops_only

    ir = lambda name: SimpleNamespace(func_id=SimpleNamespace(func_name=name))  # noqa: E731
    assert HOT_LOOPS == {"simulate_kernel", "_replay"}
    assert hot_loops_only(None, ir("simulate_kernel"), ir("rhs"))
    assert hot_loops_only(None, ir("_replay"), ir("kinematics"))
    assert not hot_loops_only(None, ir("jacobian_step"), ir("rhs"))
