"""Channels checked against what the ship and the other channels imply: a channel in a
wrong unit is refused in one line naming the file and the column (and the likely unit); a heading
that is cumulative or offset by whole turns is read like the wrapped one; a missing value in a
column a command does not use does not refuse the record for that command.

Each wrong-unit case is built from a REAL record (FRT-DS-ESSO, skipped where absent) and from a
simulated one; the real records themselves are all read (bench/channel_margins.py prints the margins).
"""
from pathlib import Path

import numpy as np
import pytest

from mmg.errors import InputError
from mmg.units import KNOT
from trials.cli import main
from trials.files.logio import read_record

from .conftest import FRT, needs_frt

REAL = [FRT / "zigzag" / "zigzag_31-Jul-2020_13_22_52.csv", FRT / "turning" / "turn_14-Sep-2020_13_39_32.csv",
        FRT / "random" / "random_31-Jul-2020_12_29_58.csv"]
DEV = FRT.parent / "diagnose-dev" / "data"
WIND = "wind_velo_relative_mid [m/s], wind_velo_true [m/s]"
KN = 1.0 / KNOT


def transformed(src: Path, dst: Path, changes: dict, rows=None) -> Path:
    """``src`` written to ``dst`` with each column of ``changes`` mapped through its function (on floats)
    and the data rows (lists of cells, empty rows dropped) passed through ``rows``."""
    lines = src.read_text().splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    body = [ln for ln in lines if not ln.startswith("#")]
    names = body[0].split(",")
    data = [ln.split(",") for ln in body[1:] if ln.replace(",", "").strip()]
    for col, fn in changes.items():
        k = names.index(col)
        for r in data:
            r[k] = repr(float(fn(float(r[k]))))
    if rows is not None:
        data = rows(data)
    dst.write_text("\n".join(head + [",".join(names)] + [",".join(r) for r in data]) + "\n")
    return dst


def refused(path, field, *words, length_m=None):
    with pytest.raises(InputError) as e:
        read_record(path, length_m=length_m)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(str(path)), msg
    assert e.value.field == field, msg
    for w in words:
        assert w in msg, msg
    return msg


def times(f):
    return lambda v: v * f


# the wrong units: (columns changed, the field named, words of the message)
WRONG = {
    "wind both km/h": ({"wind_velo_relative_mid [m/s]": times(3.6), "wind_velo_true [m/s]": times(3.6)}, WIND, "km/h"),
    "wind both knots": ({"wind_velo_relative_mid [m/s]": times(KN), "wind_velo_true [m/s]": times(KN)}, WIND, "in kn"),
    "u in knots": ({"u_velo [m/s]": times(KN)}, "u_velo [m/s]", "in kn"),
    "u in km/h": ({"u_velo [m/s]": times(3.6)}, "u_velo [m/s]", "km/h"),
    "u in cm/s": ({"u_velo [m/s]": times(100.0)}, "u_velo [m/s]", "cm/s"),
    "v in knots": ({"vm_velo [m/s]": times(KN)}, "vm_velo [m/s]", "kn"),      # v: "in kn or mph" (its track is less sure)
    "v in km/h": ({"vm_velo [m/s]": times(3.6)}, "vm_velo [m/s]", "km/h"),
    "v to port": ({"vm_velo [m/s]": times(-1.0)}, "vm_velo [m/s]", "opposite sign"),
}


@needs_frt()
@pytest.mark.parametrize("src", REAL, ids=lambda p: p.parent.name)
@pytest.mark.parametrize("case", list(WRONG))
def test_real_record_channel_in_wrong_unit(tmp_path, src, case):
    changes, field, word = WRONG[case]
    read_record(src)                                        # the record itself is read
    refused(transformed(src, tmp_path / "bad.csv", changes), field, word)


@pytest.mark.skipif(not DEV.is_dir(), reason="diagnose-dev data absent")
@pytest.mark.parametrize("case", [c for c in WRONG if not c.startswith("wind")] + ["wind both km/h"])
def test_full_scale_record_channel_in_wrong_unit(tmp_path, case):
    """A 325 m ship's log with wind (dev_07 of the independent simulator's set), 1 s sampling."""
    changes, field, word = WRONG[case]
    src = DEV / "dev_07.csv"
    read_record(src, length_m=325.0)
    refused(transformed(src, tmp_path / "bad.csv", changes), field, word, length_m=325.0)


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """A zigzag of the 3 m model with a 1.5 m/s true wind, logged in the FRT-DS-ESSO layout at 10 Hz."""
    from mmg.ship import load_ship
    from trials.measured.diagnose import Manoeuvre, RecordNoise, synthetic_record, write_frt_csv

    rec = synthetic_record(load_ship("esso_osaka_3m"), Manoeuvre("zigzag", dt=0.1), {"wind": {"scale": 1.0}},
                           true_wind=(1.5, 1.0), noise=RecordNoise(seed=3), name="sim")
    p = tmp_path_factory.mktemp("sim") / "sim.csv"
    write_frt_csv(rec, p)
    return p


@pytest.mark.parametrize("case", list(WRONG))
def test_simulated_record_channel_in_wrong_unit(simulated, tmp_path, case):
    changes, field, word = WRONG[case]
    read_record(simulated)
    refused(transformed(simulated, tmp_path / "bad.csv", changes), field, word)


@pytest.fixture(scope="module")
def truth_file(tmp_path_factory):
    from dataclasses import replace

    from trials.files.logio import write_csv
    from trials.runs.run import run_trial
    from trials.runs.trial import load_trial

    from .conftest import CONFIGS

    run = run_trial(replace(load_trial(CONFIGS / "trials" / "zz20.yaml"), duration=600.0))
    p = tmp_path_factory.mktemp("truth") / "truth.csv"
    write_csv(p, run.truth(), run.log_meta())
    return p


@pytest.mark.parametrize("col, fn, word", [("u_mps", times(KN), "in kn"), ("u_mps", times(3.6), "km/h"),
                                           ("v_mps", times(KN), "in kn"), ("v_mps", times(-1.0), "opposite sign")])
def test_truth_file_velocity_in_wrong_unit(truth_file, tmp_path, col, fn, word):
    read_record(truth_file)
    refused(transformed(truth_file, tmp_path / "bad.csv", {col: fn}), col, word)


# --------------------------------------------------------------------------- headings that are not wrapped

def _unwrapped(p):
    return np.unwrap(p)


HEADINGS = {
    "cumulative (gyro count of turns)": lambda psi: np.unwrap(psi) + 6 * np.pi,
    "all offset by -720 deg": lambda psi: psi - 4 * np.pi,
    "one +360 deg step": lambda psi: psi + np.where(np.arange(len(psi)) >= len(psi) // 2, 2 * np.pi, 0.0),
}


def _heading_rewrite(src: Path, dst: Path, fn) -> Path:
    k_of = {}

    def rows(data):
        k = k_of["k"]
        psi = fn(np.array([float(r[k]) for r in data]))
        for r, p in zip(data, psi):
            r[k] = repr(float(p))
        return data

    names = [ln for ln in src.read_text().splitlines() if not ln.startswith("#")][0].split(",")
    k_of["k"] = names.index("psi_hat [rad]")
    return transformed(src, dst, {}, rows=rows)


def _same(a, b):
    assert a.channels() == b.channels()
    for c in ("t",) + a.channels():
        np.testing.assert_allclose(getattr(a, c), getattr(b, c), rtol=0, atol=1e-9, err_msg=c)


@pytest.mark.parametrize("how", list(HEADINGS))
def test_unwrapped_heading_is_read_like_the_wrapped_one(simulated, tmp_path, how):
    ref = read_record(simulated)
    _same(ref, read_record(_heading_rewrite(simulated, tmp_path / "h.csv", HEADINGS[how])))


@needs_frt()
@pytest.mark.parametrize("how", list(HEADINGS))
def test_real_unwrapped_heading_same_record_and_metrics(tmp_path, how, capsys):
    src = REAL[0]
    ref = read_record(src)
    p = _heading_rewrite(src, tmp_path / "h.csv", HEADINGS[how])
    _same(ref, read_record(p))
    from trials.analysis.metrics import record_metrics

    a, b = record_metrics(ref, None, 3.0), record_metrics(read_record(p), None, 3.0)
    assert a.keys() == b.keys()
    for k, v in a.items():
        if isinstance(v, float):
            assert b[k] == pytest.approx(v, abs=1e-9, nan_ok=True), k


@needs_frt()
@pytest.mark.parametrize("src", REAL, ids=lambda p: p.parent.name)
def test_real_heading_in_degrees_still_refused(tmp_path, src):
    refused(transformed(src, tmp_path / "deg.csv", {"psi_hat [rad]": np.degrees}), "psi_hat [rad]", "degrees?")
    # cumulative degrees too
    refused(_heading_rewrite(src, tmp_path / "degcum.csv", lambda p: np.degrees(np.unwrap(p)) + 720.0),
            "psi_hat [rad]", "degrees?")


def test_simulated_heading_in_degrees_still_refused(simulated, tmp_path):
    refused(transformed(simulated, tmp_path / "deg.csv", {"psi_hat [rad]": np.degrees}), "psi_hat [rad]", "degrees?")


# --------------------------------------------------------------------------- missing values in unused columns

def _with_nan(src: Path, dst: Path, col: str, at=(100, 200)) -> tuple[Path, int]:
    """``src`` with ``col`` NaN / empty at data rows ``at``; returns the file line of the first."""
    lines = src.read_text().splitlines()
    first = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))
    names = lines[first].split(",")
    k = names.index(col)
    for j, cell in zip(at, ("NaN", "")):
        cells = lines[first + 1 + j].split(",")
        cells[k] = cell
        lines[first + 1 + j] = ",".join(cells)
    dst.write_text("\n".join(lines) + "\n")
    return dst, first + 1 + at[0] + 1


def _run(argv, capsys):
    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, [ln for ln in out.err.splitlines() if ln.strip()]


@needs_frt()
@pytest.mark.parametrize("col", ["wind_velo_true [m/s]", "wind_dir_true [rad]", "wind_velo_relative_mid [m/s]"])
def test_nan_in_an_unused_column_accepted_by_metrics(tmp_path, col, capsys):
    p, line = _with_nan(REAL[0], tmp_path / "nan.csv", col)
    ref_code, ref_out, _ = _run(["metrics", str(REAL[0])], capsys)
    code, out, err = _run(["metrics", str(p)], capsys)
    assert (code, ref_code) == (0, 0), err
    assert out.splitlines()[1:] == ref_out.splitlines()[1:]         # the same metrics
    rec = read_record(p)
    assert rec.meta["nan_channels"]
    # a command that uses the relative wind (the replay with the measured wind) refuses it, one line
    if "relative" in col:
        code, out, err = _run(["predict", str(p), "--ship", "esso_osaka_3m", "--wind", "on", "--json",
                               str(tmp_path / "p.json")], capsys)
        assert code == 2 and len(err) == 1, err
        assert str(p) in err[0] and col in err[0] and f"line {line}" in err[0], err


@needs_frt()
@pytest.mark.parametrize("col, argv", [("r_angvelo [rad/s]", ["metrics"]), ("delta_rudder [rad]", ["metrics"]),
                                       ("u_velo [m/s]", ["metrics"]),
                                       ("r_angvelo [rad/s]", ["nomoto", "--length", "3", "--no-output-error"]),
                                       ("n_prop [rps]", ["predict", "--ship", "esso_osaka_3m", "--json", "{tmp}/p.json"])])
def test_nan_in_a_used_column_refused_in_one_line(tmp_path, col, argv, capsys):
    p, line = _with_nan(REAL[0], tmp_path / "nan.csv", col)
    code, _, err = _run([argv[0], str(p)] + [a.format(tmp=tmp_path) for a in argv[1:]], capsys)
    assert code == 2 and len(err) == 1, err
    assert str(p) in err[0] and col in err[0] and f"line {line}" in err[0], err


@needs_frt()
def test_nan_in_the_propeller_column_not_used_by_nomoto(tmp_path, capsys):
    p, _ = _with_nan(REAL[0], tmp_path / "nan.csv", "n_prop [rps]")
    code, out, err = _run(["nomoto", str(p), "--length", "3", "--no-output-error"], capsys)
    assert code == 0, err


@needs_frt()
def test_text_in_an_unused_column_still_refused(tmp_path):
    lines = REAL[0].read_text().splitlines()
    k = lines[0].split(",").index("wind_velo_true [m/s]")
    cells = lines[10].split(",")
    cells[k] = "abc"
    lines[10] = ",".join(cells)
    p = tmp_path / "text.csv"
    p.write_text("\n".join(lines) + "\n")
    refused(p, "wind_velo_true [m/s]", "'abc'", "line 11")


def test_nan_in_a_required_column_still_refused(simulated, tmp_path):
    p, line = _with_nan(simulated, tmp_path / "nan.csv", "x_position_mid [m]")
    refused(p, "x_position_mid [m]", f"line {line}")


@pytest.fixture(scope="module")
def log_file(tmp_path_factory):
    from dataclasses import replace

    from trials.files.logio import write_csv
    from trials.runs.run import run_trial
    from trials.runs.trial import load_trial

    from .conftest import CONFIGS

    run = run_trial(replace(load_trial(CONFIGS / "trials" / "st35.yaml"), duration=900.0))
    p = tmp_path_factory.mktemp("log") / "log.csv"
    write_csv(p, run.log(), run.log_meta())
    return p


@pytest.mark.parametrize("fn", [lambda h: h - 720.0, lambda h: np.degrees(np.unwrap(np.radians(h))) + 720.0,
                                lambda h: np.where(np.arange(len(h)) > len(h) // 3, h + 360.0, h)],
                         ids=["-720", "cumulative", "one +360 step"])
def test_log_heading_not_wrapped_is_read_like_the_wrapped_one(log_file, tmp_path, fn):
    """A gyro's cumulative heading in a project log (a 35 deg turn: 2.5 turns in 900 s)."""
    names = [ln for ln in log_file.read_text().splitlines() if not ln.startswith("#")][0].split(",")
    k = names.index("heading_deg")

    def rows(data):
        h = fn(np.array([float(r[k]) for r in data]))
        for r, v in zip(data, h):
            r[k] = repr(float(v))
        return data

    _same(read_record(log_file), read_record(transformed(log_file, tmp_path / "h.csv", {}, rows=rows)))


def test_log_heading_in_another_unit_refused(log_file, tmp_path):
    refused(transformed(log_file, tmp_path / "x100.csv", {"heading_deg": times(100.0)}), "heading_deg",
            "not a heading in degrees")
