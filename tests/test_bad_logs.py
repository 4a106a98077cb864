"""Bad and wrong-looking logs: one InputError line naming the file and the field,
never a traceback or a silently wrong number; and metrics refused for a record that is not the
manoeuvre asked for."""
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mmg.errors import InputError
from mmg.limits import MAX_STEPS
from trials.cli import main
from trials.files.logio import read_record, write_csv
from trials.analysis.metrics import record_metrics
from trials.runs.run import run_trial
from trials.runs.trial import load_trial

from .conftest import CONFIGS, FRT, needs_frt

ZZ = FRT / "zigzag"
TURN = FRT / "turning"


@pytest.fixture(scope="module")
def zz20(tmp_path_factory):
    """A 1300 s ZZ20 log and truth file (three overshoots) and its run."""
    d = tmp_path_factory.mktemp("zz20")
    run = run_trial(replace(load_trial(CONFIGS / "trials" / "zz20.yaml"), duration=1300.0))
    write_csv(d / "log.csv", run.log(), run.log_meta())
    write_csv(d / "truth.csv", run.truth(), run.log_meta())
    return d, run


@pytest.fixture(scope="module")
def stype(tmp_path_factory):
    d = tmp_path_factory.mktemp("stype")
    run = run_trial(replace(load_trial(CONFIGS / "trials" / "stype120.yaml"), duration=1500.0))
    write_csv(d / "log.csv", run.log(), run.log_meta())
    return d, run


def split(path: Path):
    lines = path.read_text().splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    body = [ln for ln in lines if not ln.startswith("#")]
    return head, body[0].split(","), [ln.split(",") for ln in body[1:]]


def rewrite(src: Path, dst: Path, col=None, fn=None, rows=None, head_fn=None) -> Path:
    """Copy ``src`` to ``dst`` with column ``col`` mapped through ``fn`` (on floats), the data rows
    passed through ``rows`` and the header lines through ``head_fn``."""
    head, names, data = split(src)
    if col is not None:
        k = names.index(col)
        for r in data:
            if r[k].strip():
                r[k] = repr(float(fn(float(r[k]))))
    if rows is not None:
        data = rows(data)
    if head_fn is not None:
        head = head_fn(head)
    dst.write_text("\n".join(head + [",".join(names)] + [",".join(r) for r in data]) + "\n")
    return dst


def refused(path, field, *words):
    with pytest.raises(InputError) as e:
        read_record(path)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(str(path))
    assert e.value.field == field, msg
    for w in words:
        assert w in msg, msg
    return msg


# --------------------------------------------------------------------------- files and tables

def test_not_a_file(tmp_path):
    refused(tmp_path, "", "directory")
    refused(tmp_path / "nope.csv", "", "not found")
    (tmp_path / "empty.csv").write_text("")
    refused(tmp_path / "empty.csv", "", "no data")
    (tmp_path / "bin.csv").write_bytes(b"time_s,lat_deg\n\x00\x01\x02\xff")
    refused(tmp_path / "bin.csv", "", "binary")
    (tmp_path / "latin1.csv").write_bytes("time_s,lat_deg\n0,35\xb0\n".encode("latin-1"))
    refused(tmp_path / "latin1.csv", "", "not UTF-8", "0xb0")


def test_ragged_and_non_numeric(zz20, tmp_path):
    d, _ = zz20
    log = d / "log.csv"

    def cell(row, k, v):
        def f(rows):
            rows[row][k] = v
            return rows
        return f

    refused(rewrite(log, tmp_path / "a.csv", rows=lambda r: r[:5] + [r[5] + ["1"]] + r[6:]), "line 30", "7 cells")
    refused(rewrite(log, tmp_path / "b.csv", rows=lambda r: r[:5] + [r[5][:4]] + r[6:]), "line 30", "4 cells")
    refused(rewrite(log, tmp_path / "c.csv", rows=cell(7, 4, "fast")), "speed_kn", "'fast'", "line 32")
    refused(rewrite(log, tmp_path / "d.csv", rows=cell(7, 3, "")), "heading_deg", "empty cell")
    refused(rewrite(log, tmp_path / "e.csv", rows=cell(7, 3, "inf")), "heading_deg", "not a finite number")
    refused(rewrite(log, tmp_path / "f.csv", rows=lambda r: []), "", "no data rows")
    head, names, data = split(log)
    (tmp_path / "g.csv").write_text("\n".join(head + [",".join(names + ["rpm"])] + [",".join(r + ["1"]) for r in data]))
    refused(tmp_path / "g.csv", "rpm", "twice")


# --------------------------------------------------------------------------- time

def test_time_in_milliseconds_and_absurd_sampling(zz20, tmp_path):
    d, _ = zz20
    log = d / "log.csv"
    refused(rewrite(log, tmp_path / "ms.csv", "time_s", lambda v: v * 1000), "time_s", "milliseconds", "interval_s")
    # unbounded work: 12 rows 1e6 s apart
    twelve = rewrite(log, tmp_path / "1e6.csv", "time_s", lambda v: v / 5 * 1e6, rows=lambda r: r[:12])
    refused(twelve, "time_s", "interval_s")
    # without the header's interval the span is refused: more than MAX_STEPS steps of 0.1 s
    bare = rewrite(log, tmp_path / "bare.csv", "time_s", lambda v: v / 5 * 1e6, rows=lambda r: r[:12],
                   head_fn=lambda h: [ln for ln in h if not ln.startswith("# interval_s")])
    msg = refused(bare, "time_s", "spans", f"{MAX_STEPS * 0.1:,.0f} s")
    # and the CLI: one line, exit 2, for every command that reads a log
    for argv in (["metrics", str(twelve)], ["metrics", str(bare)]):
        assert main(argv) == 2


def test_gaps_and_irregular_steps(zz20, tmp_path):
    d, _ = zz20
    log = d / "log.csv"
    refused(rewrite(log, tmp_path / "gap.csv", rows=lambda r: r[:20] + r[21:]), "time_s", "gap of 10 s", "1 sample missing")

    def shift(rows):
        rows[20][0] = repr(float(rows[20][0]) + 1.0)
        return rows
    refused(rewrite(log, tmp_path / "odd.csv", rows=shift), "time_s", "differs from the header's interval_s")
    refused(rewrite(log, tmp_path / "back.csv", rows=lambda r: r[:20] + [r[10]] + r[21:]), "time_s", "not strictly increasing")


# --------------------------------------------------------------------------- units of a project log and truth file

@pytest.mark.parametrize("col, fn, field, words", [
    ("heading_deg", lambda v: v * 100, "heading_deg", ["not a heading in degrees"]),
    ("speed_kn", lambda v: v * 0.514444, "speed_kn", ["times the speed along the track", "wrong speed unit"]),
    ("speed_kn", lambda v: v * 100, "speed_kn", ["Froude number"]),
    ("lat_deg", lambda v: np.radians(v), "lat_deg", ["not degrees"]),
    ("rpm", lambda v: v * 1000, "rpm", ["beyond any ship"]),
])
def test_log_channel_in_wrong_unit(zz20, tmp_path, col, fn, field, words):
    d, _ = zz20
    refused(rewrite(d / "log.csv", tmp_path / "bad.csv", col, fn), field, *words)


@pytest.mark.parametrize("col, fn, field, words", [
    ("psi_rad", np.degrees, "psi_rad", ["degrees?"]),
    ("delta_rad", np.degrees, "delta_rad", ["degrees?"]),
    ("r_radps", np.degrees, "r_radps", ["deg/s?"]),
    ("time_s", lambda v: v * 1000, "time_s", ["milliseconds"]),
    ("x_m", lambda v: v * 1000, "x_m, y_m", ["Froude"]),
])
def test_truth_channel_in_wrong_unit(zz20, tmp_path, col, fn, field, words):
    d, _ = zz20
    refused(rewrite(d / "truth.csv", tmp_path / "bad.csv", col, fn), field, *words)


# --------------------------------------------------------------------------- FRT-DS-ESSO records

@needs_frt()
@pytest.mark.parametrize("col, fn, words", [
    ("psi_hat [rad]", np.degrees, ["not radians", "degrees?"]),
    ("delta_rudder [rad]", np.degrees, ["beyond the +/-45 deg", "degrees?"]),
    ("r_angvelo [rad/s]", np.degrees, ["deg/s?"]),
    ("t [s]", lambda v: v * 1000, ["10 Hz", "milliseconds"]),
    ("u_velo [m/s]", lambda v: v * 100, ["times what the track", "cm/s"]),   # named by the track
    ("x_position_mid [m]", lambda v: v * 1000, ["Froude number"]),
    ("n_prop [rps]", lambda v: v * 60, ["rpm"]),
])
def test_real_record_channel_in_wrong_unit(tmp_path, col, fn, words):
    src = ZZ / "zigzag_31-Jul-2020_13_22_52.csv"
    field = "x_position_mid [m], y_position_mid [m]" if col.startswith("x_") else col
    refused(rewrite(src, tmp_path / "bad.csv", col, fn), field, *words)


@needs_frt()
def test_heading_in_degrees_within_the_radian_range(tmp_path):
    """A heading in degrees that stays within [-pi, 2 pi] is caught by its rate or by the yaw rate."""
    src = ZZ / "zigzag_31-Jul-2020_13_22_52.csv"
    # the approach of 13_22_52 stays within 2 deg: in degrees it fits in the radian range
    refused(rewrite(src, tmp_path / "approach.csv", "psi_hat [rad]", np.degrees, rows=lambda r: r[:400]), "psi_hat [rad]")
    # a heading scaled by a tenth of 180/pi swings within the range and disagrees with the yaw rate
    refused(rewrite(src, tmp_path / "tenth.csv", "psi_hat [rad]", lambda v: np.degrees(v) / 10), "psi_hat [rad]",
            "disagree")


@needs_frt()
def test_trailing_empty_rows_are_trimmed_and_said(caplog):
    f = ZZ / "zigzag_31-Jul-2020_13_50_28.csv"
    rec = read_record(f)
    assert rec.t[-1] == pytest.approx(170.0)
    assert any("trailing empty rows" in n for n in rec.meta["notes"])
    assert any("trailing empty rows" in r.getMessage() for r in caplog.records)
    m = record_metrics(rec)
    assert m["kind"] == "zigzag" and len(m["overshoots_deg"]) == 4
    assert any("trailing empty rows" in n for n in m["notes"])


@needs_frt()
def test_only_real_gaps_are_refused(tmp_path):
    src = ZZ / "zigzag_31-Jul-2020_13_22_52.csv"
    blank = ",".join([""] * 13)
    # an empty row between two samples: no time is missing, the row is ignored
    ok = rewrite(src, tmp_path / "ok.csv", rows=lambda r: r[:500] + [blank.split(",")] + r[500:])
    rec = read_record(ok)
    assert len(rec.t) == 1730 and any("interior empty row" in n for n in rec.meta["notes"])
    # an empty row in place of a sample: a gap of 0.2 s
    refused(rewrite(src, tmp_path / "gap.csv", rows=lambda r: r[:500] + [blank.split(",")] + r[501:]),
            "t [s]", "gap of 0.2 s", "1 sample missing")


# --------------------------------------------------------------------------- metrics: not the manoeuvre asked for

@needs_frt()
@pytest.mark.parametrize("f", sorted((FRT / "random").glob("*.csv")) if FRT.is_dir() else [])
def test_random_rudder_run_is_not_a_zigzag(f, capsys):
    rec = read_record(f)
    for kind in (None, "zigzag"):
        with pytest.raises(InputError, match="not a zigzag|nor a zigzag"):
            record_metrics(rec, kind=kind)
    with pytest.raises(InputError, match="not a turning test"):
        record_metrics(rec, kind="turning")
    assert main(["metrics", str(f)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(f) in err[0]


@needs_frt()
def test_turn_is_not_a_zigzag_and_zigzag_not_a_turn():
    with pytest.raises(InputError, match="not a zigzag"):
        record_metrics(read_record(TURN / "turn_14-Sep-2020_13_39_32.csv"), kind="zigzag")
    with pytest.raises(InputError, match="not a turning test.*90 deg"):
        record_metrics(read_record(ZZ / "zigzag_31-Jul-2020_13_22_52.csv"), kind="turning")


def test_log_whose_heading_never_reaches_the_check_heading(zz20, tmp_path):
    d, _ = zz20
    bad = rewrite(d / "log.csv", tmp_path / "h.csv", head_fn=lambda h: [("# heading_deg: 60.0" if ln.startswith("# heading_deg")
                                                                         else ln) for ln in h])
    with pytest.raises(InputError, match="not a zigzag"):
        record_metrics(read_record(bad))
    rad = rewrite(d / "log.csv", tmp_path / "rad.csv", "heading_deg", lambda v: np.radians(v) % (2 * np.pi))
    with pytest.raises(InputError, match="radians"):
        record_metrics(read_record(rad))


# --------------------------------------------------------------------------- metrics of the project's own 5 s logs

def test_log_overshoots_match_the_truth(zz20):
    """The 5 s log gives the overshoots of the 0.1 s truth (measured from the check heading, the
    crossing interpolated, the extreme from a parabola) -- they were 0.6 deg low."""
    d, run = zz20
    truth = run.metrics()
    m = record_metrics(read_record(d / "log.csv"))
    n = len(truth["overshoots_deg"])
    assert n >= 3 and len(m["overshoots_deg"]) == n
    np.testing.assert_allclose(m["overshoots_deg"], truth["overshoots_deg"], atol=0.1)
    assert m["initial_turning_time_s"] == pytest.approx(truth["initial_turning_time_s"], abs=0.5)
    assert m["switching_headings_deg"][:2] == pytest.approx([20.0, -20.0], abs=1e-9)
    mt = record_metrics(read_record(d / "truth.csv"))
    np.testing.assert_allclose(mt["overshoots_deg"], truth["overshoots_deg"], atol=0.01)


def test_stype_log_metrics_match_the_truth(stype):
    d, run = stype
    truth = run.metrics()
    m = record_metrics(read_record(d / "log.csv"))
    assert m["kind"] == "stype" and len(m["overshoots_deg"]) >= 2
    np.testing.assert_allclose(m["overshoots_deg"], truth["overshoots_deg"][:len(m["overshoots_deg"])], atol=0.1)
