"""The naming decision of mmg diagnose (trials/measured/diagnose/decision.py): the size measure against plain
formulas, the kind of record, the calibrated false-alarm probability, and the floor acting on a
diagnosis (a floor above the fitted size must stop the naming; no floor must let it through)."""
from __future__ import annotations

import math

import numpy as np
import pytest


def test_magnitude_plain_formulas():
    from trials.measured.decision import magnitude

    assert magnitude("current", {"speed_mps": 0.15, "direction_deg": 30.0}, 325.0) == \
        pytest.approx(0.15 / math.sqrt(9.80665 * 325.0))
    assert magnitude("rudder_offset", {"offset_deg": -1.2}, 325.0) == 1.2
    assert magnitude("heading_bias", {"bias_deg": 0.6}, 3.0) == 0.6
    assert magnitude("wind", {"scale": 0.8, "sway_factor": 2.0, "yaw_factor": 1.0}, 325.0) == 0.8
    assert magnitude("shallow_water", {"depth_to_draft": 2.0}, 325.0) == 0.5
    assert magnitude("shallow_water", {"depth_to_draft": math.inf}, 325.0) == 0.0


def test_record_kind_by_the_rudder():
    from trials.measured.decision import record_kind

    t = np.linspace(0.0, 1000.0, 2001)
    turn = np.where(t > 10.0, math.radians(35.0), 0.0)                   # hold 35 deg to starboard
    zig = math.radians(20.0) * np.sign(np.sin(t / 60.0))               # +-20 deg
    assert record_kind([turn]) == "turn"
    assert record_kind([-turn]) == "turn"
    assert record_kind([zig]) == "zigzag"
    assert record_kind([zig, turn]) == "zigzag"            # the zigzag pins what it pins alone
    assert record_kind([turn, -turn]) == "turn_pair"
    assert record_kind([turn + math.radians(0.5)]) == "turn"          # a trim angle below 2 deg does not count


@pytest.fixture
def calib(monkeypatch):
    import trials.measured.decision as D

    table = {"floors": {"current": {"zigzag": 1.0, "turn": 1.0}},
             "clean": {"current": {"zigzag": [0.1, 0.2, 0.3, 0.4]}}}
    monkeypatch.setattr(D, "calibration", lambda: table)
    return table


def test_false_alarm_probability_counts_the_clean_records(calib):
    from trials.measured.decision import false_alarm_probability, floor

    assert false_alarm_probability("current", "zigzag", 0.25) == pytest.approx(3 / 5)   # 0.3, 0.4 and itself
    assert false_alarm_probability("current", "zigzag", 0.5) == pytest.approx(1 / 5)
    assert false_alarm_probability("current", "turn", 0.5) is None                      # not calibrated
    assert floor("current", "turn") == 1.0 and floor("wind", "turn") == 0.0


def test_the_floor_decides(monkeypatch):
    """A clear current (2.4 % of the speed) on a 3 m zigzag: named with no floor, not named when the
    floor is above its size (same fit, same dBIC and z)."""
    import mmg
    import trials.measured.decision as D
    from trials.measured.diagnose import RecordNoise, diagnose, synthetic_record

    ship = mmg.load_ship("esso_osaka_3m")
    rec = synthetic_record(ship, "zigzag", {"current": {"speed_mps": 0.012, "direction_deg": 70.0}},
                           noise=RecordNoise(seed=4))
    L = ship.particulars.L
    size = 0.012 / math.sqrt(9.80665 * L)
    monkeypatch.setattr(D, "calibration", lambda: {})
    d0 = diagnose(ship, [rec], candidates=["current"])
    assert d0.named == ["current"]
    assert d0.evidence["current"]["magnitude"] == pytest.approx(size, rel=0.2)
    monkeypatch.setattr(D, "calibration", lambda: {"floors": {"current": {"zigzag": 2.0 * size}}})
    d1 = diagnose(ship, [rec], candidates=["current"])
    assert d1.named == []
    c = d1.rounds[0]["candidates"][0]
    assert c["delta_bic"] > D.BIC_THRESHOLD and c["z"] > D.Z_THRESHOLD and c["floor"] == 2.0 * size
    # the same current judged by its components along and across the zigzag's mean heading: named
    # where its across part (70 deg off the heading) clears its floor, not where neither part does
    h = math.radians(d1.rounds[0]["heading_deg"])
    al, ac = D.current_components(d1.parameters.get("current") or c["parameters"], L, h)
    assert abs(ac) > 0.8 * size and abs(al) < 0.5 * size
    for across_floor, named in ((0.5 * size, ["current"]), (2.0 * size, [])):
        monkeypatch.setattr(D, "calibration", lambda f=across_floor: {"floors": {
            "current": {"zigzag": 2.0 * size}, "current_along": {"zigzag": 2.0 * size},
            "current_across": {"zigzag": f}}})
        assert diagnose(ship, [rec], candidates=["current"]).named == named


def test_a_named_calibration_file_that_is_not_there_is_refused(tmp_path, monkeypatch):
    """MMG_DIAGNOSE_CALIBRATION naming a missing or malformed file: one line naming it, exit 2, no
    output written (silently diagnosing with no floors would be the wrong answer)."""
    import subprocess
    import sys

    from mmg.resources import config_path

    log = tmp_path / "log.csv"
    subprocess.run([sys.executable, "-m", "trials.cli", "simulate", str(config_path("trials", "st35.yaml")),
                    "--out", str(tmp_path / "sim")], check=True, capture_output=True)
    log = tmp_path / "sim" / "log.csv"
    bad = tmp_path / "bad.yaml"
    bad.write_text("floors: [1, 2\n")
    for env in (str(tmp_path / "absent.yaml"), str(bad)):
        out = tmp_path / "d.json"
        r = subprocess.run([sys.executable, "-m", "trials.cli", "diagnose", "--ship", "esso_osaka", str(log),
                            "--json", str(out)], capture_output=True, text=True,
                           env={**__import__("os").environ, "MMG_DIAGNOSE_CALIBRATION": env})
        assert r.returncode == 2, r.stderr
        lines = [ln for ln in r.stderr.strip().splitlines() if ln.strip()]
        assert len(lines) == 1 and env in lines[0] and "Traceback" not in r.stderr, r.stderr
        assert not out.exists()


def test_a_calibration_file_with_a_malformed_model_form_section_is_refused_before_any_work(tmp_path, monkeypatch):
    """A calibration file (MMG_DIAGNOSE_CALIBRATION) whose ``model_form`` ranges are not [lo, hi]: one line
    naming the file and the section, raised before a record is read (a missing record is not reached)."""
    from mmg import load_ship, ship_path
    from mmg.errors import InputError
    from trials.measured.diagnose import decision, diagnose

    for body in ("floors: {}\nmodel_form:\n  plausible:\n    wind:\n      scale: {range: [3]}\n",
                 "floors: {}\nmodel_form:\n  plausible:\n    wind:\n      scale: {range: [3, 0.3]}\n",
                 "floors: {}\nmodel_form:\n  bound_tolerance: {value: one}\n"):
        bad = tmp_path / "cal.yaml"
        bad.write_text(body)
        monkeypatch.setenv("MMG_DIAGNOSE_CALIBRATION", str(bad))
        decision.calibration.cache_clear()
        try:
            with pytest.raises(InputError) as e:
                diagnose(load_ship(ship_path("esso_osaka")), [tmp_path / "absent.csv"])
        finally:
            monkeypatch.delenv("MMG_DIAGNOSE_CALIBRATION")
            decision.calibration.cache_clear()
        msg = str(e.value)
        assert str(bad) in msg and "model_form" in msg and "\n" not in msg, msg


def test_current_components_plain_formulas():
    """Along and across a heading: a current setting east seen from a ship heading north is all across
    (to starboard); from a ship heading east all along; speeds over sqrt(gL)."""
    from trials.measured.decision import current_components

    L = 325.0
    s = 0.2 / math.sqrt(9.80665 * L)
    al, ac = current_components({"speed_mps": 0.2, "direction_deg": 90.0}, L, 0.0)
    assert al == pytest.approx(0.0, abs=1e-12) and ac == pytest.approx(s)
    al, ac = current_components({"speed_mps": 0.2, "direction_deg": 90.0}, L, math.radians(90.0))
    assert al == pytest.approx(s) and ac == pytest.approx(0.0, abs=1e-12)
    al, ac = current_components({"speed_mps": 0.2, "direction_deg": 0.0}, L, math.radians(90.0))
    assert al == pytest.approx(0.0, abs=1e-12) and ac == pytest.approx(-s)          # from the port side
    al, ac = current_components({"speed_mps": 0.2, "direction_deg": 210.0}, L, math.radians(30.0))
    assert al == pytest.approx(-s) and ac == pytest.approx(0.0, abs=1e-12)          # head current


def test_mean_heading_is_circular():
    from trials.measured.decision import mean_heading

    assert mean_heading([np.radians([359.0, 1.0, 358.0, 2.0])]) == pytest.approx(0.0, abs=1e-12)
    assert math.degrees(mean_heading([np.radians([170.0, -170.0]), np.array([math.pi])])) == pytest.approx(180.0)
    assert math.degrees(mean_heading([np.radians([80.0, 100.0, np.nan])])) == pytest.approx(90.0)


def test_component_floors_judge_a_current_on_a_zigzag(monkeypatch):
    """A current across the heading below the speed's floor is named where the across floor (what the
    ship's own speed mismatch cannot lend) is below it, and not where both component floors are above;
    on a turn the speed's floor alone decides."""
    import trials.measured.decision as D

    L = 325.0
    across = {"speed_mps": 0.1, "direction_deg": 90.0}          # heading north: all across
    along = {"speed_mps": 0.1, "direction_deg": 180.0}          # a head current: all along
    f = 0.15 / math.sqrt(9.80665 * L)                           # the speed's floor: 0.15 m/s
    table = {"floors": {"current": {"zigzag": f, "turn": f},
                        "current_along": {"zigzag": f}, "current_across": {"zigzag": 0.02 / math.sqrt(9.80665 * L)}}}
    monkeypatch.setattr(D, "calibration", lambda: table)
    assert D.clears_floor("current", across, L, "zigzag", 0.0)
    assert not D.clears_floor("current", along, L, "zigzag", 0.0)
    assert not D.clears_floor("current", across, L, "turn", 0.0)
    assert not D.clears_floor("current", across, L, "zigzag", None)          # no heading: the speed's floor
    assert D.clears_floor("current", across, L, "zigzag", math.radians(40.0))   # 0.064 m/s across
    assert not D.clears_floor("current", across, L, "zigzag", math.radians(85.0))  # 0.009 m/s across
    table["floors"]["current_across"]["zigzag"] = f
    assert not D.clears_floor("current", across, L, "zigzag", 0.0)
    del table["floors"]["current_across"]
    assert not D.clears_floor("current", across, L, "zigzag", 0.0)           # components not calibrated
    assert D.clears_floor("rudder_offset", {"offset_deg": -1.0}, L, "zigzag", 0.0)   # not calibrated: no floor


def test_an_effect_that_loses_its_evidence_is_dropped(monkeypatch):
    """Forward selection's final check: a zigzag with a heading bias only, the search forced to name
    a current and the bias (the confusion of a cross current with a bias): in the joint fit the
    current has nothing left to explain, and the diagnosis must drop it and keep the bias."""
    import mmg
    import mmg.effects as E
    import trials.measured.decision as D
    import trials.measured.diagnose as G
    import trials.measured.diagnose.search as S

    ship = mmg.load_ship("esso_osaka_3m")
    rec = G.synthetic_record(ship, "zigzag", {"heading_bias": {"bias_deg": 1.5}}, noise=G.RecordNoise(seed=5))
    monkeypatch.setattr(D, "calibration", lambda: {})

    def forced(fitter, base, cand, ns, o, say):
        effs = [E.get("current"), E.get("heading_bias")]
        m = fitter.fit(effs, start_ship=base.theta[:ns])
        return m, ["current", "heading_bias"], [{"round": 1, "model": [], "candidates": []}], fitter

    monkeypatch.setattr(S, "_search", forced)
    d = G.diagnose(ship, [rec], candidates=["current", "heading_bias"])
    assert d.named == ["heading_bias"]
    assert [x["effect"] for x in d.rounds[-1]["dropped"]] == ["current"]
    assert d.parameters["heading_bias"]["bias_deg"] == pytest.approx(1.5, abs=0.3)


def test_floor_parts_and_the_reason_given(monkeypatch):
    """The parts a current is judged by, as the rounds log them, and the not_identifiable reason that
    cites them (not the speed's floor, which did not decide)."""
    import trials.measured.decision as D
    from trials.measured.diagnose import within_mismatch

    L = 325.0
    g = math.sqrt(9.80665 * L)
    monkeypatch.setattr(D, "calibration", lambda: {"floors": {
        "current": {"zigzag": 0.1 / g}, "current_along": {"zigzag": 0.12 / g}, "current_across": {"zigzag": 0.02 / g}}})
    parts = D.floor_parts("current", {"speed_mps": 0.1, "direction_deg": 0.0}, L, "zigzag", 0.0)
    assert parts["along"][0] == pytest.approx(0.1 / g, rel=1e-3) and parts["along"][1] == pytest.approx(0.12 / g)
    assert parts["across"][0] == pytest.approx(0.0, abs=1e-9)
    assert D.floor_parts("current", {"speed_mps": 0.1, "direction_deg": 0.0}, L, "turn", 0.0) == {}
    assert D.floor_parts("rudder_offset", {"offset_deg": 1.0}, L, "zigzag", 0.0) == {}
    cand = {"effect": "current", "delta_bic": 50.0, "z": 9.0, "magnitude": 0.1 / g, "floor": 0.1 / g,
            "parts": {k: list(v) for k, v in parts.items()}, "clears_threshold": False}
    (entry,) = within_mismatch([{"candidates": [cand]}], L)
    assert "along" in entry["reason"] and "across" in entry["reason"]


def _cand(effect="heading_bias", dbic=9.6, z=4.6, mag=0.77, fl=0.39, ok=False, **kw):
    return {"effect": effect, "delta_bic": dbic, "z": z, "magnitude": mag, "floor": fl, "clears_threshold": ok, **kw}


def test_evidence_short_of_a_name_is_reported_not_dropped():
    """A candidate whose precision and size pass but whose dBIC is between Kass & Raftery's 'positive'
    (2) and the naming threshold is reported (weak_evidence), with the figures that decided; one with
    no evidence, an imprecise one, one within its floor and one that was named are not."""
    import trials.measured.decision as D
    from trials.measured.diagnose import weak_evidence

    assert D.WEAK_BIC == 2.0 and D.BIC_THRESHOLD == 20.0
    got = weak_evidence([{"candidates": [_cand()]}])
    assert list(got) == ["heading_bias"]
    assert "dBIC 9.6" in got["heading_bias"] and "z 4.6" in got["heading_bias"]
    for c in (_cand(dbic=1.9), _cand(dbic=20.5), _cand(z=2.9), _cand(mag=0.3), _cand(ok=True)):
        assert weak_evidence([{"candidates": [c]}]) == {}, c
    assert weak_evidence([{"candidates": [_cand(dbic=2.1)]}]) and weak_evidence([{"candidates": [_cand(dbic=20.0)]}])
    assert weak_evidence([]) == {}
    # a current judged by its parts: over the floor when either part is
    parts_in = {"along": [0.001, 0.003], "across": [0.0001, 0.0003]}
    parts_out = {"along": [0.001, 0.003], "across": [0.0005, 0.0003]}
    assert weak_evidence([{"candidates": [_cand("current", mag=0.01, fl=0.001, parts=parts_in)]}]) == {}
    assert list(weak_evidence([{"candidates": [_cand("current", mag=0.0, fl=0.001, parts=parts_out)]}])) == ["current"]
    # only the last round counts: a candidate of an earlier round that a later one dropped is not reported
    assert weak_evidence([{"candidates": [_cand()]}, {"candidates": [_cand(dbic=-5.0)]}]) == {}


def test_console_line_of_an_evidence_entry_gives_its_reason():
    """The console line of an entry reported for its evidence says why, not that its std 'could not
    have shown' the size to detect (which is false for a precise candidate); an entry without a
    correlation (the floor's and the evidence's extras) is printed, not a TypeError."""
    from trials.measured.diagnose_report import not_identifiable_line

    e = {"effect": "heading_bias", "confused_with": ["N_r"], "correlation": 0.998, "what_would_separate": "a zigzag",
         "reason": "at dBIC 9.6 (a name needs 20), z 4.6", "std": 0.17, "detection_size": 1.0, "unit": "deg"}
    line = not_identifiable_line(e)
    assert "dBIC 9.6" in line and "could not have shown" not in line and "0.998" in line
    e["reason"] = "its standard error and correlation"
    assert "could not have shown 1.00 deg" in not_identifiable_line(e)
    e.update(correlation=None, reason="at dBIC 5, z 4, size 0.9 deg (floor 0.39 deg)")
    line = not_identifiable_line(e)
    assert "confused with N_r" in line and "floor 0.39 deg" in line and line.endswith("a zigzag")


def test_weak_evidence_reason_gives_the_parts_that_cleared_their_floors():
    """A current judged by its parts along and across the heading: the reason gives each part with its
    floor, not the whole speed said to be "over its floor" when the whole is under the whole's floor;
    with no part over its floor nothing is reported."""
    from trials.measured.diagnose import weak_evidence

    c = {"effect": "current", "delta_bic": 9.0, "z": 5.0, "clears_threshold": False, "magnitude": 0.002,
         "floor": 0.01, "parts": {"along": [0.0005, 0.003], "across": [0.0019, 0.0003]}}
    why = weak_evidence([{"candidates": [c]}])["current"]
    assert "across 0.0019 (floor 0.0003)" in why and "along 0.0005 (floor 0.003)" in why
    assert "size 0.002" not in why
    c["parts"]["across"] = [0.0002, 0.0003]
    assert weak_evidence([{"candidates": [c]}]) == {}


def test_short_of_name_counts_clean_first_rounds(monkeypatch):
    """The calibration's count of clean records that would carry an evidence entry: records with
    effects are not counted, a clean record counts once, the floor is the packaged one."""
    import trials.measured.decision as D
    from trials.measured.calibration import short_of_name

    monkeypatch.setattr(D, "calibration", lambda: {"floors": {"heading_bias": {"turn": 0.5}}})
    def rec(truth, *cands):
        return {"trial": "turn35", "truth": truth, "rounds": [{"kind": "turn", "heading_deg": 0.0, "candidates": list(cands)}]}
    c = lambda b, dbic=9.0: {"effect": "heading_bias", "delta_bic": dbic, "z": 5.0, "parameters": {"bias_deg": b}}
    recs = [rec({}, c(0.8), c(0.9)), rec({}, c(0.4)), rec({}, c(0.8, dbic=1.0)), rec({"heading_bias": 1.0}, c(0.8))]
    assert short_of_name(recs, 325.0) == (1, 3)


def test_an_effect_short_of_the_evidence_is_reported_by_diagnose(diagnose_rules):
    """End to end: a 1.5 deg heading bias on a zigzag, with the naming threshold raised out of reach, is
    not named and not dropped: ``not_identifiable`` carries it with the figures that decided, and the
    console line says so.  (With the threshold as shipped the same record names it: the control.)"""
    from mmg.ship import load_ship
    from trials.measured.diagnose import Manoeuvre, RecordNoise, diagnose, synthetic_record
    ship = load_ship("esso_osaka_3m")
    rec = synthetic_record(ship, Manoeuvre("zigzag", rudder_deg=20.0), {"heading_bias": {"bias_deg": 1.5}},
                           noise=RecordNoise(seed=4), name="z")
    opts = {"candidates": ["heading_bias", "current"]}
    assert diagnose(ship, [rec], **opts).named == ["heading_bias"]
    diagnose_rules(bic_threshold=1e7)            # the rules file's threshold, through MMG_DIAGNOSE_RULES
    d = diagnose(ship, [rec], **opts)
    assert d.named == []
    ent = {e["effect"]: e for e in d.not_identifiable}
    assert "heading_bias" in ent, d.not_identifiable
    assert "a name needs 1e+07" in ent["heading_bias"]["reason"] and ent["heading_bias"]["reason_kind"] == "evidence"
    (line,) = [ln for ln in d.summary_lines() if ln.startswith("heading_bias: not identifiable")]
    assert "a name needs" in line


def _block(sd, sd_alone, R):
    return {"sd": sd, "sd_conditional": sd_alone, "R": R, "ratio": sd / sd_alone}


def test_an_entry_gives_the_first_reason_that_holds():
    """The order of the reasons, each from plain figures: confounding that hides the size to detect
    (3 sd > 1 deg, R >= 0.9), then the calibrated floor, then evidence short of a name, then too little
    information without confounding (3 sd > 1 deg at R 0.5): a 1.5 deg bias fitted at z 0.3 on a
    cross-flow turn (seed 15000) was dropped silently for want of this last reason.  A precise
    candidate under its floor with no evidence is not reported."""
    from trials.measured.identifiability import STATISTICAL_REASON, verdict

    weak = "at dBIC 9.6 (a name needs 20)"
    assert verdict(_block(0.5, 0.05, 0.995), 1.0, 5.84, weak, "deg", "deg") == (True, STATISTICAL_REASON, "statistics")
    conf, floor, kind = verdict(_block(0.1, 0.05, 0.87), 1.0, 5.84, weak, "deg", "deg")
    assert conf and "5.84 deg" in floor and "1 deg" in floor and "dBIC" not in floor and kind == "floor"
    assert verdict(_block(0.5, 0.4, 0.6), 1.0, 0.389, weak, "deg", "deg") == (False, weak, "evidence")
    conf, lack, kind = verdict(_block(2.06, 0.9, 0.899), 1.0, 0.389, None, "deg", "deg")
    assert not conf and "sd 2.06 deg" in lack and "0.9 deg with every other parameter fixed" in lack and "1 deg" in lack
    assert kind == "information"
    assert verdict(_block(0.3, 0.29, 0.3), 1.0, 0.389, None, "deg", "deg") == (False, None, None)     # 3 x 0.3 < 1
    assert verdict(_block(0.34, 0.33, 0.3), 1.0, 0.389, None, "deg", "deg")[1] is not None     # 3 x 0.34 > 1


def test_a_floor_reason_gives_each_effect_its_unit():
    """The floor and the size to detect are said in the unit they are in: m/s for a current (the
    detection size scales with the ship), T/H for shallow water (not its fit parameter's H/T, which has
    no unit and left a double space), deg for the angles."""
    import mmg.effects as E
    from trials.measured.identifiability import _size_unit, verdict

    units = {c.name: _size_unit(c) for c in (E.Current, E.RudderOffset, E.HeadingBias, E.ShallowWater)}
    assert units == {"current": "m/s", "rudder_offset": "deg", "heading_bias": "deg", "shallow_water": "T/H"}
    _, text, _ = verdict(_block(0.01, 0.01, 0.1), 0.5, 0.574, None, "", units["shallow_water"])
    assert "0.574 T/H on" in text and "0.5 T/H to" in text and "  " not in text


def test_over_floor_is_the_one_floor_rule_on_plain_figures():
    """A size over its floor clears it, at or under it does not; a NaN size (an effect without a
    magnitude) is not stopped by a floor; with parts, either
    part over its own floor clears it whatever the whole size says (a current across the heading)."""
    from trials.measured.decision import over_floor

    assert over_floor(0.5, 0.4) and not over_floor(0.4, 0.4) and not over_floor(0.3, 0.4)
    assert over_floor(float("nan"), 0.4)
    assert over_floor(0.1, 0.4, {"along": (0.1, 0.2), "across": (-0.05, 0.01)})
    assert not over_floor(0.9, 0.4, {"along": (0.1, 0.2), "across": (0.005, 0.01)})
