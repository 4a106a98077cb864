"""The diagnosis rules file (configs/calibration/diagnose_rules.yaml, trials/measured/diagnose/rules.py): every
entry is there with its unit, meaning and source, and read by the code; a value changed in a copy named by
MMG_DIAGNOSE_RULES changes the decision it governs; a malformed file is refused in one line naming the file and
the entry, exit 2 through ``mmg diagnose``, before any record is read."""
from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

REPO = Path(__file__).resolve().parents[1]
RULES_FILE = REPO / "configs" / "calibration" / "diagnose_rules.yaml"
PACKAGE = REPO / "trials" / "measured" / "diagnose"


def _doc() -> dict:
    return yaml.safe_load(RULES_FILE.read_text())


def test_every_entry_is_in_the_file_with_its_unit_meaning_and_source():
    from trials.measured.diagnose.rules import ENTRIES, rules

    doc = _doc()
    assert set(doc) == set(ENTRIES)
    for name, ent in doc.items():
        assert set(ent) == {"value", "unit", "meaning", "source"}, name
        assert all(isinstance(ent[k], str) and ent[k].strip() for k in ("unit", "meaning", "source")), name
    assert rules() == {k: v["value"] for k, v in doc.items()}


def test_every_entry_is_read_by_the_code_and_no_number_is_written_twice():
    """Each entry is read by name somewhere in the package (other than the loader), and the package's
    modules assign no numeric module constant but a numerical guard (gravity is mmg.model.G), and write no
    literal g."""
    from trials.measured.diagnose.rules import ENTRIES

    src = {p.name: p.read_text() for p in PACKAGE.glob("*.py") if p.name != "rules.py"}
    text = "\n".join(src.values())
    unread = [e for e in ENTRIES if not re.search(rf"""rule\((["']){e}\1\)""", text)]
    assert not unread, unread
    consts = set(re.findall(r"^([A-Z_]+) = [-0-9.e]+\s*$", text, flags=re.M))
    assert consts == {"EIG_FLOOR"}, consts
    assert "9.80665" not in text


def test_the_module_names_are_views_of_the_file():
    import trials.measured.diagnose as G
    from trials.measured.diagnose import baseline, calibration, decision, identifiability, options, records, result

    doc = {k: v["value"] for k, v in _doc().items()}
    views = {(decision, "BIC_THRESHOLD"): "bic_threshold", (decision, "Z_THRESHOLD"): "z_threshold",
             (decision, "WEAK_BIC"): "weak_bic", (identifiability, "R_CONFOUNDED"): "r_confounded",
             (identifiability, "STD_RATIO_CONFOUNDED"): "std_ratio_confounded",
             (identifiability, "_CONFUSED_MIN"): "confused_min", (result, "UNEXPLAINED_FACTOR"): "unexplained_factor",
             (result, "MISMATCH_Z"): "mismatch_z", (baseline, "DRIFT_FALL_MIN"): "drift_fall_min",
             (records, "RESTART_SMOOTH"): "restart_smooth", (records, "STRAIGHT_YAW"): "straight_yaw",
             (records, "STRAIGHT_RUDDER_DEG"): "straight_rudder_deg", (records, "STRAIGHT_TRIM_DEG"): "straight_trim_deg",
             (records, "STRAIGHT_MIN_SAMPLES"): "straight_min_samples", (records, "STRAIGHT_WIND"): "straight_wind",
             (options, "SCREEN_NFEV"): "screen_nfev", (calibration, "MIN_PASSING"): "min_passing",
             (calibration, "RESIDUAL_QUANTILE"): "residual_quantile", (G, "DRIFT_FALL_MIN"): "drift_fall_min",
             (G, "BIC_THRESHOLD"): "bic_threshold", (G, "Z_THRESHOLD"): "z_threshold", (G, "SCREEN_NFEV"): "screen_nfev"}
    for (mod, name), entry in views.items():
        assert getattr(mod, name) == doc[entry], (mod.__name__, name)
    with pytest.raises(AttributeError):
        decision.NOT_A_RULE                                       # noqa: B018


def test_the_drift_gate_is_the_rules_file_s_and_follows_it(diagnose_rules):
    """The drift terms' size gate is read from the rules file, not copied: a copy with another value is
    what the package gives (read when asked for, after import)."""
    from trials.measured.diagnose import DRIFT_FALL_MIN

    assert DRIFT_FALL_MIN == _doc()["drift_fall_min"]["value"]
    diagnose_rules(drift_fall_min=0.5)
    from trials.measured.diagnose import DRIFT_FALL_MIN as after

    assert after == 0.5


def test_a_higher_z_threshold_stops_a_straight_run_contradiction(diagnose_rules):
    """A fit that leaves the straight run 4 standard errors off (0.5 before) contradicts it at z 3, not at 5."""
    from trials.measured.diagnose import straight_contradicts

    assert straight_contradicts([0.5], [4.0])
    diagnose_rules(z_threshold=5.0)
    assert not straight_contradicts([0.5], [4.0])


def test_weak_bic_and_the_naming_threshold_bound_the_evidence_short_of_a_name(diagnose_rules):
    from trials.measured.diagnose.decision import evidence_short

    assert evidence_short(10.0, 4.0) and not evidence_short(25.0, 4.0)
    diagnose_rules(weak_bic=12.0, bic_threshold=30.0)
    assert not evidence_short(10.0, 4.0) and evidence_short(25.0, 4.0)


def test_the_mismatch_z_decides_model_form_mismatch(diagnose_rules):
    """A coefficient fitted 4 prior std off its config value: model-form mismatch at 3, not at 5."""
    from types import SimpleNamespace

    from trials.measured.diagnose import model_form_mismatch

    free = [SimpleNamespace(name="Y_v", prior=-0.3, sigma=0.01)]
    assert set(model_form_mismatch(free, [-0.26])) == {"Y_v"}
    diagnose_rules(mismatch_z=5.0)
    assert model_form_mismatch(free, [-0.26]) == {}


def test_the_side_share_decides_the_kind_of_record(diagnose_rules):
    """A rudder 85 % of the time to starboard: a zigzag at a share of 0.9, a turn at 0.8."""
    from trials.measured.decision import record_kind

    d = np.where(np.arange(100) < 85, math.radians(20.0), math.radians(-20.0))
    assert record_kind([d]) == "zigzag"
    diagnose_rules(side_share=0.8)
    assert record_kind([d]) == "turn"


def test_the_straight_run_limits_come_from_the_file(diagnose_rules):
    """A record steady for 4 samples then turning: a straight run of 4 at the fewest of 3, none at 5; a yaw
    rate of 0.03 L/U breaks it at 0.02, not at 0.05."""
    from trials.measured.diagnose.records import leading_straight_run

    L, U, n = 100.0, 5.0, 40
    meas = np.zeros((n, 6))
    meas[:, 0] = U
    delta = np.zeros(n)
    delta[4:] = math.radians(20.0)
    assert leading_straight_run(meas, delta, L).n == 4
    diagnose_rules(straight_min_samples=5)
    assert leading_straight_run(meas, delta, L) is None
    diagnose_rules()
    meas[:, 2] = 0.03 * U / L
    assert leading_straight_run(meas, delta, L) is None
    diagnose_rules(straight_yaw=0.05)
    assert leading_straight_run(meas, delta, L).n == 4


def test_the_residual_quantile_and_the_budgets_come_from_the_file(diagnose_rules):
    """The residual floors are the file's percentile of the clean records' residuals (numpy's percentile
    by hand); the options' default budgets are the file's."""
    from trials.measured.diagnose import DiagnoseOptions
    from trials.measured.diagnose.calibration import residual_floors

    head = [0.1 * k for k in range(1, 21)]
    recs = [{"trial": "zigzag", "speed_mps": 1.0, "L_m": 1.0, "rms_after": {"u": 0, "v": 0, "r": 0, "heading": h}}
            for h in head]
    assert residual_floors(recs)["zigzag"]["heading"] == pytest.approx(float(np.percentile(head, 95.0)))
    doc = _doc()
    assert (DiagnoseOptions().screen_nfev, DiagnoseOptions().max_nfev) == (doc["screen_nfev"]["value"],
                                                                          doc["max_nfev"]["value"])
    diagnose_rules(residual_quantile=50.0, screen_nfev=3, max_nfev=7)
    assert residual_floors(recs)["zigzag"]["heading"] == pytest.approx(1.05)
    assert (DiagnoseOptions().screen_nfev, DiagnoseOptions().max_nfev) == (3, 7)


@pytest.mark.slow
def test_a_higher_z_threshold_stops_an_effect_being_named(diagnose_rules):
    """End to end: a 1.5 deg heading bias on a zigzag is named with the packaged rules and not named
    with a rules file whose z threshold is out of reach; the JSON reports the threshold used."""
    from mmg.ship import load_ship
    from trials.measured.diagnose import Manoeuvre, RecordNoise, diagnose, synthetic_record

    ship = load_ship("esso_osaka_3m")
    rec = synthetic_record(ship, Manoeuvre("zigzag", rudder_deg=20.0), {"heading_bias": {"bias_deg": 1.5}},
                           noise=RecordNoise(seed=4), name="z")
    opts = {"candidates": ["heading_bias"]}
    assert diagnose(ship, [rec], **opts).named == ["heading_bias"]
    diagnose_rules(z_threshold=1e6)
    d = diagnose(ship, [rec], **opts)
    assert d.named == [] and d.to_json()["threshold"]["z"] == 1e6


def _bad(tmp_path, edit) -> Path:
    doc = _doc()
    edit(doc)
    p = tmp_path / "rules.yaml"
    p.write_text(yaml.safe_dump(doc))
    return p


@pytest.mark.parametrize("edit, field", [
    (lambda d: d.pop("z_threshold"), "z_threshold"),
    (lambda d: d["weak_bic"].update(value="two"), "weak_bic.value"),
    (lambda d: d["drift_fall_min"].update(value=float("nan")), "drift_fall_min.value"),
    (lambda d: d["screen_nfev"].update(value=6.5), "screen_nfev.value"),
    (lambda d: d["mismatch_z"].pop("source"), "mismatch_z.source"),
    (lambda d: d.update(z_treshold=d["z_threshold"]), "z_treshold"),
    (lambda d: d.update(side_share=0.9), "side_share"),
])
def test_a_malformed_rules_file_is_refused_in_one_line(tmp_path, monkeypatch, edit, field):
    from mmg.errors import InputError
    from trials.measured.diagnose import rules as R

    p = _bad(tmp_path, edit)
    monkeypatch.setenv(R.ENV, str(p))
    R.rules.cache_clear()
    try:
        with pytest.raises(InputError) as e:
            R.rules()
    finally:
        monkeypatch.delenv(R.ENV)
        R.rules.cache_clear()
    msg = str(e.value)
    assert msg.startswith(f"{p}: {field}:") and "\n" not in msg, msg


@pytest.mark.parametrize("body", ["z_threshold: [1, 2\n", "- 1\n- 2\n", None])
def test_a_rules_file_that_is_not_one_is_refused_through_mmg_diagnose(tmp_path, body):
    """``mmg diagnose`` with MMG_DIAGNOSE_RULES naming a file that is not YAML, not a mapping, or not there:
    exit 2, one line naming the file, before any record is read (the record named does not exist) and
    nothing written."""
    p = tmp_path / "rules.yaml"
    if body is not None:
        p.write_text(body)
    out = tmp_path / "d.json"
    r = subprocess.run([sys.executable, "-m", "trials.cli", "diagnose", "--ship", "esso_osaka_3m",
                        tmp_path / "absent.csv", "--json", out], capture_output=True, text=True,
                       env={**os.environ, "MMG_DIAGNOSE_RULES": str(p)})
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1 and str(p) in lines[0], r.stderr
    assert "absent.csv" not in lines[0] and not out.exists()


def test_a_missing_entry_is_refused_through_mmg_diagnose(tmp_path):
    p = _bad(tmp_path, lambda d: d.pop("bic_threshold"))
    out = tmp_path / "d.json"
    r = subprocess.run([sys.executable, "-m", "trials.cli", "diagnose", "--ship", "esso_osaka_3m",
                        tmp_path / "absent.csv", "--json", out], capture_output=True, text=True,
                       env={**os.environ, "MMG_DIAGNOSE_RULES": str(p)})
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1, r.stderr
    assert lines[0].startswith(f"error: {p}: bic_threshold:") and not out.exists()
