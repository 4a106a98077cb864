"""Prediction bands of ``mmg predict --samples`` (:mod:`trials.measured.bands`) and the ``run_spread:`` section
``mmg identify`` writes (:func:`trials.measured.identify.run_spread`).

The band's quantiles against numpy's of draws replayed here by hand; a zero covariance and spread give the
nominal replay; a record crossing +-180 deg compared on its unwrapped heading; the coverage counted by hand;
diverged draws widen the band; the JSON keys exactly; bad ``--samples``/``--seed`` refused in one line; records
made by the model with parameters and start states drawn from the stated spread fall in the band about as
often as it says (calibration); the run spread's numbers against the fit's own offsets and the noise.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

import mmg
from mmg.model import pack
from mmg.replay import ReplayInputs, replay
from trials.measured.bands import BAND_KEYS, Bands, _quantile_bounds, prediction_bands
from trials.measured.predict import MeasuredRun, Replayed, replay_record

from .test_predict import FRT, ZIGZAG, _refused, _run_cli, _slice, needs_frt

SHIP = "esso_osaka_3m"


@pytest.fixture(scope="module")
def ship():
    return mmg.load_ship(SHIP)


def _run(ship, psi0_deg=0.0, duration=60.0, amp_deg=20.0, k=0, s0=None, truth=None, wrap=False):
    """A record of the 3 m model made by the replay itself from ``s0`` (n = 10 rps, a zigzag-like rudder);
    ``truth``: the ship that makes it (default ``ship``); ``wrap``: the heading logged in (-180, 180] deg."""
    t = np.arange(0.0, duration + 1e-9, 0.1)
    delta = np.radians(amp_deg) * np.sign(np.sin(2 * np.pi * t / (30.0 + 5 * k)))
    inp = ReplayInputs(t=t, delta=np.convolve(delta, np.ones(5) / 5, mode="same"), n=np.full_like(t, 10.0))
    s0 = [0.4, 0.0, 0.0, 0.0, 0.0, np.radians(psi0_deg)] if s0 is None else s0
    s = replay(pack(truth or ship), inp, s0)
    if wrap:
        s[:, 5] = np.angle(np.exp(1j * s[:, 5]))
    return MeasuredRun(name=f"rec{k}", source=f"rec{k}", meas=s, inputs=inp)


COV = {"names": ["N_r", "kappa"], "matrix": [[0.004 ** 2, 0.0], [0.0, 0.03 ** 2]]}
SPREAD = {"names": ["start.u", "start.r", "start.psi"], "std": [0.01, 0.003, 0.02]}


def test_band_is_numpys_quantiles_of_draws_replayed_by_hand(ship):
    """The same draws (the documented streams: the ship's from ``seed``, the spread's from ``[seed, 1]``)
    replayed here with the ship's hull changed by hand and the first state offset by hand: the band is
    numpy.quantile(5 %, 95 %) of those headings, the position band the 90 % quantile of the distance from
    their median track."""
    run = _run(ship)
    n, seed = 40, 7
    b = prediction_bands(ship, run, n, seed, covariance=COV, run_spread=SPREAD, jobs=2)
    mean = [ship.hull.value("N_r"), ship.rudder.kappa]
    rows = np.random.default_rng(seed).multivariate_normal(mean, np.asarray(COV["matrix"]), size=n, method="eigh")
    offs = np.random.default_rng([seed, 1]).normal(0.0, 1.0, (n, 3)) * SPREAD["std"]
    heads, xy = [], []
    from dataclasses import replace

    for (nr, kap), (du, dr, dpsi) in zip(rows, offs):
        s = ship.with_hull({"N_r": nr})
        s = replace(s, rudder=replace(s.rudder, kappa=kap))
        s0 = run.meas[0] + np.array([du, 0.0, dr, 0.0, 0.0, dpsi])
        p = replay(pack(s), run.inputs, s0)
        heads.append(np.degrees(p[:, 5]))
        xy.append(p[:, 3:5])
    heads, xy = np.array(heads), np.array(xy)
    np.testing.assert_allclose(b.lo, np.quantile(heads, 0.05, axis=0), atol=1e-9)
    np.testing.assert_allclose(b.hi, np.quantile(heads, 0.95, axis=0), atol=1e-9)
    med = np.median(xy, axis=0)
    np.testing.assert_allclose(b.radius, np.quantile(np.hypot(*(xy - med).transpose(2, 0, 1)), 0.9, axis=0),
                               atol=1e-9)
    assert b.median_width_deg > 0.5 and b.diverged == 0 and b.draws == n
    one = prediction_bands(ship, run, n, seed, covariance=COV, run_spread=SPREAD, jobs=1)
    np.testing.assert_array_equal(one.lo, b.lo)                  # threads change nothing


def test_zero_covariance_and_spread_give_the_nominal_replay(ship):
    run = _run(ship, amp_deg=15.0)
    b = prediction_bands(ship, run, 6, 0, covariance={"names": ["N_r"], "matrix": [[0.0]]},
                         run_spread={"names": ["start.u", "start.psi"], "std": [0.0, 0.0]}, support="none")
    nominal = np.degrees(replay_record(ship, run).pred[:, 5])
    np.testing.assert_allclose(b.lo, nominal, atol=1e-9)
    np.testing.assert_allclose(b.hi, nominal, atol=1e-9)
    assert b.median_width_deg == 0.0 and np.all(b.radius < 1e-9)
    np.testing.assert_allclose(b.x_median, run.meas[:, 3], atol=1e-9)          # the record is the model's own
    assert [n for n in b.notes if not n.startswith("no model-form term")] == []   # nothing else left undrawn


def test_band_on_the_unwrapped_heading_of_a_record_crossing_180_deg(ship):
    """A record logged in (-180, 180] deg that turns through 180 deg: the band follows its unwrapped heading
    (never 360 deg away), and the record, made by this very ship, lies inside it."""
    run = _run(ship, psi0_deg=170.0, amp_deg=25.0, wrap=True)
    psi = np.degrees(run.meas[:, 5])
    assert psi.max() > 170 and psi.min() < -170                  # it does cross
    b = prediction_bands(ship, run, 60, 3, covariance={"names": ["N_r"], "matrix": [[1e-6]]},
                         run_spread={"names": ["start.r", "start.psi"], "std": [0.001, 0.01]})
    np.testing.assert_allclose(b.heading_deg, np.degrees(np.unwrap(run.meas[:, 5])))
    assert np.all(np.abs(b.lo - b.heading_deg) < 10) and np.all(np.abs(b.hi - b.heading_deg) < 10)
    assert b.coverage90 > 0.9
    assert np.abs(np.diff(b.lo)).max() < 5                      # no jump of a turn


def _bands_by_hand(heading, lo, hi, meas_xy, xm, ym, radius):
    n = len(heading)
    t = np.arange(n, dtype=float)
    meas = np.zeros((n, 6))
    meas[:, 3:5] = meas_xy
    run = MeasuredRun("h", "h", meas, ReplayInputs(t=t, delta=np.zeros(n), n=np.ones(n)))
    return Bands(nominal=Replayed(run, meas, 3.0, 0.5), t=t, heading_deg=np.asarray(heading, float),
                 lo=np.asarray(lo, float), hi=np.asarray(hi, float), nominal_deg=np.zeros(n),
                 x_median=np.asarray(xm, float), y_median=np.asarray(ym, float), radius=np.asarray(radius, float),
                 tracks=np.zeros((0, n, 2)), draws=10, diverged=0)


def test_coverage_counted_by_hand():
    """Five samples: inside on the edge, outside above, inside, inside an unbounded band, outside below."""
    b = _bands_by_hand([0.0, 2.0, 2.0, 7.0, -1.0], [0.0, 0.5, 1.0, -np.inf, 0.0], [1.0, 1.5, 3.0, np.inf, 2.0],
                       [[0, 0], [3, 4], [1, 0], [0, 0], [0, 2]], [0, 0, 0, 0, 0], [0, 0, 0, 0, 0],
                       [1.0, 5.0, 0.5, np.inf, 1.0])
    assert b.coverage90 == pytest.approx(3 / 5)
    assert b.position_coverage90 == pytest.approx(3 / 5)         # |(3,4)| = 5 <= 5 in; 1 > 0.5 out; 2 > 1 out
    assert b.median_width_deg == pytest.approx(2.0)               # widths 1, 1, 2, inf, 2: sorted, the third
    assert b.unbounded_share == pytest.approx(1 / 5)
    assert b.coverage90_where_bounded == pytest.approx(2 / 4)    # the unbounded fourth left out
    assert b.to_json()["heading_band_median_width_deg"] == pytest.approx(2.0)


def test_diverged_draws_widen_the_band():
    """NaN (a diverged draw) counts as -inf for the lower and +inf for the upper quantile: a few keep the
    band finite but no narrower than the finite draws', more than 5 % make it unbounded."""
    x = np.random.default_rng(0).normal(size=(200, 3))
    lo, hi = _quantile_bounds(x)
    np.testing.assert_allclose(lo, np.quantile(x, 0.05, axis=0))
    np.testing.assert_allclose(hi, np.quantile(x, 0.95, axis=0))
    few = x.copy()
    few[:4] = np.nan
    lo4, hi4 = _quantile_bounds(few)
    assert np.all(np.isfinite(lo4)) and np.all(np.isfinite(hi4))
    assert np.all(hi4 - lo4 >= np.quantile(x[4:], 0.95, axis=0) - np.quantile(x[4:], 0.05, axis=0))
    many = x.copy()
    many[:15] = np.nan                                           # 7.5 %
    lo15, hi15 = _quantile_bounds(many)
    assert np.all(lo15 == -np.inf) and np.all(hi15 == np.inf)


@pytest.mark.parametrize("case", ["ship and start", "start only"])
def test_calibration_on_records_drawn_from_the_stated_spread(ship, case):
    """Records each made by a ship drawn from the covariance (``"start only"``: the ship itself, a zero
    covariance) and logged from a start state off the true one by a draw of the run spread: the band (of
    the same distributions) holds the records about as often as its 90 % says (their mean coverage
    0.7 to 0.99)."""
    from dataclasses import replace

    rng = np.random.default_rng(11)
    mean = np.array([ship.hull.value("N_r"), ship.rudder.kappa])
    cov = np.asarray(COV["matrix"]) * (case == "ship and start")
    cover = []
    for k in range(16):
        nr, kap = rng.multivariate_normal(mean, cov)
        truth = ship.with_hull({"N_r": nr})
        truth = replace(truth, rudder=replace(truth.rudder, kappa=kap))
        run = _run(ship, duration=40.0, amp_deg=15.0 + k, k=k, s0=[0.4, 0.0, 0.0, 0.0, 0.0, 0.0], truth=truth)
        meas = run.meas.copy()
        meas[0, [0, 2, 5]] += rng.normal(0.0, 1.0, 3) * SPREAD["std"]       # the logged first state's error
        run = MeasuredRun(run.name, run.source, meas, run.inputs)
        b = prediction_bands(ship, run, 60, 100 + k, covariance={"names": COV["names"], "matrix": cov.tolist()},
                             run_spread=SPREAD)
        cover.append(b.coverage90)
    assert 0.7 <= np.mean(cover) <= 0.99, cover


def test_unwrapped_heading_is_put_on_the_first_samples_turn():
    """Headings wrapped into (-pi, pi] two turns off: unwrapped, on the turn of ``first``, in degrees."""
    from trials.measured.bands import _unwrapped_deg

    ramp = np.linspace(3.0, 3.6, 50)                               # through 180 deg
    got = _unwrapped_deg(np.angle(np.exp(1j * (ramp + 4 * np.pi)))[None, :], ramp[0] + 0.01)
    np.testing.assert_allclose(got[0], np.degrees(ramp), atol=1e-9)


# --------------------------------------------------------------------------- the CLI


def _ship_with_sections(tmp_path, covariance=True, spread=True) -> Path:
    from mmg.resources import ship_path

    data = yaml.safe_load(Path(ship_path(SHIP)).read_text())
    s = mmg.load_ship(SHIP)
    if covariance:
        data["covariance"] = {"names": ["N_r", "kappa"], "units": ["1", "1"],
                              "values": [s.hull.value("N_r"), s.rudder.kappa], "matrix": COV["matrix"]}
    if spread:
        data["run_spread"] = {"names": SPREAD["names"], "units": ["m/s", "rad/s", "rad"], "std": SPREAD["std"],
                              "records": 3, "source": "test"}
    p = tmp_path / "ship.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return p


@needs_frt
def test_cli_predict_samples_json_keys_and_plots(tmp_path, capsys):
    rec = _slice(FRT / ZIGZAG, tmp_path / "zz_slice.csv", rows=300)
    js, plots = tmp_path / "p.json", tmp_path / "plots"
    rc, out, err = _run_cli(["predict", "--ship", _ship_with_sections(tmp_path), rec, "--json", js, "--plots", plots,
                             "--samples", "20", "--seed", "3"], capsys)
    assert rc == 0, err
    doc = json.loads(js.read_text(), parse_constant=lambda c: pytest.fail(f"JSON holds {c}"))
    assert list(doc) == ["runs", "bands"]
    assert doc["bands"] == {"samples": 20, "seed": 3, "support": "physical", "model_form": "none in the ship config",
                            "notes": [n for n in doc["bands"]["notes"]
                                      if n.startswith(("no model-form term", "support 'physical' without"))]}
    run = doc["runs"][0]
    assert list(run)[-len(BAND_KEYS):] == ["draws", "diverged_draws", "rejected_draws", "heading_band_deg", "coverage90",
                                           "heading_band_median_width_deg", "heading_band_unbounded_share",
                                           "coverage90_where_bounded",
                                           "position_band_m", "position_coverage90",
                                           "position_band_median_radius_m"]
    assert list(run["heading_band_deg"]) == ["t_s", "lo", "hi"]
    assert list(run["position_band_m"]) == ["t_s", "x_median", "y_median", "radius"]
    assert len(run["heading_band_deg"]["lo"]) == 300 and run["draws"] == 20
    assert all(lo <= hi for lo, hi in zip(run["heading_band_deg"]["lo"], run["heading_band_deg"]["hi"]))
    assert "heading coverage" in out and "median width" in out and "deg" in out
    assert (plots / "zz_slice.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rc, out, err = _run_cli(["predict", "--ship", _ship_with_sections(tmp_path, covariance=False), rec,
                             "--json", js, "--samples", "5"], capsys)
    assert rc == 0, err
    assert "ship not drawn" in out and any("ship not drawn" in n for n in json.loads(js.read_text())["bands"]["notes"])


@pytest.mark.parametrize("bad", [["--samples", "0"], ["--samples", "-3"], ["--samples", "2.5"], ["--seed", "-1"]])
def test_bad_samples_refused_in_one_line(bad, tmp_path, capsys):
    js = tmp_path / "p.json"
    (tmp_path / "r.csv").write_text("x\n")
    _refused(["predict", "--ship", SHIP, tmp_path / "r.csv", "--json", js, *bad], capsys, js,
             contains=(bad[0],))


def test_bad_run_spread_section_refused_naming_the_field(tmp_path):
    from mmg.errors import InputError

    p = _ship_with_sections(tmp_path)
    data = yaml.safe_load(p.read_text())
    data["run_spread"]["std"][1] = -0.1
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(InputError, match="run_spread.std.1"):
        mmg.load_ship(p)
    with pytest.raises(InputError, match="run_spread.names.0"):
        prediction_bands(mmg.load_ship(SHIP), _run(mmg.load_ship(SHIP), duration=5.0), 2,
                         run_spread={"names": ["start.q"], "std": [0.1]})


# --------------------------------------------------------------------------- mmg identify's run_spread


def _ident(ship, runs, free, theta, initial_state="fit", record_nuisance=()):
    """An :class:`~trials.measured.identify.Identification` around a fit made by hand (its parameters and values)."""
    from types import SimpleNamespace

    from trials.measured.identify import Identification

    fit = SimpleNamespace(free=free, theta=np.asarray(theta, float))
    return Identification(ship=ship, initial=ship, fit=fit, runs=runs, segment_s=np.inf,
                          initial_state=initial_state, record_nuisance=record_nuisance)


def test_run_spread_is_the_std_of_the_fitted_per_record_offsets(ship, tmp_path):
    """Three records' fitted start offsets and a per-record heading bias [deg]: each quantity's sample std
    (ddof 1) across the records that have it, the bias in radians; written into ship.yaml and read back."""
    from ekf.identify import FreeParameter, record_effect_parameters, start_parameters
    from trials.measured.identify import run_spread, ship_yaml

    import mmg.effects as E

    runs = [_run(ship, duration=5.0, k=k) for k in range(3)]
    sig = np.full((3, 6), 0.01)
    sig[0, 1] = np.nan                                          # v of the first record not fitted
    free = [FreeParameter("kappa", "kappa", 0, 0.2, 0.1)] + start_parameters(sig, names=[r.name for r in runs])
    free += record_effect_parameters([E.get("heading_bias")], 3, names=[r.name for r in runs])
    rng = np.random.default_rng(5)
    theta = np.concatenate([[0.25], rng.normal(0.0, 0.01, len(free) - 4), [1.0, -2.0, 4.0]])
    sp = run_spread(_ident(ship, runs, free, theta, record_nuisance=("heading_bias",)))
    assert sp["names"] == ["start.u", "start.v", "start.r", "start.psi", "heading_bias.bias_rad"]
    assert sp["units"] == ["m/s", "m/s", "rad/s", "rad", "rad"] and sp["records"] == 3
    by = {f.name: float(v) for f, v in zip(free, theta)}
    for nm, s in zip(("u", "v", "r", "psi"), sp["std"]):
        x = np.array([by[f"start.{nm}[{r.name}]"] for r in runs if f"start.{nm}[{r.name}]" in by])
        assert len(x) == (2 if nm == "v" else 3)
        assert s == pytest.approx(np.sqrt(np.sum((x - x.mean()) ** 2) / (len(x) - 1)), rel=1e-5)
    assert sp["std"][4] == pytest.approx(np.radians(3.0), rel=1e-5)     # 1, -2, 4 deg: std 3 deg
    assert "2 to 3 of the 3 training records" in sp["source"]
    from mmg.resources import ship_path

    (tmp_path / "ship.yaml").write_text(ship_yaml(ship_path(SHIP), {"kappa": 0.25}, "test", spread=sp))
    back = mmg.load_ship(tmp_path / "ship.yaml").run_spread
    assert list(back.names) == sp["names"] and back.std == pytest.approx(sp["std"]) and back.records == 3


def test_run_spread_without_per_record_nuisances_is_the_measured_start_noise(ship):
    """``initial_state="sample"``: no offsets fitted, so the RMS over the records of each channel's noise std."""
    from ekf.identify import FreeParameter
    from trials.measured.identify import run_spread, start_noise

    rng = np.random.default_rng(2)
    runs = []
    for k in range(2):
        r = _run(ship, duration=20.0, k=k)
        runs.append(MeasuredRun(r.name, r.source, r.meas + rng.normal(0.0, 0.003 * (k + 1), r.meas.shape), r.inputs))
    sp = run_spread(_ident(ship, runs, [FreeParameter("kappa", "kappa", 0, 0.2, 0.1)], [0.2], initial_state="sample"))
    noise = np.array([start_noise(r) for r in runs])
    assert sp["names"] == ["start.u", "start.v", "start.r", "start.psi"]
    assert sp["std"] == pytest.approx(np.sqrt(np.mean(noise[:, [0, 1, 2, 5]] ** 2, axis=0)), rel=1e-5)
    assert 0.003 < sp["std"][0] < 0.006                         # the noise added: 0.003 and 0.006
    assert "no per-record nuisance fitted" in sp["source"]


def test_a_band_with_nothing_drawn_is_empty_and_has_no_coverage(ship):
    """A ship with neither covariance: nor run_spread: replays one track N times: the band is empty and its
    JSON coverages are null (not 0 %: the record is not outside a band, there is none); one parameter drawn
    makes a band."""
    run = _run(ship, amp_deg=15.0)
    assert ship.covariance is None and ship.run_spread is None
    b = prediction_bands(ship, run, 4, 0)
    assert b.empty and b.median_width_deg == 0.0
    js = b.to_json()
    assert js["coverage90"] is None and js["position_coverage90"] is None and js["coverage90_where_bounded"] is None
    drawn = prediction_bands(ship, run, 4, 0, covariance=COV)
    assert not drawn.empty and drawn.to_json()["coverage90"] == drawn.coverage90


@needs_frt
def test_cli_predict_says_no_band_when_nothing_is_drawn(tmp_path, capsys):
    rec = _slice(FRT / ZIGZAG, tmp_path / "zz_slice.csv", rows=300)
    js, plots = tmp_path / "p.json", tmp_path / "plots"
    rc, out, err = _run_cli(["predict", "--ship", SHIP, rec, "--json", js, "--plots", plots, "--samples", "5"], capsys)
    assert rc == 0, err
    assert "no band" in out and "heading coverage" not in out and "median width" not in out
    assert json.loads(js.read_text())["runs"][0]["coverage90"] is None


def test_band_from_an_unfinished_identification_says_so(tmp_path):
    """A ship whose identification: section says the fit did not converge: its band is drawn from a covariance
    about no optimum, and the notes say so; a converged one has no such note."""
    import dataclasses

    from mmg.ship import IdentificationNotes

    ship = mmg.load_ship(str(_ship_with_sections(tmp_path, spread=False)))
    run = _run(ship, amp_deg=15.0)
    unfinished = dataclasses.replace(ship, identification=IdentificationNotes(converged=False))
    assert any("did not converge" in n for n in prediction_bands(unfinished, run, 3, 0).notes)
    finished = dataclasses.replace(ship, identification=IdentificationNotes(converged=True))
    assert not any("identification" in n for n in prediction_bands(finished, run, 3, 0).notes)
