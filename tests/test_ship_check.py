"""Records checked against their ship (:mod:`trials.files.shipcheck`).

* Every command that reads a record and analyses it with a ship or a length (predict, identify,
  diagnose, metrics, nomoto, estimate with --truth) refuses a record of another ship in one line
  naming the file and the ship, exit 2, nothing written: a full-scale log read as the 3 m model,
  a 3 m record read as the 325 m ship, a KVLCC2 model log as the Esso Osaka, a header length or
  ship that is not the ship's, a --length or --speed the record contradicts.
* Valid records are accepted: every real FRT-DS-ESSO 3 m record with both 3 m ships, every
  full-scale diagnose-dev log with esso_osaka (``../shared``, skipped where absent), the
  project's simulated logs and truth files with their ship.
* Regression: a full-scale record in the FRT-DS-ESSO layout is read with the length given
  (``--length``), not as the 3 m model; without a length the message says how to give it.
* Acceptance: ``mmg nomoto`` on a full-scale zigzag in the FRT layout with ``--length`` gives the
  same K, T1, T2, T3 as the same record in the project's truth format.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from .conftest import FRT, REPO

DEV = REPO.parent / "shared" / "data" / "diagnose-dev" / "data"
needs_frt = pytest.mark.needs_frt
needs_dev = pytest.mark.skipif(not DEV.is_dir(), reason=f"diagnose-dev data folder {DEV} absent")
FRT_ZIGZAG = FRT / "zigzag" / "zigzag_31-Jul-2020_13_14_21.csv"


def _cli(argv, capsys):
    from trials.cli import main

    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def _refused(rc, err, path, ship_words):
    """exit 2, one line on stderr naming the file and the ship."""
    assert rc == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert str(path) in lines[0] and ship_words in lines[0], lines[0]


def write_frt(rec, path, scale_length: float = 1.0, scale_speed: float = 1.0) -> Path:
    """``rec`` in the FRT-DS-ESSO column layout (:data:`trials.files.logio.FRT_COLUMNS`), heading wrapped to
    (-pi, pi]; optionally moved to another ship: lengths x ``scale_length``, speeds x ``scale_speed``
    (time x scale_length / scale_speed, yaw rate / that), so r L / U is unchanged."""
    from trials.files.logio import FRT_COLUMNS

    col = {v: k for k, v in FRT_COLUMNS.items()}
    ts = scale_length / scale_speed
    k = max(1, int(round(0.1 / (float(rec.t[1] - rec.t[0]) * ts))))     # about the layout's 10 Hz
    psi = rec.psi - 2 * np.pi * np.round(rec.psi / (2 * np.pi))
    pd.DataFrame({col["t"]: rec.t * ts, col["x"]: rec.x * scale_length, col["u"]: rec.u * scale_speed,
                  col["y"]: rec.y * scale_length, col["v"]: rec.v * scale_speed, col["psi"]: psi,
                  col["r"]: rec.r / ts, col["n"]: rec.n / ts, col["delta"]: rec.delta}).iloc[::k].to_csv(path, index=False)
    return path


@pytest.fixture(scope="module")
def sims(tmp_path_factory):
    """ZZ20 (325 m Esso Osaka) and KVLCC2 ZZ20 (7 m model) simulated, log and truth written by the project."""
    import mmg
    from trials.files.logio import write_csv

    d = tmp_path_factory.mktemp("sims")
    out = {}
    for name in ("zz20", "kvlcc2_zz20"):
        res = mmg.simulate(mmg.load_trial(REPO / "configs" / "trials" / f"{name}.yaml"))
        meta = res.log_meta()
        write_csv(d / f"{name}_log.csv", res.log(), meta)
        write_csv(d / f"{name}_truth.csv", res.truth(), meta)
        out[name] = (d / f"{name}_log.csv", d / f"{name}_truth.csv")
    return out


@pytest.fixture(scope="module")
def model3m(tmp_path_factory, sims):
    """3 m model records in the FRT layout: a real zigzag where ../shared has it, and ZZ20's truth
    Froude-scaled to 3 m (always)."""
    from trials.files.logio import read_record

    d = tmp_path_factory.mktemp("model3m")
    lam = 3.0 / 325.0
    scaled = write_frt(read_record(sims["zz20"][1]), d / "zz20_3m.csv", lam, np.sqrt(lam))
    return [scaled] + ([FRT_ZIGZAG] if FRT_ZIGZAG.is_file() else [])


@pytest.fixture(scope="module")
def full_frt(tmp_path_factory, sims):
    """ZZ20's truth (325 m, 5.14 m/s) in the FRT layout, and moved to a 120 m ship at 6 m/s."""
    from trials.files.logio import read_record

    d = tmp_path_factory.mktemp("full_frt")
    rec = read_record(sims["zz20"][1])
    return write_frt(rec, d / "zz20_frt.csv"), write_frt(rec, d / "zz20_120m.csv", 120 / 325, 6.0 / 5.1444444)


# --------------------------------------------------------------------------- regression: FRT layout with --length


def test_frt_full_scale_with_length_accepted(full_frt, tmp_path, capsys):
    """A 120 m ship at 6 m/s in the FRT layout: metrics and nomoto with --length 120 run (exit 0), not
    refused as a 3 m ship ('Froude number 1.11 for a 3 m ship')."""
    rec120 = full_frt[1]
    rc, out, err = _cli(["metrics", rec120, "--length", "120", "--json", tmp_path / "m.json"], capsys)
    assert rc == 0, err
    m = json.loads((tmp_path / "m.json").read_text())
    assert m["kind"] == "zigzag" and m["length_m"] == 120
    rc, out, err = _cli(["nomoto", rec120, "--length", "120", "--no-output-error", "--json", tmp_path / "a.json"], capsys)
    assert rc == 0, err


def test_frt_full_scale_without_length_says_how(full_frt, capsys):
    """Without a length the layout's 3 m model is assumed and the refusal says to give --length."""
    for rec in full_frt:
        rc, out, err = _cli(["metrics", rec], capsys)
        _refused(rc, err, rec, "3 m")
        assert "--length" in err


# --------------------------------------------------------------------------- every command refuses another ship's record


def test_predict_refuses_other_ship(sims, model3m, tmp_path, capsys):
    log, truth = sims["zz20"]
    for rec in (log, truth):
        rc, out, err = _cli(["predict", "--ship", "esso_osaka_3m", rec, "--json", tmp_path / "p.json"], capsys)
        _refused(rc, err, rec, "Esso Osaka 3 m model")
    # the full-scale log together with a 3 m record in one call
    rc, out, err = _cli(["predict", "--ship", "esso_osaka_3m", model3m[0], log, "--json", tmp_path / "p.json"], capsys)
    _refused(rc, err, log, "Esso Osaka 3 m model")
    for rec in model3m:                    # a 3 m record with the full-scale ship
        rc, out, err = _cli(["predict", "--ship", "esso_osaka", rec, "--json", tmp_path / "p.json"], capsys)
        _refused(rc, err, rec, "Esso Osaka (L = 325 m)")
    assert not (tmp_path / "p.json").exists()


def test_identify_refuses_other_ship(sims, model3m, tmp_path, capsys):
    """Not skipped and fitted on the rest: the call is refused (the record is of another ship)."""
    log = sims["zz20"][0]
    for train in ([log], [model3m[0], log]):
        rc, out, err = _cli(["identify", "--ship", "esso_osaka_3m", "--train", *train, "--out", tmp_path / "id"], capsys)
        _refused(rc, err, log, "Esso Osaka 3 m model")
        assert not (tmp_path / "id" / "ship.yaml").exists()


def test_diagnose_refuses_other_ship(sims, model3m, tmp_path, capsys):
    log = sims["zz20"][0]
    rc, out, err = _cli(["diagnose", "--ship", "esso_osaka_3m", model3m[0], log, "--json", tmp_path / "d.json"], capsys)
    _refused(rc, err, log, "Esso Osaka 3 m model")
    rc, out, err = _cli(["diagnose", "--ship", "esso_osaka", model3m[0], "--json", tmp_path / "d.json"], capsys)
    _refused(rc, err, model3m[0], "Esso Osaka (L = 325 m)")
    assert not (tmp_path / "d.json").exists()


def test_metrics_refuses_length_the_record_contradicts(sims, model3m, capsys):
    for rec in model3m:                    # a 3 m record called 300 m long
        rc, out, err = _cli(["metrics", rec, "--length", "300"], capsys)
        _refused(rc, err, rec, "L = 300 m")
    log = sims["zz20"][0]                  # a project log whose header says 325 m
    rc, out, err = _cli(["metrics", log, "--length", "3"], capsys)
    _refused(rc, err, log, "L = 3 m")
    assert "length_m" in err


def test_nomoto_refuses_length_or_speed_the_record_contradicts(model3m, sims, capsys):
    for rec in model3m:
        rc, out, err = _cli(["nomoto", rec, "--length", "300", "--no-output-error"], capsys)
        _refused(rc, err, rec, "L = 300 m")
        rc, out, err = _cli(["nomoto", rec, "--length", "3", "--speed", "1000", "--no-output-error"], capsys)
        assert rc == 2 and "--speed" in err and len(err.strip().splitlines()) == 1, err
        rc, out, err = _cli(["nomoto", rec, "--length", "3", "--speed", "1.5", "--no-output-error"], capsys)
        assert rc == 2 and "--speed" in err and "times" in err, err      # Fn 0.28, but 3 to 4 times the record's speed
    log = sims["kvlcc2_zz20"][0]                                          # header: 7 m
    rc, out, err = _cli(["nomoto", log, "--length", "3", "--no-output-error"], capsys)
    _refused(rc, err, log, "L = 3 m")


def test_estimate_refuses_truth_of_another_ship(tmp_path, capsys):
    """A log and truth of a ship that is not the Esso Osaka (same length, other N_r): the true values would be
    the Esso Osaka's; refused naming the truth file and both ships.  The old code estimated and reported
    the Esso Osaka's N_r as the truth."""
    import mmg
    import yaml
    from trials.files.logio import write_csv

    ship = yaml.safe_load((REPO / "configs" / "ships" / "esso_osaka.yaml").read_text())
    ship["name"] = "Esso Osaka sister"
    ship_file = tmp_path / "sister.yaml"
    ship_file.write_text(yaml.safe_dump(ship))
    trial = yaml.safe_load((REPO / "configs" / "trials" / "zz20.yaml").read_text())
    trial["ship"] = str(ship_file)
    trial["duration"] = "600 s"
    tfile = tmp_path / "zz20_sister.yaml"
    tfile.write_text(yaml.safe_dump(trial))
    res = mmg.simulate(mmg.load_trial(tfile))
    log, truth = tmp_path / "log.csv", tmp_path / "truth.csv"
    write_csv(log, res.log(), res.log_meta())
    write_csv(truth, res.truth(), res.log_meta())
    rc, out, err = _cli(["estimate", log, "--truth", truth, "--out", tmp_path / "est"], capsys)
    _refused(rc, err, truth, "Esso Osaka sister")
    assert "'Esso Osaka'" in err
    assert not (tmp_path / "est").exists()
    # with the log's own ship the header agrees: read and checked without complaint
    from ekf.estimate import load_config
    from trials.estimates.estimation import load_inputs

    d = load_inputs([log], load_config(None), ship=str(ship_file), truth=str(truth))
    assert d[0].ship.name == "Esso Osaka sister"


def test_estimate_refuses_kvlcc2_log_with_esso(sims):
    from ekf.estimate import load_config
    from mmg.errors import InputError
    from trials.estimates.estimation import load_inputs

    log, truth = sims["kvlcc2_zz20"]
    for ship in ("esso_osaka", "esso_osaka_3m"):
        with pytest.raises(InputError, match="length_m") as e:
            load_inputs([str(log)], load_config(REPO / "configs" / "estimation" / "kvlcc2_l7.yaml"), ship=ship,
                        truth=str(truth))
        assert str(log) in str(e.value) and "Esso Osaka" in str(e.value)


# --------------------------------------------------------------------------- valid records accepted, crossed refused


def _check(path, ship):
    from trials.files.shipcheck import read_for_ship

    return read_for_ship(path, ship)


@needs_frt
@pytest.mark.parametrize("ship", ["esso_osaka_3m", "esso_osaka_3m_crossflow"])
def test_real_3m_records_accepted(ship):
    """Every real record (turning, zigzag, random, berthing: low speed and astern included) with the 3 m ships."""
    import mmg
    from trials.files.shipcheck import ShipMismatch

    s = mmg.load_ship(ship)
    files = sorted(FRT.glob("*/*.csv"))
    assert len(files) >= 30
    bad = []
    for p in files:
        try:
            _check(p, s)
        except ShipMismatch as e:
            bad.append(str(e))
    assert not bad, bad


@needs_frt
def test_real_3m_records_refused_as_full_scale():
    import mmg
    from trials.files.shipcheck import ShipMismatch

    s = mmg.load_ship("esso_osaka")
    for p in sorted(FRT.glob("*/*.csv")):
        with pytest.raises(ShipMismatch, match=re.escape("Esso Osaka (L = 325 m)")):
            _check(p, s)


@needs_dev
def test_full_scale_dev_logs_accepted_and_refused_as_models():
    """The independent simulator's full-scale logs: accepted with esso_osaka, refused with the 3 m and 7 m models."""
    import mmg
    from trials.files.shipcheck import ShipMismatch

    files = sorted(DEV.glob("*.csv"))
    assert len(files) >= 30
    esso, m3, kv = (mmg.load_ship(k) for k in ("esso_osaka", "esso_osaka_3m", "kvlcc2_l7"))
    for p in files:
        _check(p, esso)
        for s in (m3, kv):
            with pytest.raises(ShipMismatch, match=re.escape(f"{s.name} (L = {s.particulars.L:g} m)")):
                _check(p, s)


def test_project_records_accepted_with_their_ship(sims):
    import mmg

    esso, kv, m3 = (mmg.load_ship(k) for k in ("esso_osaka", "kvlcc2_l7", "esso_osaka_3m"))
    for p in sims["zz20"]:
        _check(p, esso)
    for p in sims["kvlcc2_zz20"]:
        _check(p, kv)


def test_project_records_refused_with_another_ship(sims, full_frt):
    """Crossed by header and, without a header (the FRT copy of ZZ20), by the kinematics alone."""
    import mmg
    from trials.files.shipcheck import ShipMismatch

    esso, kv, m3 = (mmg.load_ship(k) for k in ("esso_osaka", "kvlcc2_l7", "esso_osaka_3m"))
    for p in sims["zz20"]:
        for s in (kv, m3):
            with pytest.raises(ShipMismatch, match="length_m"):
                _check(p, s)
    for p in sims["kvlcc2_zz20"]:
        for s in (esso, m3):
            with pytest.raises(ShipMismatch, match="length_m"):
                _check(p, s)
    with pytest.raises(ShipMismatch, match="speed"):
        _check(full_frt[0], m3)


# --------------------------------------------------------------------------- acceptance: nomoto FRT vs project format


def test_nomoto_frt_layout_equals_project_format(full_frt, sims, tmp_path, capsys):
    """ZZ20's truth file and its FRT-layout copy (same channels, same 0.1 s sampling, the heading wrapped to
    (-pi, pi] which leaves it unchanged) read to the same record bit for bit, so every identification
    (the output-error fit included: a deterministic function of the record) gives the same K, T1, T2, T3;
    the CLI is run on both without the slow output-error fit and its JSON compared exactly."""
    from trials.files.logio import read_record

    truth, frt = sims["zz20"][1], full_frt[0]
    a, b = read_record(truth), read_record(frt, length_m=325.0)
    for c in ("t", "psi", "r", "delta", "u", "v", "U", "x", "y", "n"):
        assert np.array_equal(getattr(a, c), getattr(b, c)), c
    docs = []
    for rec in (truth, frt):
        js = tmp_path / f"{Path(rec).stem}.json"
        rc, out, err = _cli(["nomoto", rec, "--length", "325", "--no-output-error", "--json", js], capsys)
        assert rc == 0, err
        docs.append(json.loads(js.read_text()))
    x, y = docs
    keys = [k for k in x if k not in ("record", "source", "name")]
    assert keys and {k: x[k] for k in keys} == {k: y[k] for k in keys}


# --------------------------------------------------------------------------- checks judge only the channels used


def test_plausibility_checks_judge_only_the_channels_a_command_uses(sims, tmp_path, capsys):
    """ZZ20's log with its rpm column x 10 (a tip speed of ~190 m/s for the 325 m ship): ``mmg nomoto``, which
    never reads the propeller, identifies it; ``mmg metrics``, which reads it, refuses it naming the column
    `rpm`; check_record_ship with channels leaving out ``n`` accepts the record, with ``n`` refuses it."""
    from trials.files.logio import read_record
    from trials.files.shipcheck import ShipMismatch, check_record_ship, tip_speed

    src = sims["zz20"][0]
    lines = src.read_text().splitlines()
    head = next(i for i, ln in enumerate(lines) if ln.startswith("time_s"))
    assert lines[head].split(",")[5] == "rpm"
    rows = [ln.split(",") for ln in lines[head + 1:]]
    for r in rows:
        r[5] = repr(float(r[5]) * 10)
    bad = tmp_path / "zz20_rpm_x10.csv"
    bad.write_text("\n".join(lines[:head + 1] + [",".join(r) for r in rows]) + "\n")
    rec = read_record(bad)
    assert tip_speed(np.percentile(rec.n, 99), 0.02 * 325.0) > 80.0          # the implausible channel
    rc, out, err = _cli(["nomoto", bad, "--length", "325", "--no-output-error"], capsys)
    assert rc == 0, err
    rc, out, err = _cli(["metrics", bad], capsys)
    assert rc == 2 and err.strip().startswith(f"error: {bad}: rpm: "), err
    check_record_ship(rec, 325.0, channels=("psi", "delta", "r", "U", "u", "v"))
    with pytest.raises(ShipMismatch):
        check_record_ship(rec, 325.0, channels=("psi", "n"))
