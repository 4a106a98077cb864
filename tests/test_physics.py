"""Physics invariants of the simulator: equilibrium, symmetry, convergence, Kijima, disturbances."""
import numpy as np
import pytest

from mmg.effects import effect_set
from mmg.integrate import CommandLaw
from mmg.kijima import compare
from mmg.simulation import prepare, simulate
from mmg.units import DEG, KNOT
from trials.analysis.metrics import turning_metrics

U0 = 10 * KNOT


def turn(ship, rudder_deg, dt=0.1, duration=3000.0, trim=True):
    law = CommandLaw.schedule([0.0, duration], [rudder_deg * DEG] * 2)
    return simulate(ship, law, duration, dt, U0, trim=trim)


def test_straight_run_equilibrium_holds_speed_and_heading(esso):
    pk, eq = prepare(esso, U0)
    assert eq.residual < 1e-10
    law = CommandLaw.schedule([0.0, 3000.0], [eq.delta, eq.delta])
    r = simulate(esso, law, 3000.0, 0.1, U0)
    assert np.max(np.abs(r.U - U0)) / KNOT < 0.01
    assert np.max(np.abs(r.psi)) / DEG < 0.1
    # the trim rudder is a fraction of a degree to starboard (Y_0 > 0, N_0 < 0)
    assert 0.0 < eq.delta / DEG < 1.0
    # and the solved rpm is near the paper's 54.12 rpm
    assert abs(eq.n * 60 - 54.12) < 0.5


def test_untrimmed_straight_run_drifts(esso):
    law = CommandLaw.schedule([0.0, 3000.0], [0.0, 0.0])
    r = simulate(esso, law, 3000.0, 0.1, U0, trim=False)
    # N_0 < 0 turns the bow to port when the rudder is held amidships
    assert r.psi[-1] < -1 * DEG


def test_port_starboard_mirror(esso):
    sym = esso.with_hull({"Y_0": 0.0, "N_0": 0.0})
    a, b = turn(sym, 35.0), turn(sym, -35.0)
    mirror = np.array([1, -1, -1, 1, -1, -1, -1, 1])
    for j in range(8):
        scale = np.max(np.abs(a.states[:, j])) or 1.0
        assert np.max(np.abs(a.states[:, j] - mirror[j] * b.states[:, j])) / scale < 1e-9


def test_tactical_diameter_converges_with_step(esso):
    L = esso.particulars.L
    td = []
    for dt in (0.1, 0.05):
        r = turn(esso, 35.0, dt=dt, duration=1200.0)
        td.append(turning_metrics(r.t, r.x, r.y, r.psi, r.U, L, t_execute=0.0)["tactical_diameter_L"])
    assert abs(td[1] - td[0]) / td[1] < 1e-3


def test_starboard_rudder_turns_to_starboard(esso):
    r = turn(esso, 35.0, duration=300.0)
    assert r.r[-1] > 0 and r.psi[-1] > 0
    assert r.v[-1] < 0  # drifts outward: beta > 0 in a starboard turn


def test_deterministic(esso):
    a, b = turn(esso, 20.0, duration=500.0), turn(esso, 20.0, duration=500.0)
    assert np.array_equal(a.states, b.states)


def test_kijima_formulas_reproduce_table2(esso):
    rows = compare(esso)
    assert len(rows) == 12
    assert max(abs(r["difference_pct"]) for r in rows) < 0.1


def test_uniform_current_drifts_track_only(esso):
    law = CommandLaw.schedule([0.0, 600.0], [0.0, 0.0])
    still = simulate(esso, law, 600.0, 0.1, U0, trim=False)
    cur = simulate(esso, law, 600.0, 0.1, U0, trim=False, effects=effect_set({"current": {"speed_mps": 1.0, "direction_deg": 90.0}}))
    np.testing.assert_allclose(cur.states[:, [0, 1, 2, 5, 6, 7]], still.states[:, [0, 1, 2, 5, 6, 7]], rtol=0, atol=1e-9)
    np.testing.assert_allclose(cur.y - still.y, cur.t * 1.0, atol=1e-6)


def test_rudder_offset_equals_shifted_rudder(esso):
    from mmg.model import pack, rhs

    x = np.array([U0, -0.1, 0.002, 0.0, 0.0, 0.0, 10 * DEG, 0.9])
    y = x.copy()
    y[6] = 12 * DEG
    out_a, out_b = np.zeros(8), np.zeros(8)
    rhs(x, x[6], *effect_set({"rudder_offset": {"offset_deg": 2.0}}).pack(pack(esso, 5e6)).args(), out_a)
    rhs(y, y[6], *pack(esso, 5e6).args(), out_b)
    np.testing.assert_allclose(out_a[:3], out_b[:3], rtol=1e-12)
