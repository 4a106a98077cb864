"""Nested cross-validation: the kept-out records never reach a fit or a choice of their fold,
the hull form is chosen by held-out prediction, a non-finite replay is a divergence with its time and
state, and ``mmg identify --hull`` refuses what it cannot do in one line."""
from __future__ import annotations

import re
from dataclasses import replace

import numpy as np
import pytest

import mmg
from mmg.model import pack
from mmg.replay import ReplayInputs, replay
from trials.measured import nested as N
from trials.measured.identify import Identification
from trials.measured.predict import MeasuredRun, replay_record


def _runs(ship, n=8, seconds=20.0):
    """Records made by ``ship`` itself (no noise): zigzag-like rudders of different amplitudes and
    periods, from a moving start; the last one a cut copy (the first half) of record 2."""
    pk = pack(ship)
    t = np.arange(0.0, seconds + 1e-9, 0.1)
    out = []
    for k in range(n):
        amp, per = np.radians(10.0 + 3 * k), 8.0 + k
        delta = amp * np.sign(np.sin(2 * np.pi * t / per + 0.3 * k))
        inp = ReplayInputs(t=t, delta=delta, n=np.full_like(t, 10.0))
        out.append(MeasuredRun(name=f"r{k}", source=f"r{k}", meas=replay(pk, inp, [0.4, 0, 0, float(k), 0, 0.1 * k]), inputs=inp))
    if n < 3:
        return out
    r2 = out[2]
    h = len(t) // 2
    out.append(MeasuredRun(name="r2_cut", source="r2_cut", meas=r2.meas[:h].copy(),
                           inputs=ReplayInputs(t=t[:h], delta=r2.inputs.delta[:h], n=r2.inputs.n[:h])))
    return out


class _FakeFit:
    def values(self):
        return {}


class _Watch:
    """A stand-in for the fit: records the names of the records each call trains on and of those replayed
    with each model it returns; the model it returns is the prior unchanged (so the candidate whose form
    made the records predicts them exactly)."""

    def __init__(self):
        self.fits, self.replayed = [], []

    def __call__(self, ship, runs, **kw):
        self.fits.append(sorted(r.name for r in runs))
        seen = []
        self.replayed.append(seen)
        watch = self

        class Ident(Identification):
            def replay(self, run, model="identified"):
                seen.append(run.name)
                return super().replay(run, model)

        del watch
        return Ident(ship=ship, initial=kw.get("initial") or ship, fit=_FakeFit(), runs=list(runs), segment_s=np.inf)


@pytest.fixture(scope="module")
def forms():
    return N.hull_candidates("esso_osaka_3m")


def test_kept_out_records_reach_no_fit_and_no_choice_of_their_fold(monkeypatch, forms):
    truth = forms["crossflow"].ship
    runs = _runs(truth)
    watch = _Watch()
    monkeypatch.setattr(N, "fit_model", watch)
    res = N.nested_cross_validate(forms, runs, folds=4, inner_folds=2, initial=forms["kijima"].ship)
    # outer folds worked out here, not by the code: 8 independent runs dealt in order, the cut with its run
    test = [{f"r{i}" for i in range(8) if i % 4 == k} for k in range(4)]
    test[2].add("r2_cut")
    names = {r.name for r in runs}
    train = [names - t for t in test]
    n_inner = 4 * 2 * 2                                   # outer folds x inner folds x candidates, in that order
    assert len(watch.fits) == n_inner + 4
    for i in range(n_inner):
        k = i // 4
        fitted, replayed = set(watch.fits[i]), set(watch.replayed[i])
        assert fitted < train[k] and not fitted & test[k]               # an inner fit: training records only
        assert replayed <= train[k] - fitted and replayed                # inner kept-out: training records too
    for k in range(4):
        assert set(watch.fits[n_inner + k]) == train[k]                  # the final fit: the whole training set
        assert set(watch.replayed[n_inner + k]) == test[k]               # only it replays the kept-out records
    assert {r["name"] for r in res.records} == names
    assert [f["choice"] for f in res.folds] == ["crossflow"] * 4      # the form that made the records
    for f in res.folds:
        assert f["inner"]["crossflow"]["mean_heading_rms_deg"] < 1e-9 < f["inner"]["kijima"]["mean_heading_rms_deg"]
        assert set(f["test"]) == test[f["fold"]]


def test_the_choice_ignores_what_the_kept_out_records_say(monkeypatch, forms):
    """Spoil fold 0's kept-out records (their measured headings turned by 90 deg after the first sample, the
    replay's start): fold 0's choice and inner figures stay as they were; the other folds, which train on
    those records, see them; fold 0's kept-out scores change."""
    runs = _runs(forms["kijima"].ship, n=6)[:6]
    monkeypatch.setattr(N, "fit_model", _Watch())
    a = N.nested_cross_validate(forms, runs, folds=3, inner_folds=2)
    turn = lambda m: np.vstack([m[:1], m[1:] + [0, 0, 0, 0, 0, np.pi / 2]])     # noqa: E731
    spoiled = [replace(r, meas=turn(r.meas)) if i % 3 == 0 else r for i, r in enumerate(runs)]
    b = N.nested_cross_validate(forms, spoiled, folds=3, inner_folds=2)
    assert [f["choice"] for f in a.folds] == [f["choice"] for f in b.folds] == ["kijima"] * 3
    for fa, fb in zip(a.folds[1:], b.folds[1:]):
        assert fa["inner"] != fb["inner"]           # folds 1, 2 train on the spoiled records: their inner CV sees them
    assert a.folds[0]["inner"] == b.folds[0]["inner"]
    ha = {r["name"]: r["identified"]["heading_rms_deg"] for r in a.records}
    hb = {r["name"]: r["identified"]["heading_rms_deg"] for r in b.records}
    n = len(runs[0].t)
    assert hb["r0"] == pytest.approx(90.0 * np.sqrt((n - 1) / n), rel=1e-9) and ha["r0"] == pytest.approx(0.0, abs=1e-9)


def _diverging(ship, t_bad=3.0):
    """A real replay forced non-finite: the propeller revolutions become NaN from ``t_bad``."""
    run = _runs(ship, n=1, seconds=10.0)[0]
    n = run.inputs.n.copy()
    n[run.t >= t_bad] = np.nan
    return replay_record(ship, replace(run, inputs=replace(run.inputs, n=n)))


def test_a_non_finite_replay_is_a_divergence_with_its_time_and_state(forms):
    ship = forms["kijima"].ship
    rep = _diverging(ship, 3.0)
    d = rep.divergence
    assert d is not None and rep.diverged_at == d["t_s"]
    i = int(np.argmax(~np.isfinite(rep.pred).all(axis=1)))
    assert 3.0 - 1e-9 <= d["t_s"] == rep.run.t[i] and d["last_t_s"] == rep.run.t[i - 1]
    assert d["last_state"] == {c: rep.pred[i - 1, j] for j, c in enumerate(("u", "v", "r", "x", "y", "psi"))}
    assert np.isfinite(list(d["last_state"].values())).all()
    s = N.replay_scores(rep, horizon_s=2.0)
    assert np.isnan(s["heading_rms_deg"]) and s["divergence"] is d
    assert np.isfinite(s["heading_rms_deg_2s"])                  # a window before the divergence is scored
    m, p = rep.run.meas[rep.run.t <= 2.0 + 1e-9], rep.pred[rep.run.t <= 2.0 + 1e-9]
    assert s["heading_rms_deg_2s"] == pytest.approx(np.degrees(np.sqrt(np.mean((p[:, 5] - m[:, 5]) ** 2))))
    fine = replay_record(ship, _runs(ship, n=1, seconds=10.0)[0])
    assert fine.divergence is None and N.replay_scores(fine)["divergence"] is None


def test_a_diverged_kept_out_replay_is_listed_not_better_and_out_of_the_means(forms):
    ship = forms["kijima"].ship
    bad = N.replay_scores(_diverging(ship, 3.0))
    h = lambda x: {"heading_rms_deg": x, "divergence": None}        # noqa: E731
    res = N.NestedCV(records=[{"name": "a", "fold": 0, "choice": "kijima", "scaled": h(10.0), "identified": h(2.0)},
                              {"name": "b", "fold": 1, "choice": "kijima", "scaled": h(6.0), "identified": h(4.0)},
                              {"name": "c", "fold": 1, "choice": "kijima", "scaled": h(9.0), "identified": bad}],
                     folds=[], inner=[], candidates=["kijima"])
    s = res.summary()
    assert (s["mean_scaled"], s["mean_identified"], s["ratio"]) == (8.0, 3.0, 8.0 / 3.0)
    assert s["better"] == 2 and s["n"] == 3 and s["n_both_finite"] == 2
    assert [(n, who) for n, who, _ in s["diverged"]] == [("c", "identified")]
    assert s["diverged"][0][2]["t_s"] >= 3.0
    js = res.to_json()
    assert js["records"][2]["identified"]["divergence"]["t_s"] == s["diverged"][0][2]["t_s"]
    assert js["records"][2]["identified"]["heading_rms_deg"] is None      # NaN as null, beside its divergence


def test_choose_prefers_fewer_divergences_then_the_lower_mean():
    d = {"t_s": 1.0}
    rows = ([{"candidate": "a", "heading_rms_deg": 1.0, "divergence": None},
             {"candidate": "a", "heading_rms_deg": float("nan"), "divergence": d}]
            + [{"candidate": "b", "heading_rms_deg": x, "divergence": None} for x in (5.0, 7.0)])
    best, table = N.choose(rows, ["a", "b"])
    assert best == "b" and table["a"] == {"n": 2, "diverged": 1, "mean_heading_rms_deg": 1.0}
    assert table["b"]["mean_heading_rms_deg"] == 6.0
    assert N.choose(rows[2:] + [{"candidate": "a", "heading_rms_deg": 5.5, "divergence": None}], ["a", "b"])[0] == "a"


def test_hull_candidates_name_both_forms_and_refuse_a_ship_without_one():
    from mmg.errors import InputError

    c = N.hull_candidates("esso_osaka_3m_crossflow")             # either form's name gives both
    assert [x.ship.name for x in c.values()] == [mmg.load_ship("esso_osaka_3m").name,
                                                 mmg.load_ship("esso_osaka_3m_crossflow").name]
    with pytest.raises(InputError, match="--hull"):
        N.hull_candidates("kvlcc2_l7")
    assert list(N.hull_candidates("kvlcc2_l7", ("kijima",))) == ["kijima"]


# ----------------------------------------------------------------------------- mmg identify --hull
from .conftest import FRT, needs_frt  # noqa: E402


def _slice(src, dst, seconds):
    lines = src.read_text().splitlines()
    keep = [lines[0]] + [ln for ln in lines[1:] if ln.strip() and float(ln.split(",")[0]) <= seconds]
    dst.write_text("\n".join(keep) + "\n")
    return dst


def _one_error(capsys):
    err = capsys.readouterr().err
    return [ln for ln in err.strip().splitlines() if ln.startswith("error")], err


@needs_frt()
@pytest.mark.parametrize("extra, words", [
    (["--hull", "auto", "--ship", "kvlcc2_l7"], ["--hull", "crossflow", "kvlcc2_l7_crossflow"]),
    (["--ship", "esso_osaka_3m", "--inner-folds", "3"], ["--inner-folds", "needs --hull auto"]),
    (["--ship", "esso_osaka_3m", "--hull", "kijima", "--inner-folds", "2"], ["--inner-folds", "nothing to choose"]),
])
def test_hull_option_refusals_are_one_line_before_any_record_is_read(tmp_path, capsys, extra, words):
    from trials.cli import main

    out = tmp_path / "out"
    rc = main(["identify", "--train", str(FRT / "zigzag" / "zigzag_31-Jul-2020_13_04_24.csv"), "--out", str(out), *extra])
    errs, err = _one_error(capsys)
    assert rc == 2 and not out.exists() and len(errs) == 1, err
    assert all(w in errs[0] for w in words), errs[0]
    assert "training on" not in err                   # refused before the records were read


def test_hull_option_parsing():
    import argparse

    from trials.cli.identify import add_parser

    ap = argparse.ArgumentParser()
    add_parser(ap.add_subparsers())
    base = ["identify", "--ship", "esso_osaka_3m", "--train", "a.csv", "--out", "o"]
    a = ap.parse_args(base + ["--hull", "auto", "--inner-folds", "2"])
    assert (a.hull, a.inner_folds) == ("auto", 2)
    assert ap.parse_args(base).hull is None and ap.parse_args(base).inner_folds is None
    for bad in (["--hull", "polynomial"], ["--hull", "auto", "--inner-folds", "1"]):
        with pytest.raises(SystemExit) as e:
            ap.parse_args(base + bad)
        assert e.value.code == 2


@needs_frt()
def test_hull_auto_reports_the_choice_and_with_cv_each_folds(tmp_path, capsys, monkeypatch):
    """--hull auto --cv 2 over three 30 s slices: the inner fits replaced by the prior itself (the choice
    then rests on the two forms' own predictions), the final fit real but short; stdout names the form
    and each fold's choice, nested_cv.json holds them, the report the kept-out records."""
    import json

    from trials.cli import main

    monkeypatch.setattr(N, "fit_model", _Watch())
    src = [FRT / "zigzag" / "zigzag_31-Jul-2020_13_04_24.csv", FRT / "zigzag" / "zigzag_31-Jul-2020_13_14_21.csv",
           FRT / "turning" / "turn_14-Sep-2020_13_51_45.csv"]
    logs = [_slice(p, tmp_path / f"{k}.csv", 30.0) for k, p in enumerate(src)]
    out = tmp_path / "out"
    args = ["identify", "--ship", "esso_osaka_3m", "--out", str(out), "--hull", "auto", "--cv", "2", "--inner-folds", "2",
            "--max-nfev", "1", "--backend", "serial", "--train"]
    assert main(args + [str(x) for x in logs[:3]]) == 2 and not out.exists()     # a training set of one: no choice
    errs, err = _one_error(capsys)
    assert errs == ["error: --hull: auto: no choice can be made on outer fold 0's training set: the inner cross-validation "
                    "needs 2 or more independent records, got 1 (a record and its cut copies count once)"], err
    assert "iteration" not in err and "[1/" not in err
    logs.append(_slice(FRT / "turning" / "turn_14-Oct-2020_14_08_51.csv", tmp_path / "3.csv", 30.0))
    rc = main(args + [str(x) for x in logs])
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    form = [ln for ln in cap.out.splitlines() if ln.startswith("hull form: ")]
    assert len(form) == 1 and form[0].split()[2] in ("kijima", "crossflow")
    res = json.loads((out / "nested_cv.json").read_text())
    assert [f["fold"] for f in res["folds"]] == [0, 1] and {r["name"] for r in res["records"]} == {"0", "1", "2", "3"}
    for f in res["folds"]:
        assert re.search(rf"^fold {f['fold']}: chose {f['choice']} \(kijima [\d.]+ deg, \d diverged; crossflow", cap.out, re.M)
        assert not set(f["test"]) & set(f["train"])
    assert "## Cross-validation (2 folds" in (out / "report.md").read_text()


@needs_frt()
@pytest.mark.slow
def test_bench_prints_every_kept_out_record_the_choices_and_the_summary(tmp_path):
    """bench/identify_cv.py end to end on the five berthing records (two outer folds, two inner, fits cut
    short): one row per record, each fold's choice, the summary lines, the JSON with the same records."""
    import json
    import subprocess
    import sys

    from .conftest import REPO

    js = tmp_path / "cv.json"
    p = subprocess.run([sys.executable, str(REPO / "bench" / "identify_cv.py"), "--records", "berthing", "--folds", "2",
                        "--inner-folds", "2", "--max-nfev", "2", "--backend", "serial", "--markdown", "--json", str(js)],
                       capture_output=True, text=True, cwd=REPO, timeout=600)
    assert p.returncode == 0, p.stderr
    names = sorted(x.stem for x in (FRT / "berthing").glob("*.csv"))
    rows = re.findall(r"^\| (berthing_\S+) \| ([01]) \| (kijima|crossflow) \|", p.stdout, re.M)
    assert sorted(r[0] for r in rows) == names
    for k in (0, 1):
        assert re.search(rf"^- fold {k}: (kijima|crossflow) \(", p.stdout, re.M)
    assert re.search(r"^- whole record: mean heading RMS scaled [\d.]+ deg, identified [\d.]+ deg, ratio", p.stdout, re.M)
    assert re.search(r"^- first 60 s: mean heading RMS \[deg\]", p.stdout, re.M)
    assert re.search(r"^- divergences: \d+", p.stdout, re.M)
    res = json.loads(js.read_text())
    assert sorted(r["name"] for r in res["records"]) == names
    assert {(r["name"], str(r["fold"]), r["choice"]) for r in res["records"]} == set(rows)


def test_the_band_spec_reaches_every_kept_out_records_band_and_none_by_default(monkeypatch, forms):
    """``bands=BandSpec(7, "bounds")``: each kept-out record's band from 7 draws truncated to the fit's bounds,
    seeded by its outer fold; the default asks for none."""
    runs = _runs(forms["kijima"].ship, n=4)[:4]
    calls = []
    monkeypatch.setattr(N, "fit_model", _Watch())
    monkeypatch.setattr(N, "band_sections", lambda ident: (None, None))
    specs = []
    monkeypatch.setattr(N, "band_ship", lambda ident, spec, initial=None, kw=None: specs.append(spec) or "with its term")
    monkeypatch.setattr(N, "band_scores", lambda ident, run, samples, seed=0, sections=None, support="none", ship=None:
                        calls.append((run.name, samples, seed, support, ship)) or {"samples": 1})
    one = {"kijima": forms["kijima"]}
    N.nested_cross_validate(one, runs, folds=2)
    assert calls == [] and specs == []
    res = N.nested_cross_validate(one, runs, folds=2, inner_folds=2, folds_by="manoeuvre",
                                  bands=N.BandSpec(samples=7, support="bounds", model_form="kept-out"))
    assert sorted(calls) == sorted((r["name"], 7, r["fold"], "bounds", "with its term") for r in res.records)
    assert len(calls) == 4 and all(r["band"] == {"samples": 1} for r in res.records)
    assert [(s.model_form, s.folds, s.folds_by) for s in specs] == [("kept-out", 2, "manoeuvre")] * 2
    specs.clear()
    N.nested_cross_validate(one, runs, folds=2, inner_folds=2, folds_by="manoeuvre",
                            bands=N.BandSpec(samples=7, model_form="kept-out", folds=4, folds_by="order"))
    assert [(s.folds, s.folds_by) for s in specs] == [(4, "order")] * 2          # its own, where it says them


@pytest.mark.parametrize("bad", [dict(samples=-1), dict(samples=2.5), dict(support="energy"), dict(model_form="cv")])
def test_a_band_spec_outside_its_range_is_refused(bad):
    with pytest.raises(ValueError, match="BandSpec"):
        N.BandSpec(**bad)


class _WindFit:
    def values(self):
        return {"wind_scale": 0.5}


def test_a_kept_out_records_band_varies_about_the_identified_replay(monkeypatch, forms):
    """The band of a kept-out record is drawn about the record as the fold's fit replays it: its wind loads
    (made with the initial ship's wind section) times the fitted wind scale, so that the band's nominal
    replay is the replay its score is made of."""
    from types import SimpleNamespace

    import trials.measured.bands as B

    ship = forms["kijima"].ship
    runs = []
    for r in _runs(ship, n=4)[:4]:
        ext = np.tile([100.0, 50.0, 1e3], (len(r.inputs.t), 1))
        runs.append(replace(r, inputs=replace(r.inputs, ext=ext)))
    idents, seen = [], {}

    def fit(ship, train, **kw):
        idents.append(Identification(ship=ship, initial=kw.get("initial") or ship, fit=_WindFit(),
                                     runs=list(train), segment_s=np.inf))
        return idents[-1]

    def bands(ship, run, samples, seed=0, **kw):
        seen[run.name] = (ship, run)
        t = run.t
        return SimpleNamespace(t=t, unbounded_share=0.0, coverage90_where_bounded=1.0, coverage90=1.0,
                               median_width_deg=1.0, draws=samples, diverged=0, rejected=0,
                               position_coverage90=1.0, median_radius_m=1.0)

    monkeypatch.setattr(N, "fit_model", fit)
    monkeypatch.setattr(N, "band_sections", lambda ident: (None, None))
    monkeypatch.setattr(N, "band_ship", lambda ident, spec, initial=None, kw=None: ident.ship)
    monkeypatch.setattr(B, "prediction_bands", bands)
    N.nested_cross_validate({"kijima": forms["kijima"]}, runs, folds=2, bands=N.BandSpec(samples=3))
    assert sorted(seen) == sorted(r.name for r in runs)
    for r in runs:
        band_ship, band_run = seen[r.name]
        np.testing.assert_allclose(band_run.inputs.ext, 0.5 * r.inputs.ext)
        np.testing.assert_array_equal(replay_record(band_ship, band_run).pred, idents[0].replay(r).pred)
