"""The diagnosis package (:mod:`trials.measured.diagnose`): its old flat module paths name the same module
objects as the package's rooms, its public names are exactly these, no room is over 800 lines,
and the fitter a step passes on cannot be changed after the fact."""
from __future__ import annotations

import dataclasses
import importlib
from pathlib import Path

import pytest

ROOMS = Path(__file__).resolve().parents[1] / "trials" / "measured" / "diagnose"


@pytest.mark.parametrize("old, new", [("decision", "decision"), ("calibration", "calibration"),
                                      ("identifiability", "identifiability"), ("diagnose_report", "report"),
                                      ("diagnose_plots", "plots"), ("diagnose_records", "records")])
def test_an_old_module_path_is_the_room_itself(old, new):
    a = importlib.import_module(f"trials.measured.{old}")
    b = importlib.import_module(f"trials.measured.diagnose.{new}")
    assert a is b                                   # one module: a patch of either is seen by both
    exec(f"from trials.measured import {old} as c", globals())
    assert c is b  # noqa: F821


def test_the_package_exports_what_the_module_did():
    import trials.measured.diagnose as G

    assert set(G.__all__) == {
        "diagnose", "DiagnoseOptions", "Diagnosis", "straight_run_table", "straight_contradicts", "prepare",
        "synthetic_record", "Manoeuvre", "RecordNoise", "write_frt_csv", "diagnose_each", "SHIP_FREE_TERMS", "MASS_FREE", "CONSTANTS_FREE",
        "TURN_CONSTANTS_FREE", "ZIGZAG_CONSTANTS_FREE", "TURN_HULL_TERMS", "DRIFT_FALL_MIN", "BIC_THRESHOLD",
        "Z_THRESHOLD", "CHANNELS"}
    assert all(hasattr(G, n) for n in G.__all__)


def test_no_room_is_over_800_lines():
    sizes = {p.name: len(p.read_text().splitlines()) for p in ROOMS.glob("*.py")}
    assert len(sizes) >= 10 and max(sizes.values()) <= 800, sizes


def test_the_fitter_and_the_result_are_frozen():
    from trials.measured.diagnose.fit import _Fitter
    from trials.measured.diagnose.result import Diagnosis

    f = _Fitter(ship=None, packed=None, recs=[], scales=None, stride=1, max_nfev=1, ship_free=[], kind="zigzag",
                heading=0.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        f.kind = "turn_drift"
    g = dataclasses.replace(f, kind="turn_drift")
    assert (f.kind, g.kind, g.straight_weight) == ("zigzag", "turn_drift", 1.0)
    assert Diagnosis.__dataclass_params__.frozen
