"""Trial logic and metrics: S-type switching, schedules, zigzag and turning metrics."""
import numpy as np
import pytest
import yaml

from mmg.units import DEG
from trials.analysis.metrics import fit_circle, turning_metrics, zigzag_metrics
from trials.runs.run import run_trial
from trials.runs.trial import load_trial, periodic_order

from .conftest import CONFIGS, FRT, needs_frt


def test_stype_switches_at_psi_s_and_zero():
    run = run_trial(load_trial(CONFIGS / "trials" / "stype120.yaml"))
    r = run.result
    sw = np.flatnonzero(np.diff(np.sign(r.orders)) != 0) + 1
    assert len(sw) >= 3
    # reversal to port when the heading change reaches 120 deg, to starboard when back at 0
    assert abs(r.psi[sw[0]] / DEG - 120) < 0.1
    assert abs(r.psi[sw[1]] / DEG - 0) < 0.1
    assert abs(r.psi[sw[2]] / DEG - 120) < 0.1
    assert np.max(np.abs(r.orders)) == pytest.approx(35 * DEG)


def test_zigzag_port_first_mirrors_starboard_first(tmp_path):
    d = yaml.safe_load((CONFIGS / "trials" / "zz10.yaml").read_text())
    d["ship"] = str(CONFIGS / "ships" / "esso_osaka.yaml")
    d["manoeuvre"]["first"] = "port"
    p = tmp_path / "zz10p.yaml"
    p.write_text(yaml.safe_dump(d))
    port = run_trial(load_trial(p)).metrics()
    stbd = run_trial(load_trial(CONFIGS / "trials" / "zz10.yaml")).metrics()
    # Y_0, N_0 break the symmetry slightly: overshoots agree within 1 deg
    np.testing.assert_allclose(port["overshoots_deg"][:3], stbd["overshoots_deg"][:3], atol=1.0)


def test_schedule_table(tmp_path):
    d = yaml.safe_load((CONFIGS / "trials" / "st35.yaml").read_text())
    d["ship"] = str(CONFIGS / "ships" / "esso_osaka.yaml")
    d["manoeuvre"] = {"kind": "schedule", "table": [[0, 0], [100, 0], [100.1, 20], [3000, 20]]}
    p = tmp_path / "sched.yaml"
    p.write_text(yaml.safe_dump(d))
    r = run_trial(load_trial(p)).result
    assert abs(r.orders[500]) < 1e-12 and r.orders[2000] == pytest.approx(20 * DEG)
    assert r.psi[-1] > np.pi


def test_periodic_orders():
    t = np.linspace(0, 600, 6001)
    s = periodic_order("sine", t, 35 * DEG, 600)
    assert s[1500] == pytest.approx(35 * DEG)
    w = periodic_order("sawtooth", t, 35 * DEG, 600)
    assert w[0] == pytest.approx(0) and w[2999] == pytest.approx(35 * DEG, rel=1e-3)
    assert w[3001] == pytest.approx(-35 * DEG, rel=1e-3)


def test_zigzag_metrics_on_synthetic_record():
    t = np.linspace(0, 100, 10001)
    psi = 15 * DEG * np.sin(2 * np.pi * t / 40)  # peaks of 15 deg
    order = np.where(psi >= 0, 1.0, -1.0) * 10 * DEG
    # heading-triggered switches at +/-10 deg
    m = zigzag_metrics(t, psi, angle=10 * DEG, first=1)
    assert m["overshoots_deg"][0] == pytest.approx(5.0, abs=0.01)
    assert m["overshoots_deg"][1] == pytest.approx(5.0, abs=0.01)


def test_turning_metrics_on_a_circle():
    R, L = 500.0, 100.0
    th = np.linspace(0, 4 * np.pi, 4001)
    x, y = R * np.sin(th), R * (1 - np.cos(th))
    m = turning_metrics(th, x, y, th, np.full_like(th, 5.0), L, t_execute=0.0)
    assert m["advance_L"] == pytest.approx(5.0, rel=1e-4)
    assert m["transfer_L"] == pytest.approx(5.0, rel=1e-4)
    assert m["tactical_diameter_L"] == pytest.approx(10.0, rel=1e-4)
    assert m["steady_diameter_L"] == pytest.approx(10.0, rel=1e-6)
    assert fit_circle(x, y)[2] == pytest.approx(R)


@needs_frt()
def test_real_turn_metrics_match_fact_sheet():
    from trials.analysis.metrics import record_metrics
    from trials.files.logio import read_record

    m = record_metrics(read_record(FRT / "turning" / "turn_14-Sep-2020_13_39_32.csv"), kind="turning")
    # reduced independently in the fact sheet: 2.73 L, 1.08 L, 2.43 L
    assert m["advance_L"] == pytest.approx(2.73, abs=0.02)
    assert m["transfer_L"] == pytest.approx(1.08, abs=0.02)
    assert m["tactical_diameter_L"] == pytest.approx(2.43, abs=0.02)


@pytest.mark.slow
def test_reproduce_main_job(tmp_path):
    from trials.cli import main

    assert main(["reproduce", "--out", str(tmp_path)]) == 0
    text = (tmp_path / "report.md").read_text()
    assert "approach rpm" in text and (tmp_path / "trials" / "st35" / "log.csv").exists()


@needs_frt()
def test_real_zigzag_ignores_small_approach_rudder_motions():
    from trials.analysis.metrics import record_metrics
    from trials.files.logio import read_record

    rec = read_record(FRT / "zigzag" / "zigzag_31-Jul-2020_13_04_24.csv")
    m = record_metrics(rec, kind="zigzag", length=3.0)
    # the rudder twitches by up to 6 deg during the approach; executes are the +/-20 deg moves
    assert len(m["execute_times_s"]) == 5
    assert m["execute_times_s"][0] > 40.0
    assert len(m["overshoots_deg"]) == 3 and all(2.0 < o < 12.0 for o in m["overshoots_deg"])
