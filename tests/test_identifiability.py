"""What the records cannot tell apart (trials.measured.identifiability).

The maths against a hand-built covariance; a single full-scale turning circle of a ship that is not
its model (hull terms 7-25 %, rudder lift and inflow 10-13 % off the config) with a rudder offset of
1.5 deg, which the hull coefficients absorb: reported ``not_identifiable`` with the hull terms it is
confused with and a second trial that would separate it; the starboard and port turns diagnosed
together (one shared offset) name it.  The development set of an independent simulator where present."""
import json
import math
from dataclasses import replace

import numpy as np
import pytest

from .conftest import REPO

DEV = REPO.parent / "shared" / "data" / "diagnose-dev"
NOISE = 6.0 * np.array([0.02, 0.02, 2e-4, 0.5, 0.5, math.radians(0.05)]) / math.sqrt(3.0)
"""Record noise std per column u, v, r, x, y, psi: six times the dev set's uniform half widths' std
(a GNSS velocity of 0.07 m/s, a position of 1.7 m): the information of a short full-scale turn."""


def test_multiple_correlation_against_regression_formula():
    """R^2 of one parameter on the rest is the regression R^2 c' C_rest^-1 c / C_ii (independent of the
    module's canonical-correlation route), and marginal / conditional std = 1 / sqrt(1 - R^2)."""
    from trials.measured.identifiability import block_confounding

    rng = np.random.default_rng(3)
    A = rng.normal(size=(5, 5))
    C = A @ A.T + 0.05 * np.eye(5)
    C[0, 1] = C[1, 0] = 0.97 * math.sqrt(C[0, 0] * C[1, 1])       # a strongly confounded pair
    C = C + max(0.0, -np.linalg.eigvalsh(C)[0] + 1e-3) * np.eye(5)
    for i in range(5):
        rest = [j for j in range(5) if j != i]
        c = C[rest, i]
        r2 = float(c @ np.linalg.solve(C[np.ix_(rest, rest)], c)) / C[i, i]
        b = block_confounding(C, [i])
        assert b["R"] == pytest.approx(math.sqrt(r2), rel=1e-9)
        assert b["ratio"] == pytest.approx(1.0 / math.sqrt(1.0 - r2), rel=1e-9)
        assert b["sd"] == pytest.approx(math.sqrt(C[i, i]), rel=1e-12)
        # conditional std: sd of x_i given the rest, the Schur complement
        cond = C[i, i] - float(c @ np.linalg.solve(C[np.ix_(rest, rest)], c))
        assert b["sd_conditional"] == pytest.approx(math.sqrt(cond), rel=1e-6)


def test_block_correlation_is_first_canonical_correlation():
    """Two parameters (a current's components) against three: the first canonical correlation of the
    blocks, from the whitened cross-covariance's largest singular value (an independent route)."""
    from scipy.linalg import sqrtm

    from trials.measured.identifiability import block_confounding

    rng = np.random.default_rng(5)
    X = rng.normal(size=(400, 5))
    X[:, 0] += 3.0 * X[:, 3]                   # the block's first parameter nearly a copy of another
    C = np.cov(X.T)
    b, r = [0, 1], [2, 3, 4]
    W1 = np.linalg.inv(np.real(sqrtm(C[np.ix_(b, b)])))
    W2 = np.linalg.inv(np.real(sqrtm(C[np.ix_(r, r)])))
    rho = np.linalg.svd(W1 @ C[np.ix_(b, r)] @ W2, compute_uv=False)[0]
    out = block_confounding(C, b)
    assert out["R"] == pytest.approx(rho, rel=1e-8)
    assert out["sd"] == pytest.approx(math.sqrt(np.linalg.eigvalsh(C[np.ix_(b, b)])[-1]), rel=1e-12)
    assert abs(out["corr"][3]) > 0.9 > abs(out["corr"][2])      # the copy is what it is confused with


def test_detection_sizes_in_fit_units():
    from trials.measured.identifiability import detection_size

    assert detection_size("rudder_offset", 325.0) == 1.0 and detection_size("heading_bias", 3.0) == 1.0
    assert detection_size("current", 325.0) == pytest.approx(0.15, rel=0.03)        # m/s at full scale
    assert detection_size("wind", 325.0) == 0.5


@pytest.fixture(scope="module")
def full():
    from mmg.ship import load_ship

    ship = load_ship("esso_osaka")
    v = dict(zip(ship.hull.names, ship.hull.values))
    hull = ship.hull.with_values({"N_r": v["N_r"] * 1.1, "Y_beta": v["Y_beta"] * 0.9, "N_rr": v["N_rr"] * 1.25,
                                  "Y_rr": v["Y_rr"] * 0.75, "N_beta": v["N_beta"] * 1.1, "Y_r": v["Y_r"] * 1.1})
    truth = replace(ship, hull=hull, rudder=replace(ship.rudder, f_alpha=ship.rudder.f_alpha * 0.87,
                                                    epsilon=ship.rudder.epsilon * 1.1))
    return ship, truth


def _turn(full, rudder_deg, seed):
    from trials.measured.diagnose import Manoeuvre, RecordNoise, synthetic_record

    ship, truth = full
    return synthetic_record(ship, Manoeuvre("turning", rudder_deg=rudder_deg, duration=500.0, dt=1.0, speed=5.14),
                            {"rudder_offset": {"offset_deg": 1.5}}, truth_ship=truth,
                            noise=RecordNoise(NOISE, seed=seed), name="stbd" if rudder_deg > 0 else "port")


def test_single_turn_rudder_offset_not_identifiable(full):
    """One starboard turn: the offset is not named (the hull coefficients absorb it) and the diagnosis
    says so, naming hull terms and the port turn or zigzag that would separate it."""
    from trials.measured.diagnose import diagnose
    from trials.measured.identifiability import not_identifiable_lines

    d = diagnose(full[0], [_turn(full, 35.0, 1)])
    assert "rudder_offset" not in d.named
    j = json.loads(json.dumps(d.to_json()))
    ent = {e["effect"]: e for e in j["not_identifiable"]}
    assert "rudder_offset" in ent, j["not_identifiable"]
    e = ent["rudder_offset"]
    hull = set(full[0].hull.names) | {"w_P0", "epsilon", "m_x", "m_y", "J_z"}
    assert e["confused_with"] and set(e["confused_with"]) <= hull
    assert e["correlation"] >= 0.9
    assert 3.0 * e["std"] > 1.0                    # could not have been named at 1 deg
    from trials.measured.decision import REASON_KINDS

    assert e["reason_kind"] == "statistics"        # confounded and imprecise: the first reason that holds
    assert all(x["reason_kind"] in REASON_KINDS for x in j["not_identifiable"])
    assert "port turn" in e["what_would_separate"] or "zigzag" in e["what_would_separate"]
    tr = {t["trial"]: t["std"] for t in e["trials"]}
    assert tr["a 35 deg port turn"] < 0.5 * e["std"]          # the mirror turn separates it
    line = [ln for ln in not_identifiable_lines(j["not_identifiable"]) if "rudder_offset" in ln]
    assert len(line) == 1 and "deg" in line[0]


@pytest.mark.xfail(reason="not met (several records together): the pair's offset fits 0.28 +- 0.10 deg "
                          "(truth 1.5) from every start (0, +-1, 2 deg), dBIC -2.4: the mismatched hull and rudder take "
                          "it; with the 50 % priors of before it was named (1.11 deg) only after a false current "
                          "(0.055 m/s) was named first, its own first-round dBIC -3.4 then too", strict=False)
def test_port_and_starboard_turns_together_name_the_offset(full):
    """The same two turns diagnosed together share one offset (one parameter, not one per record) and
    the pair separates it from the hull terms: named, near its value, not reported as confounded."""
    from ekf.identify import effect_parameters
    from mmg.effects import RudderOffset
    from trials.measured.diagnose import diagnose

    assert all(f.record is None for f in effect_parameters([RudderOffset]))     # shared by every record
    d = diagnose(full[0], [_turn(full, 35.0, 1), _turn(full, -35.0, 2)], max_nfev=30)
    assert "rudder_offset" in d.named
    assert d.parameters["rudder_offset"]["offset_deg"] == pytest.approx(1.5, abs=0.5)
    assert "rudder_offset" not in {e["effect"] for e in d.not_identifiable}
    row = {r["effect"]: r for r in d.identifiability}["rudder_offset"]
    assert row["named"] and 3.0 * row["std"] < 1.0


@pytest.mark.skipif(not (DEV / "manifest.json").is_file(), reason="development set ../shared/data/diagnose-dev absent")
@pytest.mark.parametrize("stem", ["dev_02", "dev_12"])
def test_dev_single_turn_offset_reported(stem):
    """The independent simulator's single 35 deg turns with a rudder offset of 1.2-1.5 deg: not named as
    another effect, reported not identifiable (confused with the ship's own coefficients)."""
    from mmg.resources import ship_path
    from mmg.ship import load_ship
    from trials.measured.diagnose import diagnose

    man = {f["file"]: f for f in json.loads((DEV / "manifest.json").read_text())["files"]}
    assert man[f"data/{stem}.csv"]["effects"] == ["rudder_offset"]
    ship = load_ship(ship_path("esso_osaka"))
    d = diagnose(ship, [DEV / "data" / f"{stem}.csv"], wind=False)
    assert not set(d.named) - {"rudder_offset"}
    if "rudder_offset" not in d.named:
        ent = {e["effect"]: e for e in d.to_json()["not_identifiable"]}
        assert "rudder_offset" in ent
        assert set(ent["rudder_offset"]["confused_with"]) <= set(ship.hull.names) | {"w_P0", "epsilon", "m_x", "m_y", "J_z"}


def test_trial_advice_with_a_named_wind_in_the_model(monkeypatch):
    """A wind named in the model (the 3 m model's turn with a wind and a rudder offset): the candidate
    trials, simulated without wind channels, are replayed in calm air, and the advice is still formed
    (detection size lowered so that the heading bias is reported and the trial path runs)."""
    import trials.measured.identifiability as I
    from mmg.ship import load_ship
    from trials.measured.diagnose import Manoeuvre, RecordNoise, diagnose, synthetic_record

    ship = load_ship("esso_osaka_3m")
    rec = synthetic_record(ship, Manoeuvre("turning", rudder_deg=35.0),
                           {"wind": {"scale": 1.0}, "rudder_offset": {"offset_deg": 1.0}},
                           true_wind=(3.0, math.radians(40.0)), noise=RecordNoise(seed=1), name="t")
    monkeypatch.setitem(I.DETECTION_SIZE, "heading_bias", (1e-3, "deg"))
    d = diagnose(ship, [rec])
    assert "wind" in d.named
    ent = {e["effect"]: e for e in d.not_identifiable}["heading_bias"]
    assert {t["trial"] for t in ent["trials"]} == {"a 35 deg port turn", "a 20/20 zigzag"}
    assert all(t["std"] < ent["std"] for t in ent["trials"])
