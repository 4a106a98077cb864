"""A candidate whose evidence the wind's shape terms take is reported ``not_identifiable``, not dropped
silently (:func:`trials.measured.diagnose.verdicts.absorbed`).

The round logs are written out here in the form the search keeps them (``round``, ``model``: the effects
named before the round; ``candidates`` with ``effect``, ``delta_bic``, ``z``, ``magnitude``,
``clears_threshold``, ``parameters``); magnitudes in the effects' magnitude units (deg; a current's speed
over sqrt(g L))."""
from __future__ import annotations

import mmg.effects as E
from trials.measured.diagnose.decision import REASON_KINDS
from trials.measured.diagnose.verdicts import absorbed, has_shape_terms


def _c(effect, dbic, z, clears, size, **values):
    return {"effect": effect, "delta_bic": dbic, "z": z, "clears_threshold": clears, "magnitude": size,
            "parameters": values}


CURRENT = ("current", -9.9, 1.4, False, 0.0001)


def _rounds(first, after):
    """``first`` named in round 1, where a 1.3 deg rudder offset cleared too; ``after``: the offset in round 2."""
    return [{"round": 1, "model": [],
             "candidates": [_c(first, 270.8, 15.6, True, 0.67, scale=0.67),
                            _c("rudder_offset", 56.3, 7.7, True, 1.3, offset_deg=-1.3),
                            _c(*CURRENT, speed_mps=0.02, direction_deg=175.0)]},
            {"round": 2, "model": [first], "candidates": [after, _c(*CURRENT, speed_mps=0.005, direction_deg=150.0)]}]


FELL = _c("rudder_offset", -6.7, 0.2, False, 0.04, offset_deg=0.04)


def test_an_offset_whose_evidence_the_wind_takes_is_not_identifiable_beside_it():
    e, = absorbed(_rounds("wind", FELL), ["wind"])
    assert e["effect"] == "rudder_offset" and e["confused_with"] == ["wind"]
    assert e["reason_kind"] == "absorbed" and e["reason_kind"] in REASON_KINDS
    assert "dBIC 56.3" in e["reason"] and "dBIC -6.7" in e["reason"] and "-1.30 deg" in e["reason"]


def test_only_the_wind_has_shape_terms():
    assert {n for n in E.names() if has_shape_terms(E.get(n))} == {"wind"}


def test_an_effect_without_shape_terms_that_takes_the_evidence_leaves_the_value_standing():
    assert absorbed(_rounds("heading_bias", FELL), ["heading_bias"]) == []


def test_nothing_is_reported_where_the_evidence_stays_never_was_or_was_too_small():
    assert absorbed(_rounds("wind", _c("rudder_offset", 40.0, 5.0, True, 1.1, offset_deg=-1.1)), ["wind"]) == []
    never = _rounds("wind", FELL)
    never[0]["candidates"][2] = _c("current", -9.9, 1.4, False, 0.01, speed_mps=0.6, direction_deg=175.0)
    assert [e["effect"] for e in absorbed(never, ["wind"])] == ["rudder_offset"]      # a large current that never cleared
    small = _rounds("wind", FELL)
    small[0]["candidates"][1] = _c("rudder_offset", 30.0, 5.0, True, 0.6, offset_deg=-0.6)   # under 1 deg
    assert absorbed(small, ["wind"]) == []
    assert absorbed(_rounds("wind", FELL)[:1], ["wind"]) == []                      # one round: nothing named


def test_a_wind_dropped_or_demoted_after_is_not_blamed():
    assert absorbed(_rounds("wind", FELL), []) == []


def test_a_loss_to_an_effect_named_after_the_wind_is_not_laid_on_the_wind():
    rounds = _rounds("wind", _c("rudder_offset", 40.0, 5.0, True, 1.1, offset_deg=-1.1))
    rounds[1]["candidates"].append(_c("heading_bias", 90.0, 9.0, True, 1.5, bias_deg=1.5))
    rounds.append({"round": 3, "model": ["wind", "heading_bias"],
                   "candidates": [_c("rudder_offset", -5.0, 0.5, False, 0.1, offset_deg=-0.1)]})
    assert absorbed(rounds, ["wind", "heading_bias"]) == []
