"""mmg identify end to end on slices of real records: DIR/ship.yaml is a ship config every command
takes (mmg simulate through a trial file naming it, mmg predict), and mmg predict with it gives
the report's numbers."""
from __future__ import annotations

import contextlib
import io
import json
import re

import pytest

from trials.cli import main

from .conftest import FRT, needs_frt

pytestmark = needs_frt()


def _slice(src, dst, seconds):
    lines = src.read_text().splitlines()
    keep = [lines[0]] + [ln for ln in lines[1:] if ln.strip() and float(ln.split(",")[0]) <= seconds]
    dst.write_text("\n".join(keep) + "\n")
    return dst


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    d = tmp_path_factory.mktemp("ident")
    a = _slice(FRT / "zigzag" / "zigzag_31-Jul-2020_13_14_21.csv", d / "zz.csv", 90.0)
    b = _slice(FRT / "turning" / "turn_14-Sep-2020_13_51_45.csv", d / "turn.csv", 90.0)
    out = d / "out"
    console = io.StringIO()
    with contextlib.redirect_stdout(console):
        assert main(["identify", "--ship", "esso_osaka_3m", "--train", str(a), str(b), "--out", str(out),
                     "--wind", "on"]) == 0
    (d / "console.txt").write_text(console.getvalue())
    return d, out, (a, b)


def test_console_and_report_count_the_fitted_parameters_alike(identified):
    d, out, _ = identified
    console = re.search(r"^identified (.+?) over \d+ records", (d / "console.txt").read_text(), re.M)
    report = re.search(r"fitted: (.+?); residuals", (out / "report.md").read_text())
    assert console and report and console.group(1) == report.group(1)
    m = re.fullmatch(r"(\d+) model parameters and (\d+) start-state offsets \((\d+) in all\)", report.group(1))
    assert m and int(m.group(1)) + int(m.group(2)) == int(m.group(3))
    assert int(m.group(2)) > 0 and int(m.group(2)) % 2 == 0    # the same start states of each of the two records


def test_report_and_ship_written(identified):
    _, out, _ = identified
    assert sorted(p.name for p in out.iterdir()) == ["report.md", "ship.yaml"]
    rep = (out / "report.md").read_text()
    for section in ("Values and standard errors", "Correlations", "Training fits", "Manoeuvre metrics"):
        assert section in rep


def test_predict_with_the_identified_ship_gives_the_reports_numbers(identified, tmp_path):
    d, out, logs = identified
    js = tmp_path / "p.json"
    assert main(["predict", "--ship", str(out / "ship.yaml"), *map(str, logs), "--json", str(js), "--wind", "on"]) == 0
    runs = json.loads(js.read_text())["runs"]
    rep = (out / "report.md").read_text()
    for r, log in zip(runs, logs):
        row = re.search(rf"^\| {log.stem} \| ([0-9.]+) \| ([0-9.]+) \|", rep, re.M)
        assert row, log.stem
        assert f"{r['heading_rms_deg']:.2f}" == row.group(2)          # identified model's heading RMS


def test_simulate_accepts_the_identified_ship(identified, tmp_path):
    _, out, _ = identified
    trial = tmp_path / "turn.yaml"
    trial.write_text(f"name: T35\nship: {out / 'ship.yaml'}\napproach: {{speed: 0.9 kn, rpm: solve}}\n"
                     "duration: 60 s\ndt: 0.1 s\nmanoeuvre: {kind: turning, rudder: 35 deg}\n")
    assert main(["simulate", str(trial), "--out", str(tmp_path / "sim")]) == 0
    m = json.loads((tmp_path / "sim" / "metrics.json").read_text())
    assert m["ship"].endswith("(identified)")


def test_unknown_free_name_is_one_line_and_nothing_written(tmp_path, capsys):
    out = tmp_path / "out"
    rc = main(["identify", "--ship", "esso_osaka_3m", "--train", str(FRT / "zigzag" / "zigzag_31-Jul-2020_13_04_24.csv"),
               "--out", str(out), "--free", "N_r", "Y_vv_typo"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and not out.exists()
    assert len(err) == 1 and "--free" in err[0] and "Y_vv_typo" in err[0] and "rudder_offset" in err[0]


def _errors(err):
    return [ln for ln in err.strip().splitlines() if ln.startswith("error")]


def test_cv_with_one_independent_run_is_refused_before_any_fit(tmp_path, capsys):
    """--cv over one record, or over a record and its own cut (one run: a kept-out copy would be in its
    own training set), is refused in one line, exit 2, before any iteration, nothing written."""
    d = tmp_path
    whole = _slice(FRT / "turning" / "turn_14-Sep-2020_13_51_45.csv", d / "turn.csv", 60.0)
    cut = _slice(whole, d / "turn_cut.csv", 30.0)
    for train in ([whole], [whole, cut]):
        out = d / "out"
        rc = main(["identify", "--ship", "esso_osaka_3m", "--train", *map(str, train), "--out", str(out), "--cv", "4"])
        err = capsys.readouterr().err
        assert rc == 2 and not out.exists()
        assert _errors(err) == ["error: --cv: cross-validation needs 2 or more independent records, got 1 "
                                "(a record and its cut copies count once)"]
        assert "iteration" not in err


def test_cv_narrowed_to_the_independent_runs(tmp_path, capsys):
    """--cv 4 over two runs uses two folds (each record kept out once, said in a note), not four fits
    of which two keep nothing out."""
    from trials.measured.identify import cv_folds, load_runs

    import mmg

    a = _slice(FRT / "zigzag" / "zigzag_31-Jul-2020_13_14_21.csv", tmp_path / "zz.csv", 40.0)
    b = _slice(FRT / "turning" / "turn_14-Sep-2020_13_51_45.csv", tmp_path / "turn.csv", 40.0)
    runs = load_runs(mmg.load_ship("esso_osaka_3m"), [a, b])
    assert cv_folds(runs, 4) == 2 and cv_folds(runs, 2) == 2 and cv_folds(runs + runs[:1], 4) == 2
    out = tmp_path / "out"
    rc = main(["identify", "--ship", "esso_osaka_3m", "--train", str(a), str(b), "--out", str(out), "--cv", "4"])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "note: --cv 4: 2 independent records, so 2 folds (each kept out once)" in err
    assert sorted(re.findall(r"cross-validation fold (\d)/(\d)", err)) == [("1", "2"), ("2", "2")]
    report = (out / "report.md").read_text()
    assert "## Cross-validation (2 folds, each record kept out once)" in report
    # the report's Warnings items and the one stderr line pointing to them agree, each item naming a
    # parameter of the values table or the fit's stop
    table = set(re.findall(r"^\| (\w+) \| [-\d.e+]+ \| [-\d.e+]+ \|", report, flags=re.M))
    items = re.findall(r"^- (.+)$", report.split("## Warnings", 1)[1].split("\n## ", 1)[0], flags=re.M) \
        if "## Warnings" in report else []
    said = re.findall(r"^warning: (\d+) finding\(s\) on where the identified values", err, flags=re.M)
    assert said == ([str(len(items))] if items else [])
    assert all(it.split()[0] in table or it.startswith(("stage ", "training record ", "physical check: "))
               for it in items)
    assert re.search(r"\| zz \| 0 \|", report) and re.search(r"\| turn \| 1 \|", report)


def test_an_unusable_test_record_is_refused_before_the_fit(tmp_path, capsys):
    """--test with no usable record stops before the fit, exit 2, nothing written; one line, which says
    why the record was skipped."""
    bad = tmp_path / "empty.csv"
    bad.write_text((FRT / "zigzag" / "zigzag_31-Jul-2020_13_04_24.csv").read_text().splitlines()[0] + "\n")
    out = tmp_path / "out"
    rc = main(["identify", "--ship", "esso_osaka_3m", "--train", str(FRT / "zigzag" / "zigzag_31-Jul-2020_13_04_24.csv"),
               "--test", str(bad), "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and not out.exists() and "iteration" not in err
    assert err.strip().splitlines() == [f"error: --test: no usable record (skipped: {bad}: no data rows after the header)"]



@pytest.mark.parametrize("bad", ["0", "-1", "nan", "inf", "ten"])
def test_a_bad_velocity_weight_is_one_line_and_nothing_written(tmp_path, capsys, bad):
    out = tmp_path / "out"
    rc = main(["identify", "--ship", "esso_osaka_3m", "--train", str(FRT / "zigzag" / "zigzag_31-Jul-2020_13_04_24.csv"),
               "--out", str(out), "--velocity-weight", bad])
    err = _errors(capsys.readouterr().err)
    assert rc == 2 and not out.exists()
    assert len(err) == 1 and "--velocity-weight" in err[0] and "positive finite" in err[0]


def test_velocity_weight_reaches_the_fit_and_the_report(identified, tmp_path):
    """--velocity-weight is passed to the fit (another result than the default's) and the report says it."""
    d, out, (a, b) = identified
    out2 = tmp_path / "vw"
    assert main(["identify", "--ship", "esso_osaka_3m", "--train", str(a), str(b), "--out", str(out2),
                 "--wind", "on", "--velocity-weight", "0.1"]) == 0
    rep, rep0 = (out2 / "report.md").read_text(), (out / "report.md").read_text()
    assert "velocity residuals weighted 0.1 beside the heading's" in rep
    assert "velocity residuals weighted 1 beside the heading's" in rep0
    import mmg

    h2, h0 = mmg.load_ship(out2 / "ship.yaml").hull, mmg.load_ship(out / "ship.yaml").hull
    assert any(abs(h2.value(n) - h0.value(n)) > 1e-6 * (1 + abs(h0.value(n))) for n in h0.names)


def test_max_nfev_stages_labelled_and_explained(tmp_path, capsys):
    """The fit's evaluation limit is an option (--max-nfev, reaching each stage); the progress
    names each stage (its iterations labelled by it: the second series is another cost, not a restart);
    the report says what each stage fitted in words (no "segment length inf s") and how it stopped."""
    a = _slice(FRT / "zigzag" / "zigzag_31-Jul-2020_13_14_21.csv", tmp_path / "zz.csv", 40.0)
    b = _slice(FRT / "turning" / "turn_14-Sep-2020_13_51_45.csv", tmp_path / "turn.csv", 40.0)
    out = tmp_path / "out"
    rc = main(["identify", "--ship", "esso_osaka_3m", "--train", str(a), str(b), "--out", str(out),
               "--free", "N_r", "Y_beta", "--max-nfev", "2"])
    err = capsys.readouterr().err
    assert rc == 0, err
    heads = [ln for ln in err.splitlines() if ln.startswith("stage ")]
    assert len(heads) == 2, err
    assert heads[0].startswith("stage 1/2: segment-wise fit: ") and heads[0].endswith("at most 2 evaluations")
    assert heads[1].startswith("stage 2/2: whole-record fit: ") and "not cut" in heads[1]
    its = re.findall(r"^  (stage \d/\d), iteration (\d+): cost", err, flags=re.M)
    assert its and {s for s, _ in its} == {"stage 1/2", "stage 2/2"} and all(int(k) <= 2 for _, k in its)
    assert not re.search(r"^  iteration", err, flags=re.M)             # no unlabelled series
    rep = (out / "report.md").read_text()
    assert "inf s" not in rep and "segment length" not in rep
    assert re.search(r"^1\. segment-wise fit: [\d.]+ s segments, each restarted from the measured state; \d+ "
                     r"evaluations of at most 2", rep, flags=re.M), rep
    assert re.search(r"^2\. whole-record fit: each record replayed open-loop from its first sample \(not cut into "
                     r"segments\); \d+ evaluations of at most 2", rep, flags=re.M), rep
    stopped = re.findall(r"^note: (.+) stopped at its evaluation limit \(2\)", err, flags=re.M)
    assert stopped == re.findall(r"^\d\. ([\w-]+ fit): .*stopped at its evaluation limit", rep, flags=re.M)
    # the limit reaches the fit (the library's stages record it) and more evaluations are allowed
    from trials.measured.identify import identify, load_runs

    import mmg

    ship = mmg.load_ship("esso_osaka_3m")
    ident = identify(ship, load_runs(ship, [a, b]), free=["N_r", "Y_beta"], max_nfev=3, say=lambda m: None)
    assert [s["max_nfev"] for s in ident.stages] == [3, 3] and all(s["evaluations"] <= 3 for s in ident.stages)
    assert ident.stages[0]["segment_s"] < float("inf") == ident.stages[1]["segment_s"]


def test_records_named_after_their_files_in_the_report(tmp_path, capsys):
    """Two records of one stem (two days' zz.csv) are two rows of the report, told apart by their folders
    (a test record of that stem too)."""
    from trials.measured.identify import load_runs

    import mmg

    (tmp_path / "day1").mkdir()
    (tmp_path / "day2").mkdir()
    a = _slice(FRT / "zigzag" / "zigzag_31-Jul-2020_13_14_21.csv", tmp_path / "day1" / "zz.csv", 40.0)
    b = _slice(FRT / "zigzag" / "zigzag_31-Jul-2020_13_22_52.csv", tmp_path / "day2" / "zz.csv", 40.0)
    assert [r.name for r in load_runs(mmg.load_ship("esso_osaka_3m"), [a, b])] == ["day1/zz", "day2/zz"]
    (tmp_path / "day3").mkdir()                 # a test record of the same stem: named with the training ones
    c = _slice(FRT / "zigzag" / "zigzag_31-Jul-2020_13_29_19.csv", tmp_path / "day3" / "zz.csv", 40.0)
    out = tmp_path / "out"
    assert main(["identify", "--ship", "esso_osaka_3m", "--train", str(a), str(b), "--test", str(c), "--out", str(out),
                 "--free", "N_r", "--max-nfev", "2"]) == 0
    rep = (out / "report.md").read_text()
    for name in ("day1/zz", "day2/zz", "day3/zz"):
        assert re.search(rf"^\| {name} \| [\d.]+ \| [\d.]+ \|", rep, flags=re.M), rep


def test_cv_folds_on_dask_give_the_serial_numbers(tmp_path):
    """The folds of --cv are independent fits: on a dask cluster (--backend dask) they give the serial
    run's kept-out scores to the last digit, in the same order."""
    distributed = pytest.importorskip("distributed")
    import mmg
    from trials.measured.identify import cross_validate, load_runs

    a = _slice(FRT / "zigzag" / "zigzag_31-Jul-2020_13_14_21.csv", tmp_path / "zz.csv", 40.0)
    b = _slice(FRT / "turning" / "turn_14-Sep-2020_13_51_45.csv", tmp_path / "turn.csv", 40.0)
    ship = mmg.load_ship("esso_osaka_3m")
    runs = load_runs(ship, [a, b])
    ser = cross_validate(ship, runs, folds=2, max_nfev=4)
    with distributed.LocalCluster(n_workers=2, processes=False, threads_per_worker=1,
                                  dashboard_address=":0") as cluster, distributed.Client(cluster) as client:
        par = cross_validate(ship, runs, folds=2, max_nfev=4, backend="dask", client=client)
    assert [(r["name"], r["fold"], r["identified"], r["initial"]) for r in par] == \
        [(r["name"], r["fold"], r["identified"], r["initial"]) for r in ser]
