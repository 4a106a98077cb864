"""The equations of motion are well-posed down to rest (``mmg.model.kinematics``).

Every measured record starts at rest, where beta = atan(-v/u) and r' = r L / U are undefined.
The model floors the hull's speed scale smoothly below U_low = ``p[P_ULOW]`` (Fn 0.02).  Checked
here on the 3 m Esso Osaka model (``esso_osaka_3m``):

* at u = v = r = 0 the state derivative is finite with the propeller stopped and turning; with
  n = 0 and delta = 0 there is no force at all (exactly zero accelerations); with n > 0 the
  thrust accelerates the ship ahead;
* the derivative is continuous across U_low (just above and just below agree to O(eps));
* above U_low the forces and accelerations are the textbook ones, written independently in
  ``tests/test_physics_reference.py`` (:class:`PaperModel`, from Rhee & Kim 1999 and MMG 2015);
* a replay from rest at constant revolutions accelerates monotonically to the self-propulsion
  speed, finite all the way;
* (hypothesis) the derivative is finite anywhere in |u|, |v| < 2 U_service, |r| < 0.1 rad/s,
  |delta| < 35 deg, n in [-n0, 2 n0].

Astern (u < 0, which the ``random/`` records meet 8-36 % of the time) the hull keeps damping the
motion: resistance opposes it and sway stays damped, continuously across the floor.
"""
from __future__ import annotations

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from .conftest import CONFIGS
from .test_physics_reference import PaperModel

SHIP_3M = CONFIGS / "ships" / "esso_osaka_3m.yaml"
LAMBDA = 325.0 / 3.0
U_SERVICE = 10.0 * 1852.0 / 3600.0 / np.sqrt(LAMBDA)      # 10 kn Froude-scaled: 0.494 m/s
N0 = 10.0                                                  # rps: the records' set revolutions (8 to 16.67)


@pytest.fixture(scope="module")
def ship():
    from mmg.ship import load_ship

    return load_ship(SHIP_3M)


@pytest.fixture(scope="module")
def packed(ship):
    from mmg.model import pack

    return pack(ship)


def deriv(packed, u, v, r, delta=0.0, n=0.0, psi=0.0):
    from mmg.model import rhs

    out = np.zeros(8)
    rhs(np.array([u, v, r, 0.0, 0.0, psi, delta, n], dtype=float), float(delta), *packed.args(), out)
    return out


def accel(packed, *a, **k):
    return deriv(packed, *a, **k)[:3]


def u_low(packed) -> float:
    from mmg.model import P_ULOW

    return float(packed.p[P_ULOW])


# --------------------------------------------------------------------------- at rest


def test_full_scale_paper_trials_stay_above_the_floor():
    """The floor must not touch the reproduced paper trials: the full-scale ST35 (the slowest, it
    keeps 17 % of its speed in the steady turn) and ZZ20 stay above U_low throughout, so their
    forces are the textbook ones (a floor at Fn 0.02 = 1.13 m/s would cut ST35's 0.75 m/s)."""
    import mmg
    from mmg.model import P_ULOW, pack

    ul = pack(mmg.load_ship("esso_osaka")).p[P_ULOW]
    for trial in ("st35", "zz20"):
        tr = mmg.simulate(mmg.load_trial(trial)).truth()
        assert np.hypot(tr.u_mps, tr.v_mps).min() > ul and tr.u_mps.min() > ul, trial


@pytest.mark.parametrize("n", [0.0, 1e-9, 5.0, 10.0, 16.67, -10.0])
@pytest.mark.parametrize("delta_deg", [0.0, 20.0, -35.0])
def test_rhs_at_rest_is_finite(packed, n, delta_deg):
    d = deriv(packed, 0.0, 0.0, 0.0, np.radians(delta_deg), n)
    assert np.all(np.isfinite(d)), d


def test_no_force_at_rest(packed):
    """At rest with the propeller stopped and the rudder amidships nothing acts: exactly zero."""
    d = deriv(packed, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert np.all(d[:3] == 0.0), d[:3]
    assert np.all(d[3:6] == 0.0)


def test_thrust_at_rest_accelerates_ahead(packed):
    """Bollard thrust: du/dt > 0 at rest with n > 0, no sway or yaw with the rudder amidships
    (the rudder's slipstream force is zero at delta = 0), and it grows with n^2."""
    a5, a10 = accel(packed, 0, 0, 0, 0.0, 5.0), accel(packed, 0, 0, 0, 0.0, 10.0)
    assert a5[0] > 0 and a10[0] > 0
    assert a10[0] == pytest.approx(4 * a5[0], rel=1e-12)
    assert a10[1] == 0.0 and a10[2] == 0.0
    # and with the rudder over the slipstream turns the ship even at rest (to starboard for delta > 0)
    assert accel(packed, 0, 0, 0, np.radians(20), 10.0)[2] > 0


# --------------------------------------------------------------------------- continuity across U_low


@pytest.mark.parametrize("angle_deg", [0.0, 10.0, -25.0, 60.0])
@pytest.mark.parametrize("r", [0.0, 0.02, -0.05])
@pytest.mark.parametrize("n,delta_deg", [(0.0, 0.0), (10.0, 0.0), (10.0, 20.0), (16.67, -35.0)])
def test_continuous_across_the_floor(packed, angle_deg, r, n, delta_deg):
    """Just below and just above U_low (1 -+ 1e-9) the accelerations agree to ~1e-9 of their size: the floor
    U_h = (U^2 + U_low^2) / (2 U_low) meets U with equal value and slope (ahead, u > 0)."""
    ul = u_low(packed)
    th = np.radians(angle_deg)
    f = [accel(packed, ul * k * np.cos(th), ul * k * np.sin(th), r, np.radians(delta_deg), n)
         for k in (1 - 1e-9, 1 + 1e-9)]
    scale = max(np.max(np.abs(f[0])), 1e-6)
    assert np.max(np.abs(f[1] - f[0])) <= 1e-7 * scale, (f[0], f[1])


def test_continuous_across_the_floor_astern(packed):
    ul = u_low(packed)
    th = np.radians(180.0 - 20.0)
    f = [accel(packed, ul * k * np.cos(th), ul * k * np.sin(th), 0.01) for k in (1 - 1e-9, 1 + 1e-9)]
    assert np.max(np.abs(f[1] - f[0])) <= 1e-7 * np.max(np.abs(f[0]))


def test_hull_damps_motion_astern(packed):
    """Resistance opposes the motion astern, and sway stays damped (beta of the flow along the hull)."""
    a = accel(packed, -0.2, 0.0, 0.0)            # drifting astern, propeller stopped
    assert a[0] > 0                              # the water slows it
    b = accel(packed, -0.2, 0.05, 0.0)           # astern with some sway to starboard
    assert b[1] < 0                              # sway damped


# --------------------------------------------------------------------------- above U_low: the textbook forces


class Model3m(PaperModel):
    """The reference model of test_physics_reference on the 3 m config; its straight-run solve (a
    constant-power engine the 3 m model does not have) is replaced by fixed values: only the forces
    and the equations of motion are compared."""

    def _straight_run(self):
        return N0, 0.0, 0.0


@pytest.fixture(scope="module")
def reference():
    cfg = yaml.safe_load(SHIP_3M.read_text())
    cfg["engine"] = {"mode": "constant_power", "shaft_inertia_coefficient": 2.0, "watts_per_hp": 745.0, "SHP_0": [1.0]}
    return Model3m(cfg, u0=U_SERVICE)


def test_forces_above_the_floor_are_the_textbook_ones(packed, reference):
    """300 states with U in [1.5 U_low, 0.6 m/s], |beta| < 20 deg, |r'| < 0.5, n 8-20 rps (J < 0.75, the
    propeller polynomial's range), |delta| < 35 deg: total X, Y, N and du, dv, dr as the independent
    reference, to 1e-9 (x_G = 0.094 m: the MMG 2015 midship equations)."""
    from mmg.model import forces

    from .test_physics_reference import assert_close_per_column

    rng = np.random.default_rng(311)
    k = 300
    U = rng.uniform(1.5 * u_low(packed), 0.6, k)
    beta = rng.uniform(-20, 20, k) * np.pi / 180
    u, v = U * np.cos(beta), -U * np.sin(beta)
    r = rng.uniform(-0.5, 0.5, k) * U / 3.0
    delta = rng.uniform(-35, 35, k) * np.pi / 180
    n = rng.uniform(8.0, 20.0, k)
    X = np.zeros((k, 8))
    X[:, 0], X[:, 1], X[:, 2], X[:, 6], X[:, 7] = u, v, r, delta, n
    got_f = np.array([forces(np.ascontiguousarray(x), *packed.args())[:3] for x in X])
    ref_f = np.column_stack(reference.total_forces(u, v, r, delta, n))
    assert_close_per_column(got_f, ref_f, ("X", "Y", "N"))
    got_a = np.array([accel(packed, *x[[0, 1, 2, 6, 7]]) for x in X])
    ref_a = np.column_stack(reference.accelerations(u, v, r, delta, n))
    assert_close_per_column(got_a, ref_a, ("du", "dv", "dr"))


# --------------------------------------------------------------------------- a replay from rest


def test_replay_from_rest_reaches_self_propulsion_monotonically(ship, packed):
    """n = 10 rps from rest, rudder amidships, 300 s: u rises monotonically (no overshoot, no stall at the
    floor) to the self-propulsion speed at which X(u) = 0 (solved here from the forces); finite throughout.
    The hull's constant Y_0', N_0' (asymmetry of the full-scale table) turn the model slowly, so v and r stay
    small but not zero; the speed is compared with the straight-line balance to 0.5 %."""
    from mmg.model import forces
    from mmg.replay import ReplayInputs, replay_states

    t = np.round(np.arange(0.0, 300.0 + 1e-9, 0.1), 10)
    s = replay_states(packed, ReplayInputs(t=t, delta=np.zeros_like(t), n=np.full_like(t, N0)), np.zeros(6))
    assert np.all(np.isfinite(s))
    u = s[:, 0]
    assert np.all(np.diff(u) >= -1e-12), "u not monotonic from rest"
    x_of = lambda uu: forces(np.array([uu, 0, 0, 0, 0, 0, 0, N0], float), *packed.args())[0]  # noqa: E731
    u_sp = brentq(x_of, 0.01, 2.0, xtol=1e-14)
    assert 0.2 < u_sp < 1.0                                   # a plausible model speed at 10 rps
    assert u[-1] == pytest.approx(u_sp, rel=5e-3)
    assert np.max(np.abs(s[:, 2])) < 0.02 and np.max(np.abs(s[:, 1])) < 0.05


# --------------------------------------------------------------------------- anywhere in the envelope


@settings(max_examples=400, deadline=None)
@given(u=st.floats(-2 * U_SERVICE, 2 * U_SERVICE), v=st.floats(-2 * U_SERVICE, 2 * U_SERVICE),
       r=st.floats(-0.1, 0.1), delta=st.floats(-np.radians(35), np.radians(35)), n=st.floats(-N0, 2 * N0),
       psi=st.floats(-7.0, 7.0))
def test_rhs_finite_in_the_envelope(ship, u, v, r, delta, n, psi):
    from mmg.model import pack

    d = deriv(_PACKED.setdefault("p", pack(ship)), u, v, r, delta, n, psi)
    assert np.all(np.isfinite(d)), (u, v, r, delta, n, d)


_PACKED: dict = {}


def test_full_scale_shaft_at_rest():
    """Recorded, not required: the full-scale ship's constant-power engine, Q_E = P / (2 pi n), has no limit
    at n = 0 (dn/dt = inf); the replay prescribes n(t) and never uses it, the simulator never stops the shaft."""
    from mmg.model import rhs
    from mmg.ship import load_ship
    from mmg.simulation import prepare

    pk, _ = prepare(load_ship(CONFIGS / "ships" / "esso_osaka.yaml"), 10 * 1852 / 3600)
    out = np.zeros(8)
    rhs(np.zeros(8), 0.0, *pk.args(), out)
    assert np.all(out[:6] == 0.0)            # no force at rest on the full-scale ship either
    assert not np.isfinite(out[7])           # the shaft equation alone: P / (2 pi n) at n = 0
