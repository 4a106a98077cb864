"""bench/diagnose_devset.py's scoring and its classes, on hand-made manifest entries and diagnoses."""
from .conftest import load_bench

dev = load_bench("diagnose_devset")


def _entry(effects, **parameters):
    return {"effects": effects, "parameters": parameters}


def test_current_scored_in_the_set_conventions():
    # the manifest's set_towards_deg is where the current goes: 350 against a named 5 is 15 deg off, not 345
    e = _entry(["current"], current={"speed_m_s": 0.25, "set_towards_deg": 350.0})
    s = dev.score(e, {"named": ["current"], "parameters": {"current": {"speed_mps": 0.22, "direction_deg": 5.0}}})
    assert s["exact"] and not s["false_alarm"]
    assert abs(s["errors"]["current.direction_deg"] - 15.0) < 1e-9
    assert abs(s["errors"]["current.speed_mps"] - 0.03) < 1e-9
    assert s["values_ok"]                                 # 0.03 m/s and 15 deg: on the tolerances
    s = dev.score(e, {"named": ["current"], "parameters": {"current": {"speed_mps": 0.25, "direction_deg": 6.0}}})
    assert not s["values_ok"]


def test_missing_effect_reported_not_identifiable_is_honest_but_not_exact():
    e = _entry(["wind", "rudder_offset"])
    res = {"named": ["wind"], "parameters": {}, "not_identifiable": [{"effect": "rudder_offset"}]}
    s = dev.score(e, res)
    assert not s["exact"] and s["exact_or_not_identifiable"]
    wrong = {"named": ["wind", "current"], "parameters": {}, "not_identifiable": [{"effect": "rudder_offset"}]}
    assert not dev.score(e, wrong)["exact_or_not_identifiable"]      # a wrong name is never honest


def test_clean_log_with_a_name_is_a_false_alarm():
    s = dev.score(_entry(["none"]), {"named": ["current"], "parameters": {"current": {}}})
    assert s["false_alarm"] and not s["exact"]
    assert not dev.score(_entry(["none"]), {"named": [], "parameters": {}})["false_alarm"]


def test_classes_by_hand_and_wind_beside():
    rows = [{"trial": "zz20p", "true": ["rudder_offset", "wind"], "exact": False, "exact_or_not_identifiable": True,
             "false_alarm": False},
            {"trial": "zz10", "true": ["wind"], "exact": True, "exact_or_not_identifiable": True, "false_alarm": False},
            {"trial": "turn25p", "true": ["none"], "exact": False, "exact_or_not_identifiable": False, "false_alarm": True},
            {"trial": "zz15", "true": ["current"], "exact": True, "exact_or_not_identifiable": True, "false_alarm": False}]
    assert [dev.log_class(r) for r in rows] == [("port", "wind beside"), ("starboard", "wind alone"),
                                                ("port", "clean"), ("starboard", "other")]
    lines = dev.class_lines(rows)
    assert any(line.split() == ["port", "clean", "0", "/", "0", "/", "1", "of", "1"] for line in lines)
    assert any(line.split() == ["port", "wind", "beside", "0", "/", "1", "/", "0", "of", "1"] for line in lines)
