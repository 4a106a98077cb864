"""The calibration of mmg diagnose's floors (:mod:`trials.measured.calibration`, the command
bench/calibrate_diagnose.py): which candidate fits count as clean samples, the effects a kind of record
cannot show at the size worth detecting, and the floor's rule on hand-made records."""
from __future__ import annotations

import numpy as np
import pytest

L = 325.0


@pytest.fixture(scope="module")
def cal():
    import trials.measured.calibration as mod

    return mod


def _cand(effect, dbic, z, **params):
    return {"effect": effect, "delta_bic": dbic, "z": z, "parameters": params}


def _turn_with_offset():
    """A single turn with a true 1 deg rudder offset, not named: its first round tries a current that
    clears dBIC and z at 0.06 m/s."""
    return {"trial": "turn35", "truth": {"rudder_offset": {"offset_deg": 1.0}},
            "rounds": [{"round": 1, "model": [], "kind": "turn", "heading_deg": 0.0,
                        "candidates": [_cand("current", 40.0, 6.0, speed_mps=0.06, direction_deg=90.0),
                                       _cand("rudder_offset", -5.0, 0.5, offset_deg=2.0)]}]}


def test_a_hidden_effects_record_lends_clean_samples_to_the_others(cal):
    rec = _turn_with_offset()
    clean, passes, _ = cal.clean_magnitudes([rec], L)
    assert "current" not in clean                       # the offset is not in the model: not a clean round
    clean, passes, _ = cal.clean_magnitudes([rec], L, hidden={"turn": {"rudder_offset"}})
    assert clean["current"]["turn"] == [pytest.approx(0.06 / np.sqrt(9.80665 * L))]
    assert passes["current"]["turn"] == [True]
    assert "rudder_offset" not in clean                 # the record's own effect is no sample of itself
    clean, _, _ = cal.clean_magnitudes([rec], L, hidden={"zigzag": {"rudder_offset"}})
    assert "current" not in clean                       # hidden on zigzags only: this turn is not clean


def test_hidden_effects_are_those_whose_floor_exceeds_the_size_to_detect(cal):
    """Floors are in the unit of decision.magnitude (a current's speed over sqrt(g L)); the size worth
    detecting a current is 0.0027 sqrt(g L), 0.152 m/s at 325 m (the 0.15 m/s worth detecting)."""
    g = np.sqrt(9.80665 * L)
    fl = {"rudder_offset": {"turn": 4.9, "zigzag": 0.66}, "heading_bias": {"turn": 0.9},
          "current": {"turn": 0.5 * 0.0027, "turn_pair": 0.16 / g, "zigzag": 0.19 / g}}
    assert cal.hidden_effects(fl, L) == {"turn": {"rudder_offset": 4.9}, "turn_pair": {"current": 0.16 / g},
                                         "zigzag": {"current": 0.19 / g}}
    # on zigzags a current is judged by its parts: 0.19 m/s along, 0.017 across -> one across the heading shows
    fl.update({"current_along": {"zigzag": 0.19 / g}, "current_across": {"zigzag": 0.017 / g}})
    assert cal.hidden_effects(fl, L) == {"turn": {"rudder_offset": 4.9}, "turn_pair": {"current": 0.16 / g}}


def test_only_kind_keeps_the_records_of_one_kind(cal):
    rec = _turn_with_offset()
    assert cal.only_kind(rec, "turn") is rec
    assert cal.only_kind(rec, "zigzag") is None
    assert cal.record_kind_of({"trial": "zz20", "rounds": []}) == "zigzag"


def test_floor_is_the_half_normal_tail_at_the_passing_share(cal):
    """20 clean samples, 5 passing with sizes 1..5: the floor is RMS * Q(1 - alpha / (m p_up)), p_up
    the Clopper-Pearson upper 95 % bound of 5/20, computed here from scipy's beta and half-normal."""
    from scipy.stats import beta, halfnorm

    sizes = [1.0, 2.0, 3.0, 4.0, 5.0] + [0.0] * 15
    out = cal.floors({"rudder_offset": {"zigzag": sizes}}, 0.05)
    p_up = beta.ppf(0.95, 6, 15)
    want = np.sqrt(np.mean(np.square([1, 2, 3, 4, 5]))) * halfnorm.ppf(1 - 0.05 / p_up)
    assert out["rudder_offset"]["zigzag"] == pytest.approx(max(want, 5.0), rel=1e-3)


def _clean_turn(current_mps, dbic=40.0, z=6.0):
    """A clean single turn whose first round finds a current of ``current_mps`` at the given dBIC and z."""
    return {"trial": "turn35", "truth": {},
            "rounds": [{"round": 1, "model": [], "kind": "turn", "heading_deg": 0.0,
                        "candidates": [_cand("current", dbic, z, speed_mps=current_mps, direction_deg=90.0),
                                       _cand("rudder_offset", 30.0, 4.0, offset_deg=6.0)]}]}


def test_calibrate_sets_the_floors_twice(cal):
    """Clean turns lend a rudder offset 6 deg (over the 1 deg worth detecting: hidden on turns) and a
    current of 0.01-0.05 m/s; a turn with a true offset lends a current of 0.2 m/s.  The first pass
    hides the offset on turns; the second counts that turn's current as a clean sample, so the
    current's floor is never below 0.2 m/s in sqrt(g L) (without that record the half-normal tail of
    the clean sizes, RMS 0.033 m/s, puts it near 0.07 m/s), and the result says what it rests on."""
    from trials.measured.identifiability import detection_size

    offset_turn = _turn_with_offset()
    offset_turn["rounds"][0]["candidates"][0]["parameters"]["speed_mps"] = 0.2
    recs = [_clean_turn(0.01 * (1 + i % 5)) for i in range(20)] + [offset_turn]
    c = cal.calibrate(recs, L)
    g = np.sqrt(9.80665 * L)
    assert set(c.hidden) == {"turn"} and set(c.hidden["turn"]) == {"rudder_offset"}
    assert c.floors["rudder_offset"]["turn"] > detection_size("rudder_offset", L)
    assert c.n_clean == 20 and c.n_effects == 1
    assert len(c.clean["current"]["turn"]) == 21                 # 20 clean rounds + the offset turn's
    assert c.floors["current"]["turn"] >= 0.2 / g * (1 - 1e-3)
    without = cal.calibrate(recs[:20], L)
    assert without.floors["current"]["turn"] < 0.1 / g
    df = c.to_pandas()
    row = df[(df.effect == "current") & (df.kind == "turn")].iloc[0]
    assert row.samples == 21 and row.passing == 21 and row.unit == "sqrt(gL)"
    doc = c.to_json()
    assert doc["floors"] == c.floors and doc["alpha"] == 0.05


def test_a_hidden_effect_larger_than_its_floor_lends_no_clean_sample(cal):
    """A turn with a true 1 deg offset counts as clean for the current where the offset's floor on turns
    (5 deg) could lend it; with a floor of 0.8 deg a 1 deg offset could have been named, and it does not."""
    rec = _turn_with_offset()
    clean, _, _ = cal.clean_magnitudes([rec], L, hidden={"turn": {"rudder_offset": 5.0}})
    assert len(clean["current"]["turn"]) == 1
    clean, _, _ = cal.clean_magnitudes([rec], L, hidden={"turn": {"rudder_offset": 0.8}})
    assert "current" not in clean


def test_merge_kinds_replaces_only_the_kinds_named(cal):
    old = {"source": "a", "alpha": 0.05,
           "floors": {"current": {"turn": 1.0, "zigzag": 2.0, "turn_pair": 3.0}, "rudder_offset": {"turn": 5.0, "zigzag": 0.6}},
           "residual_floors": {"turn": {"u": 0.03}, "zigzag": {"u": 0.004}},
           "clean": {"current": {"turn": [0.1], "zigzag": [0.2]}}}
    new = {"alpha": 0.05, "floors": {"current": {"turn": 0.5}, "rudder_offset": {"turn": 6.0}, "wind": {"turn": 0.0}},
           "residual_floors": {"turn": {"u": 0.02}}, "clean": {"current": {"turn": [0.0, 0.3]}}}
    m = cal.merge_kinds(old, new, ["turn", "turn_pair"])
    assert m["floors"]["current"] == {"zigzag": 2.0, "turn": 0.5}         # turn_pair had none in new: dropped
    assert m["floors"]["rudder_offset"] == {"zigzag": 0.6, "turn": 6.0}
    assert m["floors"]["wind"] == {"turn": 0.0}
    assert m["residual_floors"] == {"zigzag": {"u": 0.004}, "turn": {"u": 0.02}}
    assert m["clean"]["current"] == {"zigzag": [0.2], "turn": [0.0, 0.3]}
    assert old["floors"]["current"]["turn"] == 1.0                          # the input is not changed


def test_calibrating_one_ship_on_runs_of_another_is_refused(tmp_path, capsys):
    """The floors' sqrt(gL) unit is the diagnosed config's: runs of the KVLCC2 do not calibrate the
    Esso Osaka (exit 2, one line naming both), and nothing is written."""
    import importlib.util
    import json
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "bench" / "calibrate_diagnose.py"
    spec = importlib.util.spec_from_file_location("calibrate_diagnose_cli", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    run = tmp_path / "run.json"
    run.write_text(json.dumps({"records": [{**_turn_with_offset(), "ship": "kvlcc2_l7", "effect": None}]}))
    out = tmp_path / "cal.yaml"
    with pytest.raises(SystemExit) as e:
        mod.main([str(run), "--ship", "esso_osaka", "--write", "--out", str(out)])
    assert e.value.code == 2
    assert "kvlcc2_l7" in capsys.readouterr().err
    assert not out.exists()


def test_bench_ship_needs_mismatch_and_a_known_ship(capsys):
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "bench" / "bench_diagnose.py"
    spec = importlib.util.spec_from_file_location("bench_diagnose_cli", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    for argv, why in ((["--ship", "kvlcc2_l7"], "give --mismatch"),
                      (["--mismatch", "--ship", "no_such_ship", "--effects", "none", "--clean", "1"], "no_such_ship: no bundled")):
        with pytest.raises(SystemExit) as e:
            mod.main(argv)
        assert e.value.code == 2, argv
        assert why in capsys.readouterr().err, argv
