"""The model-form term of the prediction bands (:mod:`trials.measured.modelform`, the ``model_form:`` section).

The growth curve against quantiles counted by hand on made-up error curves (bins, the records a bin needs,
made non-decreasing, a diverged sample as an infinite error); the same errors of a model and of its
full-scale ship (times sqrt(lambda) apart) give the same section; the band of a ship with a term and
nothing else drawn is the nominal replay plus or minus the term's half-width; a bad section is refused
naming its field; ``mmg identify`` writes a section that loads back, from the training replays or, with
``--cv``, the kept-out ones.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import yaml

import mmg
from mmg.errors import InputError
from mmg.ship import ModelForm
from trials.measured.bands import prediction_bands
from trials.measured.modelform import (ELAPSED_EDGES, MIN_RECORDS, Z90, heading_error_curves, heading_error_growth,
                                       heading_half_width, model_form_of, model_form_section)

from .test_predict_bands import SHIP, _run

L, G = 3.0, 9.80665
UNIT = np.sqrt(L / G)                       # the Froude time unit of a 3 m model [s]


def _curve(t_froude, err):
    return np.asarray(t_froude, float) * UNIT, np.asarray(err, float)


def test_growth_is_the_90_percent_quantile_per_bin_counted_by_hand():
    """Three records sampled in the first two bins (0-10, 10-20 sqrt(L/g)); the third bin (20-40) reached by
    two only: left out.  The quantile is numpy's 'higher' one of the absolute errors pooled in the bin."""
    t1 = np.arange(0.0, 20.0, 0.5)
    recs = [_curve(t1, 0.1 * (k + 1) * t1 * (-1) ** k) for k in range(3)]
    recs += [_curve(np.arange(20.0, 30.0, 0.5), np.full(20, 50.0)), _curve(np.arange(20.0, 30.0, 0.5), np.full(20, 60.0))]
    nodes, q, n = heading_error_growth(recs, L)
    assert n == 5 and MIN_RECORDS == 3
    np.testing.assert_allclose(nodes, [10.0, 20.0])
    for j, (lo, hi) in enumerate([(0, 10), (10, 20)]):
        pooled = np.concatenate([np.abs(e)[(t / UNIT >= lo) & (t / UNIT < hi)] for t, e in recs[:3]])
        assert q[j] == pytest.approx(np.sort(pooled)[int(np.ceil(0.9 * (len(pooled) - 1)))])


def test_growth_never_falls_and_a_diverged_sample_counts_as_infinite():
    """Errors that shrink in the second bin keep the first bin's value; a NaN (diverged) in a bin where over a
    tenth of the samples are NaN makes that bin's quantile infinite, and no section is written from it."""
    t = np.arange(0.0, 20.0, 0.5)
    shrink = [_curve(t, np.where(t < 10, 30.0, 1.0)) for _ in range(3)]
    _, q, _ = heading_error_growth(shrink, L)
    np.testing.assert_allclose(q, [30.0, 30.0])
    bad = [_curve(t, np.where(t < 10, 1.0, np.nan)) for _ in range(3)]
    _, q, _ = heading_error_growth(bad, L)
    assert np.isinf(q[-1])
    sec, why = model_form_section(bad, L, "test")
    assert sec["elapsed_froude"] == [10.0] and sec["heading_q90_deg"] == [1.0]      # the finite part kept
    assert sec["unbounded_from_froude"] == 10.0 and "unbounded" in why               # and unbounded beyond it
    assert "unbounded_from_froude" not in model_form_section(shrink, L, "test")[0]
    assert "diverged" in why and "diverged" in sec["source"]
    assert model_form_section([_curve(t, np.full(len(t), np.nan)) for _ in range(3)], L, "x")[0] is None


@pytest.mark.parametrize("ends", [20.0, 19.9999999])
def test_records_ending_on_a_bin_edge_give_a_section_the_loader_takes(tmp_path, ends):
    """Records whose last sample lies on (or within the kept digits of) a bin edge: the nodes still
    increase, and the section loads back; records of one sample give none."""
    t = np.r_[np.arange(0.0, 20.0, 0.5), ends]
    recs = [_curve(t, 0.1 * t * (k + 1)) for k in range(3)]
    sec, _ = model_form_section(recs, L, "x")
    assert np.all(np.diff(sec["elapsed_froude"]) > 0)
    data = yaml.safe_load(_ship_file().read_text())
    data["model_form"] = sec
    p = tmp_path / "ship.yaml"
    p.write_text(yaml.safe_dump(data))
    assert mmg.load_ship(str(p)).model_form.elapsed_froude == tuple(sec["elapsed_froude"])
    one = [_curve([0.0], [0.0]) for _ in range(3)]
    assert model_form_section(one, L, "x")[0] is None


def test_heading_error_curves_unwrap_align_and_keep_a_divergence():
    """A record logged in (-180, 180] crossing 180 deg and its replay 2 deg ahead, the replay starting a whole
    turn away: the error is +2 deg throughout; a replay that diverges gives NaN from there on."""
    from types import SimpleNamespace

    t = np.arange(0.0, 10.0, 1.0)
    true = np.radians(170.0 + 3.0 * t)
    logged = np.angle(np.exp(1j * true))
    pred = np.zeros((len(t), 6))
    pred[:, 5] = true + np.radians(2.0) + 2 * np.pi
    run = SimpleNamespace(t=t + 100.0, meas=np.column_stack([np.zeros((len(t), 5)), logged]))
    (el, e), = heading_error_curves([SimpleNamespace(run=run, pred=pred)])
    np.testing.assert_allclose(el, t)
    np.testing.assert_allclose(e, 2.0, atol=1e-9)
    pred[6:, 5] = np.nan
    (_, e), = heading_error_curves([SimpleNamespace(run=run, pred=pred)])
    np.testing.assert_allclose(e[:6], 2.0, atol=1e-9)
    assert np.isnan(e[6:]).all()


def test_model_and_full_scale_give_the_same_section():
    """Froude similarity: the full-scale ship (lambda = 100) sees the same errors 10x later in seconds."""
    t = np.arange(0.0, 200.0, 0.1)
    recs = [(t, 0.2 * (k + 1) * t) for k in range(4)]
    big = [(10.0 * tt, e) for tt, e in recs]
    a, b = model_form_section(recs, L, "x")[0], model_form_section(big, 100 * L, "x")[0]
    assert a == b and a["elapsed_froude"][0] == ELAPSED_EDGES[1]


def test_half_width_is_linear_from_zero_and_held_beyond_the_last_node():
    mf = ModelForm((10.0, 20.0), (2.0, 6.0))
    hw = heading_half_width(mf, np.array([0.0, 5.0, 10.0, 15.0, 20.0, 400.0]) * UNIT, L)
    np.testing.assert_allclose(hw, [0.0, 1.0, 2.0, 4.0, 6.0, 6.0])


def test_band_of_a_term_alone_is_the_nominal_plus_minus_its_half_width():
    """No covariance, no run spread: every draw replays the nominal ship, so the band is the nominal heading
    plus the term's normal error, whose 5 % and 95 % quantiles are -+ the half-width (within the sampling error
    of 400 draws, about 7 %); without the term the band has no width."""
    ship = mmg.load_ship(SHIP)
    run = _run(ship, duration=30.0)
    mf = ModelForm((10.0, 20.0, 40.0), (2.0, 5.0, 9.0))
    ship = replace(ship, covariance=None, run_spread=None)
    b = prediction_bands(replace(ship, model_form=mf), run, 400, seed=3, jobs=2)
    hw = heading_half_width(mf, run.t - run.t[0], L)
    late = hw > 1.0
    np.testing.assert_allclose((b.hi - b.nominal_deg)[late] / hw[late], 1.0, atol=0.2)
    np.testing.assert_allclose((b.nominal_deg - b.lo)[late] / hw[late], 1.0, atol=0.2)
    assert any("model-form" in n for n in b.notes)
    z = np.sort(np.random.default_rng([3, 2]).standard_normal(400))      # the documented third stream of the seed
    np.testing.assert_allclose(b.hi - b.nominal_deg, np.quantile(z, 0.95) * hw / Z90, atol=1e-9)
    assert any("held at its last value" in n for n in b.notes)          # a 30 s record, the term to 40 sqrt(L/g) = 22 s
    plain = prediction_bands(replace(ship, model_form=None), run, 50, seed=3, jobs=2)
    assert plain.empty


def test_position_band_of_a_term_alone_is_a_disc_of_its_radius():
    """No covariance, no run spread: every draw replays the nominal track and adds the term's circular normal
    offset, so the band's radius is the term's (the Rayleigh 90 % quantile, scipy's, of 400 draws: within
    about 10 %) about the nominal track; a section without ``position_q90_L`` leaves the radius at zero and
    says the position band is the draws' alone."""
    from scipy.stats import rayleigh

    from trials.measured.modelform import R90, position_half_width

    assert R90 == pytest.approx(rayleigh.ppf(0.9))
    ship = replace(mmg.load_ship(SHIP), covariance=None, run_spread=None)
    run = _run(ship, duration=30.0)
    mf = ModelForm((10.0, 20.0, 40.0), (2.0, 5.0, 9.0), position_q90_L=(0.1, 0.3, 0.5))
    b = prediction_bands(replace(ship, model_form=mf), run, 400, seed=3, jobs=2)
    np.testing.assert_allclose(position_half_width(mf, np.array([0.0, 5.0, 10.0, 15.0, 40.0, 99.0]) * UNIT, L),
                               [0.0, 0.15, 0.3, 0.6, 1.5, 1.5])            # ship lengths to metres, linear, held
    r = position_half_width(mf, run.t - run.t[0], L)
    late = r > 0.3
    np.testing.assert_allclose(b.radius[late] / r[late], 1.0, atol=0.15)
    np.testing.assert_allclose(b.x_median[late], b.nominal.pred[late, 3], atol=0.1 * r[late].max())
    assert any("model-form position offset" in n for n in b.notes)
    heading_only = prediction_bands(replace(ship, model_form=ModelForm((10.0, 20.0), (2.0, 5.0))), run, 50, seed=3, jobs=2)
    assert np.all(heading_only.radius <= 1e-9) and any("position band is the draws' alone" in n for n in heading_only.notes)


def test_position_growth_and_a_position_divergence_end_the_section():
    """Position errors binned as the heading's (in ship lengths); a bin where the position diverged ends the
    section for both terms, even where the heading stayed finite."""
    t = np.arange(0.0, 40.0, 0.5)
    head = [_curve(t, 0.1 * t) for _ in range(3)]
    pos = [_curve(t, 0.01 * (k + 1) * t) for k in range(3)]
    sec, _ = model_form_section(head, L, "x", pos)
    np.testing.assert_allclose(sec["position_q90_L"], _binned_q90_by_hand(pos, L))
    pos[0] = _curve(t, np.where(t < 20, 0.01 * t, np.nan))
    pos[1] = _curve(t, np.where(t < 20, 0.01 * t, np.nan))
    sec, why = model_form_section(head, L, "x", pos)
    assert sec["elapsed_froude"] == [10.0, 20.0] and len(sec["position_q90_L"]) == 2 and "diverged" in why
    assert len(sec["heading_q90_deg"]) == 2 and "position error" in why and "heading" not in why
    mf = model_form_of(sec)                  # the section as the ship carries it (the bench's band_ship path)
    assert mf.position_q90_L == tuple(sec["position_q90_L"]) and mf.heading_q90_deg == tuple(sec["heading_q90_deg"])
    assert model_form_of({k: v for k, v in sec.items() if k != "position_q90_L"}).position_q90_L is None
    with pytest.raises(ValueError):          # position curves of other replays: nodes that do not line up
        model_form_section(head, L, "x", [_curve(t[:20], 0.01 * t[:20]) for _ in range(3)])


def test_a_term_whose_replays_diverged_makes_the_bands_unbounded_beyond():
    """A section unbounded from 20 sqrt(L/g) (11 s of a 3 m model) on a 30 s record: the heading band and the
    position radius are finite up to 11 s and unbounded after (counted inside, as a diverged draw's), and the
    notes say why; the same section without it is held at its last value and bounded throughout."""
    ship = replace(mmg.load_ship(SHIP), covariance=None, run_spread=None)
    run = _run(ship, duration=30.0)
    mf = ModelForm((10.0, 20.0), (2.0, 5.0), position_q90_L=(0.1, 0.3), unbounded_from_froude=20.0)
    b = prediction_bands(replace(ship, model_form=mf), run, 50, seed=3, jobs=2)
    out = (run.t - run.t[0]) / UNIT > 20.0
    assert out.any() and (~out).any()
    assert np.all(np.isinf(b.lo[out])) and np.all(np.isinf(b.hi[out])) and np.all(np.isinf(b.radius[out]))
    assert np.all(np.isfinite(b.lo[~out])) and np.all(np.isfinite(b.radius[~out]))
    assert b.unbounded_share == pytest.approx(out.mean()) and any("unbounded from" in n for n in b.notes)
    held = prediction_bands(replace(ship, model_form=replace(mf, unbounded_from_froude=None)), run, 50, seed=3, jobs=2)
    assert np.all(np.isfinite(held.hi)) and any("held at its last value" in n for n in held.notes)
    # unbounded from 40 sqrt(L/g) (22 s) with the last node at 20 (11 s): held between, unbounded after, said so
    later = prediction_bands(replace(ship, model_form=replace(mf, unbounded_from_froude=40.0)), run, 50, seed=3, jobs=2)
    out = (run.t - run.t[0]) / UNIT > 40.0
    assert np.all(np.isinf(later.hi[out])) and np.all(np.isfinite(later.hi[~out]))
    assert any(f"unbounded from {40 * UNIT:.4g} s" in n for n in later.notes)
    assert any(f"held at its last value beyond up to {40 * UNIT:.4g} s" in n for n in later.notes)


def test_unbounded_from_round_trips_and_a_bad_one_is_refused(tmp_path):
    data = yaml.safe_load(_ship_file().read_text())
    data["model_form"] = {"elapsed_froude": [10.0, 20.0], "heading_q90_deg": [1.0, 2.0], "unbounded_from_froude": 20.0}
    p = tmp_path / "ship.yaml"
    p.write_text(yaml.safe_dump(data))
    assert mmg.load_ship(str(p)).model_form.unbounded_from_froude == 20.0
    for bad in (10.0, float("nan")):                 # before the last node; not a number
        data["model_form"]["unbounded_from_froude"] = bad
        p.write_text(yaml.safe_dump(data))
        with pytest.raises(InputError) as e:
            mmg.load_ship(str(p))
        assert "model_form.unbounded_from_froude" in str(e.value) and str(p) in str(e.value)


@pytest.mark.parametrize("section, field", [
    ({"elapsed_froude": [10.0, 20.0], "heading_q90_deg": [1.0, 2.0], "position_q90_L": [0.1]}, "model_form.position_q90_L"),
    ({"elapsed_froude": [10.0, 20.0], "heading_q90_deg": [1.0, 2.0], "position_q90_L": [0.2, 0.1]}, "model_form.position_q90_L"),
    ({"elapsed_froude": [10.0, 20.0], "heading_q90_deg": [1.0, 2.0], "position_q90_L": [0.1, float("inf")]},
     "model_form.position_q90_L"),
    ({"elapsed_froude": [10.0, 20.0], "heading_q90_deg": [1.0]}, "model_form.heading_q90_deg"),
    ({"elapsed_froude": [20.0, 10.0], "heading_q90_deg": [1.0, 2.0]}, "model_form.elapsed_froude"),
    ({"elapsed_froude": [0.0, 10.0], "heading_q90_deg": [1.0, 2.0]}, "model_form.elapsed_froude"),
    ({"elapsed_froude": [10.0, 20.0], "heading_q90_deg": [3.0, 2.0]}, "model_form.heading_q90_deg"),
    ({"elapsed_froude": [10.0, 20.0], "heading_q90_deg": [-1.0, 2.0]}, "model_form.heading_q90_deg"),
    ({"elapsed_froude": [10.0, 20.0], "heading_q90_deg": [1.0, float("nan")]}, "model_form.heading_q90_deg"),
])
def test_a_bad_section_is_refused_naming_its_field(tmp_path, section, field):
    data = yaml.safe_load(_ship_file().read_text())
    data["model_form"] = section
    p = tmp_path / "ship.yaml"
    p.write_text(yaml.safe_dump(data))
    with pytest.raises(InputError) as e:
        mmg.load_ship(str(p))
    assert field in str(e.value) and str(p) in str(e.value)


def _ship_file():
    from pathlib import Path

    return Path(__file__).resolve().parents[1] / "configs" / "ships" / f"{SHIP}.yaml"


def _binned_q90_by_hand(curves, L):
    """The 90 % quantile ('higher') of |error| per bin of ELAPSED_EDGES reached by 3 or more records."""
    out = []
    for lo, hi in zip(ELAPSED_EDGES[:-1], ELAPSED_EDGES[1:]):
        parts = [np.abs(e)[(t / np.sqrt(L / G) >= lo) & (t / np.sqrt(L / G) < hi)] for t, e in curves]
        if sum(len(p) > 0 for p in parts) >= 3:
            out.append(np.quantile(np.concatenate(parts), 0.9, method="higher"))
    return np.maximum.accumulate(out)


@pytest.fixture(scope="module")
def three_slices(tmp_path_factory):
    from .conftest import FRT

    if not FRT.is_dir():
        pytest.skip("FRT-DS-ESSO records not found")
    from .test_identify_cli import _slice

    d = tmp_path_factory.mktemp("mf")
    return [_slice(FRT / "zigzag" / "zigzag_31-Jul-2020_13_14_21.csv", d / "zz.csv", 40.0),
            _slice(FRT / "turning" / "turn_14-Sep-2020_13_51_45.csv", d / "turn.csv", 40.0),
            _slice(FRT / "zigzag" / "zigzag_31-Jul-2020_13_04_24.csv", d / "zz2.csv", 40.0)]


def test_identify_writes_the_training_replays_term_and_it_loads_back(three_slices, tmp_path):
    """``mmg identify`` without ``--cv``: the section is the 90 % quantiles, binned here by hand, of the
    identified ship's heading errors on its training records (replayed here from the written ship.yaml), and
    says it is in sample; it loads back as the same :class:`mmg.ship.ModelForm`."""
    from trials.cli import main
    from trials.measured.identify import load_runs
    from trials.measured.predict import replay_record

    out = tmp_path / "out"
    assert main(["identify", "--ship", SHIP, "--train", *map(str, three_slices), "--out", str(out),
                 "--max-nfev", "8"]) == 0
    sec = yaml.safe_load((out / "ship.yaml").read_text())["model_form"]
    assert "in sample" in sec["source"] and sec["records"] == 3
    ship = mmg.load_ship(str(out / "ship.yaml"))
    assert ship.model_form == ModelForm(tuple(sec["elapsed_froude"]), tuple(sec["heading_q90_deg"]), 3, sec["source"],
                                        tuple(sec["position_q90_L"]))
    curves, dist = [], []
    for r in load_runs(ship, three_slices):
        p = replay_record(ship, r).pred
        curves.append((r.t - r.t[0], np.degrees(np.unwrap(p[:, 5]) - np.unwrap(r.meas[:, 5]))))
        dist.append((r.t - r.t[0], np.sqrt((p[:, 3] - r.meas[:, 3]) ** 2 + (p[:, 4] - r.meas[:, 4]) ** 2)
                     / ship.particulars.L))
    np.testing.assert_allclose(sec["heading_q90_deg"], _binned_q90_by_hand(curves, ship.particulars.L), rtol=1e-4,
                               atol=1e-4)
    np.testing.assert_allclose(sec["position_q90_L"], _binned_q90_by_hand(dist, ship.particulars.L), rtol=1e-4,
                               atol=1e-6)
    report = (out / "report.md").read_text().split("## Model-form term", 1)[1]
    rows = [ln.split(" | ") for ln in report.splitlines() if ln.startswith("| ") and "[" not in ln]
    assert len(rows) == len(sec["elapsed_froude"])
    for (t_s, t_f, q, d), tf, qq, dd in zip(rows, sec["elapsed_froude"], sec["heading_q90_deg"], sec["position_q90_L"]):
        assert float(t_s.strip("| ")) == pytest.approx(tf * UNIT, rel=1e-3) and float(q.strip("| ")) == pytest.approx(qq, rel=2e-3)
        assert float(d.strip("| ")) == pytest.approx(dd * L, rel=5e-3)      # 3 significant figures


def test_identify_with_cv_writes_the_kept_out_term(three_slices, tmp_path):
    """With ``--cv 3`` the section is made of the three kept-out replays and says so."""
    from trials.cli import main

    out = tmp_path / "out"
    assert main(["identify", "--ship", SHIP, "--train", *map(str, three_slices), "--out", str(out),
                 "--max-nfev", "8", "--cv", "3"]) == 0
    sec = yaml.safe_load((out / "ship.yaml").read_text())["model_form"]
    assert "kept-out replays of a 3-fold cross-validation" in sec["source"] and sec["records"] == 3


def test_predict_model_form_on_and_off(tmp_path, capsys):
    """``mmg predict --samples`` on a ship with a ``model_form:`` section: on (default) the JSON says so and
    the band is wider than with ``--model-form off``, whose JSON and notes say no term was drawn."""
    import json

    from .test_predict import FRT, ZIGZAG, _run_cli, _slice

    if not FRT.is_dir():
        pytest.skip("FRT-DS-ESSO records not found")
    from .test_predict_bands import _ship_with_sections

    p = _ship_with_sections(tmp_path)
    data = yaml.safe_load(p.read_text())
    data["model_form"] = {"elapsed_froude": [10.0, 40.0], "heading_q90_deg": [3.0, 12.0], "records": 5, "source": "t"}
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    rec = _slice(FRT / ZIGZAG, tmp_path / "zz.csv", rows=300)
    docs = {}
    for form in ("on", "off"):
        js = tmp_path / f"{form}.json"
        rc, out, err = _run_cli(["predict", "--ship", p, rec, "--json", js, "--samples", "40", "--model-form", form], capsys)
        assert rc == 0, err
        docs[form] = json.loads(js.read_text())
    assert docs["on"]["bands"]["model_form"] == "on" and docs["off"]["bands"]["model_form"] == "off"
    assert any(n.startswith("no model-form term") for n in docs["off"]["bands"]["notes"])
    w = {k: d["runs"][0]["heading_band_median_width_deg"] for k, d in docs.items()}
    assert w["on"] > w["off"] + 5.0


def test_the_kept_out_term_replays_each_record_with_its_folds_ship(three_slices):
    """``model_form(ident, cv)`` takes each kept-out record's replay by the ship of the fit that did not see it:
    with a made-up cross-validation whose every fold ship is the unfitted config (not the identified ship),
    the section is the quantiles, binned here by hand, of the config's replays, and says kept-out."""
    from trials.measured.identify import identify, load_runs, model_form
    from trials.measured.predict import replay_record

    ship = mmg.load_ship(SHIP)
    runs = load_runs(ship, three_slices)
    ident = identify(ship, runs, max_nfev=2, say=lambda m: None)
    cv = [{"name": r.name, "fold": k, "ship": ship, "values": {}} for k, r in enumerate(runs)]
    sec, _ = model_form(ident, cv)
    curves = []
    for r in runs:
        p = replay_record(ship, r).pred
        curves.append((r.t - r.t[0], np.degrees(np.unwrap(p[:, 5]) - np.unwrap(r.meas[:, 5]))))
    np.testing.assert_allclose(sec["heading_q90_deg"], _binned_q90_by_hand(curves, ship.particulars.L), rtol=1e-4,
                               atol=1e-4)
    assert "kept-out replays of a 3-fold" in sec["source"]
    own, _ = model_form(ident)
    assert own["heading_q90_deg"] != sec["heading_q90_deg"]               # the identified ship's differ


def test_a_ship_identified_from_an_identified_ship_does_not_carry_its_priors_uncertainty(three_slices, tmp_path):
    """The prior carries a ``covariance:``, ``run_spread:`` and ``model_form:`` of its own fit; the ship
    identified from it has none of them (a band drawn from ``ident.ship`` would otherwise draw the prior's doubt
    as the new fit's); ``mmg identify`` writes the new fit's."""
    from trials.measured.identify import identify

    from .test_predict_bands import _ship_with_sections

    p = _ship_with_sections(tmp_path)
    data = yaml.safe_load(p.read_text())
    data["model_form"] = {"elapsed_froude": [10.0], "heading_q90_deg": [99.0], "records": 9, "source": "prior"}
    data["identification"] = {"converged": False, "warnings": ["the prior's own fit did not converge"]}
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    prior = mmg.load_ship(str(p))
    assert prior.covariance is not None and prior.run_spread is not None and prior.model_form is not None
    assert prior.identification is not None
    ident = identify(prior, three_slices, free=["N_r", "kappa"], max_nfev=2)
    assert ident.ship.covariance is None and ident.ship.run_spread is None and ident.ship.model_form is None
    assert ident.ship.identification is None
    assert ident.ship.hull.value("N_r") == pytest.approx(ident.fit.values()["N_r"])
