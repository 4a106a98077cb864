"""Augmented EKF (Rhee & Kim 1999): Jacobian, covariance, preprocessing, CLI outputs and failures."""
from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ekf.data import PAPER_DERIVATIVES as DERIVATIVES, estimable_names, hull_slots
from ekf.filter import AugmentedEKF, FilterDivergence, is_pd, propagate_jacobian, run_filter
from mmg.simulation import prepare
from trials.cli import main
from trials.runs.trial import load_trial

REPO = Path(__file__).resolve().parents[1]
ZZ20 = REPO / "configs" / "trials" / "zz20.yaml"
NZ = 4 + len(DERIVATIVES)


@pytest.fixture(scope="module")
def short_zz(tmp_path_factory):
    """ZZ20 shortened to 600 s, simulated once, log and truth written."""
    from trials.files.logio import write_csv
    from trials.runs.run import run_trial

    tr = replace(load_trial(ZZ20), duration=600.0)
    run = run_trial(tr)
    d = tmp_path_factory.mktemp("zz")
    write_csv(d / "log.csv", run.log(), run.log_meta())
    write_csv(d / "truth.csv", run.truth(), run.log_meta())
    return tr, d


@pytest.fixture(scope="module")
def packed():
    tr = load_trial(ZZ20)
    pk, eq = prepare(tr.ship, tr.u0)
    return tr, pk, hull_slots(tr.ship, DERIVATIVES)


def test_jacobian_matches_finite_differences(packed):
    tr, pk, slots = packed
    true = np.array([tr.ship.hull.value(n) for n in DERIVATIVES])
    z = np.r_[4.5, -0.3, 0.003, 0.88, 1.1 * true]
    zn = np.empty(NZ)
    F = np.empty((NZ, NZ))
    propagate_jacobian(z, 0.2, 0.25, 0.1, *pk.args(), slots, zn, F)
    Ffd = np.empty((NZ, NZ))
    a, b = np.empty(NZ), np.empty(NZ)
    G = np.empty((NZ, NZ))
    for j in range(NZ):
        h = 1e-6 * max(abs(z[j]), 1e-3)
        zp, zm = z.copy(), z.copy()
        zp[j] += h
        zm[j] -= h
        propagate_jacobian(zp, 0.2, 0.25, 0.1, *pk.args(), slots, a, G)
        propagate_jacobian(zm, 0.2, 0.25, 0.1, *pk.args(), slots, b, G)
        Ffd[:, j] = (a - b) / (2 * h)
    scale = np.abs(F).max(axis=1, keepdims=True)
    assert np.allclose(F, Ffd, atol=1e-6 * scale + 1e-12, rtol=1e-5)
    assert np.allclose(F[4:], np.eye(NZ)[4:])


def test_filterpy_update_is_joseph_and_matches_compiled(packed):
    """filterpy's update keeps a non-optimal-gain-safe Joseph form; our compiled loop agrees with it."""
    import inspect

    from filterpy.kalman import ExtendedKalmanFilter
    src = inspect.getsource(ExtendedKalmanFilter.update)
    assert "dot(I_KH, self.P).dot(I_KH.T) + dot(self.K, R).dot(self.K.T)" in src
    tr, pk, slots = packed
    true = np.array([tr.ship.hull.value(n) for n in DERIVATIVES])
    rng = np.random.default_rng(0)
    N = 50
    t = np.arange(N) * 0.1
    delta = np.full(N, 0.3)
    meas = np.column_stack([5.1 + 0.01 * rng.standard_normal(N), 0.01 * rng.standard_normal(N),
                            1e-4 * rng.standard_normal(N), np.full(N, 0.9)])
    z0 = np.r_[5.14, 0.0, 0.0, 0.9, 1.2 * true]
    P0 = np.diag(np.r_[0.5, 0.1, 0.1, 0.1, 0.4 * np.abs(true)])
    R = np.diag([8e-2, 6e-2, 2e-4, 4e-1])
    res = run_filter(pk, slots, t, meas, delta, z0, P0, R, "unit", nis_max=0)
    ekf = AugmentedEKF(pk, slots, 0.1)
    ekf.x, ekf.P, ekf.R = z0.copy(), P0.copy(), R
    for k in range(1, N):
        ekf.predict((delta[k - 1], delta[k]))
        ekf.update_uvrn(meas[k])
        assert np.allclose(ekf.P, ekf.P.T)
        assert np.all(np.linalg.eigvalsh(ekf.P) > -1e-12 * np.abs(ekf.P).max())
    assert np.allclose(ekf.x, res.z[-1], rtol=1e-8, atol=1e-12)
    assert np.allclose(np.diag(ekf.P), res.pdiag[-1], rtol=1e-6, atol=1e-15)
    assert np.allclose(res.P, res.P.T) and is_pd(res.P)


def test_preprocessing_recovers_uvr(short_zz, packed):
    from ekf.preprocess import compare_with_truth, recover
    from trials.files.logio import read_record

    tr, d = short_zz
    _, pk, _ = packed
    from trials.estimates.estimation import record_info

    rec = read_record(d / "log.csv")
    info = record_info(rec)
    m = recover(rec, pk.p, kind=info.kind, manoeuvre=info.manoeuvre, delta0=info.trim_rudder)
    rms = compare_with_truth(m, read_record(d / "truth.csv"))
    # stated accuracy (Table 4 noise levels): 0.02 m/s, 0.01 m/s, 1e-4 rad/s, 0.2 deg, 0.005 rps
    assert rms["u"] < 0.02 and rms["v"] < 0.01 and rms["r"] < 1e-4
    assert rms["delta"] < np.radians(0.2) and rms["n"] < 0.005


def test_cli_estimate_writes_json_keys(short_zz, tmp_path):
    tr, d = short_zz
    out = tmp_path / "est"
    rc = main(["estimate", str(d / "log.csv"), "--truth", str(d / "truth.csv"), "--out", str(out), "--no-plots"])
    assert rc == 0
    js = json.loads((out / "estimates.json").read_text())
    assert set(js) == set(DERIVATIVES)
    for v in js.values():
        assert set(v) == {"estimate", "true", "error_pct"}
        assert np.isfinite(v["estimate"]) and np.isfinite(v["error_pct"])
    assert (out / "error_table.csv").exists() and (out / "error_table.md").exists()
    assert js["Y_beta"]["error_pct"] < 10 and js["N_r"]["error_pct"] < 10


def test_cli_bad_input_exit_2(tmp_path, capsys, short_zz):
    _, d = short_zz
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,lat_deg,lon_deg,heading_deg\n0,35,129,0\n5,35,129,0\n")
    assert main(["estimate", str(bad), "--out", str(tmp_path / "o1")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "missing column" in err
    assert main(["estimate", str(tmp_path / "nope.csv"), "--out", str(tmp_path / "o2")]) == 2
    # a log that does not fit the ship: speeds three times too high
    text = (d / "log.csv").read_text().replace("# approach_speed_kn: 10.0", "# approach_speed_kn: 30.0")
    fast = tmp_path / "fast.csv"
    fast.write_text(text)
    assert main(["estimate", str(fast), "--out", str(tmp_path / "o3")]) == 2
    assert "rpm" in capsys.readouterr().err or True
    assert main(["estimate", str(d / "log.csv"), "--out", str(tmp_path / "o4"), "--set", "R.ZZ20.u=-1"]) == 2
    assert not (tmp_path / "o1").exists() and not (tmp_path / "o4").exists()


def test_divergence_names_trial_and_time(short_zz, tmp_path, capsys):
    _, d = short_zz
    out = tmp_path / "div"
    rc = main(["estimate", str(d / "log.csv"), "--out", str(out), "--no-plots",
               "--set", "R.ZZ20.u=8e-8", "--set", "R.ZZ20.v=6e-8", "--set", "R.ZZ20.r=2e-10", "--set", "R.ZZ20.n=4e-7"])
    assert rc == 3
    err = capsys.readouterr().err
    assert "ZZ20" in err and "t = " in err and "diverged" in err
    assert not out.exists()


def test_divergence_on_nonfinite(packed):
    tr, pk, slots = packed
    true = np.array([tr.ship.hull.value(n) for n in DERIVATIVES])
    N = 20
    meas = np.column_stack([np.full(N, 5.0), np.zeros(N), np.zeros(N), np.full(N, 0.9)])
    z0 = np.r_[-1.0, 0.0, 0.0, 0.9, true]
    with pytest.raises(FilterDivergence, match=r"'T' at t = 0\.1 s"):
        run_filter(pk, slots, np.arange(N) * 0.1, meas, np.zeros(N), z0, np.eye(NZ) * 1e-2,
                   np.eye(4) * 1e-2, "T")


def test_absurd_initial_guess_is_refused(short_zz, tmp_path, capsys):
    _, d = short_zz
    rc = main(["estimate", str(d / "log.csv"), "--out", str(tmp_path / "a"), "--no-plots", "--set", "initial.scale=-1000"])
    assert rc == 3
    err = capsys.readouterr().err
    assert "ZZ20" in err and "t = " in err and "nan" not in err.lower()


def test_r_far_too_large_warns_that_the_filter_learned_nothing(short_zz, tmp_path, capsys):
    _, d = short_zz
    big = ["--set", "R.ZZ20.u=8e4", "--set", "R.ZZ20.v=6e4", "--set", "R.ZZ20.r=200", "--set", "R.ZZ20.n=4e5"]
    assert main(["estimate", str(d / "log.csv"), "--out", str(tmp_path / "big"), "--no-plots"] + big) == 0
    assert "learned almost nothing" in capsys.readouterr().err
    assert main(["estimate", str(d / "log.csv"), "--out", str(tmp_path / "ok"), "--no-plots"]) == 0
    assert "learned almost nothing" not in capsys.readouterr().err


def test_free_run_catches_a_filter_that_converged_to_the_wrong_model(short_zz, tmp_path, capsys):
    """From a 500 % start the paper EKF converges to wrong derivatives without diverging and
    with small innovations; re-simulating the trial with them shows it."""
    _, d = short_zz
    out = tmp_path / "ok"
    assert main(["estimate", str(d / "log.csv"), "--truth", str(d / "truth.csv"), "--out", str(out), "--no-plots"]) == 0
    assert "does not reproduce" not in capsys.readouterr().err
    fr = json.loads((out / "free_run.json").read_text())["ZZ20"]
    assert fr["ok"] and fr["completed"] and fr["heading_rms_deg"] < 1.0 and fr["position_rms_L"] < 0.01
    assert fr["true_derivatives"]["ok"] and fr["true_derivatives"]["heading_rms_deg"] < fr["heading_rms_deg"]
    out5 = tmp_path / "five"
    assert main(["estimate", str(d / "log.csv"), "--truth", str(d / "truth.csv"), "--out", str(out5), "--no-plots",
                 "--set", "initial.scale=5"]) == 0
    err = capsys.readouterr().err
    assert "ZZ20" in err and "does not reproduce the data" in err and "rudder offset" in err
    fr5 = json.loads((out5 / "free_run.json").read_text())["ZZ20"]
    assert not fr5["ok"] and fr5["heading_rms_deg"] > 1.0
    # the estimates are indeed wrong
    js = json.loads((out5 / "estimates.json").read_text())
    assert max(v["error_pct"] for v in js.values()) > 50


def test_free_run_with_the_true_derivatives_reproduces_the_log(short_zz):
    from ekf.estimate import free_run, load_config
    from trials.estimates.estimation import data_from_log

    _, d = short_zz
    data = data_from_log(d / "log.csv", load_config(), truth_path=d / "truth.csv")
    fr = free_run(data, data.true_values)
    assert fr.ok and fr.heading_rms_deg < 0.1 and fr.position_rms_m < 2.0
    assert fr.t.shape == (121,) and fr.sim.shape == fr.log.shape == (121, 4)
    wrong = {**data.true_values, "N_r": 2.0 * data.true_values["N_r"]}
    assert not free_run(data, wrong).ok
    # a joint record (no log of its own) is not re-simulated
    assert free_run(replace(data, joint=True, source="ZZ20+ZZ10"), data.true_values) is None


def test_free_run_judges_heading_not_a_current_drifted_track(tmp_path):
    """An unmodelled current moves the track, not the heading: the true derivatives still pass."""
    from ekf.estimate import free_run, load_config
    from mmg.effects import effect_set
    from trials.files.logio import write_csv
    from trials.estimates.estimation import data_from_log
    from trials.runs.run import run_trial

    tr = replace(load_trial(ZZ20), duration=600.0)
    tr = replace(tr, effects=effect_set({"current": {"speed_mps": 0.3 * 0.5144, "direction_deg": 90.0}}))
    run = run_trial(tr)
    write_csv(tmp_path / "log.csv", run.log(), run.log_meta())
    write_csv(tmp_path / "truth.csv", run.truth(), run.log_meta())
    data = data_from_log(tmp_path / "log.csv", load_config(), truth_path=tmp_path / "truth.csv")
    fr = free_run(data, data.true_values)
    assert fr.position_rms_m > 20.0            # the current carried the ship off the still-water track
    assert fr.ok and fr.heading_rms_deg < 0.5
    assert json.dumps(fr.to_dict())


def test_estimate_filterpy_engine_gives_the_compiled_numbers(short_zz):
    """The filterpy class a user can step is the same filter as the compiled fast path."""
    from ekf.estimate import estimate, load_config
    from trials.estimates.estimation import data_from_log

    _, d = short_zz
    cfg = load_config(None, ["divergence.nis_max=0"])
    data = data_from_log(d / "log.csv", cfg)
    data.meas = replace(data.meas, **{c: getattr(data.meas, c)[:1200] for c in ("t", "u", "v", "r", "delta", "n", "psi", "x", "y")})
    a = estimate(data, cfg)
    b = estimate(data, cfg, engine="filterpy")
    assert a.final.keys() == b.final.keys()
    for n in a.final:
        assert b.final[n] == pytest.approx(a.final[n], rel=1e-8, abs=1e-14)
    np.testing.assert_allclose(b.result.pdiag[-1], a.result.pdiag[-1], rtol=1e-6, atol=1e-15)
