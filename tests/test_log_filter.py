"""The EKF on the raw 5 s log (ekf/log_filter.py): runs, keeps P symmetric PD, learns."""
import numpy as np
import pytest

from pathlib import Path

from ekf.data import PAPER_DERIVATIVES as DERIVATIVES
from ekf.estimate import load_config
from ekf.filter import is_pd
from ekf.log_filter import ND, log_measurements, run_log_filter
from mmg.rudder import reversal_timing_errors
from trials.estimates.estimation import data_from_trial

REPO = Path(__file__).resolve().parents[1]
NZ = ND + len(DERIVATIVES)

LINEAR = ("Y_beta", "Y_r", "N_beta", "N_r")


@pytest.fixture(scope="module")
def zz20_600(tmp_path_factory):
    cfg = load_config()
    data = data_from_trial(REPO / "configs" / "trials" / "zz20.yaml", cfg, seed=1000)
    rec = data.record
    return cfg, data, rec, run_log_filter(data, rec, cfg, duration=600.0, passes=1)


def test_measurement_noise_from_header(zz20_600):
    _, data, rec, _ = zz20_600
    t, obs, R = log_measurements(rec, data.info)
    assert obs.shape == (len(t), 4)
    # lat 8e-7 deg x 1852*60 m/deg, heading 0.012 deg, rpm 0.2: variance a^2 / 3
    np.testing.assert_allclose(np.sqrt(np.diag(R) * 3.0),
                               [8e-7 * 1852 * 60, 4e-7 * 1526.16 * 60, np.radians(0.012), 0.2 / 60], rtol=1e-9)


def test_runs_and_P_symmetric_pd(zz20_600):
    _, _, _, res = zz20_600
    assert res.z.shape == (6001, NZ) and np.all(np.isfinite(res.z))
    P = res.P
    np.testing.assert_allclose(P, P.T, rtol=0, atol=1e-14 * np.abs(P).max())
    assert is_pd(P)
    assert np.all(np.linalg.eigvalsh(P / np.sqrt(np.outer(np.diag(P), np.diag(P)))) > -1e-9)
    assert np.all(res.pdiag[-1, ND:] < res.pdiag[0, ND:])
    # the filter is consistent: mean normalised innovation squared ~ 4 (4 channels)
    assert 2.0 < np.nanmean(res.nis) < 8.0


def test_linear_derivatives_move_towards_truth(zz20_600):
    cfg, data, _, res = zz20_600
    tv = data.true_values
    for i, n in enumerate(DERIVATIVES):
        if n in LINEAR:
            start = res.z[0, ND + i]
            assert start == pytest.approx(1.2 * tv[n])
            assert abs(res.final[n] - tv[n]) < 0.25 * abs(start - tv[n]), n


def test_second_pass_relinearises(zz20_600):
    cfg, data, rec, res1 = zz20_600
    res2 = run_log_filter(data, rec, cfg, duration=600.0, passes=2)
    # pass 2 starts at pass 1's estimates with 100 x its final covariance as prior
    np.testing.assert_allclose(res2.z[0, ND:], res1.z[-1, ND:])
    np.testing.assert_allclose(res2.pdiag[0, ND:], 100.0 * res1.pdiag[-1, ND:], rtol=1e-12)
    assert is_pd(res2.P)
    assert 2.0 < np.nanmean(res2.nis) < 8.0
    tv = data.true_values
    for n in LINEAR:
        assert abs(res2.final[n] - tv[n]) < 0.25 * 0.2 * abs(tv[n]), n


def test_timing_state_recovers_the_rebuilt_rudders_timing_error(zz20_600):
    """The first reversal of the rebuilt rudder is a step (0.1 s) late on this seed; the filter's
    tau for that movement finds it, and with the truth file's rudder it finds nothing."""
    from ekf.log_filter import TAU

    cfg, data, rec, _ = zz20_600
    late = reversal_timing_errors(data.meas.t, data.meas.delta, data.truth.t, data.truth.delta)[0]
    assert late == pytest.approx(0.1, abs=1e-6)
    taus = {}
    for rudder in ("rebuilt", "true"):
        res = run_log_filter(data, rec, cfg, duration=600.0, passes=1, rudder=rudder)
        sd = np.sqrt(res.pdiag[:, TAU])
        resets = np.nonzero(np.diff(sd) > 0)[0]          # tau restarts: the last value before is the estimate
        assert len(resets) == 2                          # the start's movement, then the first reversal's
        taus[rudder] = res.z[resets[1], TAU]
        assert is_pd(res.P) and 2.0 < np.nanmean(res.nis) < 8.0
    # model rudder = delta(t) + tau g = delta(t - tau): a late rebuilt reversal needs tau = -late
    assert taus["rebuilt"] == pytest.approx(-late, abs=0.03)
    assert abs(taus["true"]) < 0.03
    with pytest.raises(ValueError):
        run_log_filter(data, rec, cfg, duration=60.0, passes=1, rudder="measured")


def test_reversal_timing_errors_pair_each_true_reversal_with_the_nearest_rebuilt_one():
    t = np.arange(0.0, 100.0, 0.1)
    true = np.sin(2 * np.pi * t / 40.0 + 0.3)
    late = np.sin(2 * np.pi * (t - 0.07) / 40.0 + 0.3)
    e = reversal_timing_errors(t, late, t, true)
    assert len(e) == 5 and np.allclose(e, 0.07, atol=2e-3)     # linear interpolation of a sine
    assert len(reversal_timing_errors(t, np.ones_like(t), t, true)) == 0


def test_monte_carlo_cli_refuses_bad_trials_before_writing(tmp_path, capsys):
    from trials.cli import main

    out = tmp_path / "mc"
    assert main(["log-filter", str(out), "--seeds", "1", "--trials", str(tmp_path / "nope.yaml")]) == 2
    assert main(["log-filter", str(out), "--seeds", "1", "--trials", str(REPO / "configs" / "trials" / "sine.yaml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "nope.yaml" in err[0] and "manoeuvre.kind" in err[1]
    assert not out.exists()


def test_cli_log_filter_says_what_it_wrote_and_how_many_diverged(tmp_path, capsys, monkeypatch):
    """`mmg log-filter` writes runs.csv alone: its console says so, with the runs and the diverged ones counted
    (a diverged run is not silent), and its help names no summary it does not write."""
    import pandas as pd

    import trials.estimates.montecarlo as mc
    from trials.cli import main

    def fake(out, **kw):
        runs = pd.DataFrame({"trial": ["ZZ20", "ZZ20", "ST35"], "seed": [1000, 1001, 1000],
                             "diverged": [None, "covariance not positive definite", None]})
        runs.to_csv(Path(out) / "runs.csv", index=False)
        return runs

    monkeypatch.setattr(mc, "log_filter_monte_carlo", fake)
    assert main(["log-filter", str(tmp_path / "lf"), "--seeds", "1", "--backend", "serial"]) == 0
    out = capsys.readouterr().out
    assert "3 run(s) of 2 trial(s), 1 diverged" in out and "runs.csv" in out
    try:
        main(["log-filter", "--help"])
    except SystemExit:
        pass
    helptext = capsys.readouterr().out
    assert "runs.csv" in helptext and "summary" not in helptext
