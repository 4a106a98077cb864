"""An identification's doubts travel into the IMO verdicts, and the stopping test's reversal ramp is
Froude-scaled on a model.

``mmg identify`` writes its warnings into ship.yaml (header comments and an ``identification:``
section); ``mmg imo`` lists them in imo.md and imo.json and, where the fit did not converge or made its
own training replays worse, reports no criterion as passed (a pass becomes "undecided" with a note).
A ship without the section, or with a clean one, gets today's verdicts.  The full-astern ramp is
120 s at full scale and 120 / sqrt(lambda) s on a model, lambda from the two configs' lengths.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml

import mmg
from trials.cli import main

WARNINGS = ["N_r changed sign: -0.05 in the config, 0.01 identified",
            "stage 2/2 (whole-record fit) stopped at its evaluation limit (30) after 30 evaluations without converging"]


def serial(func, tasks):
    return [func(t) for t in tasks]


# ----------------------------------------------------------------- mmg identify writes its doubts

def test_identification_stopped_at_its_limit_writes_its_doubts_into_ship_yaml(tmp_path):
    """max_nfev=1 stops both stages unconverged; scored against the ship that made the records (a perfect
    initial model) the barely-moved fit replays its training record worse: both land in the section, and
    every warning is a header comment."""
    from tests.test_identify import SHIP, _synthetic_runs
    from trials.measured.identify import identification_summary, identify, write_identification
    from trials.measured.predict import replay_record

    prior = mmg.load_ship(SHIP)
    true = prior.with_hull({"N_r": prior.hull.value("N_r") * 1.4, "N_beta": prior.hull.value("N_beta") * 0.7})
    runs = _synthetic_runs(true, seeds=(0,), duration=40.0)
    ident = identify(prior, runs, free=["N_r", "N_beta"], segment_s=(20.0, np.inf), say=lambda m: None,
                     max_nfev=1, initial=true)
    assert [s["status"] for s in ident.stages] == [0, 0]            # both stopped at their limit
    path = write_identification(ident, mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path)["ship"]
    text = path.read_text()
    sec = yaml.safe_load(text)["identification"]
    assert list(sec) == ["converged", "warnings", "covariance_method", "training_replays_worse"]
    assert sec["converged"] is False
    assert sum("stopped at its evaluation limit" in w for w in sec["warnings"]) == 2
    # worse than the initial model, by the replays themselves (heading RMS)
    worse = [r.name for r in runs if replay_record(ident.ship, r).scores()["heading_rms_deg"]
             > replay_record(true, r).scores()["heading_rms_deg"]]
    assert worse == ["syn0"] and sec["training_replays_worse"] == worse
    assert any(w.startswith("training record syn0:") for w in sec["warnings"])
    assert sec["covariance_method"] == yaml.safe_load(text)["covariance"]["method"] == "posterior"   # one run: no jackknife
    head = [ln for ln in text.splitlines() if ln.startswith("#")]
    for w in sec["warnings"]:
        assert f"# - {w}" in head
    assert any("NOT CONVERGED" in ln for ln in head)
    back = mmg.load_ship(path)                                      # still a ship config
    assert back.identification.converged is False and list(back.identification.warnings) == sec["warnings"]
    assert back.froude_scale == pytest.approx(325.0 / 3.0)          # the model's full_scale section kept
    assert identification_summary(ident, {"method": "jackknife over 4 folds"})["covariance_method"] == \
        "jackknife over 4 folds"
    assert "## Warnings" in (tmp_path / "report.md").read_text()


def test_bundled_ships_have_no_identification_section():
    for name in ("esso_osaka", "esso_osaka_3m", "esso_osaka_3m_crossflow", "kvlcc2_l7"):
        assert mmg.load_ship(name).identification is None


# ----------------------------------------------------------------- mmg imo carries them into its verdicts

def _ship_yaml(tmp_path, name: str, section: dict | None):
    """The full-scale Esso Osaka with a small covariance (its criteria pass at P = 1) and ``section``."""
    from trials.measured.identify import ship_yaml

    ship = mmg.load_ship("esso_osaka")
    names = ["N_r", "Y_r"]
    vals = [ship.hull.value("N_r"), ship.hull.value("Y_r")]
    sd = np.abs(vals) * 0.02
    cov = {"names": names, "units": ["1", "1"], "values": vals, "matrix": np.diag(sd ** 2).tolist()}
    path = tmp_path / f"{name}.yaml"
    path.write_text(ship_yaml(mmg.config_path("ships", "esso_osaka.yaml"), {}, "test", cov, section))
    return path


def _imo_cli(path, out, samples: int) -> tuple[dict, str]:
    args = ["imo", str(path), "--speed", "10 kn", "--out", str(out), "--backend", "serial"]
    assert main(args + (["--samples", str(samples)] if samples else [])) == 0
    return json.loads((out / "imo.json").read_text()), (out / "imo.md").read_text()


@pytest.mark.parametrize("samples", [8, 0])
@pytest.mark.parametrize("section", [
    {"converged": False, "warnings": WARNINGS, "covariance_method": "test", "training_replays_worse": []},
    {"converged": True, "warnings": WARNINGS[:1], "covariance_method": "test", "training_replays_worse": ["ST35"]}])
def test_an_unfinished_identification_never_passes(tmp_path, samples, section):
    """Not converged, or a training replay made worse: the criteria the clean ship passes (with samples at
    P >= 0.95) are 'undecided' with a note; no criterion passes; the warnings are in both files."""
    clean, _ = _imo_cli(_ship_yaml(tmp_path, "clean", None), tmp_path / "clean", samples)
    doc, md = _imo_cli(_ship_yaml(tmp_path, "doubted", section), tmp_path / "doubted", samples)
    passed = {c["name"] for c in clean["criteria"] if c["verdict"] == "pass"}
    assert len(passed) >= 10                                     # the Esso Osaka meets nearly all at 10 kn
    if samples:
        assert all(c["probability"] >= 0.95 for c in clean["criteria"] if c["name"] in passed)
    assert not any(c["verdict"] == "pass" for c in doc["criteria"])
    for c, c0 in zip(doc["criteria"], clean["criteria"]):
        assert c["value"] == c0["value"] and c["probability"] == c0["probability"]   # same figures
        if c["name"] in passed:
            assert c["verdict"] == "undecided" and ("did not converge" in c["note"]) == (not section["converged"])
            assert ("ST35" in c["note"]) == bool(section["training_replays_worse"])
        else:
            assert c["verdict"] == c0["verdict"] and "note" not in c
    assert doc["warnings"][:len(section["warnings"])] == section["warnings"]
    top = md.index("## Warnings of the identification")
    assert top < md.index("## Criteria")
    for w in section["warnings"]:
        assert w in md[top:md.index("## Criteria")]
    assert "undecided (identification)" in md and "no criterion is reported as passed" in md


def test_a_clean_section_or_none_changes_no_verdict(tmp_path):
    """A converged identification with no worse replay keeps every verdict (its warnings listed); a ship
    without the section is checked as before, with an empty warnings list."""
    none, md0 = _imo_cli(_ship_yaml(tmp_path, "none", None), tmp_path / "none", 8)
    clean_section = {"converged": True, "warnings": [], "covariance_method": "test", "training_replays_worse": []}
    clean, md1 = _imo_cli(_ship_yaml(tmp_path, "clean", clean_section), tmp_path / "clean", 8)
    warned, md2 = _imo_cli(_ship_yaml(tmp_path, "warned", {**clean_section, "warnings": WARNINGS[:1]}),
                           tmp_path / "warned", 8)
    assert none["warnings"] == [] and clean["warnings"] == [] and warned["warnings"] == WARNINGS[:1]
    assert none["criteria"] == clean["criteria"] == warned["criteria"]
    for c in none["criteria"]:
        assert list(c) == ["name", "value", "unit", "limit", "interval", "probability", "verdict"]
    assert "Warnings of the identification" not in md0 and "Warnings of the identification" not in md1
    assert WARNINGS[0] in md2 and "undecided (identification)" not in md2


# ----------------------------------------------------------------- the reversal ramp, Froude-scaled

def _stopping_ramp(ship) -> float:
    from trials.imo.standard import STOPPING_RUN, plan

    return plan(ship, "0.5 m/s" if ship.particulars.L < 10 else "10 kn").trials[STOPPING_RUN].astern_order().ramp_s


def test_the_stopping_ramp_is_froude_scaled_on_a_model(tmp_path):
    """The 3 m model's ramp is 120 s / sqrt(lambda), lambda from the two configs' lengths; the full-scale
    ship, and the model scaled to it (--scale-to), keep 120 s; imo.md says which."""
    from dataclasses import replace

    from trials.imo.result import stopping_note
    from trials.imo.scaling import scaling
    from trials.imo.standard import STOPPING_RUN, plan, run_manoeuvres

    model, full = mmg.load_ship("esso_osaka_3m"), mmg.load_ship("esso_osaka")
    lam = yaml.safe_load(mmg.config_path("ships", "esso_osaka.yaml").read_text())["particulars"]["L"]
    lam = float(lam.split()[0]) / float(
        yaml.safe_load(mmg.config_path("ships", "esso_osaka_3m.yaml").read_text())["particulars"]["L"].split()[0])
    assert _stopping_ramp(model) == pytest.approx(120.0 / math.sqrt(lam), rel=1e-12)     # 11.53 s
    assert _stopping_ramp(mmg.load_ship("esso_osaka_3m_crossflow")) == pytest.approx(120.0 / math.sqrt(lam))
    assert _stopping_ramp(full) == 120.0
    scaled = scaling(model, full, 10 * 1852 / 3600).ship(model)
    assert _stopping_ramp(scaled) == 120.0
    p = plan(model, "0.5 m/s")
    one = replace(p, trials={STOPPING_RUN: p.trials[STOPPING_RUN]})
    note = stopping_note(run_manoeuvres(one)[STOPPING_RUN])
    assert f"in {120.0 / math.sqrt(lam):.3g} s (the full-scale 120 s Froude-scaled" in note
