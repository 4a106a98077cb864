"""The full-astern stopping test (MSC.137(76) 5.3.4): the engine order, the metrics, the simulated stop.

The reaches are checked against figures computed here another way (the velocities integrated in time,
not the positions' polyline; closed forms on made-up tracks), the revolutions against the ramp written
out here, and the physics by properties that must hold: the ship slows steadily once the engine is
full astern, stops within the record, and stops sooner with more astern revolutions or a faster reversal.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import mmg
from mmg.engine_order import AsternOrder
from mmg.errors import InputError
from trials.analysis.metrics import stopping_metrics
from trials.runs.run import run_trial
from trials.runs.trial import make_trial, stopping

L_ESSO = 325.0


@pytest.fixture(scope="module")
def esso_stop():
    return run_trial(stopping("esso_osaka", speed="10 kn", duration="4000 s", dt="0.1 s"))


def _trapezoid(f, t):
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(t)))


def test_reaches_equal_the_integrated_velocities(esso_stop):
    """Track reach = time integral of the speed through the water (calm water: over ground too); head
    reach and lateral deviation = the integrals of the velocity along and across the approach heading."""
    r = esso_stop
    m = r.metrics()
    assert m["stopped"] and not r.completed                    # the simulator ended the run at the stop
    t, u, v, psi = r.t, r.u, r.v, r.psi
    psi0 = psi[0]
    speed = np.hypot(u, v)
    along = u * np.cos(psi - psi0) - v * np.sin(psi - psi0)
    across = u * np.sin(psi - psi0) + v * np.cos(psi - psi0)
    # the record ends less than a step before the stop: what is left is < U dt < 0.01 m
    assert m["track_reach_L"] == pytest.approx(_trapezoid(speed, t) / L_ESSO, rel=1e-6)
    assert m["head_reach_L"] == pytest.approx(_trapezoid(along, t) / L_ESSO, rel=1e-6)
    assert m["lateral_deviation_L"] == pytest.approx(_trapezoid(across, t) / L_ESSO, rel=1e-5, abs=1e-6)
    assert m["time_to_stop_s"] == pytest.approx(t[-1], abs=0.1)
    assert 0.0 < m["head_reach_L"] <= m["track_reach_L"]
    # the straight-line distance cannot exceed the path
    assert math.hypot(m["head_reach_L"], m["lateral_deviation_L"]) <= m["track_reach_L"] + 1e-9


def test_the_revolutions_follow_the_order_whatever_the_engine(esso_stop):
    """The Esso Osaka has a constant-power engine; in the stopping test its revolutions are prescribed:
    n0 down to -0.7 n0 along a straight line in 120 s, then held."""
    r = esso_stop
    assert r.trial.ship.engine.mode == "constant_power"
    n0 = r.n[0]
    want = np.where(r.t < 120.0, n0 + (r.t / 120.0) * (-0.7 * n0 - n0), -0.7 * n0)
    assert np.allclose(r.n, want, rtol=0, atol=1e-9 * n0)
    assert n0 * 60 == pytest.approx(r.metrics()["approach_rpm"], rel=1e-12)


def test_the_ship_slows_steadily_once_full_astern(esso_stop):
    """After the reversal the surge speed falls at every step until the stop; the speed through the
    water and the kinetic energy (rigid body plus added mass) too."""
    r = esso_stop
    after = r.t >= 120.0
    assert np.all(np.diff(r.u[after]) < 0.0)
    from mmg.nondim import inertia_scale, mass_scale

    sh = r.trial.ship
    pa, ms = sh.particulars, sh.mass
    k, kz = mass_scale(pa.rho, pa.L, pa.T), inertia_scale(pa.rho, pa.L, pa.T)
    m, mx, my = ms.m_prime * k, ms.m_x_prime * k, ms.m_y_prime * k
    Iz = (ms.I_zG_prime + ms.J_z_prime) * kz
    xG = pa.x_G                      # the mass matrix about midship (mmg.model.accelerations)
    energy = 0.5 * ((m + mx) * r.u ** 2 + (m + my) * r.v ** 2 + (Iz + xG ** 2 * m) * r.r ** 2) + xG * m * r.v * r.r
    assert np.all(np.diff(energy[after]) < 0.0)
    assert energy[-1] < 1e-3 * energy[0]


def test_more_astern_thrust_stops_sooner():
    """More astern revolutions (more astern thrust) or a faster reversal: a shorter track reach and
    an earlier stop; a property of any braking, not a value."""
    ship = mmg.load_ship("esso_osaka")
    kw = {"speed": "10 kn", "duration": "6000 s", "dt": "0.2 s"}
    reach, time = {}, {}
    for k, (ratio, ramp) in enumerate([(0.5, "120 s"), (0.7, "120 s"), (0.9, "120 s"), (0.7, "30 s"),
                                       (0.7, "400 s")]):
        m = run_trial(stopping(ship, astern_ratio=ratio, reversal=ramp, **kw)).metrics()
        assert m["stopped"]
        reach[ratio, ramp], time[ratio, ramp] = m["track_reach_L"], m["time_to_stop_s"]
    assert reach[0.5, "120 s"] > reach[0.7, "120 s"] > reach[0.9, "120 s"]
    assert time[0.5, "120 s"] > time[0.7, "120 s"] > time[0.9, "120 s"]
    assert reach[0.7, "30 s"] < reach[0.7, "120 s"] < reach[0.7, "400 s"]


@pytest.mark.parametrize("psi0_deg", [0.0, 30.0, -135.0])
def test_metrics_of_a_straight_stop_match_the_closed_form(psi0_deg):
    """u = V (1 - t / T) along a straight line at heading psi0: reach V T / 2 (to the 1 % speed:
    V T (1 - 0.01^2) / 2), no lateral deviation, time to stop 0.99 T."""
    V, T, L = 5.0, 1000.0, 300.0
    t = np.linspace(0.0, 1200.0, 12001)
    u = np.maximum(V * (1 - t / T), -1.0)
    s = V * t - 0.5 * V * t ** 2 / T
    psi = np.full_like(t, np.radians(psi0_deg))
    m = stopping_metrics(t, s * np.cos(psi), s * np.sin(psi), psi, u, 0 * t, L)
    want = V * T * (1 - 0.01 ** 2) / 2 / L
    assert m["stopped"]
    assert m["track_reach_L"] == pytest.approx(want, rel=1e-9)
    assert m["head_reach_L"] == pytest.approx(want, rel=1e-9)
    assert m["lateral_deviation_L"] == pytest.approx(0.0, abs=1e-9)
    assert m["time_to_stop_s"] == pytest.approx(0.99 * T, rel=1e-9)


def test_metrics_of_a_stop_on_an_arc():
    """Along a circle of radius R turning to starboard through theta at the stop: track reach R theta,
    head reach R sin theta, lateral deviation + R (1 - cos theta) (starboard)."""
    R, L, V, T = 2000.0, 300.0, 5.0, 800.0
    t = np.linspace(0.0, 1000.0, 100001)
    u = V * (1 - t / T)
    s = V * t - 0.5 * V * t ** 2 / T
    th = s / R
    x, y = R * np.sin(th), R * (1 - np.cos(th))           # north, east; heading north at the order
    m = stopping_metrics(t, x, y, th, u, 0 * t, L)
    th_stop = V * T * (1 - 0.01 ** 2) / 2 / R
    assert m["track_reach_L"] == pytest.approx(R * th_stop / L, rel=1e-6)
    assert m["head_reach_L"] == pytest.approx(R * np.sin(th_stop) / L, rel=1e-6)
    assert m["lateral_deviation_L"] == pytest.approx(R * (1 - np.cos(th_stop)) / L, rel=1e-5)
    assert m["heading_change_deg"] == pytest.approx(np.degrees(th_stop), rel=1e-6)


def test_a_ship_that_never_stops_gives_none():
    t = np.linspace(0.0, 100.0, 101)
    m = stopping_metrics(t, 5.0 * t, 0 * t, 0 * t, np.full_like(t, 5.0), 0 * t, 100.0)
    assert not m["stopped"] and m["track_reach_L"] is None and m["head_reach_L"] is None


def test_order_table_and_refusals():
    o = AsternOrder(astern_ratio=0.8, ramp_s=60.0, execute_s=10.0)
    t, n = o.table(2.0, 500.0)
    assert np.interp([0.0, 10.0, 40.0, 70.0, 400.0], t, n) == pytest.approx([2.0, 2.0, 0.2, -1.6, -1.6])
    assert o.revolutions([0.0, 40.0, 1000.0], 2.0) == pytest.approx([2.0, 0.2, -1.6])
    for bad in ({"astern_ratio": 0.0}, {"astern_ratio": -0.5}, {"astern_ratio": float("nan")}, {"ramp_s": -1.0},
                {"execute_s": float("inf")}, {"astern_ratio": True}):
        with pytest.raises(ValueError):
            AsternOrder(**bad)


def test_the_yaml_edge_takes_units_and_names_the_field():
    tr = make_trial("esso_osaka", {"kind": "stopping", "reversal": "2 min", "astern_ratio": 0.6},
                    speed="10 kn", duration="3000 s")
    assert tr.manoeuvre["reversal"] == 120.0 and tr.astern_order() == AsternOrder(0.6, 120.0, 0.0)
    assert tr.manoeuvre["rudder"] == 0.0
    for man, field in (({"kind": "stopping", "reversal": "120"}, "manoeuvre.reversal"),
                       ({"kind": "stopping", "astern_ratio": 2.0}, "manoeuvre.astern_ratio"),
                       ({"kind": "stopping", "rudder": "40 deg"}, "manoeuvre.rudder")):
        with pytest.raises(InputError) as e:
            make_trial("esso_osaka", man, speed="10 kn", duration="3000 s")
        assert e.value.field == field
