"""Output-error refinement (ekf.output_error): recovery on a noise-free record, standard errors."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ekf import output_error as oe
from ekf.data import PAPER_DERIVATIVES as DERIVATIVES
from ekf.estimate import load_config
from ekf.output_error.fit import _Problem
from mmg.model import PSI_, V_, X_, Y_
from trials.estimates.estimation import data_from_log, noise_half_widths
from trials.files.logio import write_csv
from trials.runs.run import run_trial
from trials.runs.trial import load_trial

REPO = Path(__file__).resolve().parents[1]


def _data(tmp, name, duration, noise_free=True):
    tr = load_trial(REPO / "configs" / "trials" / name)
    lg = tr.log
    if noise_free:
        lg = replace(lg, noise_lat=0.0, noise_lon=0.0, noise_heading=0.0, noise_rpm=0.0, noise_speed=0.0)
    tr = replace(tr, duration=duration, log=lg)
    run = run_trial(tr)
    write_csv(tmp / "log.csv", run.log(), run.log_meta())
    write_csv(tmp / "truth.csv", run.truth(), run.log_meta())
    return data_from_log(tmp / "log.csv", load_config(), truth_path=tmp / "truth.csv")


@pytest.fixture(scope="module")
def st35_short(tmp_path_factory):
    return _data(tmp_path_factory.mktemp("st35"), "st35.yaml", 600.0)


def test_noise_half_widths_from_header():
    hw = noise_half_widths({"noise": "uniform: lat 8e-07 deg, lon 4e-07 deg, heading 0.012 deg, speed 0 kn, rpm 0.2 rpm"})
    assert hw == {"lat_deg": 8e-7, "lon_deg": 4e-7, "heading_deg": 0.012, "rpm": 0.2}
    # the numeric header keys win over the text line; a zero level keeps Table 4's weight
    hw = noise_half_widths({"noise_lat_deg": 2e-6, "noise_rpm": 0.0, "noise": "uniform: lat 8e-07 deg"})
    assert hw["lat_deg"] == 2e-6 and hw["rpm"] == 0.2
    assert noise_half_widths({"noise": "uniform: lat 0 deg"})["lat_deg"] == 8e-7


def test_residuals_vanish_at_truth_on_noise_free_log(st35_short):
    tr = oe.trial_from_data(st35_short)
    tv = np.array([st35_short.true_values[n] for n in DERIVATIVES])
    nu = tr.nuisance0()
    nu[0] = -0.000830334  # the trimmed approach's sway speed (ST35 and ZZ20 share the approach)
    r = tr.residuals(tv, nu)
    assert np.abs(r).max() < 0.05  # in noise standard deviations (positions ~0.05 m)


def test_recovers_truth_from_120_percent_start(st35_short):
    tr = oe.trial_from_data(st35_short)
    tv = np.array([st35_short.true_values[n] for n in DERIVATIVES])
    res = oe.fit([tr], 1.2 * tv, DERIVATIVES, max_nfev=80)
    rel = np.abs(res.theta / tv - 1)
    well = [i for i, n in enumerate(DERIVATIVES) if n != "N_bb"]
    # 1e-3 for the well-excited ones; Y_rr, Y_bbr, Y_brr stop within 1 % on this short 600 s turn
    assert rel[well].max() < 1e-2, dict(zip(DERIVATIVES, rel))
    assert np.median(rel[well]) < 1e-3
    # N_bb is barely excited: its error stays inside a small fraction of its standard error
    i = DERIVATIVES.index("N_bb")
    assert abs(res.theta[i] - tv[i]) < 0.05 * res.se[i]
    assert res.chi2_per_dof < 1e-3


def test_standard_errors_positive_and_shrink_with_more_data(st35_short):
    tv = np.array([st35_short.true_values[n] for n in DERIVATIVES])
    short = oe.trial_from_data(st35_short, duration=300.0)
    full = oe.trial_from_data(st35_short)
    _, se_short = oe.information([short], tv)
    _, se_full = oe.information([full], tv)
    assert np.all(se_short > 0) and np.all(se_full > 0)
    assert np.all(se_full < se_short)


@pytest.mark.slow
def test_joint_information_of_the_paper_trials(tmp_path):
    """Cramér-Rao standard errors of the joint four-trial fit at the paper's noise: all but N_bb well below 5 %."""
    cfg = load_config()
    from trials.estimates.estimation import data_from_trial
    from trials.estimates.rhee_kim import TRIALS
    datas = [data_from_trial(REPO / "configs" / "trials" / f, cfg) for f in TRIALS.values()]
    tv = np.array([datas[0].true_values[n] for n in DERIVATIVES])
    _, se = oe.information([oe.trial_from_data(d) for d in datas], tv)
    pct = 100 * se / np.abs(tv)
    for n, p in zip(DERIVATIVES, pct):
        if n != "N_bb":
            assert p < 2.0, (n, p)
    assert pct[DERIVATIVES.index("N_bb")] > 5.0


# --------------------------------------------------------------------------- zigzag: reversal times as parameters


@pytest.fixture(scope="module")
def zz20_short(tmp_path_factory):
    return _data(tmp_path_factory.mktemp("zz20"), "zz20.yaml", 600.0)


def _law_switch_times(data, tv):
    """The heading-switch law's reversal steps at the truth, as ramp times (i - 1/2) dt."""
    from mmg.integrate import integrate
    law = oe.trial_from_data(data, rudder="law")
    x0 = law.x0.copy()
    x0[V_] = -0.000830334
    _, S, orders, _ = integrate(law._pk(tv), x0, law.law, law.duration, law.dt)
    return law, x0, S, (oe.switches(orders) - 0.5) * law.dt


def test_ramp_rudder_reproduces_the_switch_law_exactly(zz20_short):
    tv = np.array([zz20_short.true_values[n] for n in DERIVATIVES])
    law, x0, S, tsw = _law_switch_times(zz20_short, tv)
    tr = oe.trial_from_data(zz20_short)  # rudder="ramp"
    assert tr.tsw is not None and len(tr.tsw) == len(tsw) == 2
    assert np.all(np.abs(tr.tsw - tsw) <= 2 * tr.dt + 1e-9)  # start values from the recovered heading
    nu = np.r_[x0[V_], x0[PSI_], x0[X_], x0[Y_], tsw]
    assert np.abs(tr.states(tv, nu) - S).max() < 1e-9


def test_cost_is_continuous_in_a_reversal_time(zz20_short):
    tv = np.array([zz20_short.true_values[n] for n in DERIVATIVES])
    _, x0, _, tsw = _law_switch_times(zz20_short, tv)
    tr = oe.trial_from_data(zz20_short)
    nu = np.r_[x0[V_], x0[PSI_], x0[X_], x0[Y_], tsw]
    s = np.linspace(-1.0, 1.0, 17)  # crosses two step boundaries
    cost = []
    for d in s:
        n2 = nu.copy()
        n2[oe.NNUIS] += d * tr.dt
        r = tr.residuals(tv, n2)
        cost.append(r @ r)
    cost = np.array(cost)
    assert cost[8] < 1e-2 and np.all(cost[[0, -1]] > 100.0)  # ~0 at the law's reversal (log rounding), steep off it
    q = np.polyval(np.polyfit(s, cost, 2), s)  # nearly a parabola: no steps (the old law jumped by a cell)
    assert np.abs(cost - q).max() < 0.05 * cost.max()
    assert np.all(np.diff(cost[:9]) < 0) and np.all(np.diff(cost[8:]) > 0)


def test_switch_time_jacobian_columns_match_full_differences(zz20_short):
    tv = np.array([zz20_short.true_values[n] for n in DERIVATIVES])
    tr = oe.trial_from_data(zz20_short)
    prob = _Problem([tr], tv, np.abs(tv))
    prob.free_theta = False
    q = prob.q0.copy()
    q[prob.nd + oe.NNUIS:] += 0.3  # 0.03 s, inside a ramp cell
    J = prob.jac(q)
    for k in range(len(tr.tsw)):
        c = prob.nd + oe.NNUIS + k
        h = 1e-3
        qq = q.copy()
        qq[c] += h
        fd = (prob.fun(qq) - prob.fun(q)) / h
        assert np.allclose(J[:, c], fd, rtol=1e-3, atol=1e-3 * np.abs(fd).max())


def test_cli_estimate_output_error(tmp_path):
    import json

    from trials.cli import main

    d = tmp_path / "zz"
    d.mkdir()
    _data(d, "zz20.yaml", 600.0)
    out = tmp_path / "out"
    rc = main(["estimate", str(d / "log.csv"), "--truth", str(d / "truth.csv"), "--out", str(out),
               "--method", "output-error"])
    assert rc == 0
    js = json.loads((out / "estimates.json").read_text())
    assert set(js) == set(DERIVATIVES)
    for v in js.values():
        assert {"estimate", "true", "error_pct", "std_error"} <= set(v)
        assert np.isfinite(v["estimate"]) and np.isfinite(v["error_pct"]) and v["std_error"] > 0
    fit = json.loads((out / "oe_fit.json").read_text())
    assert len(fit["nuisance"]["ZZ20"]["reversal_times_s"]) == 2 and fit["chi2_per_dof"] < 1.0
    assert (out / "error_table.md").exists()
