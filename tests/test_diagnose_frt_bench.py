"""The record-side figures of bench/diagnose_frt.py (the measured wind beside the diagnosis), checked
against hand-made geometry, not the module's own output."""
import importlib.util
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np

_spec = importlib.util.spec_from_file_location("diagnose_frt", Path(__file__).resolve().parents[1] / "bench" / "diagnose_frt.py")
frt = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(frt)


def test_circular_mean_wraps_through_north():
    mean, R = frt.circular_mean_deg(np.radians([350.0, 10.0]))
    assert min(mean, 360.0 - mean) < 1e-9          # 0 deg, not the arithmetic 180
    assert math.isclose(R, math.cos(math.radians(10.0)), rel_tol=1e-12)


def _rec(**kw):
    base = dict(wind_speed_rel=None, wind_dir_rel=None, wind_speed_true=None, wind_dir_true=None,
                u=None, v=None, psi=None)
    base.update(kw)
    return SimpleNamespace(**base)


def test_true_wind_computed_from_relative_when_not_logged():
    # ship heading north at 1 m/s; a 2 m/s true wind FROM the east (air moving west).  Air relative to
    # the ship moves (north, east) = (-1, -2): it comes from (1, 2), i.e. atan2(2, 1) to starboard of the bow.
    n = 50
    rec = _rec(wind_speed_rel=np.full(n, math.sqrt(5.0)), wind_dir_rel=np.full(n, math.atan2(2.0, 1.0)),
               u=np.ones(n), v=np.zeros(n), psi=np.zeros(n))
    w = frt.measured_wind(rec)
    assert w["source"] == "computed from relative wind"
    assert math.isclose(w["true_speed_mean_mps"], 2.0, rel_tol=1e-9)
    assert math.isclose(w["true_from_deg"], 90.0, abs_tol=1e-6)


def test_logged_true_wind_preferred_and_zero_wind_reported_absent():
    n = 4
    rec = _rec(wind_speed_rel=np.ones(n), wind_dir_rel=np.zeros(n), wind_speed_true=np.array([1.0, 3.0, 1.0, 3.0]),
               wind_dir_true=np.radians([300.0, 300.0, 300.0, 300.0]), u=np.ones(n), v=np.zeros(n), psi=np.zeros(n))
    w = frt.measured_wind(rec)
    assert w["source"] == "logged true wind" and w["true_speed_mean_mps"] == 2.0
    assert math.isclose(w["true_from_deg"], 300.0, abs_tol=1e-9)
    assert frt.measured_wind(_rec(wind_speed_rel=np.zeros(n), wind_dir_rel=np.zeros(n), u=np.ones(n), v=np.zeros(n),
                                  psi=np.zeros(n)))["source"] == "none"


def test_summary_counts_model_form_effects_record_by_record():
    """Two records: one whose wind the rule reported model_form_mismatch beside a named current, one with
    nothing named; the summary counts 1 of the 2 effects the search named, on 1 of 2 records, by name."""
    form = {"effect": "wind", "status": "model_form_mismatch", "shapes": {"yaw_factor": {}}, "coefficients": {},
            "parameters": {"scale": 1.0, "sway_factor": 1.0, "yaw_factor": 0.2}}
    d1 = {"named_effects": ["current"], "parameters": {"current": {"speed_mps": 0.01, "direction_deg": 30.0}},
          "model_form_effects": [form]}
    d2 = {"named_effects": [], "parameters": {}, "model_form_effects": []}
    recs = [{"file": "turning/turn_14-Oct-2020_14_08_51.csv", "folder": "turning", "diagnosis": d1, "seconds": 1.0},
            {"file": "zigzag/zigzag_31-Jul-2020_13_04_24.csv", "folder": "zigzag", "diagnosis": d2, "seconds": 1.0}]
    line = frt.form_summary(recs)
    assert "1 of the 2 the search named, on 1 of 2 records" in line
    assert "shape on its bound 1, value outside its plausible range 0" in line
    assert "turning: 14-Oct-2020_14_08_51 1 (wind)" in line and "13_04_24" not in line
    assert frt.fitted_text(d1, "wind").startswith("model_form_mismatch (scale 1.00")
