"""KVLCC2 L7 (MMG standard method): config, port/starboard mirror, agreement with shipmmg.

Tolerances for the shipmmg comparison come from bench/bench_kvlcc2.py (shipmmg 0.0.11,
its 35 deg / 200 s turn test conditions, RK45 at rtol 1e-10):

* x_G = 0: the two codes solve the same equations; ours (RK4 at the test's 0.1 s step) and
  shipmmg differ by 3e-9 L in position and 1e-7 deg in heading.  Tolerance 1e-6 L, 1e-4 deg
  (RK4 truncation is ~1e-10 L, so this still catches any change of model).
* x_G = 0.25 m (as published): shipmmg evaluates U and beta with (v - x_G r) although its v is
  the midship sway velocity; that alone makes 2.7e-2 L and 1.3 deg after 200 s (with those two
  lines changed to MMG 2015's definitions shipmmg agrees with us to 3e-9 L).  Tolerance
  0.04 L and 2 deg: it bounds that known difference without hiding a real one (a 1 % change of
  N_r already moves the turn by more, see test_shipmmg_tolerance_is_discriminating).
"""
from dataclasses import replace
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from mmg.integrate import CommandLaw
from mmg.ship import load_ship
from mmg.simulation import simulate
from mmg.units import DEG
from trials.analysis.metrics import turning_metrics

REPO = Path(__file__).resolve().parents[1]
YAML = REPO / "configs" / "ships" / "kvlcc2_l7.yaml"


def _bench():
    spec = importlib.util.spec_from_file_location("bench_kvlcc2", REPO / "bench" / "bench_kvlcc2.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def kvlcc2():
    return load_ship(YAML)


def test_config_loads_with_the_mmg2015_model(kvlcc2):
    s = kvlcc2
    assert s.particulars.L == pytest.approx(7.0)
    assert s.propeller.wake_model == "mmg2015"
    assert s.engine.mode == "constant_rpm"
    assert len(s.hull.names) == 17
    terms = dict(zip(s.hull.names, s.hull.terms))
    assert terms["X_0"] == "1" and terms["X_vvvv"] == "v^4" and terms["N_vrr"] == "v*r^2"
    assert s.hull.value("X_0") == pytest.approx(-0.022)  # -R_0'
    # internal consistency of derived constants
    assert s.rudder.eta == pytest.approx(s.propeller.D / s.rudder.H_R, rel=1e-5)
    assert s.mass.I_zG_prime == pytest.approx(s.mass.m_prime * 0.25**2, rel=1e-4)  # k_zz = 0.25 L


def _turn(ship, side, duration=200.0, dt=0.05):
    law = CommandLaw.schedule([0.0, duration], [side * 35 * DEG] * 2)
    return simulate(ship, law, duration, dt, 1.179, n0=17.95, trim=False)


def _swap_signed_constants(ship):
    """gamma_R and C_2 for beta > 0 and beta < 0 exchanged: the mirror image of the ship."""
    ru, pr = ship.rudder, ship.propeller
    return replace(
        ship,
        rudder=replace(ru, gamma_R_pos=ru.gamma_R_neg, gamma_R_neg=ru.gamma_R_pos),
        propeller=replace(pr, C_2_pos=pr.C_2_neg, C_2_neg=pr.C_2_pos),
    )


def test_port_and_starboard_turns_mirror_each_other(kvlcc2):
    stbd = _turn(kvlcc2, +1)
    port_of_mirror = _turn(_swap_signed_constants(kvlcc2), -1)
    flip = np.array([1, -1, -1, 1, -1, -1, -1, 1])  # u, v, r, x, y, psi, delta, n
    assert stbd.completed and port_of_mirror.completed
    np.testing.assert_allclose(port_of_mirror.states * flip, stbd.states, rtol=1e-10, atol=1e-10)
    # the published gamma_R and C_2 differ with the sign of beta_R, beta_P (single-screw
    # asymmetry), so the real ship's port turn is close to, but not exactly, the mirror
    port = _turn(kvlcc2, -1)
    L = kvlcc2.particulars.L
    td_s = turning_metrics(stbd.t, stbd.x, stbd.y, stbd.psi, stbd.U, L, delta=stbd.delta)["tactical_diameter_L"]
    td_p = turning_metrics(port.t, port.x, port.y, port.psi, port.U, L, delta=port.delta)["tactical_diameter_L"]
    assert 1e-4 < abs(td_p / td_s - 1.0) < 0.05


@pytest.mark.parametrize("x_G, pos_tol_L, psi_tol_deg", [(0.0, 1e-6, 1e-4), (None, 0.04, 2.0)])
def test_35deg_turn_agrees_with_shipmmg(kvlcc2, x_G, pos_tol_L, psi_tol_deg):
    pytest.importorskip("shipmmg")
    b = _bench()
    s = b.shipmmg_equivalent(kvlcc2, x_G)
    t = b.test_grid()
    _, ours = b.ours_turn_from_rudder(s, 35 * DEG)
    ref = b.shipmmg_run(s, t, np.full(len(t), 35 * DEG), rtol=1e-10, atol=1e-12)
    ag = b.agreement(ours, ref, s.particulars.L)
    assert ag["pos_max_L"] < pos_tol_L, ag
    assert ag["psi_max_deg"] < psi_tol_deg, ag


def test_shipmmg_tolerance_is_discriminating(kvlcc2):
    """A 1 % change of N_r moves the turn by more than the x_G = 0.25 m tolerance above."""
    b = _bench()
    s = b.shipmmg_equivalent(kvlcc2)
    _, a = b.ours_turn_from_rudder(s, 35 * DEG)
    _, c = b.ours_turn_from_rudder(s.with_hull({"N_r": 1.01 * s.hull.value("N_r")}), 35 * DEG)
    assert b.agreement(a, c, s.particulars.L)["pos_max_L"] > 0.04
