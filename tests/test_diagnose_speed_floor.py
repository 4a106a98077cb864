"""A current's part floor along the heading in a fraction of the records' speed U (unit ``U`` in the
calibration file): the floor rule on hand-computed cases, the unit read from the file (a file that says
sqrt(gL) keeps its meaning), the calibration's samples in that unit, and the printed SI value."""
from __future__ import annotations

import math

import pytest

L = 325.0
G = math.sqrt(9.80665 * L)          # sqrt(g L) = 56.457 m/s
KN = 1852.0 / 3600.0                # m/s per knot


def _table(along_unit: str, along: float, across: float) -> dict:
    return {"units": {"current": "sqrt(gL)", "current_along": along_unit, "current_across": "sqrt(gL)"},
            "floors": {"current": {"zigzag": 0.1 / G}, "current_along": {"zigzag": along},
                       "current_across": {"zigzag": across}}}


def test_a_current_along_the_heading_is_judged_against_the_speed(monkeypatch):
    """0.12 m/s along the heading (north, the current setting north): at 14 kn (U = 7.2022 m/s) it is
    0.12 / 7.2022 = 0.01666 of U, at 7 kn (3.6011 m/s) 0.03332 of U.  Against a floor of 0.02 U it is
    named at 7 kn and not at 14 kn; against a floor in sqrt(gL), as packaged, 0.002017 sqrt(gL) = 0.1139 m/s,
    it clears at both speeds.  Across the heading the floor stays 0.0005 sqrt(gL) = 0.0282 m/s at
    either speed."""
    import trials.measured.diagnose.decision as D

    u14, u7 = 14 * KN, 7 * KN
    assert u14 == pytest.approx(7.2022, abs=1e-4) and u7 == pytest.approx(3.6011, abs=1e-4)
    along = {"speed_mps": 0.12, "direction_deg": 0.0}
    across = {"speed_mps": 0.03, "direction_deg": 90.0}          # 0.03 m/s to starboard: 0.000531 sqrt(gL)
    small_across = {"speed_mps": 0.02, "direction_deg": 270.0}   # 0.000354 sqrt(gL), to port

    monkeypatch.setattr(D, "calibration", lambda: _table("U", 0.02, 0.0005))
    parts = D.floor_parts("current", along, L, "zigzag", 0.0, u14)
    assert parts["along"][0] == pytest.approx(0.016662, rel=1e-3) and parts["along"][1] == 0.02
    assert parts["across"][0] == pytest.approx(0.0, abs=1e-9) and parts["across"][1] == 0.0005
    assert D.floor_parts("current", along, L, "zigzag", 0.0, u7)["along"][0] == pytest.approx(0.033324, rel=1e-3)
    assert not D.clears_floor("current", along, L, "zigzag", 0.0, u14)
    assert D.clears_floor("current", along, L, "zigzag", 0.0, u7)
    for u in (u7, u14):                                          # across: the speed does not enter
        assert D.clears_floor("current", across, L, "zigzag", 0.0, u)
        assert not D.clears_floor("current", small_across, L, "zigzag", 0.0, u)
    # no speed known: not judged by its parts but by the speed's floor, 0.1 m/s
    assert D.floor_parts("current", along, L, "zigzag", 0.0) == {}
    assert D.clears_floor("current", along, L, "zigzag", 0.0)

    monkeypatch.setattr(D, "calibration", lambda: _table("sqrt(gL)", 0.002017, 0.0005))
    assert D.clears_floor("current", along, L, "zigzag", 0.0, u14)     # 0.12 m/s > 0.1139 m/s, any speed
    assert D.clears_floor("current", along, L, "zigzag", 0.0, u7)
    assert D.floor_parts("current", along, L, "zigzag", 0.0, u14)["along"][0] == pytest.approx(0.12 / G, rel=1e-3)


def test_the_least_floor_counts_a_speed_floor_at_the_records_froude_number(monkeypatch):
    """Along 0.02 U at U = 7.2022 m/s is 0.02 * 7.2022 / 56.457 = 0.002551 sqrt(gL); across 0.005."""
    import trials.measured.diagnose.decision as D

    monkeypatch.setattr(D, "calibration", lambda: _table("U", 0.02, 0.005))
    assert D.least_floor("current", "zigzag", froude=14 * KN / G) == pytest.approx(0.002551, rel=1e-3)
    assert D.least_floor("current", "zigzag") == pytest.approx(0.005)        # no speed: the across part alone
    fl = {"current_along": {"zigzag": 0.02}, "current_across": {"zigzag": 0.005}}
    assert D.least_floor("current", "zigzag", fl, froude=7 * KN / G, units=D.speed_part_units()) == pytest.approx(0.0012757, rel=1e-3)
    assert D.least_floor("current", "zigzag", fl, froude=7 * KN / G, units={}) == pytest.approx(0.005)


def _write(tmp_path, unit: str):
    p = tmp_path / "cal.yaml"
    p.write_text(f"units:\n  current_along: {unit}\n  current_across: sqrt(gL)\n"
                 "floors:\n  current:\n    zigzag: 0.002\n  current_along:\n    zigzag: 0.02\n"
                 "  current_across:\n    zigzag: 0.0005\n")
    return p


def test_the_unit_is_read_from_the_calibration_file(tmp_path, monkeypatch):
    """The same number, 0.02, is a floor of 0.02 U in a file that says U, and of 0.02 sqrt(gL) =
    1.13 m/s in one that says sqrt(gL): 0.12 m/s along at 7 kn clears the first, not the second."""
    import trials.measured.diagnose.decision as D

    along = {"speed_mps": 0.12, "direction_deg": 0.0}
    for unit, named in (("U", True), ("sqrt(gL)", False)):
        monkeypatch.setenv("MMG_DIAGNOSE_CALIBRATION", str(_write(tmp_path, unit)))
        D.calibration.cache_clear()
        assert D.part_units("zigzag") == {"current_along": unit, "current_across": "sqrt(gL)"}
        assert D.clears_floor("current", along, L, "zigzag", 0.0, 7 * KN) is named
    D.calibration.cache_clear()


def test_a_part_floor_in_an_unknown_unit_is_refused(tmp_path, monkeypatch):
    import trials.measured.diagnose.decision as D
    from mmg.errors import InputError

    p = _write(tmp_path, "knots")
    monkeypatch.setenv("MMG_DIAGNOSE_CALIBRATION", str(p))
    D.calibration.cache_clear()
    with pytest.raises(InputError, match="units.current_along"):
        D.calibration()
    D.calibration.cache_clear()


def test_the_packaged_calibration_keeps_the_along_floor_in_sqrt_gL():
    """The packaged along floor is in sqrt(gL) (a speed-scaled floor is a calibration file's choice): on the
    wide family's clean zigzags the along part does not grow with the speed (CHANGELOG)."""
    import trials.measured.diagnose.decision as D

    cal = D.packaged_calibration()
    assert cal["units"]["current_along"] == "sqrt(gL)" and cal["units"]["current_across"] == "sqrt(gL)"
    assert D.part_units("zigzag", cal["units"]) == {"current_along": "sqrt(gL)", "current_across": "sqrt(gL)"}


def test_calibration_samples_the_along_part_over_the_rounds_speed():
    """A clean zigzag whose first round's current, 0.1 m/s setting 30 deg off a heading of 10 deg, clears
    dBIC and z at U = 4 m/s: along 0.1 cos 20 deg / 4 = 0.023492 U, across 0.1 sin 20 deg / 56.457 =
    0.00060577 sqrt(gL).  A round without its speed takes the record's."""
    from trials.measured.calibration import UNITS, calibrate, clean_magnitudes
    from trials.measured.diagnose.decision import speed_part_units

    cand = {"effect": "current", "delta_bic": 50.0, "z": 10.0, "parameters": {"speed_mps": 0.1, "direction_deg": 30.0}}
    rec = {"trial": "zz20", "truth": {}, "speed_mps": 2.0,
           "rounds": [{"round": 1, "model": [], "kind": "zigzag", "heading_deg": 10.0, "speed_mps": 4.0,
                       "candidates": [cand]}]}
    clean, _, _ = clean_magnitudes([rec], L, part_units=speed_part_units())
    assert clean["current_along"]["zigzag"] == [pytest.approx(0.023492, rel=1e-4)]
    assert clean["current_across"]["zigzag"] == [pytest.approx(0.00060577, rel=1e-4)]
    assert calibrate([rec], L, part_units=speed_part_units()).units["current_along"] == "U"
    plain, _, _ = clean_magnitudes([rec], L)       # the default: both parts over sqrt(gL)
    assert plain["current_along"]["zigzag"] == [pytest.approx(0.1 * math.cos(math.radians(20)) / G, rel=1e-4)]
    assert UNITS["current_along"] == "sqrt(gL)" and calibrate([rec], L).units["current_along"] == "sqrt(gL)"
    del rec["rounds"][0]["speed_mps"]
    clean, _, _ = clean_magnitudes([rec], L, part_units=speed_part_units())
    assert clean["current_along"]["zigzag"] == [pytest.approx(0.046985, rel=1e-4)]


def test_merge_of_named_effects_keeps_every_other_figure():
    from trials.measured.calibration import merge_kinds

    old = {"source": "s", "units": {"current_along": "sqrt(gL)", "wind": "1"},
           "floors": {"wind": {"zigzag": 1.0, "turn": 2.0}, "current_along": {"zigzag": 0.002}},
           "residual_floors": {"zigzag": {"u": 0.1}}, "clean": {"current_along": {"zigzag": [0.001]}},
           "model_form": {"x": 1}}
    new = {"units": {"current_along": "U", "wind": "1"}, "floors": {"wind": {"zigzag": 9.0}, "current_along": {"zigzag": 0.03}},
           "residual_floors": {"zigzag": {"u": 9.0}}, "clean": {"current_along": {"zigzag": [0.02]}, "wind": {"zigzag": [9.0]}}}
    out = merge_kinds(old, new, ["zigzag"], ["current_along"])
    assert out["floors"] == {"wind": {"zigzag": 1.0, "turn": 2.0}, "current_along": {"zigzag": 0.03}}
    assert out["units"] == {"current_along": "U", "wind": "1"}
    assert out["residual_floors"] == {"zigzag": {"u": 0.1}}
    assert out["clean"] == {"current_along": {"zigzag": [0.02]}}
    assert out["model_form"] == {"x": 1}


def test_a_size_in_U_is_printed_with_its_speed():
    from trials.measured.diagnose.report import size_with_unit

    assert size_with_unit(0.015, "U", L, 20.0, 7.72) == "0.0150 U = 0.116 m/s at U = 7.72 m/s"
    assert size_with_unit(0.002, "sqrt(gL)", L, 20.0, 7.72) == "0.00200 sqrt(gL) = 0.113 m/s"


def test_a_rounds_parts_carry_their_units_into_the_reason(monkeypatch):
    """The search logs each part with its unit; the not_identifiable reason says a part in U in U."""
    from types import SimpleNamespace

    import trials.measured.diagnose.decision as D
    from trials.measured.diagnose.search import _parts
    from trials.measured.diagnose.verdicts import within_mismatch

    monkeypatch.setattr(D, "calibration", lambda: _table("U", 0.02, 0.0005))
    fitter = SimpleNamespace(ship=SimpleNamespace(particulars=SimpleNamespace(L=L)), kind="zigzag", heading=0.0,
                             speed=14 * KN)
    p = _parts(fitter, "current", {"speed_mps": 0.12, "direction_deg": 0.0})
    assert p["part_units"] == {"along": "U", "across": "sqrt(gL)"}
    assert p["parts"]["along"][0] == pytest.approx(0.016662, rel=1e-3)
    cand = {"effect": "current", "delta_bic": 50.0, "z": 9.0, "magnitude": 0.12 / G, "floor": 0.1 / G,
            "clears_threshold": False, **p}
    (entry,) = within_mismatch([{"candidates": [cand]}], L)
    assert "along 0.0167 (floor 0.02) U" in entry["reason"] and "across 0 (floor 0.0005) sqrt(gL)" in entry["reason"]
