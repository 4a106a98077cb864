"""Sensitivity (Rhee & Kim eqs. 21-22), Fisher information and CRB, design criteria, mmg sensitivity."""
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from mmg.integrate import integrate
from mmg.simulation import prepare
from trials.cli import main
from trials.planning.fisher import _tangent_kernel, crb, criteria, fisher, movements, tangent
from trials.planning.sensitivity import (DERIVATIVES, LINEAR, NONLINEAR, efficiency, group_sums, normalise,
                                sensitivity, trial_differences)
from trials.runs.trial import load_trial

from .conftest import CONFIGS


def short(stem, duration=300.0):
    return replace(load_trial(CONFIGS / "trials" / f"{stem}.yaml"), duration=duration)


@pytest.fixture(scope="module")
def diffs():
    return [trial_differences(short(s)) for s in ("st35", "zz10", "stype120")]


def test_sensitivities_sum_to_100_over_the_group(diffs):
    df = normalise(diffs)
    assert df["sensitivity_pct"].sum() == pytest.approx(100.0, abs=1e-9)
    assert (df["sensitivity_pct"] >= 0).all()
    # eq. (21): per channel the normalised differences of the whole group sum to one
    for col in ("sum_abs_du_m_s", "sum_abs_dv_m_s", "sum_abs_dr_rad_s"):
        assert (df[col] / df[col].sum()).sum() == pytest.approx(1.0)
    # a different group gives a different normalisation, but each group sums to 100 again
    two = normalise(diffs[:2])
    assert two["sensitivity_pct"].sum() == pytest.approx(100.0)
    assert not np.allclose(two["sensitivity_pct"], df["sensitivity_pct"][: len(two)])
    gs = group_sums(df)
    assert np.allclose(gs["linear"] + gs["nonlinear"], gs["total"])
    assert gs["total"].sum() == pytest.approx(100.0)


def test_differences_are_absolute_sums_of_a_perturbed_rerun(diffs):
    tr = short("zz10")
    d = diffs[1]
    assert d.sums.shape == (12, 3) and d.completed
    pk, eq = prepare(tr.ship, tr.u0, tr.n0, tr.trim)
    law = tr.command_law(trim_rudder=eq.delta)
    _, ref, _, _ = integrate(pk, eq.state(), law, tr.duration, tr.dt)
    coef = pk.hull_coef.copy()
    coef[tr.ship.hull.index("N_r")] *= 1.2
    _, per, _, _ = integrate(replace(pk, hull_coef=coef), eq.state(), law, tr.duration, tr.dt)
    assert np.allclose(d.sums[DERIVATIVES.index("N_r")], np.abs(per[:, :3] - ref[:, :3]).sum(axis=0))
    # zigzag: the linear derivatives dominate the nonlinear ones (Rhee & Kim section 3.2)
    lin = sum(d.sums[DERIVATIVES.index(n)].sum() for n in LINEAR)
    non = sum(d.sums[DERIVATIVES.index(n)].sum() for n in NONLINEAR)
    assert lin > non


def test_efficiency_is_reciprocal_sum_normalised():
    rows = [{"trial": t, "coeff": n, "err_pct": e} for t, e in (("A", 1.0), ("B", 3.0)) for n in DERIVATIVES]
    eff = efficiency(pd.DataFrame(rows))
    assert np.allclose(eff.sum(axis=0), 100.0)
    assert eff.loc["A", "linear"] == pytest.approx(75.0)   # 1/4 : 1/12 -> 75 % : 25 %


@pytest.fixture(scope="module")
def turn_tangent():
    return short("st35", 200.0), tangent(short("st35", 200.0))


def test_tangent_matches_finite_differences_of_the_simulator(turn_tangent):
    tr, tan = turn_tangent
    # the EKF model follows the simulator
    assert np.abs(tan.y - tan.sim[:, [0, 1, 2, 7]]).max() < 1e-5
    pk, eq = prepare(tr.ship, tr.u0, tr.n0, tr.trim)
    law = tr.command_law(trim_rudder=eq.delta)
    for name in ("Y_beta", "N_r", "N_brr"):
        j = tr.ship.hull.index(name)
        h = 1e-4 * abs(pk.hull_coef[j])
        runs = []
        for s in (+1, -1):
            coef = pk.hull_coef.copy()
            coef[j] += s * h
            runs.append(integrate(replace(pk, hull_coef=coef), eq.state(), law, tr.duration, tr.dt)[1])
        fd = (runs[0][:, [0, 1, 2, 7]] - runs[1][:, [0, 1, 2, 7]]) / (2 * h)
        ex = tan.S[:, :, 4 + DERIVATIVES.index(name)]
        scale = np.abs(fd).max(axis=0)
        assert np.all(np.abs(ex - fd).max(axis=0) <= 2e-3 * scale + 1e-12), name


def test_fisher_symmetric_psd_and_equal_to_finite_difference_information(turn_tangent):
    tr, tan = turn_tangent
    R = np.array([0.08, 0.06, 2e-4, 0.4])
    I, names = fisher(tan, "filter", R=R)
    assert np.allclose(I, I.T)
    assert np.linalg.eigvalsh(I / np.sqrt(np.outer(np.diag(I), np.diag(I)))).min() > -1e-10
    # information of the derivatives from finite-difference sensitivities of the simulator
    pk, eq = prepare(tr.ship, tr.u0, tr.n0, tr.trim)
    law = tr.command_law(trim_rudder=eq.delta)
    cols = []
    for name in DERIVATIVES:
        j = tr.ship.hull.index(name)
        h = 1e-4 * abs(pk.hull_coef[j])
        st = []
        for s in (+1, -1):
            coef = pk.hull_coef.copy()
            coef[j] += s * h
            st.append(integrate(replace(pk, hull_coef=coef), eq.state(), law, tr.duration, tr.dt)[1][:, [0, 1, 2, 7]])
        cols.append((st[0] - st[1]) / (2 * h))
    Sfd = np.stack(cols, axis=2)
    Ifd = np.einsum("kij,i,kil->jl", Sfd, 1 / R, Sfd)
    Id = I[4:, 4:]
    assert np.allclose(Id, Ifd, rtol=5e-3, atol=5e-3 * np.abs(np.diag(Id)).max())
    # CRB scales with the noise: 4 x R -> 2 x the standard deviation
    c1 = crb(I, names)
    c4 = crb(fisher(tan, "filter", R=4 * R)[0], names)
    assert all(c4[n] == pytest.approx(2 * c1[n], rel=1e-9) for n in DERIVATIVES)


def test_log_information_grows_with_the_record_and_criteria_are_finite(turn_tangent):
    tr, tan = turn_tangent
    I, names = fisher(tan, "log")
    assert I.shape == (19, 19) and np.allclose(I, I.T)
    crit = criteria(I, names, tan.values)
    assert all(np.isfinite(v) and v > 0 for v in crit.values())
    # a longer record of the same trial never has less information (CRB cannot grow)
    longer = tangent(short("st35", 400.0))
    I2, _ = fisher(longer, "log")
    c, c2 = crb(I, names), crb(I2, names)
    assert all(c2[n] <= c[n] * (1 + 1e-9) for n in DERIVATIVES)


def test_movements_start_one_second_before_each_order_change():
    order = np.r_[np.zeros(25), np.ones(35), -np.ones(40)]
    seg = movements(order, 0.1)
    assert seg.dtype.kind == "i" and seg[0] == 0 and seg[-1] == 2
    assert list(np.nonzero(np.diff(seg))[0] + 1) == [15, 50]
    # an order change within the first second still starts its own movement (at step 1)
    assert movements(np.r_[0.0, 0.0, np.ones(20)], 0.1)[1] == 1


@pytest.fixture(scope="module")
def zigzag_tangent():
    tr = short("zz10", 500.0)                          # order changes at 129.9 s and 442.5 s
    return tr, tangent(tr, rudder_timing=True)


def test_rudder_timing_sensitivities_match_finite_differences(zigzag_tangent):
    """d(u, v, r, n)/d tau_j (complex step through the raw-log EKF's RK4) against central
    differences of the other EKF model (ekf.filter) run with movement j shifted in time."""
    tr, tan = zigzag_tangent
    n_mov = tan.S_tau.shape[2]
    assert n_mov >= 3                                   # the start and the two switches
    pk, eq = prepare(tr.ship, tr.u0, tr.n0, tr.trim)
    orders = integrate(pk, eq.state(), tr.command_law(trim_rudder=eq.delta), tr.duration, tr.dt)[2]
    seg = movements(orders, tr.dt)
    g = -np.gradient(tan.delta, tr.dt)
    idx = np.array([tr.ship.hull.index(n) for n in DERIVATIVES], dtype=np.int64)
    z0 = np.r_[tan.y[0], tan.values]
    N = len(tan.delta)
    for j in (1, 2):
        h = 1e-3                                        # [s]
        runs = []
        for sgn in (+1, -1):
            d = np.ascontiguousarray(tan.delta + sgn * h * g * (seg == j))
            Y, S = np.empty((N, 4)), np.empty((N, 4, 16))
            _tangent_kernel(z0, d, tr.dt, pk.args()[:4], pk.hull_coef, idx, Y, S)
            runs.append(Y)
        fd = (runs[0] - runs[1]) / (2 * h)
        ex = tan.S_tau[:, :, j]
        scale = np.abs(fd).max(axis=0)
        assert scale[2] > 0                             # the movement does turn the ship
        assert np.all(np.abs(ex - fd).max(axis=0) <= 1e-4 * scale + 1e-12), j
        assert np.all(ex[seg < j] == 0.0)               # nothing before the movement starts


def test_rudder_timing_sensitivities_are_the_raw_log_filters_tau(zigzag_tangent):
    """The bound's nuisance tau_j is the raw-log EKF's tau: propagating that filter's own
    Jacobian column d z_next / d tau over the steps of movement j gives the same sensitivities."""
    from ekf.kernels import make_workspace
    from ekf.log_filter import ND, NS as LNS, TAU, propagate_log

    LNZ = ND + len(DERIVATIVES)

    tr, tan = zigzag_tangent
    pk, eq = prepare(tr.ship, tr.u0, tr.n0, tr.trim)
    orders = integrate(pk, eq.state(), tr.command_law(trim_rudder=eq.delta), tr.duration, tr.dt)[2]
    seg = movements(orders, tr.dt)
    g = -np.gradient(tan.delta, tr.dt)
    idx = np.array([tr.ship.hull.index(n) for n in DERIVATIVES], dtype=np.int64)
    x0 = eq.state()
    z = np.r_[0.0, 0.0, 0.0, tan.y[0, 3], tan.y[0, 0], tan.y[0, 1], tan.y[0, 2], 0.0, tan.values]
    ws = make_workspace(LNZ, LNS, pk.hull_coef)
    j = 1
    s = np.zeros(LNS)
    got = np.zeros((len(tan.t), 4))
    for k in range(1, len(tan.t)):
        propagate_log(z, (tan.delta[k - 1], tan.delta[k], g[k - 1], g[k]), tr.dt, pk.args()[:4], idx, ws)
        F = ws[9]
        s = F[:LNS, :LNS] @ s + (F[:LNS, TAU] if seg[k - 1] == j else 0.0)
        z[:LNS] = ws[8][:LNS]
        got[k] = s[[4, 5, 6, 3]]                        # u, v, r, n of the filter's layout
    assert x0[0] == pytest.approx(tan.y[0, 0])
    scale = np.abs(got).max(axis=0)
    assert scale[2] > 0
    assert np.all(np.abs(tan.S_tau[:, :, j] - got).max(axis=0) <= 1e-9 * scale + 1e-15)


def test_rudder_timing_nuisances_can_only_widen_the_bound(zigzag_tangent):
    tr, tan = zigzag_tangent
    known = crb(*fisher(tan, "log"))
    I, names = fisher(tan, "log", rudder_timing=0.15)
    assert [n for n in names if n.startswith("tau_")] == [f"tau_{j + 1}" for j in range(tan.S_tau.shape[2])]
    assert names[-12:] == list(DERIVATIVES)
    assert I.shape == (19 + tan.S_tau.shape[2],) * 2 and np.allclose(I, I.T)
    prior = crb(I, names)
    free = crb(*fisher(tan, "log", rudder_timing=np.inf))
    tight = crb(*fisher(tan, "log", rudder_timing=1e-7))
    for n in DERIVATIVES:
        assert known[n] * (1 - 1e-9) <= prior[n] <= free[n] * (1 + 1e-9), n
        assert tight[n] == pytest.approx(known[n], rel=1e-4), n
    # the timing is not free information: the bound of the sway derivatives does widen
    # (by 2 % here, two movements; by 2.2 x over the 3000 s ZZ20 with its 9 movements)
    assert prior["Y_beta"] > 1.01 * known["Y_beta"]
    with pytest.raises(ValueError):
        fisher(tangent(short("st35", 50.0)), "log", rudder_timing=0.15)


def test_timing_bound_without_prior_drops_a_movement_the_log_never_saw():
    from trials.planning.fisher import trial_crb

    tr = short("zz10", 129.95)                          # the first reversal's movement starts at 128.9 s
    tan = tangent(tr, rudder_timing=True)
    assert tan.S_tau.shape[2] == 2
    I, names = fisher(tan, "log", rudder_timing=np.inf)
    assert "tau_1" in names and "tau_2" not in names   # no log sample after it: no information
    assert all(np.isfinite(v) for v in crb(I, names).values())
    for bad in (0.0, -0.1):
        with pytest.raises(ValueError):
            fisher(tan, "log", rudder_timing=bad)
    # the convenience wrapper passes the option through
    r = trial_crb(tr, rudder_timing=0.15)
    assert r["crb"]["Y_beta"] >= trial_crb(tr)["crb"]["Y_beta"]


def test_a_time_scheduled_rudder_has_no_timing_nuisance():
    tan = tangent(short("sine", 100.0), rudder_timing=True)
    assert tan.S_tau.shape == (len(tan.t), 4, 0)
    I, names = fisher(tan, "log", rudder_timing=0.15)
    I0, names0 = fisher(tan, "log")
    assert names == names0 and np.array_equal(I, I0)


def test_cli_writes_csv_and_charts(tmp_path, capsys):
    out = tmp_path / "sens"
    code = main(["sensitivity", str(CONFIGS / "trials" / "zz10.yaml"), str(CONFIGS / "trials" / "zz20.yaml"),
                 "--out", str(out), "--backend", "serial"])
    assert code == 0
    df = pd.read_csv(out / "sensitivity.csv")
    assert set(df.trial) == {"ZZ10", "ZZ20"} and len(df) == 24
    assert df.sensitivity_pct.sum() == pytest.approx(100.0, abs=1e-3)
    assert (out / "sensitivity.png").stat().st_size > 10_000
    assert (out / "group_sums.png").exists()


@pytest.mark.parametrize("argv, field", [
    (["sensitivity", "nope.yaml"], "nope.yaml"),
    (["sensitivity"], "arguments"),
    (["sensitivity", "--paper-figures", "--design"], "arguments"),
    (["sensitivity", "--paper-figures", "--ekf-comparison", "missing.csv"], "missing.csv"),
    (["sensitivity", "--paper-figures", "--jobs", "0"], "--jobs"),
])
def test_bad_input_exit_2(tmp_path, capsys, argv, field):
    out = tmp_path / "out"
    code = main(argv + ["--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and field in err[0], err
    assert not out.exists() or not any(out.iterdir())
    assert not list(tmp_path.glob(".staging-*"))


def test_bad_trial_yaml_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text((CONFIGS / "trials" / "zz10.yaml").read_text().replace("rudder: 10 deg", "rudder: 10 m")
                   .replace("../ships/esso_osaka.yaml", str(CONFIGS / "ships" / "esso_osaka.yaml")))
    out = tmp_path / "out"
    assert main(["sensitivity", str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "manoeuvre.rudder" in err
    assert not out.exists()


def test_design_search_rows_carry_both_criteria():
    from trials.planning.design import CRITERION, TIMING, best, search

    base = short("stype120", 600.0)
    df = search(base, {"S-type psi_S": [60, 120]}, references=[short("sine", 600.0)], backend="serial")
    assert list(df.trial) == ["S-type 60", "S-type 120", "Sine"]
    assert list(df.param[:2]) == ["psi_S_deg"] * 2 and df.family.iloc[2] == "reference"
    # not knowing when the rudder moved can only cost information; the sine's schedule is known
    assert (df[TIMING + CRITERION] >= df[CRITERION] * (1 - 1e-9)).all()
    assert (df.rudder_movements[:2] >= 2).all() and df.rudder_movements.iloc[2] == 0
    assert df[TIMING + CRITERION].iloc[2] == pytest.approx(df[CRITERION].iloc[2], rel=1e-12)
    assert best(df).trial == df.loc[df[CRITERION].idxmin(), "trial"]
    known_only = search(base, {"S-type psi_S": [60]}, rudder_timing=None, backend="serial")
    assert TIMING + CRITERION not in known_only
    assert known_only[CRITERION].iloc[0] == pytest.approx(df[CRITERION].iloc[0], rel=1e-12)


@pytest.mark.parametrize("value", ["abc", "0", "-1", "nan"])
def test_bad_rudder_timing_exits_2_naming_the_option(tmp_path, capsys, value):
    assert main(["sensitivity", "--crb-vs-mc", str(tmp_path), f"--rudder-timing={value}", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--rudder-timing" in err[0]
    assert not (tmp_path / "o").exists()


def test_crb_table_finds_a_non_paper_trial_through_its_trial_file(tmp_path):
    """runs.csv of trials.estimates.montecarlo.log_filter_monte_carlo names each run's trial YAML, so any trial can be compared."""
    from mmg.errors import InputError
    from trials.planning.sensitivity_report import crb_table

    yml = tmp_path / "zz35_90_short.yaml"
    yml.write_text((CONFIGS / "trials" / "zz35_90.yaml").read_text().replace("duration: 3000 s", "duration: 400 s")
                   .replace("../ships/esso_osaka.yaml", str(CONFIGS / "ships" / "esso_osaka.yaml")))
    tan = tangent(load_trial(yml))
    rng = np.random.default_rng(0)
    rows = [{"trial": "ZZ35/90", "seed": s, "diverged": "", "trial_file": str(yml),
             **{f"final_{n}": v * (1 + 0.01 * rng.standard_normal()) for n, v in zip(DERIVATIVES, tan.values)}}
            for s in range(5)]
    mc = tmp_path / "mc"
    mc.mkdir()
    pd.DataFrame(rows).to_csv(mc / "runs.csv", index=False)
    out = tmp_path / "out"
    out.mkdir()
    tab = crb_table(mc, out, verbose=False)
    assert list(dict.fromkeys(tab.trial)) == ["ZZ35/90"] and len(tab) == 12
    assert (tab.crb_std_log_timing >= tab.crb_std_log * (1 - 1e-9)).all()
    assert (out / "crb_vs_mc.csv").exists() and (out / "crb_vs_mc.png").exists()
    pd.DataFrame(rows).drop(columns="trial_file").to_csv(mc / "runs.csv", index=False)
    with pytest.raises(InputError, match="trial_file"):
        crb_table(mc, out, verbose=False)
    # several folders pool per trial; the same trial and seed twice is refused
    pd.DataFrame(rows).to_csv(mc / "runs.csv", index=False)
    more = tmp_path / "more"
    more.mkdir()
    extra = [{**r, "seed": r["seed"] + 100} for r in rows]
    pd.DataFrame(extra).to_csv(more / "runs.csv", index=False)
    assert crb_table([mc, more], out, verbose=False).runs.iloc[0] == 10
    text = (out / "crb_vs_mc.txt").read_text()
    assert "all derivatives with MC std within a factor 2" in text and "nonlinear derivatives, std / |value|" in text
    with pytest.raises(InputError, match="more than one"):
        crb_table([mc, mc], out, verbose=False)
    with pytest.raises(InputError, match="not found"):
        crb_table([mc, tmp_path / "nothing"], out, verbose=False)
