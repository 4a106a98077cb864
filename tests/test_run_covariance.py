"""The run-to-run covariance mmg identify writes: a delete-one-run jackknife of the fit, checked against
refits by hand (for a linear model one Gauss-Newton step is the refit), against the spread of many
independent repetitions when the runs share an error the model does not carry, and on a real fit of the
simulator's records (the per-record parts add up to the whole)."""
from __future__ import annotations

import numpy as np
import pytest

import mmg
from ekf.identify import run_jackknife_covariance
from trials.measured.identify import identification_covariance, identify

from .test_identify_covariance import _linear_fit, _records


def _fit(A, y, rows, prior, sig):
    """The MAP linear least squares solved by hand, as ekf.identify's result with each record's rows."""
    return _linear_fit(A, y, prior, sig, rows)


def _problem(rng, n_rec=12, per=30, offset_sd=0.0, noise_sd=0.05):
    """y = A theta + noise, records of ``per`` rows each; each record's rows share an offset of std ``offset_sd``
    along its own regressor mix (an error the model does not carry)."""
    theta = np.array([1.0, -0.5, 0.3])
    A, y, rows = [], [], []
    for k in range(n_rec):
        a = rng.normal(size=(per, 3)) + rng.normal(size=3)
        A.append(a)
        y.append(a @ theta + rng.normal(0.0, noise_sd, per) + offset_sd * rng.normal() * a[:, 0])
        rows.append(np.arange(k * per, (k + 1) * per))
    return np.vstack(A), np.concatenate(y), rows, theta


def test_the_run_jackknife_equals_the_jackknife_of_refits_without_each_run():
    """A linear model: the one-step delete-one-group estimate is the exact refit, so the covariance equals
    (G - 1) / G sum (theta_-g - mean)(theta_-g - mean)^T over refits made by hand without each group; groups of
    several records (a run and its cuts) leave out together."""
    rng = np.random.default_rng(3)
    A, y, rows, _ = _problem(rng, offset_sd=0.2)
    prior, sig = np.zeros(3), np.full(3, 2.0)
    fit, _ = _fit(A, y, rows, prior, sig)
    groups = [0, 0, 1, 2, 3, 3, 3, 4, 5, 6, 7, 8]
    got = run_jackknife_covariance(fit, groups)
    refits = []
    for g in sorted(set(groups)):
        keep = np.concatenate([r for r, gg in zip(rows, groups) if gg != g])
        Ak, yk = A[keep], y[keep]
        refits.append(np.linalg.solve(Ak.T @ Ak + np.diag(1.0 / sig ** 2), Ak.T @ yk + prior / sig ** 2))
    refits = np.array(refits)
    d = refits - refits.mean(axis=0)
    G = len(refits)
    want = (G - 1) / G * d.T @ d
    np.testing.assert_allclose(got, want, rtol=1e-8, atol=1e-14)


def test_the_run_jackknife_needs_two_groups_and_a_label_per_record():
    rng = np.random.default_rng(4)
    A, y, rows, _ = _problem(rng, n_rec=3)
    fit, _ = _fit(A, y, rows, np.zeros(3), np.ones(3))
    with pytest.raises(ValueError, match="two or more"):
        run_jackknife_covariance(fit, [0, 0, 0])
    with pytest.raises(ValueError, match="labels"):
        run_jackknife_covariance(fit, [0, 1])
    bare, _ = _fit(A, y, None, np.zeros(3), np.ones(3))
    with pytest.raises(ValueError, match="per-record"):
        run_jackknife_covariance(bare, [0, 1, 2])


def test_run_errors_the_model_does_not_carry_are_covered_by_the_run_jackknife_not_by_the_residual_noise():
    """Many repetitions of a fit whose records each carry a shared error: the spread of the estimates over the
    repetitions is the truth.  The residual-noise covariance (s^2 (J^T J)^-1) is several times too sure; the
    run jackknife's standard errors are within 25 % of the spread and its 90 % intervals cover 80-97 %."""
    rng = np.random.default_rng(11)
    est, se_jk, se_noise = [], [], []
    for _ in range(300):
        A, y, rows, theta = _problem(rng, n_rec=20, per=40, offset_sd=0.15, noise_sd=0.05)
        fit, th = _fit(A, y, rows, np.zeros(3), np.full(3, 100.0))
        est.append(th)
        se_jk.append(np.sqrt(np.diag(run_jackknife_covariance(fit, range(20)))))
        r = A @ th - y
        se_noise.append(np.sqrt(np.diag(np.linalg.inv(A.T @ A)) * (r @ r) / (len(r) - 3)))
    est, se_jk, se_noise = np.array(est), np.array(se_jk), np.array(se_noise)
    spread = est.std(axis=0, ddof=1)
    assert np.all(spread / np.median(se_noise, axis=0) > 3.0)          # the noise-only errors are far too sure
    ratio = spread / np.median(se_jk, axis=0)
    assert np.all((ratio > 0.8) & (ratio < 1.25)), ratio
    covered = np.abs(est - theta) <= 1.6449 * se_jk
    assert 0.80 <= covered.mean() <= 0.97, covered.mean()


def test_a_fits_per_record_parts_add_up_and_the_written_covariance_holds_both_parts():
    """mmg identify on the simulator's records: the records' J^T J add up to the data rows' (each data row
    belongs to one record), their scores to the data rows' J^T r, and the written covariance is the posterior
    plus the run jackknife, named by its method."""
    ship = mmg.load_ship("esso_osaka_3m")
    _, runs = _records(ship)
    ident = identify(ship, runs, free=["kappa", "epsilon"], segment_s=(np.inf,), say=lambda m: None, max_nfev=4)
    fit = ident.fit
    np.testing.assert_allclose(fit.record_info.sum(axis=0), fit.info_data, rtol=1e-10, atol=1e-12)
    assert fit.record_scores.shape == (len(runs), len(fit.free))
    section, post, runs_cov = identification_covariance(ident, parts=True)
    assert section["method"] == "posterior+run-jackknife"
    keep = [i for i, f in enumerate(fit.free) if f.record is None]
    want = (post + runs_cov)[np.ix_(keep, keep)]
    np.testing.assert_allclose(np.asarray(section["matrix"]), 0.5 * (want + want.T), rtol=1e-8)
    loaded = mmg.ship.ParameterCovariance(tuple(section["names"]), tuple(section["units"]),
                                          tuple(section["values"]), tuple(map(tuple, section["matrix"])),
                                          section["source"], section["method"])
    assert loaded.method == "posterior+run-jackknife"


def test_kept_out_bands_pool_samples_inside_over_all_samples():
    """The nested cross-validation's pooled band figures by hand: coverage is samples inside over samples (a
    long record counts by its length), the width the median over the records of their medians, the rejected
    share the rejected candidates over all candidates."""
    from trials.measured.nested import band_summary

    recs = [{"band": {"samples": 100, "inside": 90, "bounded": 100, "inside_bounded": 90, "median_width_deg": 4.0,
                      "draws": 200, "rejected_draws": 100}},
            {"band": {"samples": 300, "inside": 150, "bounded": 200, "inside_bounded": 50, "median_width_deg": 10.0,
                      "draws": 200, "rejected_draws": 0}},
            {"band": {"samples": 50, "inside": 50, "bounded": 0, "inside_bounded": 0, "median_width_deg": 2.0}},
            {"name": "no band"}]
    s = band_summary(recs)
    assert s["band_coverage90"] == pytest.approx(290 / 450) and s["band_median_width_deg"] == 4.0
    assert s["band_unbounded_share"] == pytest.approx(150 / 450)
    assert s["band_coverage90_where_bounded"] == pytest.approx(140 / 300)
    assert s["band_records"] == 3 and band_summary([{"name": "x"}]) == {}
    assert s["band_rejected_share"] == pytest.approx(100 / 500)
    assert "band_position_coverage90" not in s                              # not every record carries it
    for r, (k, rad) in zip(recs[:3], [(80, 3.0), (270, 5.0), (10, 1.0)]):
        r["band"].update(position_inside=k, median_radius_m=rad)
    s = band_summary(recs)
    assert s["band_position_coverage90"] == pytest.approx(360 / 450) and s["band_median_radius_m"] == 3.0


def test_refused_bands_are_counted_and_left_out_of_the_pooled_figures():
    """A kept-out record whose fold's covariance admits no ship (``band_refused``) is counted apart and does
    not enter the coverage, so a pooled figure never silently covers fewer records than it names."""
    from trials.measured.nested import band_summary

    ok = {"band": {"samples": 100, "inside": 80, "bounded": 100, "inside_bounded": 80, "median_width_deg": 6.0}}
    s = band_summary([ok, {"name": "r", "band_refused": "covariance.matrix: none of 10000 ships drawn"}])
    assert s["band_refused_records"] == 1 and s["band_records"] == 1
    assert s["band_coverage90"] == pytest.approx(0.8)
    assert band_summary([{"band_refused": "x"}, {"band_refused": "y"}]) == {"band_refused_records": 2}
    assert band_summary([ok])["band_refused_records"] == 0


def test_a_folds_band_of_a_kept_out_record_draws_from_its_fit():
    """band_scores of a record the fit did not see: the ship drawn from the fit's written covariance and the
    start from its run-to-run spread, so the band has width; its inside count is its coverage times its samples."""
    from trials.measured.nested import band_scores

    ship = mmg.load_ship("esso_osaka_3m")
    _, runs = _records(ship, n_rec=4)
    ident = identify(ship, runs[:3], free=["kappa", "epsilon"], segment_s=(np.inf,), say=lambda m: None, max_nfev=4)
    b = band_scores(ident, runs[3], 16)
    assert b["samples"] == len(runs[3].meas) and b["draws"] == 16
    assert b["median_width_deg"] > 0.0 and 0.0 <= b["coverage90"] <= 1.0
    assert b["inside"] == round(b["coverage90"] * b["samples"])
    assert b["bounded"] == round((1 - b["unbounded_share"]) * b["samples"]) and b["inside_bounded"] <= b["bounded"]
    assert 0 <= b["position_inside"] <= b["samples"] and b["median_radius_m"] > 0.0
