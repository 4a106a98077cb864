"""Bad input: one line naming the file and the field, exit status 2, nothing written."""
import shutil
from pathlib import Path

import pytest
import yaml

from trials.cli import main

from .conftest import CONFIGS


def make_trial(tmp_path, edit):
    data = yaml.safe_load((CONFIGS / "trials" / "zz10.yaml").read_text())
    data["ship"] = str(CONFIGS / "ships" / "esso_osaka.yaml")
    edit(data)
    p = tmp_path / "trial.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


def run_bad(capsys, tmp_path, argv, field):
    out = tmp_path / "out"
    code = main(argv + ["--out", str(out)] if argv[0] == "simulate" else argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1, err
    assert field in err[0]
    assert not out.exists() or not any(out.iterdir())
    # no staging folders left behind
    assert not list(tmp_path.glob(".staging-*"))
    return err[0]


CASES = {
    "unknown key": (lambda d: d.update(colour="red"), "colour"),
    "unknown nested key": (lambda d: d["manoeuvre"].update(rudderr="10 deg"), "manoeuvre.rudderr"),
    "wrong type": (lambda d: d["log"].update(seed="abc"), "log.seed"),
    "wrong unit": (lambda d: d["manoeuvre"].update(rudder="10 m"), "manoeuvre.rudder"),
    "missing unit": (lambda d: d["approach"].update(speed=10), "approach.speed"),
    "negative speed": (lambda d: d["approach"].update(speed="-3 kn"), "approach.speed"),
    "rudder beyond limit": (lambda d: d["manoeuvre"].update(rudder="40 deg"), "manoeuvre.rudder"),
    "missing field": (lambda d: d.pop("duration"), "duration"),
    "unknown kind": (lambda d: d["manoeuvre"].update(kind="spiral"), "manoeuvre"),
    "log interval not a multiple of dt": (lambda d: d["log"].update(interval="5.05 s"), "log.interval"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_trial_config(case, tmp_path, capsys):
    edit, field = CASES[case]
    p = make_trial(tmp_path, edit)
    line = run_bad(capsys, tmp_path, ["simulate", str(p)], field)
    assert str(p) in line


def test_bad_ship_config(tmp_path, capsys):
    ship = yaml.safe_load((CONFIGS / "ships" / "esso_osaka.yaml").read_text())
    ship["hull"]["coefficients"]["Y_beta"]["term"] = "beta^7"
    sp = tmp_path / "ship.yaml"
    sp.write_text(yaml.safe_dump(ship))
    p = make_trial(tmp_path, lambda d: d.update(ship=str(sp)))
    line = run_bad(capsys, tmp_path, ["simulate", str(p)], "hull.coefficients.Y_beta.term")
    assert str(sp) in line


def test_malformed_yaml(tmp_path, capsys):
    p = tmp_path / "trial.yaml"
    p.write_text("name: [unclosed\n")
    run_bad(capsys, tmp_path, ["simulate", str(p)], "malformed YAML")


def test_missing_config_file(tmp_path, capsys):
    run_bad(capsys, tmp_path, ["simulate", str(tmp_path / "nope.yaml")], "file not found")


@pytest.fixture(scope="module")
def good_log(tmp_path_factory):
    d = tmp_path_factory.mktemp("sim")
    assert main(["simulate", str(CONFIGS / "trials" / "zz10.yaml"), "--out", str(d)]) == 0
    return d / "log.csv"


def _rewrite(src: Path, dst: Path, fn):
    lines = src.read_text().splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    body = [ln for ln in lines if not ln.startswith("#")]
    dst.write_text("\n".join(head + fn(body)) + "\n")
    return dst


def _set(body, row, col, value):
    cells = body[row].split(",")
    cells[col] = value
    body[row] = ",".join(cells)
    return body


LOG_CASES = {
    "NaN": (lambda b: _set(b, 10, 3, "nan"), "heading_deg"),
    "text in a number": (lambda b: _set(b, 10, 5, "fast"), "rpm"),
    "missing column": (lambda b: [",".join(ln.split(",")[:5]) for ln in b], "rpm"),
    "non-monotonic time": (lambda b: _set(b, 20, 0, "1"), "time_s"),
    "gap": (lambda b: b[:30] + b[60:], "time_s"),
}


@pytest.mark.parametrize("case", sorted(LOG_CASES))
def test_bad_log(case, good_log, tmp_path, capsys):
    fn, field = LOG_CASES[case]
    bad = _rewrite(good_log, tmp_path / "bad.csv", fn)
    code = main(["metrics", str(bad)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert str(bad) in err[0] and field in err[0]


def test_metrics_of_good_log(good_log, capsys):
    assert main(["metrics", str(good_log)]) == 0
    assert "overshoots_deg" in capsys.readouterr().out
