"""``mmg diagnose`` on records it did not write (tests that can fail).

The records here are NOT made by :mod:`mmg.effects` (the code the diagnosis inverts): the clean
ship is simulated by :func:`mmg.simulation.simulate`, and each effect is applied afterwards by the
plain formulas of the independent writer, ``tests/independent_writer.py`` (its docstring gives the
conventions, those of ``../shared/data/diagnose-dev/README.md``).

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
import pytest

from .conftest import REPO
from .independent_writer import G, load_config
from .independent_writer import angdiff as _angdiff
from .independent_writer import log as _log
from .independent_writer import records as _records
from .independent_writer import truth_ship as _truth_ship
from .independent_writer import turn as _turn

DEV = REPO.parent / "shared" / "data" / "diagnose-dev"


# --------------------------------------------------------------------------- the independent writer (tests/independent_writer.py)


@pytest.fixture(scope="module")
def config():
    return load_config()


@pytest.fixture(scope="module")
def truth(config):
    return _truth_ship(config)


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
    positive dBIC whose z clears Z_THRESHOLD: shallow water at dBIC 16, z 11, has been seen),
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
    sea trial runs it): nothing named; a diagnosis that takes the ship's own 5 % mismatch for an effect
    names a rudder offset here (dBIC 38)."""
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
    the config has equal: the offset named at its value within 0.3 deg (the tolerance).  The
    asymmetry makes the rudder's force one-sided in the swing, what an offset does; with gamma_R held
    at the config's (``ZIGZAG_CONSTANTS_FREE`` empty) the offset takes it:
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
