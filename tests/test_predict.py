"""Replay of records against their own inputs (``trials.measured.predict``, ``mmg predict``).

* Acceptance 4: the full-scale simulator's own truth files replayed with their true rudder and
  revolutions reproduce the truth (heading RMS < 0.05 deg), through the project's writers and
  :func:`trials.files.logio.read_record`, so the replay, the readers and the conventions are checked
  end to end; a project sea-trial log (no rudder channel, the rudder rebuilt) to a justified
  tolerance.
* ``mmg predict`` end to end on small slices of the real FRT-DS-ESSO files (``../shared``,
  or ``$MMG_FRT_DATA``: :func:`trials.files.data.frt_folder`; skipped where absent): the JSON's keys exactly, the numbers the
  library's, one line per run, the plots.
* Bad records (acceptance 5): a dropout, a wrapped heading, a missing column, channels in the
  wrong unit, a ``--start`` outside the record: handled (the wrapped heading) or refused in one
  line, exit 2, nothing written.
* Wind: the replay with wind on differs from wind off only when the record has wind channels;
  without them the run says ``"no wind channels"``.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from .conftest import FRT, FRT_FOUND, FRT_MISSING

needs_frt = pytest.mark.needs_frt

ZIGZAG = "zigzag/zigzag_31-Jul-2020_13_04_24.csv"
TURNING = "turning/turn_14-Sep-2020_13_39_32.csv"
SLICE_ROWS = 600             # 60 s at 10 Hz: the start from rest and the first rudder movements
SCORE_KEYS = ["heading_rms_deg", "yaw_rate_rms_degps", "speed_rms_mps", "final_position_error_m",
              "final_position_error_L"]


@pytest.fixture(scope="module")
def ship3m():
    import mmg

    return mmg.load_ship("esso_osaka_3m")


# --------------------------------------------------------------------------- acceptance 4: the simulator's own files


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """ST35 and ZZ20 of the full-scale ship simulated once, truth and log written by the project's writer."""
    import mmg
    from trials.files.logio import write_csv

    d = tmp_path_factory.mktemp("simulated")
    out = {}
    for name in ("st35", "zz20"):
        res = mmg.simulate(mmg.load_trial(name))
        meta = res.log_meta()
        write_csv(d / f"{name}_truth.csv", res.truth(), meta)
        write_csv(d / f"{name}_log.csv", res.log(), meta)
        out[name] = (res, d / f"{name}_truth.csv", d / f"{name}_log.csv")
    return out


@pytest.mark.parametrize("name", ["st35", "zz20"])
def test_replay_of_the_simulators_truth_file_reproduces_it(simulated, name):
    """Acceptance 4: truth file -> read_record -> replay with its own delta(t), n(t) -> the truth again.

    The simulator integrates the steering gear and the shaft inside its RK4 step; the replay
    interpolates the rudder and revolutions linearly between the 0.1 s samples, which costs
    ~1e-5 deg of heading over 3000 s, far inside the 0.05 deg asked."""
    from trials.files.logio import read_record
    from trials.measured.predict import replay_record

    res, truth, _ = simulated[name]
    ship = res.trial.ship
    rec = read_record(truth, length_m=ship.particulars.L)
    rep = replay_record(ship, rec)
    s = rep.scores()
    assert rep.run.notes == [] and rep.run.wind == "off"
    assert s["heading_rms_deg"] < 0.05
    assert s["yaw_rate_rms_degps"] < 1e-3 and s["speed_rms_mps"] < 1e-3
    assert s["final_position_error_L"] < 1e-3
    # and the replay's states are the truth's at every sample (heading within 0.05 deg everywhere)
    psi_true = res.truth()["psi_rad"].to_numpy()
    assert np.max(np.abs(np.degrees(rep.pred[:, 5] - psi_true))) < 0.05


@pytest.mark.parametrize("name", ["st35", "zz20"])
def test_replay_of_a_project_sea_trial_log(simulated, name):
    """A project log (5 s samples of position, heading, speed, rpm; no rudder, no u, v, r) replays with the
    rudder rebuilt from the header's trial logic, u the logged speed, v = 0 and r from the heading.

    Tolerance: 1 deg heading RMS, the limit at which the project itself calls a free run a wrong
    model (``mmg estimate``'s free_run.json warning).  What stays between the log and the truth is
    the made-up initial state (v = 0 instead of the approach drift, u = speed over ground, r from
    the spline through the heading), the rpm noise (0.2 rpm) prescribed as n(t) and the spline
    interpolation of 5 s samples; measured: ST35 0.38 deg over 3000 s of turning, ZZ20 0.09 deg.
    Position: 0.1 L after 3000 s (measured 0.02-0.04 L)."""
    from trials.files.logio import read_record
    from trials.measured.predict import replay_record

    res, _, log = simulated[name]
    ship = res.trial.ship
    rep = replay_record(ship, read_record(log, length_m=ship.particulars.L))
    s = rep.scores()
    assert any("rudder rebuilt" in n for n in rep.run.notes)
    assert s["heading_rms_deg"] < 1.0
    assert s["final_position_error_L"] < 0.1
    assert np.all(np.isfinite(rep.pred))


# --------------------------------------------------------------------------- slices of the real files


def _slice(src: Path, dst: Path, rows: int = SLICE_ROWS, drop=None, edit=None, drop_columns=()) -> Path:
    """The header line and the first ``rows`` data rows of ``src`` into ``dst``; ``drop``: a slice of
    data rows removed (a dropout); ``edit(df)``: a change of the table (written back by pandas) ."""
    lines = src.read_text().splitlines()
    header, data = lines[0], lines[1:1 + rows]
    if drop is not None:
        del data[drop]
    if edit is None and not drop_columns:
        dst.write_text("\n".join([header] + data) + "\n")
        return dst
    from io import StringIO

    df = pd.read_csv(StringIO("\n".join([header] + data)))
    if edit is not None:
        edit(df)
    df = df.drop(columns=list(drop_columns))
    df.to_csv(dst, index=False)               # repr of every float: the untouched columns unchanged
    return dst


@pytest.fixture()
def slices(tmp_path):
    if FRT_FOUND is None:
        pytest.skip(FRT_MISSING)
    return [_slice(FRT / ZIGZAG, tmp_path / "zz_slice.csv"), _slice(FRT / TURNING, tmp_path / "turn_slice.csv")]


def _run_cli(argv, capsys):
    from trials.cli import main

    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


@needs_frt
def test_cli_predict_end_to_end(slices, tmp_path, ship3m, capsys):
    """``mmg predict`` on two slices: exact JSON layout, the library's numbers, one line per run, the plots."""
    from trials.measured.predict import predict
    from trials.measured.window import with_windows

    js, plots = tmp_path / "out" / "pred.json", tmp_path / "plots"
    rc, out, err = _run_cli(["predict", "--ship", "esso_osaka_3m", *slices, "--json", js, "--plots", plots], capsys)
    assert rc == 0, err
    doc = json.loads(js.read_text(), parse_constant=lambda c: pytest.fail(f"JSON holds {c}"))
    assert list(doc) == ["runs"] and len(doc["runs"]) == 2
    lib = with_windows(ship3m, predict(ship3m, slices), 60.0, 30.0)    # --window 60 --every 30: the defaults
    for run, path, rep, win in zip(doc["runs"], slices, lib.runs, lib.windows):
        assert list(run) == ["name", "file", *SCORE_KEYS, "window"]
        assert run["file"] == str(path) and run["name"] == path.stem
        assert run == {"name": path.stem, "file": str(path), **rep.scores(),   # the library's numbers, bit for bit
                       "window": win.to_json()}
        assert run["window"]["n_windows"] == 1 and run["window"]["window_s"] < 60.0   # a 60 s slice: one, shorter
        assert f"{path.stem}: from the measured state, 1 window of the whole" in out
        assert all(np.isfinite(run[k]) for k in SCORE_KEYS)
        assert run["final_position_error_L"] == pytest.approx(run["final_position_error_m"] / 3.0, rel=1e-15)
    lines = out.strip().splitlines()
    assert [ln.split(":")[0] for ln in lines[:2]] == ["zz_slice", "turn_slice"]
    assert "heading" in lines[0] and "wind on" in lines[0]
    assert [ln for ln in err.splitlines() if ln.startswith("replayed")] == \
        ["replayed 1/2: zz_slice", "replayed 2/2: turn_slice"]
    assert sorted(p.name for p in plots.iterdir()) == ["turn_slice.png", "zz_slice.png"]
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in plots.iterdir())


@needs_frt
def test_two_records_of_one_trial_are_named_after_their_files(tmp_path, capsys):
    """Two records of one trial, not ST35.png and ST35_2.png with "ST35" printed twice: every
    output and printed line is named after the file, two files of one stem told apart by their folders
    (the same file given again numbered), the same names in the JSON, the lines and the plots."""
    a, b = tmp_path / "day1", tmp_path / "day2"
    a.mkdir()
    b.mkdir()
    for d in (a, b):                           # one trial's record, twice: the same name inside the file
        _slice(FRT / ZIGZAG, d / "zigzag.csv")
    other = _slice(FRT / TURNING, tmp_path / "turn.csv")
    js, plots = tmp_path / "p.json", tmp_path / "plots"
    rc, out, err = _run_cli(["predict", "--ship", "esso_osaka_3m", a / "zigzag.csv", b / "zigzag.csv", other,
                             a / "zigzag.csv", "--json", js, "--plots", plots], capsys)
    assert rc == 0, err
    names = ["day1/zigzag", "day2/zigzag", "turn", "day1/zigzag_2"]
    runs = json.loads(js.read_text())["runs"]
    assert [r["name"] for r in runs] == names
    assert [r["file"] for r in runs] == [str(a / "zigzag.csv"), str(b / "zigzag.csv"), str(other), str(a / "zigzag.csv")]
    assert [ln.split(":")[0] for ln in out.strip().splitlines()[:4]] == names
    assert sorted(str(p.relative_to(plots)) for p in plots.rglob("*.png")) == sorted(f"{n}.png" for n in names)
    assert runs[0]["heading_rms_deg"] == runs[3]["heading_rms_deg"]      # the same file, the same scores


def test_record_labels_are_unique_and_deterministic(tmp_path):
    from trials.files.output import record_labels

    paths = [tmp_path / "x" / "a" / "ST35.csv", tmp_path / "y" / "a" / "ST35.csv", tmp_path / "ST35_2.csv",
             tmp_path / "z" / "ZZ.csv", tmp_path / "z" / "ZZ.txt", tmp_path / "x" / "a" / "ST35.csv"]
    got = record_labels(paths)
    assert got == ["x/a/ST35", "y/a/ST35", "ST35_2", "ZZ.csv", "ZZ.txt", "x/a/ST35_2"]
    assert record_labels(paths) == got and len(set(got)) == len(got)
    assert record_labels([tmp_path / "one.csv"]) == ["one"]


@needs_frt
def test_cli_predict_wind_switch_and_start(slices, tmp_path, ship3m, capsys):
    """--wind off and --start S reach the library: the JSON equals predict(..., start, wind=False)."""
    from trials.measured.predict import predict
    from trials.measured.window import with_windows

    js = tmp_path / "p.json"
    rc, out, err = _run_cli(["predict", "--ship", "esso_osaka_3m", slices[0], "--json", js, "--wind", "off",
                             "--start", "20"], capsys)
    assert rc == 0, err
    doc = json.loads(js.read_text())
    assert doc == with_windows(ship3m, predict(ship3m, slices[:1], start=20.0, wind=False)).to_json()
    assert "wind off" in out


def _refused(argv, capsys, *targets, contains=()):
    rc, out, err = _run_cli(argv, capsys)
    lines = err.strip().splitlines()
    assert rc == 2, (rc, err)
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    for c in contains:
        assert c in lines[0], lines[0]
    for t in targets:
        assert not Path(t).exists(), f"{t} was written"
    return lines[0]


@needs_frt
@pytest.mark.parametrize("case", ["dropout", "missing n_prop", "rudder in degrees", "revolutions in rpm",
                                  "heading in degrees", "wind speed beyond 60 m/s"])
def test_bad_records_are_refused_in_one_line(case, tmp_path, capsys):
    """A dropout (20 rows = 2 s removed: a time gap), a missing propeller channel, channels in the wrong unit:
    exit 2, one line naming the file and the channel, no JSON and no plots folder."""
    src = FRT / ZIGZAG
    bad = tmp_path / "bad.csv"
    col = {"rudder in degrees": ("delta_rudder [rad]", np.degrees), "revolutions in rpm": ("n_prop [rps]", lambda a: a * 60),
           "heading in degrees": ("psi_hat [rad]", np.degrees),
           "wind speed beyond 60 m/s": ("wind_velo_relative_mid [m/s]", lambda a: a * 100)}
    if case == "dropout":
        _slice(src, bad, drop=slice(300, 320))
        what = ("gap",)
    elif case == "missing n_prop":
        _slice(src, bad, drop_columns=("n_prop [rps]",))
        what = ("n", "revolutions")
    else:
        c, f = col[case]
        _slice(src, bad, edit=lambda df: df.__setitem__(c, f(df[c].to_numpy())))
        what = (c,)
    good = _slice(src, tmp_path / "good.csv")
    js, plots = tmp_path / "o" / "p.json", tmp_path / "plots"
    line = _refused(["predict", "--ship", "esso_osaka_3m", good, bad, "--json", js, "--plots", plots], capsys,
                    js, plots, js.parent, contains=(str(bad), *what))
    assert "Traceback" not in line


@needs_frt
def test_wind_speed_in_kmh_is_refused(tmp_path, capsys):
    bad = _slice(FRT / ZIGZAG, tmp_path / "kmh.csv",
                 edit=lambda df: df.__setitem__("wind_velo_relative_mid [m/s]", df["wind_velo_relative_mid [m/s]"] * 3.6))
    _refused(["predict", "--ship", "esso_osaka_3m", bad, "--json", tmp_path / "p.json"], capsys, tmp_path / "p.json")


@needs_frt
def test_wrapped_heading_is_unwrapped(tmp_path, ship3m):
    """The heading wrapped to [0, 2 pi) instead of (-pi, pi]: the reader unwraps it, the replay's scores are
    the same (the zigzag slice crosses psi = 0, so the [0, 2 pi) copy jumps by 2 pi there)."""
    from trials.measured.predict import predict

    col = "psi_hat [rad]"
    ref = _slice(FRT / ZIGZAG, tmp_path / "ref.csv", rows=1400, edit=lambda df: None)
    wrapped = _slice(FRT / ZIGZAG, tmp_path / "wrapped.csv", rows=1400,
                     edit=lambda df: df.__setitem__(col, np.mod(df[col].to_numpy(), 2 * np.pi)))
    raw = pd.read_csv(wrapped)[col].to_numpy()
    assert np.max(np.abs(np.diff(raw))) > 6.0, "the test's heading never crosses the wrap"
    a, b = (predict(ship3m, [p]).runs[0] for p in (ref, wrapped))
    assert np.max(np.abs(a.run.meas[:, 5] - b.run.meas[:, 5])) < 1e-12
    sa, sb = a.scores(), b.scores()
    for k in SCORE_KEYS:
        assert sb[k] == pytest.approx(sa[k], rel=1e-9, abs=1e-12), k


@needs_frt
def test_bad_options_and_targets_refused_before_any_work(slices, tmp_path, capsys):
    """A --start outside the record, a missing log, an unusable --json or --plots target: one line, exit 2."""
    js, plots = tmp_path / "o" / "p.json", tmp_path / "plots"
    base = ["predict", "--ship", "esso_osaka_3m"]
    _refused(base + [slices[0], "--json", js, "--plots", plots, "--start", "1e4"], capsys, js, plots, js.parent,
             contains=("--start", "outside the record"))
    _refused(base + [slices[0], tmp_path / "absent.csv", "--json", js, "--plots", plots], capsys, js, plots,
             contains=("absent.csv", "file not found"))
    _refused(base + [slices[0], "--json", tmp_path, "--plots", plots], capsys, plots, contains=("--json",))
    (tmp_path / "afile").write_text("x")
    _refused(base + [slices[0], "--json", js, "--plots", tmp_path / "afile"], capsys, js, contains=("--plots",))
    _refused(["predict", "--ship", "no_such_ship", slices[0], "--json", js], capsys, js, contains=("no_such_ship",))


# --------------------------------------------------------------------------- wind on and off


def _synthetic_record(ship, wind: bool):
    """A 60 s record of the 3 m model made by the replay itself (n = 10 rps, a 20 deg rudder step at 20 s),
    with a constant 2 m/s relative wind from 30 deg off the starboard bow when ``wind``."""
    from mmg.model import pack
    from mmg.replay import ReplayInputs, replay_states
    from trials.files.records import TrialRecord

    t = np.round(np.arange(0.0, 60.0 + 1e-9, 0.1), 10)
    delta = np.where(t >= 20.0, np.radians(20.0), 0.0)
    n = np.full_like(t, 10.0)
    s = replay_states(pack(ship), ReplayInputs(t=t, delta=delta, n=n), [0.3, 0.0, 0.0, 0.0, 0.0, 0.0])
    kw = {}
    if wind:
        kw = {"wind_speed_rel": np.full_like(t, 2.0), "wind_dir_rel": np.full_like(t, np.radians(30.0))}
    return TrialRecord(t=t, name="synthetic", source="synthetic", u=s[:, 0], v=s[:, 1], r=s[:, 2], x=s[:, 3],
                       y=s[:, 4], psi=s[:, 5], delta=delta, n=n, **kw)


def test_wind_changes_the_replay_only_with_wind_channels(ship3m):
    from trials.measured.predict import replay_record

    with_w, without = _synthetic_record(ship3m, True), _synthetic_record(ship3m, False)
    on, off = replay_record(ship3m, with_w, wind=True), replay_record(ship3m, with_w, wind=False)
    assert (on.run.wind, off.run.wind) == ("on", "off")
    assert on.run.inputs.ext is not None and np.any(on.run.inputs.ext != 0)
    assert np.max(np.abs(on.pred[:, 5] - off.pred[:, 5])) > 1e-3          # the wind turns the model
    # without wind channels, wind on is wind off exactly, and says why
    on2, off2 = replay_record(ship3m, without, wind=True), replay_record(ship3m, without, wind=False)
    assert on2.run.wind == "no wind channels" and off2.run.wind == "off"
    assert np.array_equal(on2.pred, off2.pred)
    # off is the measured record itself (it was made by the replay without wind)
    assert off.scores()["heading_rms_deg"] < 1e-12
    # the ship config's switch is the default (esso_osaka_3m: wind enabled)
    assert ship3m.wind is not None and ship3m.wind.enabled
    assert replay_record(ship3m, with_w).run.wind == "on"


@needs_frt
def test_wind_on_and_off_on_a_real_slice(tmp_path, ship3m):
    """The same on a real slice: wind channels present -> wind on differs; the wind columns removed -> the
    run says 'no wind channels' and wind on equals wind off exactly."""
    from trials.measured.predict import predict

    wind_cols = ("wind_velo_relative_mid [m/s]", "wind_dir_relative_mid [rad]", "wind_velo_true [m/s]",
                 "wind_dir_true [rad]")
    full = _slice(FRT / ZIGZAG, tmp_path / "full.csv")
    bare = _slice(FRT / ZIGZAG, tmp_path / "bare.csv", drop_columns=wind_cols)
    on, off = predict(ship3m, [full], wind=True).runs[0], predict(ship3m, [full], wind=False).runs[0]
    assert (on.run.wind, off.run.wind) == ("on", "off")
    assert not np.array_equal(on.pred, off.pred)
    on2, off2 = predict(ship3m, [bare], wind=True).runs[0], predict(ship3m, [bare], wind=False).runs[0]
    assert on2.run.wind == "no wind channels"
    assert np.array_equal(on2.pred, off2.pred) and np.array_equal(off2.pred, off.pred)


def test_a_diverged_replay_says_where_and_scores_null(simulated, tmp_path, capsys):
    """A model whose surge resistance is turned into thrust (X_uu > 0: du/dt grows like u^2, a
    blow-up in finite time) diverges on the ZZ20 record: ``Replayed.diverged_at`` is the time of
    the first non-finite predicted sample (finite before it, not after), the scores are NaN, and
    ``mmg predict`` says where in one line, writes null scores and leaves it out of the mean.  The
    unchanged ship replays the same record to the end (``diverged_at`` None)."""
    from mmg.resources import ship_path
    from trials.measured.identify import ship_yaml
    from trials.files.logio import read_record
    from trials.measured.predict import replay_record

    res, truth, _ = simulated["zz20"]
    ship = res.trial.ship
    rec = read_record(truth, length_m=ship.particulars.L)
    assert replay_record(ship, rec).diverged_at is None
    bad = ship.with_hull({"X_uu": 0.5})
    rep = replay_record(bad, rec)
    t_div = rep.diverged_at
    assert t_div is not None and rec.t[0] < t_div <= rec.t[-1]
    k = int(np.searchsorted(rep.run.t, t_div))
    assert np.isfinite(rep.pred[:k]).all() and not np.isfinite(rep.pred[k:]).all(axis=1).any()
    assert all(np.isnan(v) for v in rep.scores().values())
    # the figure marks the divergence and keeps every panel on the measured record's range
    fig = rep.plot(pyplot=False)
    hist = [a for a in fig.axes if a.get_ylabel() in ("heading (deg)", "yaw rate (deg/s)", "speed (m/s)", "sway v (m/s)")]
    assert len(hist) == 4 and f"replay diverged at t = {t_div:.1f} s" in hist[0].get_title()
    meas = {"heading (deg)": np.degrees(rep.run.meas[:, 5]), "yaw rate (deg/s)": np.degrees(rep.run.meas[:, 2]),
            "speed (m/s)": np.hypot(rep.run.meas[:, 0], rep.run.meas[:, 1]), "sway v (m/s)": rep.run.meas[:, 1]}
    for a in hist:
        lo, hi = a.get_ylim()
        m = meas[a.get_ylabel()]
        assert lo <= m.min() and hi >= m.max() and hi - lo <= 3.0 * (m.max() - m.min()) + 1e-5
        assert any(ln.get_label().startswith("replay diverged") and ln.get_xdata()[0] == t_div for ln in a.get_lines())

    yml = tmp_path / "bad.yaml"
    yml.write_text(ship_yaml(ship_path("esso_osaka"), {"X_uu": 0.5}, "X_uu with the wrong sign (test)"))
    js = tmp_path / "p.json"
    rc, out, err = _run_cli(["predict", "--ship", yml, truth, truth, "--json", js], capsys)
    assert rc == 0, err
    lines = out.strip().splitlines()
    said = (f": the replay diverged at t = {t_div:.1f} s (the predicted state is not finite from there; scores null), "
            f"wind {rep.run.wind}")
    stem = Path(truth).stem                                             # runs named after their file
    assert lines[:2] == [stem + said, f"{stem}_2" + said]
    assert not any(ln.startswith("mean over") for ln in lines)          # nothing finite to average
    doc = json.loads(js.read_text())
    assert all(run[k] is None for run in doc["runs"] for k in SCORE_KEYS)


def test_cli_predict_horizon_gives_the_first_seconds(slices, tmp_path, ship3m, capsys):
    """--horizon S: each run's JSON has "first", the RMS over the samples of its first S seconds
    (computed here from the replay's own table), and the console line says it; a horizon longer than
    the record gives the whole record's scores."""
    import numpy as np

    from trials.measured.predict import predict

    js = tmp_path / "p.json"
    rc, out, err = _run_cli(["predict", "--ship", "esso_osaka_3m", slices[0], "--json", js, "--horizon", "30"], capsys)
    assert rc == 0, err
    first = json.loads(js.read_text())["runs"][0]["first"]
    df = predict(ship3m, slices[:1]).runs[0].to_pandas()
    w = df[df.index <= df.index[0] + 30.0]
    want = float(np.sqrt(np.mean(np.degrees(w["psi_pred"] - w["psi_meas"]) ** 2)))
    assert first["horizon_s"] == 30.0 and first["heading_rms_deg"] == pytest.approx(want, rel=1e-12)
    assert "first 30 s: heading" in out
    whole = predict(ship3m, slices[:1]).to_json(horizon_s=1e6)["runs"][0]
    assert whole["first"]["heading_rms_deg"] == whole["heading_rms_deg"]
    _refused(["predict", "--ship", "esso_osaka_3m", slices[0], "--json", js.with_name("q.json"), "--horizon", "0"],
             capsys, js.with_name("q.json"), contains=("--horizon",))


@needs_frt
def test_cli_predict_window_and_every_reach_the_library(slices, tmp_path, capsys):
    """--window 20 --every 10 on a 59.9 s slice: floor((59.9 - 20) / 10) + 1 = 4 windows starting 0, 10, 20, 30 s
    (counted by hand), their means in the JSON with units on the console; --every 0 is refused."""
    js = tmp_path / "p.json"
    rc, out, err = _run_cli(["predict", "--ship", "esso_osaka_3m", slices[0], "--json", js, "--window", "20",
                             "--every", "10"], capsys)
    assert rc == 0, err
    w = json.loads(js.read_text())["runs"][0]["window"]
    assert (w["window_s"], w["every_s"], w["n_windows"], w["n_diverged"]) == (20.0, 10.0, 4, 0)
    assert "zz_slice: from the measured state, 4 windows of 20 s every 10 s: mean heading" in out
    assert " deg RMS, mean final position " in out and " m (" in out and " L)" in out
    _refused(["predict", "--ship", "esso_osaka_3m", slices[0], "--json", js.with_name("q.json"), "--every", "0"],
             capsys, js.with_name("q.json"), contains=("--every",))
