"""The straight run's evidence in ``mmg diagnose``: the mean sway over ground of a record's leading
steady straight run, which a heading bias and a current's cross part set and the hull does not.

The logged states here are written from plain kinematics in the test (earth-frame velocity resolved
in the logged heading's axes, as the development set's README says the logs are made), not with the
effects' own code, so a sign or frame error in :mod:`mmg.effects` or in the residual fails them.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from ekf.identify import (STRAIGHT_RUN_DRIFT_SD, Segmented, StraightRun, effect_parameters,
                          straight_run_residual)
from mmg.effects import Current, HeadingBias
from trials.measured.diagnose import _delta_bic
from trials.measured.diagnose_records import STRAIGHT_RUDDER_DEG, leading_straight_run

U = 5.144          # 10 kn through the water
PSI = math.radians(30.0)
SIGMA = 0.01       # m/s


def _logged(bias_deg=0.0, current=(0.0, 0.0), n=12):
    """(N, 6) logged u, v, r, x, y, heading of a straight run at true heading PSI, no drift through
    the water, a current of (speed [m/s], towards [deg]) and a compass reading ``bias_deg`` high."""
    cs, cd = current
    vn = U * math.cos(PSI) + cs * math.cos(math.radians(cd))
    ve = U * math.sin(PSI) + cs * math.sin(math.radians(cd))
    psi_log = PSI + math.radians(bias_deg)
    u = vn * math.cos(psi_log) + ve * math.sin(psi_log)
    v = -vn * math.sin(psi_log) + ve * math.cos(psi_log)
    t = np.arange(n, dtype=float)
    return np.column_stack([np.full(n, u), np.full(n, v), np.zeros(n), vn * t, ve * t, np.full(n, psi_log)])


def _seg(meas):
    return Segmented("straight", meas, None, np.zeros(len(meas), bool), straight=StraightRun(n=len(meas), sigma=SIGMA))


def _residual(meas, effects, values):
    free = effect_parameters(effects)
    return straight_run_residual(_seg(meas), effects, free, np.array(values, float))


def test_a_heading_bias_is_read_from_the_straight_run():
    meas = _logged(bias_deg=1.2)
    # the true bias explains the logged sway; none leaves -(-U sin b) / sigma
    assert _residual(meas, [HeadingBias], [1.2]) == pytest.approx(0.0, abs=1e-9)
    assert _residual(meas, [HeadingBias], [0.0]) == pytest.approx(U * math.sin(math.radians(1.2)) / SIGMA, rel=1e-6)
    # the opposite sign doubles it
    assert abs(_residual(meas, [HeadingBias], [-1.2])) > 1.9 * abs(_residual(meas, [HeadingBias], [0.0]))


def test_a_current_is_read_from_the_straight_run_by_its_cross_part():
    cs, cd = 0.3, 200.0
    meas = _logged(current=(cs, cd))
    cn, ce = cs * math.cos(math.radians(cd)), cs * math.sin(math.radians(cd))
    assert _residual(meas, [Current], [cn, ce]) == pytest.approx(0.0, abs=1e-9)
    cross = cs * math.sin(math.radians(cd) - PSI)              # its part across the heading, to starboard
    assert _residual(meas, [Current], [0.0, 0.0]) == pytest.approx(-cross / SIGMA, rel=1e-6)
    assert _residual(meas, [Current], [-cn, -ce]) == pytest.approx(-2 * cross / SIGMA, rel=1e-6)
    # a current along the heading sets no sway: the straight run cannot see it
    along = _logged(current=(0.3, 30.0))
    assert _residual(along, [Current], [0.0, 0.0]) == pytest.approx(0.0, abs=1e-9)


def test_a_bias_and_a_current_together():
    meas = _logged(bias_deg=-0.8, current=(0.2, 120.0))
    cn, ce = 0.2 * math.cos(math.radians(120.0)), 0.2 * math.sin(math.radians(120.0))
    assert _residual(meas, [HeadingBias, Current], [-0.8, cn, ce]) == pytest.approx(0.0, abs=1e-9)
    assert abs(_residual(meas, [HeadingBias, Current], [0.0, cn, ce])) > 5.0


def test_a_record_without_a_straight_run_has_no_row():
    seg = Segmented("x", _logged(), None, np.zeros(12, bool))
    assert straight_run_residual(seg, [HeadingBias], effect_parameters([HeadingBias]), np.array([1.0])) is None


def _run(n_straight=10, n=40, L=325.0):
    meas = _logged(n=n)
    delta = np.zeros(n)
    delta[n_straight:] = np.radians(np.minimum(35.0, 2.3 * (1 + np.arange(n - n_straight))))
    return meas, delta, L


def test_the_straight_run_ends_where_the_rudder_moves():
    meas, delta, L = _run()
    st = leading_straight_run(meas, delta, L)
    assert st.n == 10
    # noise-free sway: the sigma is the hull's drift allowance alone
    assert st.sigma == pytest.approx(U * STRAIGHT_RUN_DRIFT_SD, rel=1e-3)
    small = delta.copy()
    small[3:] = np.radians(0.9 * STRAIGHT_RUDDER_DEG)       # a move within the tolerance keeps it straight
    small[10:] = delta[10:]
    assert leading_straight_run(meas, small, L).n == 10


def test_no_straight_run_when_yawing_windy_or_too_short():
    meas, delta, L = _run()
    yawing = meas.copy()
    yawing[:, 2] = 0.05 * U / L                             # r' = 0.05: a turn already under way
    assert leading_straight_run(yawing, delta, L) is None
    assert leading_straight_run(meas, delta, L, wind_speed_rel=np.full(len(delta), 0.6 * U)) is None
    assert leading_straight_run(meas, delta, L, wind_speed_rel=np.full(len(delta), 0.4 * U)).n == 10
    m2, d2, _ = _run(n_straight=2)
    assert leading_straight_run(m2, d2, L) is None


def test_the_noise_of_the_sway_widens_sigma_by_one_over_root_n():
    meas, delta, L = _run(n=400)
    rng = np.random.default_rng(1)
    noisy = meas.copy()
    noisy[:, 1] += rng.normal(0.0, 0.02, len(meas))
    st = leading_straight_run(noisy, delta, L)
    expect = math.hypot(0.02 / math.sqrt(10), U * STRAIGHT_RUN_DRIFT_SD)
    assert st.sigma == pytest.approx(expect, rel=0.15)


def test_the_decision_statistic_counts_the_straight_runs_chi_square():
    """dBIC adds the fall of the straight runs' chi-square: a bias that explains a 4-sigma straight run
    gains 16 over the same channel residuals."""
    rng = np.random.default_rng(0)
    d = [rng.normal(size=(200, 6))]
    taus = np.ones(6)
    before = SimpleNamespace(diffs=d, straight=np.array([4.0]))
    after = SimpleNamespace(diffs=d, straight=np.array([0.0]))
    none0 = SimpleNamespace(diffs=d, straight=np.zeros(0))
    none1 = SimpleNamespace(diffs=d, straight=np.zeros(0))
    base = _delta_bic(none0, none1, 1, taus, 1)
    assert _delta_bic(before, after, 1, taus, 1) == pytest.approx(base + 16.0)
    assert _delta_bic(after, before, 1, taus, 1) == pytest.approx(base - 16.0)


# --------------------------------------------------------------------------- the dev set (another simulator)

DEV = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "diagnose-dev"


def _dev(names):
    if not (DEV / "manifest.json").is_file():
        pytest.skip("dev set ../shared/data/diagnose-dev absent")
    man = {f["file"]: f for f in json.loads((DEV / "manifest.json").read_text())["files"]}
    return [(DEV / f"data/{n}.csv", man[f"data/{n}.csv"]) for n in names]


def test_the_straight_runs_of_another_simulators_logs():
    """Its logs open with 10 s straight ahead, then the execute.  The straight run found is those
    samples; its logged drift is the hidden bias (dev_09: -1.0, dev_19: +2.0 deg), zero on a clean
    log (dev_05), and none is taken where a wind blows (dev_28, 18 m/s on a 10 kn ship)."""
    import mmg
    from trials.measured.diagnose_records import prepare

    ship = mmg.load_ship(mmg.ship_path("esso_osaka"))
    runs = _dev(["dev_09", "dev_19", "dev_05", "dev_28"])
    prep = prepare(ship, [p for p, _ in runs])
    for (path, entry), p in zip(runs, prep):
        st = p.seg.straight
        if entry["effects"] == ["wind"]:
            assert st is None, path.name
            continue
        assert 10 <= st.n <= 12, (path.name, st.n)
        m = p.seg.meas[:st.n]
        drift = math.degrees(float(np.mean(np.arctan2(-m[:, 1], m[:, 0]))))
        bias = entry["parameters"].get("heading_bias", {}).get("bias_deg", 0.0)
        assert abs(drift - bias) < 3 * math.degrees(st.sigma / U), (path.name, drift, bias)


def test_a_diagnosis_reports_its_straight_run():
    """dev_09 (a port turn, compass 1 deg low): the straight run is in the JSON and on the console,
    many of its standard errors off before the bias and within two after."""
    import mmg
    from trials.measured.diagnose import diagnose

    ship = mmg.load_ship(mmg.ship_path("esso_osaka"))
    (path, entry), = _dev(["dev_09"])
    d = diagnose(ship, [path])
    assert d.named == ["heading_bias"]
    st, = d.to_json()["straight_runs"]
    assert st["record"] == "dev_09" and st["samples"] >= 10
    assert abs(st["logged_drift_deg"] - entry["parameters"]["heading_bias"]["bias_deg"]) < 0.2
    assert abs(st["z_before"]) > 5.0 and abs(st["z_after"]) < 2.0
    line = next(x for x in d.summary_lines() if x.startswith("straight run"))
    assert "dev_09" in line and "deg" in line and " s)" in line


# --------------------------------------------------------------------------- a name beside its rival


def _res(name, dbic, ok):
    return (dbic, ok, SimpleNamespace(name=name), None, {}, {}, 5.0, 1.0, 0.5)


def test_a_rival_is_a_candidate_with_as_much_evidence_that_could_not_be_named():
    from trials.measured.diagnose import BIC_THRESHOLD, _rival
    from trials.measured.decision import WEAK_BIC

    bias = _res("heading_bias", 60.0, True)
    # a current under its floor with more evidence than the bias: its rival
    assert _rival([bias, _res("current", 130.0, False)], bias)[2].name == "current"
    # within WEAK_BIC below it: still as much evidence
    assert _rival([bias, _res("current", 60.0 - 0.9 * WEAK_BIC, False)], bias)[2].name == "current"
    # clearly less evidence, or none worth a name, or a candidate that could be named: no rival
    assert _rival([bias, _res("current", 60.0 - 1.1 * WEAK_BIC, False)], bias) is None
    assert _rival([_res("heading_bias", 10.0, True), _res("current", BIC_THRESHOLD - 1, False)],
                  _res("heading_bias", 10.0, True)) is None
    assert _rival([bias, _res("current", 130.0, True)], bias) is None


def test_a_withheld_name_and_its_rival_are_reported_as_rivals():
    from trials.measured.decision import REASON_KINDS
    from trials.measured.diagnose import rivals_withheld, withheld

    rounds = [{"round": 1, "candidates": [],
               "withheld": [{"effect": "heading_bias", "rival": "current", "delta_bic": 3.2, "z": 1.1,
                             "parameters": {"bias_deg": 0.1}}]}]
    w, = withheld(rounds)
    r, = rivals_withheld(rounds)
    assert (w["effect"], w["confused_with"], r["effect"], r["confused_with"]) == \
        ("heading_bias", ["current"], "current", ["heading_bias"])
    assert w["reason_kind"] == r["reason_kind"] == "rival" and "rival" in REASON_KINDS
    assert "dBIC 3.2" in w["reason"] and "z 1.1" in w["reason"]


def test_no_straight_run_when_the_record_opens_with_the_helm_over():
    meas, delta, L = _run()
    over = np.full(len(delta), np.radians(10.0))              # opens at the execute, 10 deg of helm held
    assert leading_straight_run(meas, over, L) is None
    trim = delta + np.radians(1.5)                              # a 1.5 deg trim helm is straight
    assert leading_straight_run(meas, trim, L).n == 10


def test_a_fit_the_straight_run_contradicts_is_not_named():
    """The straight run reads a bias (plus a current's cross part) directly: a candidate whose fit leaves
    it beyond the naming z, and further off than before, is not named; one that brings it in is."""
    from trials.measured.diagnose import Z_THRESHOLD, straight_contradicts, within_mismatch

    assert straight_contradicts([0.5], [5.7])                      # a 0.06 deg drift read as a 0.56 deg bias
    assert not straight_contradicts([9.0], [0.2])                  # the bias the straight run shows
    assert not straight_contradicts([4.0], [3.5])                  # off, but less than without it
    assert not straight_contradicts([0.5], [0.9 * Z_THRESHOLD])
    assert not straight_contradicts([], [])                        # no straight run: no say
    rounds = [{"round": 1, "candidates": [
        {"effect": "heading_bias", "delta_bic": 22.0, "z": 5.5, "magnitude": 0.56, "floor": 0.39,
         "clears_threshold": False, "parameters": {"bias_deg": -0.56}, "straight_z": [5.66],
         "straight_contradicts": True}]}]
    e, = within_mismatch(rounds, 325.0)
    assert e["reason_kind"] == "straight_run" and "5.66 sd off" in e["reason"]


def test_a_name_the_statistics_cannot_separate_is_demoted_and_its_parameters_dropped():
    """`_demote` refits without the effect, from the model's own values less that effect's."""
    from ekf.identify import FreeParameter, effect_parameters
    from mmg.effects import RudderOffset
    from trials.measured.diagnose import DiagnoseOptions, _demote, _Model

    ship_free = [FreeParameter("Y_beta", "hull", 0, 0.4, 0.06, -np.inf, np.inf)]
    effects = [Current, RudderOffset]
    free = ship_free + effect_parameters(effects)
    theta = np.array([0.41, 0.02, -0.03, 6.97])
    fit = SimpleNamespace(theta=theta)
    model = _Model(effects, free, fit, [])
    calls = []

    class Stub:
        def fit(self, keep, start=None, max_nfev=None):
            calls.append((list(keep), np.asarray(start)))
            return "refitted"

    rounds = [{"round": 1, "candidates": []}]
    m, named = _demote(Stub(), model, ["current", "rudder_offset"], ["rudder_offset"], rounds, DiagnoseOptions(),
                       lambda s: None)
    assert m == "refitted" and named == ["current"]
    (keep, start), = calls
    assert keep == [Current] and np.allclose(start, [0.41, 0.02, -0.03])
    assert rounds[-1]["demoted"] == [{"effect": "rudder_offset"}]


def test_only_a_confounded_name_whose_floor_exceeds_what_matters_is_demoted():
    from trials.measured.diagnose import to_demote

    rows = [{"effect": "rudder_offset", "named": True, "reason_kind": "statistics", "floor": 5.84, "detection_size": 1.0},
            {"effect": "wind", "named": True, "reason_kind": "statistics", "floor": 0.0, "detection_size": 0.5},
            {"effect": "heading_bias", "named": True, "reason_kind": None, "floor": 0.39, "detection_size": 1.0},
            {"effect": "current", "named": False, "reason_kind": "statistics", "floor": 9.0, "detection_size": 1.0}]
    assert to_demote(rows) == ["rudder_offset"]
