"""``mmg diagnose`` on records it did not write (issue 26, "Tests that can fail").

The records here are NOT made by :mod:`mmg.effects` (the code the diagnosis inverts): the clean
ship is simulated by :func:`mmg.simulation.simulate`, and each effect is applied afterwards by the
plain formulas below, in the conventions of ``../shared/data/diagnose-dev/README.md``:

* current ``c`` setting towards ``chi`` (clockwise from north; x north, y east): the simulation in
  still water is the motion relative to the water; over ground x += c cos(chi) t, y += c sin(chi) t,
  and the logged u, v are the over-ground velocity resolved in the heading axes;
* heading bias ``b``: logged heading = true + b, logged u, v = the over-ground velocity resolved in
  the logged heading's axes, positions right;
* rudder offset ``o``: the blade sits o to starboard of the indicator: the ship is simulated with
  the actual blade angle, the indicator logs actual - o (a zigzag: the helm orders +-a on the
  indicator, so the blade is at +-a + o);
* noise: uniform, independent per sample, seeded (the dev set's half-widths, Froude-scaled).

The record is written as an FRT-DS-ESSO CSV and the FILE is diagnosed.  The truth ship differs
from the config by 5 % in a few hull coefficients, so "the same model" is not what passes.  A sign
error in an effect (the current's direction, the heading bias, the rudder offset) fails one of
these; so does a decision rule without its threshold (the clean test).  The dev-set tests read two
logs of another simulator (skipped where ../shared/data/diagnose-dev is absent).
"""
import json
import math
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from .conftest import REPO

DEV = REPO.parent / "shared" / "data" / "diagnose-dev"

G = 9.80665
DT = 0.2                     # logged sampling step [s] of the 3 m model records
DT_SIM = 0.02                # integration step [s]
TURN_S, ZIGZAG_S = 120.0, 160.0   # record lengths [sqrt(L/g)]


def _angdiff(a_deg, b_deg):
    return (a_deg - b_deg + 180.0) % 360.0 - 180.0


# --------------------------------------------------------------------------- the independent writer


@pytest.fixture(scope="module")
def config():
    from mmg.resources import ship_path
    from mmg.ship import load_ship

    return load_ship(ship_path("esso_osaka_3m"))


@pytest.fixture(scope="module")
def truth(config):
    return _truth_ship(config)


def _truth_ship(config):
    """The ship that makes the records: a few hull coefficients 5 % off the config's."""
    h = config.hull
    moved = {"Y_beta": 1.05, "N_r": 1.05, "Y_r": 0.95, "N_beta": 0.95, "Y_bb": 1.05, "N_rr": 0.95}
    vals = tuple(v * moved.get(n, 1.0) for n, v in zip(h.names, h.values))
    return replace(config, hull=replace(h, values=vals))


def _speed(ship):
    return 0.09 * math.sqrt(G * ship.particulars.L)


def _simulate(ship, order_t, order_delta, T):
    """The clean ship in still water under a rudder schedule (actual blade orders)."""
    from mmg.integrate import CommandLaw
    from mmg.simulation import simulate

    law = CommandLaw.schedule(order_t, order_delta)
    return simulate(ship, law, T, DT_SIM, _speed(ship), trim=False)


def _turn(ship, rudder_deg, T):
    """A turn: blade 0 in the approach, ``rudder_deg`` from 5 sqrt(L/g) on (actual angles)."""
    s = math.sqrt(ship.particulars.L / G)
    a = math.radians(rudder_deg)
    t1 = 5.0 * s
    return _simulate(ship, [0.0, t1, t1 + 1e-6, T], [0.0, 0.0, a, a], T)


def _zigzag(ship, rudder_deg, heading_deg, offset_deg, T):
    """A zigzag steered on the indicator: the helm orders +-a there, the blade goes to +-a + o; the
    order reverses when the (true) heading passes +-heading_deg.  Built by re-simulating with the
    reversal times found so far (the schedule is the helm's, the simulator only integrates)."""
    s = math.sqrt(ship.particulars.L / G)
    a, o, lim = math.radians(rudder_deg), math.radians(offset_deg), math.radians(heading_deg)
    t0 = 5.0 * s
    switches = []                                   # reversal times

    def table():
        # before the execute the helm holds the indicator at -o (blade at 0: a straight approach)
        ts, ds, side = [0.0, t0, t0 + 1e-6], [0.0, 0.0, a + o], 1.0
        for tk in switches:
            ts += [tk, tk + 1e-6]
            ds += [side * a + o, -side * a + o]
            side = -side
        ts.append(T)
        ds.append(side * a + o)
        return ts, ds, side

    while True:
        ts, ds, side = table()
        sim = _simulate(ship, ts, ds, T)
        psi = sim.states[:, 5]
        after = sim.t > (switches[-1] if switches else t0) + 1e-9
        hit = np.nonzero(after & ((psi >= lim) if side > 0 else (psi <= -lim)))[0]
        if not len(hit):
            return sim
        switches.append(float(sim.t[hit[0]]))


def _log(ship, sim, *, current=None, bias_deg=0.0, offset_deg=0.0, seed=0):
    """Sample the simulation every DT and log it with the effects and noise (plain formulas)."""
    L = ship.particulars.L
    lam = 325.0 / L                                       # Froude scale of the dev set's noise
    t = np.arange(0.0, sim.t[-1] + 1e-9, DT)
    i = np.minimum(np.searchsorted(sim.t, t - 1e-9), len(sim.t) - 1)
    u, v, r, x, y, psi, delta, n = (sim.states[i, j] for j in range(8))
    # earth-frame velocity through the water (x north, y east)
    xd = u * np.cos(psi) - v * np.sin(psi)
    yd = u * np.sin(psi) + v * np.cos(psi)
    if current is not None:
        c, chi = current[0], math.radians(current[1])
        xd, yd = xd + c * math.cos(chi), yd + c * math.sin(chi)
        x, y = x + c * math.cos(chi) * t, y + c * math.sin(chi) * t
    psi_log = psi + math.radians(bias_deg)
    u_log = xd * np.cos(psi_log) + yd * np.sin(psi_log)
    v_log = -xd * np.sin(psi_log) + yd * np.cos(psi_log)
    delta_log = delta - math.radians(offset_deg)
    rng = np.random.default_rng(seed)
    uni = lambda h: rng.uniform(-h, h, len(t))        # noqa: E731
    vel = 0.02 / math.sqrt(lam)
    return pd.DataFrame({
        "t [s]": t,
        "x_position_mid [m]": x + uni(0.5 / lam),
        "u_velo [m/s]": u_log + uni(vel),
        "y_position_mid [m]": y + uni(0.5 / lam),
        "vm_velo [m/s]": v_log + uni(vel),
        "psi_hat [rad]": np.mod(psi_log + uni(math.radians(0.05)) + math.pi, 2 * math.pi) - math.pi,
        "r_angvelo [rad/s]": r + uni(0.0002 * math.sqrt(lam)),
        "n_prop [rps]": n,
        "delta_rudder [rad]": delta_log,
        "wind_velo_relative_mid [m/s]": 0.0 * t,
        "wind_dir_relative_mid [rad]": 0.0 * t,
        "wind_velo_true [m/s]": 0.0 * t,
        "wind_dir_true [rad]": 0.0 * t,
    })


def _records(tmp_path, ship, kinds=("turn", "zigzag"), zigzag_s=ZIGZAG_S, **effects):
    """Write the records (35 deg starboard turn of TURN_S, 20/20 zigzag of ``zigzag_s`` sqrt(L/g)) with
    ``effects`` as FRT-DS-ESSO CSVs; returns their paths."""
    s = math.sqrt(ship.particulars.L / G)
    off = effects.get("offset_deg", 0.0)
    paths = []
    for k, kind in enumerate(kinds):
        if kind == "turn":
            sim = _turn(ship, 35.0, TURN_S * s)
        else:
            sim = _zigzag(ship, 20.0, 20.0, off, zigzag_s * s)
        p = tmp_path / f"{kind}.csv"
        _log(ship, sim, seed=k + 1, **effects).to_csv(p, index=False)
        paths.append(p)
    return paths


def _diagnose(config, paths, **kw):
    from trials.measured.diagnose import diagnose

    return diagnose(config, paths, **kw)


# --------------------------------------------------------------------------- the writer itself


def test_writer_conventions(truth, tmp_path):
    """The writer's own conventions, checked on its output (not on the diagnosis): a current towards
    east moves the track east by c t; a bias adds to the logged heading; an offset shifts the indicator."""
    s = math.sqrt(truth.particulars.L / G)
    sim = _turn(truth, 0.0, 10.0 * s)                     # rudder 0: a straight run north
    clean = _log(truth, sim)
    cur = _log(truth, sim, current=(0.05, 90.0), bias_deg=2.0, offset_deg=1.0)
    t = clean["t [s]"].to_numpy()
    dy = (cur["y_position_mid [m]"] - clean["y_position_mid [m]"]).to_numpy()
    assert np.allclose(dy, 0.05 * t, atol=0.02)
    dpsi = _angdiff(np.degrees(cur["psi_hat [rad]"]), np.degrees(clean["psi_hat [rad]"]))
    assert abs(np.median(dpsi) - 2.0) < 0.02
    # heading north + 2 deg, current east: logged sway = +c cos(2 deg) - u sin(2 deg) to starboard
    u0 = np.median(clean["u_velo [m/s]"])
    assert abs(np.median(cur["vm_velo [m/s]"]) - (0.05 * math.cos(math.radians(2)) - u0 * math.sin(math.radians(2)))) < 2e-3
    assert np.allclose(cur["delta_rudder [rad]"] - clean["delta_rudder [rad]"], -math.radians(1.0))


# --------------------------------------------------------------------------- the decision rule


def test_clean_mismatched_ship_names_nothing_by_the_threshold(truth, config, tmp_path):
    """A clean turn and a 20/20 zigzag of six reversals (300 sqrt(L/g)) of a ship 5 % off its config:
    nothing named, every candidate tried; and the threshold is what keeps one out (a candidate with a
    positive dBIC whose z clears Z_THRESHOLD: on the code of issue 26 shallow water at dBIC 16, z 11),
    so the decision rule without its threshold or its BIC penalty fails here."""
    from trials.measured.diagnose import Z_THRESHOLD

    d = _diagnose(config, _records(tmp_path, truth, zigzag_s=300.0))
    assert d.named == [], d.rounds
    tried = {c["effect"] for c in d.rounds[0]["candidates"]}
    assert {"current", "heading_bias", "rudder_offset"} <= tried
    cands = [c for r in d.rounds for c in r["candidates"]]
    assert any(c["delta_bic"] > 0 and c["z"] > Z_THRESHOLD for c in cands), cands


def test_clean_full_zigzag_names_nothing(truth, config, tmp_path):
    """The same ship on a turn and a full 20/20 zigzag (nine reversals and more, 400 sqrt(L/g), as a
    sea trial runs it): nothing named.  On the code of issue 26 this names a rudder offset
    (dBIC 38): the ship's own 5 % mismatch taken for an effect (the issue's defect 2)."""
    d = _diagnose(config, _records(tmp_path, truth, zigzag_s=400.0))
    assert d.named == [], d.rounds


# --------------------------------------------------------------------------- each effect, value and sign


def test_current_named_speed_and_direction(truth, config, tmp_path):
    """A current of 0.012 sqrt(gL) (0.65 m/s at 325 m) setting towards 120 deg on a turn and a
    zigzag, every candidate tried: the current alone, direction within 10 deg, speed within 15 %."""
    c = 0.012 * math.sqrt(G * truth.particulars.L)
    d = _diagnose(config, _records(tmp_path, truth, current=(c, 120.0)))
    assert d.named == ["current"], d.rounds
    p = d.parameters["current"]
    assert abs(_angdiff(p["direction_deg"], 120.0)) <= 10.0, p
    assert abs(p["speed_mps"] - c) <= 0.15 * c, p


def test_current_direction_on_a_turn(truth, config, tmp_path):
    """One turn, a current towards 300 deg (the other side): direction and speed."""
    c = 0.012 * math.sqrt(G * truth.particulars.L)
    d = _diagnose(config, _records(tmp_path, truth, kinds=("turn",), current=(c, 300.0)), candidates=["current"])
    assert d.named == ["current"], d.rounds
    p = d.parameters["current"]
    assert abs(_angdiff(p["direction_deg"], 300.0)) <= 10.0, p
    assert abs(p["speed_mps"] - c) <= 0.15 * c, p


@pytest.mark.parametrize("bias", [2.0, -2.0])
def test_heading_bias_named_with_sign(truth, config, tmp_path, bias):
    d = _diagnose(config, _records(tmp_path, truth, kinds=("zigzag",), bias_deg=bias),
                  candidates=["heading_bias"])
    assert d.named == ["heading_bias"], d.rounds
    assert abs(d.parameters["heading_bias"]["bias_deg"] - bias) <= 0.3, d.parameters


@pytest.mark.parametrize("offset", [2.0, -2.0])
def test_rudder_offset_named_with_sign(truth, config, tmp_path, offset):
    d = _diagnose(config, _records(tmp_path, truth, kinds=("zigzag",), offset_deg=offset),
                  candidates=["rudder_offset"])
    assert d.named == ["rudder_offset"], d.rounds
    assert abs(d.parameters["rudder_offset"]["offset_deg"] - offset) <= 0.3, d.parameters


def _asymmetric(truth, pos=1.15, neg=0.85):
    """``truth`` whose rudder flow straightening differs for the two signs of its inflow angle
    (gamma_R_pos 15 % above the config's, gamma_R_neg 15 % below: a real ship's two differ)."""
    ru = truth.rudder
    return replace(truth, rudder=replace(ru, gamma_R_pos=ru.gamma_R_pos * pos, gamma_R_neg=ru.gamma_R_neg * neg))


@pytest.mark.parametrize("offset", [1.0])
def test_rudder_offset_beside_an_asymmetric_rudder_inflow(truth, config, tmp_path, offset):
    """A 1 deg offset on a zigzag of a ship whose gamma_R differ by 30 % between the two sides, which
    the config has equal: the offset named at its value within 0.3 deg (the issue's tolerance).  The
    asymmetry makes the rudder's force one-sided in the swing, what an offset does; with gamma_R held
    at the config's (``ZIGZAG_CONSTANTS_FREE`` empty, the code before stop 40) the offset took it:
    +1 deg fitted 0.22 deg and not named, -1 deg fitted -1.75 deg (0.85 and -1.27 deg with them
    freed).  -1 deg is left out of the fast suite: its 0.03 deg margin on the tolerance is too thin
    for a test meant to catch a lost gamma_R, and the sign is checked at 2 deg above."""
    ship = _asymmetric(truth)
    d = _diagnose(config, _records(tmp_path, ship, kinds=("zigzag",), offset_deg=offset),
                  candidates=["rudder_offset"])
    assert d.named == ["rudder_offset"], d.rounds
    assert abs(d.parameters["rudder_offset"]["offset_deg"] - offset) <= 0.3, d.parameters


def test_asymmetric_rudder_inflow_is_not_an_offset(truth, config, tmp_path):
    """The same asymmetric ship on a clean zigzag: no rudder offset named.  With gamma_R held at the
    config's an offset of -0.75 deg was fitted and named (dBIC 185, z 14.6); with them freed -0.24 deg
    at dBIC 6.5."""
    ship = _asymmetric(truth)
    d = _diagnose(config, _records(tmp_path, ship, kinds=("zigzag",)), candidates=["rudder_offset"])
    assert d.named == [], d.rounds


# --------------------------------------------------------------------------- the dev set (another simulator)


def _dev(name):
    if not (DEV / "manifest.json").is_file():
        pytest.skip("dev set ../shared/data/diagnose-dev absent")
    man = json.loads((DEV / "manifest.json").read_text())
    entry = next(f for f in man["files"] if f["file"] == f"data/{name}.csv")
    return DEV / entry["file"], entry


def test_dev_current_on_a_port_turn():
    """dev_06: a port 35 deg turn with a current: the current alone, within 0.05 m/s and 15 deg."""
    from mmg.resources import ship_path
    from mmg.ship import load_ship

    path, entry = _dev("dev_06")
    assert entry["effects"] == ["current"]
    truth = entry["parameters"]["current"]
    d = _diagnose(load_ship(ship_path("esso_osaka")), [path])
    assert d.named == ["current"], d.rounds
    p = d.parameters["current"]
    assert abs(p["speed_mps"] - truth["speed_m_s"]) <= 0.05, p
    assert abs(_angdiff(p["direction_deg"], truth["set_towards_deg"])) <= 15.0, p


def test_dev_heading_bias_on_a_zigzag():
    """dev_14: a 20/20 zigzag with a heading bias: the bias alone, within 0.3 deg."""
    from mmg.resources import ship_path
    from mmg.ship import load_ship

    path, entry = _dev("dev_14")
    assert entry["effects"] == ["heading_bias"]
    truth = entry["parameters"]["heading_bias"]["bias_deg"]
    d = _diagnose(load_ship(ship_path("esso_osaka")), [path])
    assert d.named == ["heading_bias"], d.rounds
    assert abs(d.parameters["heading_bias"]["bias_deg"] - truth) <= 0.3, d.parameters
