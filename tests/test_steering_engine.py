"""The steering gear (Rhee & Kim eq. 20) and the constant-power shaft (eqs. 15-19), each on its own.

The paper's constants are used *as printed* (T_E = 2.5 s, |delta_dot_max| = 2.34 deg/s,
delta_max = 35 deg, Q_E = 745 SHP_0 / (2 pi n), SHP_0 of eq. 19, (I+J) = 2.0 D^5), not
read back from the config, so a wrong number in the config or in the packing is
caught here as well as a wrong formula in the compiled code.  The compiled model
is called through its public packing only (``prepare`` -> ``rhs`` / ``integrate``).
"""
from __future__ import annotations

import numpy as np
import pytest

from tests.test_physics_reference import (
    DEGREE, IDELTA, IN, IU, IV, PAPER_KT, PAPER_SHAFT_INERTIA_COEF, PAPER_SHP0, PAPER_T_E,
    PAPER_TABLE1, PAPER_W_PER_SHP, SHIP_YAML, U_APPROACH, PaperModel, _poly, compiled_rhs,
    load_config, random_states,
)

T_E = PAPER_T_E                                      # s
RATE = PAPER_TABLE1["delta_rate_max_deg_s"] * DEGREE  # rad/s
DMAX = PAPER_TABLE1["delta_max_deg"] * DEGREE         # rad
BAND = T_E * RATE                                    # eq. (20): linear below |delta* - delta| <= T_E |delta_dot_max|


@pytest.fixture(scope="module")
def compiled():
    from mmg.ship import load_ship
    from mmg.simulation import prepare

    return prepare(load_ship(SHIP_YAML), U_APPROACH)


@pytest.fixture(scope="module")
def paper():
    return PaperModel(load_config())


def eq20(cmd, delta):
    """Eq. (20) with the order clipped to +-35 deg (Table 1)."""
    err = np.clip(cmd, -DMAX, DMAX) - delta
    return np.where(np.abs(err) <= BAND, err / T_E, np.sign(err) * RATE)


def run_rudder(packed, eq, order, duration, dt, delta0=0.0):
    """Integrate the full model with a constant rudder order from rudder angle delta0; (t, delta)."""
    from mmg.integrate import CommandLaw, integrate

    x0 = eq.state().copy()
    x0[IDELTA] = delta0
    t, states, _, done = integrate(packed, x0, CommandLaw.schedule([0.0, duration], [order, order]), duration, dt)
    assert done
    return t, states[:, IDELTA]


# --------------------------------------------------------------------------- steering gear, eq. (20)


def test_steering_rate_is_eq20(compiled):
    """delta_dot of rhs() at random (order, angle) pairs, both branches and the band edge, = eq. (20)."""
    packed, eq = compiled
    rng = np.random.default_rng(20)
    X = np.tile(eq.state(), (300, 1))
    X[:, IDELTA] = rng.uniform(-35, 35, 300) * DEGREE
    cmd = np.concatenate([X[:100, IDELTA] + rng.uniform(-1, 1, 100) * BAND,          # linear branch
                          rng.uniform(-45, 45, 150) * DEGREE,                          # mostly rate-limited
                          X[250:275, IDELTA] + BAND * (1 - 1e-9),                      # just inside the band
                          X[275:, IDELTA] - BAND * (1 + 1e-9)])                        # just outside
    got = compiled_rhs(packed, X, cmd)[:, IDELTA]
    np.testing.assert_allclose(got, eq20(cmd, X[:, IDELTA]), rtol=1e-13, atol=1e-16)
    # rate limit and time constant are the paper's: the fastest rate is 2.34 deg/s, the band 5.85 deg
    assert np.max(np.abs(got)) == pytest.approx(RATE, rel=1e-14)
    assert BAND / DEGREE == pytest.approx(5.85, rel=1e-12)


def test_small_step_is_first_order_with_T_E(compiled):
    """A 3 deg step (inside the band) is delta*(1 - exp(-t/T_E)) with T_E = 2.5 s."""
    packed, eq = compiled
    dt, step = 0.05, 3.0 * DEGREE
    t, d = run_rudder(packed, eq, step, 20.0, dt)
    # the continuous solution of eq. (20) (RK4 error ~1e-10 here)
    np.testing.assert_allclose(d, step * (1.0 - np.exp(-t / T_E)), rtol=0, atol=1e-9)
    # and, exactly, the RK4 recursion of d' = (step - d)/T_E: factor g per step
    h = dt / T_E
    g = 1 - h + h**2 / 2 - h**3 / 6 + h**4 / 24
    np.testing.assert_allclose(d, step * (1.0 - g ** np.arange(t.size)), rtol=0, atol=1e-14)
    # 63.2 % of the step after one time constant
    assert d[int(round(T_E / dt))] / step == pytest.approx(1 - np.exp(-1), rel=1e-8)


def test_large_step_is_rate_limited_then_first_order(compiled):
    """35 deg order from amidships: slope exactly 2.34 deg/s until 5.85 deg short, then exp(-t/T_E)."""
    packed, eq = compiled
    dt = 0.01
    t, d = run_rudder(packed, eq, DMAX, 40.0, dt)
    t1 = (DMAX - BAND) / RATE                           # end of the rate-limited part: 12.457 s
    lin = t <= t1 - dt
    np.testing.assert_allclose(d[lin], RATE * t[lin], rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(np.diff(d[lin]) / dt, RATE, rtol=1e-9)
    after = t >= t1 + dt
    analytic = DMAX - BAND * np.exp(-(t[after] - t1) / T_E)
    # (the step that crosses the band edge carries an O(dt^3) RK4 error: ~1.3e-8 rad = 1e-6 deg here)
    np.testing.assert_allclose(d[after], analytic, rtol=0, atol=5e-8)
    assert np.all(d <= DMAX)
    # mirror: a port order goes the same way down
    _, dm = run_rudder(packed, eq, -DMAX, 40.0, dt)
    np.testing.assert_allclose(dm, -d, rtol=0, atol=1e-15)


def test_order_beyond_the_stop_is_clipped(compiled):
    """A 50 deg order is a 35 deg order (Table 1 delta_max); the angle never passes 35 deg."""
    packed, eq = compiled
    _, d50 = run_rudder(packed, eq, 50 * DEGREE, 60.0, 0.05)
    _, d35 = run_rudder(packed, eq, DMAX, 60.0, 0.05)
    np.testing.assert_array_equal(d50, d35)
    assert np.max(d50) <= DMAX and d50[-1] == pytest.approx(DMAX, abs=1e-6)
    # from the stop a reversal starts at the full rate
    _, back = run_rudder(packed, eq, -50 * DEGREE, 1.0, 0.05, delta0=DMAX)
    assert (back[0] - back[-1]) == pytest.approx(RATE * 1.0, rel=1e-12)


# --------------------------------------------------------------------------- constant-power shaft, eqs. (15)-(19)


def shp0_watts(u0):
    """Eqs. (18)-(19) as printed: 745 x SHP_0(u0), SHP_0 = -601.1 + 632.0 u - 182.0 u^2 + 74.7 u^3."""
    return PAPER_W_PER_SHP * _poly(PAPER_SHP0, u0)


def test_engine_power_is_eq19_at_the_approach_speed(compiled):
    from mmg.model import P_POWER

    packed, eq = compiled
    P0 = shp0_watts(U_APPROACH)
    assert P0 == pytest.approx(5.963e6, rel=1e-3)          # 8004 HP at 10 kn (fact sheet s. 6)
    assert eq.power_W == pytest.approx(P0, rel=1e-12)
    assert packed.p[P_POWER] == pytest.approx(P0, rel=1e-12)


def test_torque_balance_at_the_straight_run(compiled, paper):
    """At the 10 kn straight run Q_E = 745 SHP_0/(2 pi n_0) equals rho n_0^2 D^5 K_Q(J_0) and dn/dt = 0."""
    packed, eq = compiled
    D, rho = PAPER_TABLE1["D_P"], 1025.0
    n0 = eq.n
    Q_E = shp0_watts(U_APPROACH) / (2 * np.pi * n0)
    assert Q_E == pytest.approx(1.05e6, rel=0.01)           # 1.05 MN m (fact sheet s. 6)
    J0 = paper.propeller(eq.u, eq.v, 0.0, n0)[1]
    assert J0 == pytest.approx(eq.u * paper.one_minus_wake(eq.u, eq.v, 0.0) / (n0 * D), rel=1e-15)
    # surge balance at J_0 with the paper's K_T (eq. 12) is what fixes n_0
    assert _poly(PAPER_KT, J0) > 0.15
    Q_P = rho * n0**2 * D**5 * eq.K_Q_scale * _poly(paper.K_Q, J0)
    assert Q_P == pytest.approx(Q_E, rel=1e-10)
    out = compiled_rhs(packed, eq.state()[None, :], np.array([eq.delta]))[0]
    assert abs(out[IN]) < 1e-12 and abs(out[IU]) < 1e-10


def test_shaft_acceleration_is_eq15(compiled, paper):
    """dn/dt of rhs() = (Q_E - Q_P) / (2 pi (I+J)), with Q_E = 745 SHP_0(u_0)/(2 pi n) (constant power),
    Q_P = rho n^2 D^5 K_Q(J_P), (I+J) = 2.0 D^5, at random (u, v, r, n)."""
    packed, eq = compiled
    D, rho = PAPER_TABLE1["D_P"], 1025.0
    X, cmd = random_states(np.random.default_rng(15), 300)
    u, v, r, n = X[:, IU], X[:, IV], X[:, 2], X[:, IN]
    J = paper.propeller(u, v, r, n)[1]
    Q_E = shp0_watts(U_APPROACH) / (2 * np.pi * n)
    Q_P = rho * n**2 * D**5 * paper.kq_scale * _poly(paper.K_Q, J)
    expect = (Q_E - Q_P) / (2 * np.pi * PAPER_SHAFT_INERTIA_COEF * D**5)
    got = compiled_rhs(packed, X, cmd)[:, IN]
    np.testing.assert_allclose(got, expect, rtol=1e-9, atol=1e-9 * np.max(np.abs(expect)))
    # the engine delivers constant power: (2 pi I dn/dt + Q_P) 2 pi n = P_0 at every state
    P = (2 * np.pi * PAPER_SHAFT_INERTIA_COEF * D**5 * got + Q_P) * 2 * np.pi * n
    np.testing.assert_allclose(P, shp0_watts(U_APPROACH), rtol=1e-9)


def test_shaft_recovers_from_an_rpm_step_at_the_eq15_rate(compiled, paper):
    """1 % rpm above the straight run the shaft decelerates at (Q_E - Q_P)/(2 pi 2.0 D^5), and the linearised
    time constant is the fact sheet's ~0.17 s for (I+J) in kg m^2."""
    packed, eq = compiled
    x = eq.state()[None, :].copy()
    x[0, IN] *= 1.01
    dn = compiled_rhs(packed, x, np.array([eq.delta]))[0, IN]
    assert dn < 0
    tau = -(0.01 * eq.n) / dn
    assert 0.1 < tau < 0.25
    assert dn == pytest.approx(paper.shaft(x[0, IU], x[0, IV], 0.0, x[0, IN]), rel=1e-9)
