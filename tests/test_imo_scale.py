"""``mmg imo --scale-to``: Froude scaling of a model to the full-scale ship, with the scale effects.

The expected figures are computed by hand here: the ITTC-1957 line from its formula with the logarithms
typed in, the Froude ratios from lambda, the 3 m config header's own hand-computed scale effects (written
before this code: X_uu' -0.00873 at full scale against -0.0228, w_P0 0.319 against 0.452).
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import mmg
from trials.cli import main

KN = 1852.0 / 3600.0


def serial(func, tasks):
    return [func(t) for t in tasks]


@pytest.fixture(scope="module")
def ships():
    return mmg.load_ship("esso_osaka_3m"), mmg.load_ship("esso_osaka")


@pytest.mark.parametrize("re, want", [
    (1e6, 0.075 / 4.0 ** 2),           # log10 = 6
    (1e7, 0.075 / 5.0 ** 2),           # 0.003
    (1e9, 0.075 / 7.0 ** 2),           # 0.0015306
    (1.2e6, 0.00451),                  # the 3 m config header's model value (0.00452, rounded there)
    (1.3e9, 0.00148),                  # and its ship value
])
def test_ittc57_line_by_hand(re, want):
    from trials.imo.scaling import ittc57_cf

    assert ittc57_cf(re) == pytest.approx(want, rel=3e-3)


def test_froude_scaling_by_hand(ships):
    """Primed coefficients unchanged; lambda = 325 / 3; model speed V / sqrt(lambda); a primed force made
    dimensional scales as (rho_S / rho_M) lambda^3, time L/V as sqrt(lambda); added mass as lambda^3."""
    from trials.imo.scaling import scaling

    m, f = ships
    V = 10 * KN
    sc = scaling(m, f, V)
    lam = 325.0 / 3.0
    assert sc.lam == pytest.approx(lam, rel=1e-12)
    assert sc.u_model == pytest.approx(V / math.sqrt(lam), rel=1e-12)
    s = sc.ship(m)
    for name in ("Y_beta", "Y_r", "N_beta", "N_r", "Y_bbr", "N_brr", "X_br"):
        assert s.hull.value(name) == m.hull.value(name)
    # a primed force made dimensional with each ship's own particulars and speed
    Fm = 0.5 * 1000.0 * 3.0 * 0.201 * sc.u_model ** 2 * m.hull.value("Y_beta")
    Fs = 0.5 * 1025.0 * 325.0 * 21.73 * V ** 2 * s.hull.value("Y_beta")
    assert Fs / Fm == pytest.approx(1025.0 / 1000.0 * lam ** 3, rel=5e-3)   # T: 21.73 / 0.201 = 108.1, not 108.33
    assert (325.0 / V) / (3.0 / sc.u_model) == pytest.approx(math.sqrt(lam), rel=1e-12)
    mx_m = m.mass.m_y_prime * 0.5 * 1000.0 * 3.0 ** 2 * 0.201
    mx_s = s.mass.m_y_prime * 0.5 * 1025.0 * 325.0 ** 2 * 21.73
    assert mx_s / mx_m == pytest.approx(1025.0 / 1000.0 * lam ** 3, rel=5e-3)
    # the full-scale config's own: geometry, propeller, engine, steering
    assert s.particulars == f.particulars and s.propeller.D == f.propeller.D and s.engine == f.engine
    assert s.steering == f.steering and s.rudder.A_R == f.rudder.A_R


def test_scale_effects_by_hand(ships):
    """The friction and wake corrections from their formulas typed in here, and the round trip to the
    full-scale config the 3 m config was made from (its header's hand figures)."""
    from trials.imo.scaling import scaling

    m, f = ships
    V = 10 * KN
    sc = scaling(m, f, V)
    um = V / math.sqrt(325.0 / 3.0)
    re_m, re_s = um * 3.0 / 1.1386e-6, V * 325.0 / 1.1892e-6
    cf_m, cf_s = 0.075 / (math.log10(re_m) - 2) ** 2, 0.075 / (math.log10(re_s) - 2) ** 2
    dX = 1.2 * (cf_m - cf_s) * 2.3273 / (3.0 * 0.201)
    s = sc.ship(m)
    assert s.hull.value("X_uu") == pytest.approx(-0.0228 + dX, rel=1e-6)
    assert s.hull.value("X_uu") == pytest.approx(-0.00873, rel=0.06)          # the header's full-scale value
    t = 0.1093 + 0.30809 * um - 0.34667 * um ** 2 + 0.12967 * um ** 3
    w_m = 0.3946 + 0.26333 * um - 0.36833 * um ** 2 + 0.14658 * um ** 3
    w_s = (t + 0.04) + (w_m - t - 0.04) * (1.2 * cf_s + 0.0004) / (1.2 * cf_m)
    w_ship = s.propeller.w_P0
    got = sum(c * V ** k for k, c in enumerate(w_ship))
    assert got == pytest.approx(w_s, abs=1e-9)
    assert got == pytest.approx(0.319, abs=0.01)                              # the header: 0.452 -> 0.319
    assert w_ship[1:] == f.propeller.w_P0[1:]                                 # the ship's speed dependence kept
    w_r = 1 - 1.009 * (1 - w_m)
    w_rs = (t + 0.04) + (w_r - t - 0.04) * (1.2 * cf_s + 0.0004) / (1.2 * cf_m)
    assert s.rudder.epsilon == pytest.approx((1 - w_rs) / (1 - w_s), rel=1e-9)
    # each correction times (1 + xi)
    s2 = sc.ship(m, xi=[0.5, -1.0, 0.1, -0.2])
    assert s2.hull.value("X_uu") == pytest.approx(-0.0228 + 1.5 * dX, rel=1e-6)
    assert sum(c * V ** k for k, c in enumerate(s2.propeller.w_P0)) == pytest.approx(w_m, abs=1e-9)
    assert s2.rudder.epsilon == pytest.approx(1.1 * s.rudder.epsilon, rel=1e-12)
    assert s2.rudder.kappa == pytest.approx(0.8 * 0.595, rel=1e-12)


def test_scaled_samples_and_interval_widths(ships):
    """Samples of a model covariance scaled to the ship: the model's draws are the ones written in, the
    intervals with the scale-effect uncertainty are the wider ones, the JSON schema unchanged."""
    m, _ = ships
    cov = {"names": ["N_r", "Y_beta"], "matrix": [[(0.05 * 0.05433) ** 2, 0.0], [0.0, (0.05 * 0.3998) ** 2]]}
    res = mmg.imo(m, scale_to="esso_osaka", samples=12, cov=cov, seed=2, executor=serial)
    pn = res.parameters
    k = pn["names"].index("N_r")
    assert np.allclose(pn["draws"][:, k], pn["model"]["draws"][:, 0])       # primed: unchanged by the scaling
    assert res.scaling["lambda"] == pytest.approx(325 / 3)
    ws = res.interval_widths()
    assert len(ws) == 13                      # the six manoeuvres to both sides and the stopping test
    assert sum(w["width"] >= w["width_identified"] for w in ws) >= 9
    doc = json.loads(res.to_json())
    assert list(doc) == ["ship", "warnings", "criteria"] and all(len(c) == 7 for c in doc["criteria"])
    from trials.imo.report import report_lines

    md = "\n".join(report_lines(res))
    assert "the model's 2 parameters (N_r, Y_beta)" in md and "4 scale-effect corrections" in md
    assert "| tactical diameter, port |" in md and "from the scaling" in md


def test_cli_scale_to_writes_the_schema(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["imo", "esso_osaka_3m", "--scale-to", "esso_osaka", "--out", str(out)]) == 0
    doc = json.loads((out / "imo.json").read_text())
    assert list(doc) == ["ship", "warnings", "criteria"] and doc["ship"].startswith("Esso Osaka (scaled from")
    for c in doc["criteria"]:
        assert list(c) == ["name", "value", "unit", "limit", "interval", "probability", "verdict"]
    lim = {c["name"]: c["limit"] for c in doc["criteria"]}
    assert lim["10/10 first overshoot, port"] == 20.0                   # the ship's L/V = 63.2 s, not the model's 6 s
    md = (out / "imo.md").read_text()
    assert "From the model to the ship" in md and "ITTC" in md


@pytest.mark.parametrize("argv, names", [
    (["imo", "esso_osaka_3m", "--scale-to", "no_such_ship"], "--scale-to"),
    (["imo", "esso_osaka_3m", "--scale-to", "kvlcc2_l7"], "hull form"),       # another hull form
    (["imo", "esso_osaka", "--scale-to", "esso_osaka_3m", "--speed", "0.5 m/s"], "not larger"),    # a "model" larger than the ship
])
def test_bad_scale_to_is_one_line(argv, names, tmp_path, capsys):
    out = tmp_path / "o"
    assert main(argv + ["--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and names in err[0]
    assert not out.exists()


def test_a_model_resistance_below_its_friction_is_refused(ships):
    """An identified X_uu' smaller in size than the friction-line correction (1.2 (C_FM - C_FS) 3.86 = 0.0137
    at 10 kn) would leave the ship no resistance: refused, naming --scale-to, before any run."""
    from mmg.errors import InputError

    m, _ = ships
    weak = m.with_hull({"X_uu": -0.0112})          # the pond fit with X_uu and w_P0 both free (docs/imo.md)
    with pytest.raises(InputError) as e:
        mmg.imo(weak, scale_to="esso_osaka")
    assert e.value.source == "--scale-to" and "X_uu" in e.value.message
    mmg.imo(m.with_hull({"X_uu": -0.0150}), scale_to="esso_osaka")   # 0.0013 left: scaled and run


# ----------------------------------------------------------------- the coverage bench's covariance variants

def test_coverage_bench_posterior_with_the_stated_prior():
    """bench/imo_coverage.py's 'prior-stated' covariance, rebuilt from what a fit keeps (std, corr, cost,
    residual count, priors), equals the linearised posterior (J_d^T J_d / s_d^2 + diag(1/sigma^2))^-1 built
    here from the Jacobian of a linear least-squares problem with prior rows, as ekf.identify sets it up."""
    import sys
    from pathlib import Path
    from types import SimpleNamespace

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
    from imo_coverage import covariances

    rng = np.random.default_rng(4)
    N, n = 200, 3
    Jd = rng.normal(size=(N, n))
    sig, prior = np.array([0.5, 2.0, 1.0]), np.array([0.1, -0.3, 0.2])
    y = Jd @ np.array([0.3, 0.1, -0.2]) + rng.normal(0.0, 0.05, N)
    J = np.vstack([Jd, np.diag(1.0 / sig)])
    b = np.concatenate([y, prior / sig])
    theta = np.linalg.lstsq(J, b, rcond=None)[0]
    r = J @ theta - b
    s2 = float(r @ r) / (N + n - n)                              # ekf.identify._result: all rows, dof N + n - n
    cov = np.linalg.inv(J.T @ J) * s2
    std = np.sqrt(np.diag(cov))
    free = [SimpleNamespace(sigma=s, prior=p) for s, p in zip(sig, prior)]
    fit = SimpleNamespace(std=std, corr=cov / np.outer(std, std), n_residuals=N + n, cost_final=0.5 * float(r @ r),
                          theta=theta, free=free)
    rd = Jd @ theta - y
    sd2 = float(rd @ rd) / (N - n)
    want = np.linalg.inv(Jd.T @ Jd / sd2 + np.diag(1.0 / sig ** 2))
    got = covariances(fit, tau=1.0)
    assert np.allclose(got["gauss-newton"], cov, rtol=1e-9)
    assert np.allclose(got["prior-stated"], want, rtol=1e-6)
    got3 = covariances(fit, tau=3.0)
    assert np.allclose(got3["tau"], 3.0 * cov, rtol=1e-9)
    assert np.allclose(got3["prior-stated-tau"], np.linalg.inv(Jd.T @ Jd / (3.0 * sd2) + np.diag(1.0 / sig ** 2)),
                       rtol=1e-6)


@pytest.mark.slow
def test_coverage_bench_runs_one_seed():
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
    from imo_coverage import VARIANTS, one_seed, summary

    r = one_seed(0, 8)
    assert set(r["variants"]) == set(VARIANTS) and r["tau"] >= 1.0
    sm = summary([r])
    for v in VARIANTS:
        assert len(sm[v]["per_criterion"]) == 13 and 0.0 <= sm[v]["overall"] <= 1.0
