"""A named effect whose fit stands for a gap of the model's form (a shape parameter on its bound, a value
outside its plausible range) is reported ``model_form_mismatch``, not named: the rule on constructed
diagnoses (no fit), its JSON and its one console line.  Bounds and ranges are read from the effect's
parameters and the packaged calibration, the distances to them computed here."""
from __future__ import annotations

import pytest

import mmg.effects as E
from trials.measured.diagnose import Diagnosis
from trials.measured.diagnose.model_form import STATUS, reclassify, rules

WIND = {p.name: p for p in E.REGISTRY["wind"].fit_parameters()}
RMS = {"u": 0.01, "v": 0.02, "r": 0.03, "heading": 0.4, "position": 5.0}


def _diag(wind: dict, se: float = 0.1) -> Diagnosis:
    """A diagnosis that named a current and a wind with the values ``wind``, each with standard error ``se``."""
    cur = {"speed_mps": 0.2, "direction_deg": 45.0}
    return Diagnosis(named=["current", "wind"], parameters={"current": dict(cur), "wind": dict(wind)},
                     standard_errors={"current": {"speed_mps": 0.01, "direction_deg": 3.0},
                                      "wind": {k: se for k in wind}},
                     rms_config=RMS, rms_before=RMS, rms_after=RMS, unexplained=False, unexplained_description="",
                     candidates=[], rounds=[], ship_values={}, records=[], pred_before=[], pred_after=[], seconds=0.0,
                     intervals_95={"current": {}, "wind": {k: [v - 0.2, v + 0.2] for k, v in wind.items()}},
                     evidence={"current": {"delta_bic": 80.0}, "wind": {"delta_bic": 45.0, "z": 6.0}},
                     model_form_mismatch={"gamma_R_pos": {"config": 0.5, "fitted": 0.9, "prior_std": 0.075, "z": 5.3}})


def test_packaged_rule_has_a_tolerance_and_a_wind_scale_range():
    r = rules()
    assert 0 < r["bound_tolerance"] < 0.1
    lo, hi = r["plausible"]["wind"]["scale"]
    assert lo < 1.0 < hi                    # the published loads themselves are plausible


def test_shape_on_its_bound_is_model_form_mismatch_not_named():
    yaw = WIND["yaw_factor"]
    d = _diag({"scale": 1.1, "sway_factor": 0.9, "yaw_factor": yaw.lower})
    d, out = reclassify(d)
    assert d.named == ["current"] and "wind" not in d.parameters and "wind" not in d.evidence
    assert [e["effect"] for e in out] == ["wind"] and out[0]["status"] == STATUS == "model_form_mismatch"
    z = (yaw.default - yaw.lower) / 0.1                   # 8 standard errors from the published curve's 1
    assert out[0]["shapes"] == {"yaw_factor": {"fitted": yaw.lower, "lower": yaw.lower, "upper": yaw.upper, "z": z}}
    assert out[0]["coefficients"] == {}
    assert out[0]["parameters"]["yaw_factor"] == yaw.lower and out[0]["evidence"]["delta_bic"] == 45.0
    assert out[0]["ship_coefficients"] == ["gamma_R_pos"] and "yaw_factor" in out[0]["reason"]
    j = d.to_json()
    assert j["named_effects"] == ["current"]
    assert j["effect_status"] == {"current": "named", "wind": "model_form_mismatch"}
    assert j["model_form_effects"][0]["shapes"]["yaw_factor"]["upper"] == yaw.upper


def test_interior_shape_and_plausible_scale_stay_named():
    d = _diag({"scale": 1.1, "sway_factor": 0.6, "yaw_factor": 1.8})
    d, out = reclassify(d)
    assert out == [] and d.named == ["current", "wind"] and d.model_form_effects == []
    assert d.to_json()["effect_status"]["wind"] == "named"


def test_shape_on_its_bound_the_records_do_not_pin_stays_named():
    """A real wind whose yaw factor wandered to its upper bound 3 with a standard error of 0.69 (a 12 m/s
    wind on a 10/10 zigzag of the independent development set): (3 - 1) / 0.69 = 2.9 standard errors from
    the published curve, short of the 3 a finding needs, so the bound says nothing of the form."""
    yaw = WIND["yaw_factor"]
    assert (yaw.upper - yaw.default) / 0.69 < 3.0
    d = _diag({"scale": 0.72, "sway_factor": 1.0, "yaw_factor": yaw.upper}, se=0.69)
    d, out = reclassify(d)
    assert out == [] and d.named == ["current", "wind"]
    d = _diag({"scale": 0.72, "sway_factor": 1.0, "yaw_factor": yaw.upper}, se=float("nan"))
    assert reclassify(d)[1] == []                       # no standard error: not judged on its bound


@pytest.mark.parametrize("frac, flagged", [(0.5, True), (2.0, False)])
def test_bound_tolerance_is_a_fraction_of_the_range(frac, flagged):
    """A shape factor half the tolerance from its upper bound sits on it; twice the tolerance off does not."""
    sway, tol = WIND["sway_factor"], rules()["bound_tolerance"]
    v = sway.upper - frac * tol * (sway.upper - sway.lower)
    d = _diag({"scale": 1.0, "sway_factor": v, "yaw_factor": 1.0})
    d, out = reclassify(d)
    assert bool(out) is flagged and ("wind" in d.named) is not flagged


@pytest.mark.parametrize("scale", [5.4, 0.2])
def test_scale_outside_what_a_measured_wind_allows(scale):
    lo, hi = rules()["plausible"]["wind"]["scale"]
    assert not lo <= scale <= hi            # the cases are outside the packaged range
    d = _diag({"scale": scale, "sway_factor": 1.0, "yaw_factor": 1.0})
    d, (ent,) = reclassify(d)
    assert ent["shapes"] == {} and ent["coefficients"] == {"scale": {"fitted": scale, "plausible": [lo, hi]}}
    assert d.named == ["current"]


def test_no_rule_without_the_calibration_section():
    d = _diag({"scale": 5.4, "sway_factor": 0.2, "yaw_factor": 3.0})
    d, out = reclassify(d, rules({}))
    assert out == [] and d.named == ["current", "wind"]


def test_console_says_it_in_one_line():
    d = _diag({"scale": 5.4, "sway_factor": 0.9, "yaw_factor": WIND["yaw_factor"].upper})
    d, _ = reclassify(d)
    lines = d.summary_lines()
    hits = [ln for ln in lines if "model_form_mismatch" in ln]
    assert len(hits) == 1 and hits[0].startswith("wind: model_form_mismatch, not named")
    assert "scale 5.40" in hits[0] and "yaw_factor 3 on its bound" in hits[0] and "gamma_R_pos" in hits[0]
    assert not any(ln.startswith("wind ") for ln in lines)          # no named-effect line for it
    assert lines[0].startswith("current")
