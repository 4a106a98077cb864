"""Logs: write -> read round trips, the real-data reader, and property tests of the parser."""
import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings, strategies as st

from mmg.errors import InputError
from trials.files.logio import LOG_COLUMNS, read_record, write_csv
from trials.runs.run import run_trial
from trials.runs.trial import load_trial

from .conftest import CONFIGS, FRT, needs_frt


@pytest.fixture(scope="module")
def zz20_run():
    return run_trial(load_trial(CONFIGS / "trials" / "zz20.yaml"))


def test_truth_round_trip(zz20_run, tmp_path):
    p = tmp_path / "truth.csv"
    write_csv(p, zz20_run.truth(), zz20_run.log_meta())
    rec = read_record(p)
    r = zz20_run.result
    for name, arr in (("u", r.u), ("v", r.v), ("r", r.r), ("delta", r.delta), ("x", r.x), ("y", r.y), ("psi", r.psi), ("n", r.n)):
        np.testing.assert_allclose(getattr(rec, name), arr, rtol=1e-9, atol=1e-12)
    # a second write of the record read back gives the identical record
    p2 = tmp_path / "truth2.csv"
    write_csv(p2, zz20_run.truth(), zz20_run.log_meta())
    assert read_record(p2).equals(rec)
    assert rec.meta["trial"] == "ZZ20" and rec.meta["seed"] == 3


def test_log_round_trip_and_noise_levels(zz20_run, tmp_path):
    p = tmp_path / "log.csv"
    df = zz20_run.log()
    write_csv(p, df, zz20_run.log_meta())
    rec = read_record(p)
    back = pd.DataFrame({"time_s": rec.t, "lat_deg": 35 + rec.x / 111120.0, "lon_deg": 129 + rec.y / 91569.6,
                         "heading_deg": np.mod(np.degrees(rec.psi), 360), "speed_kn": rec.U / (1852 / 3600),
                         "rpm": rec.n * 60})
    np.testing.assert_allclose(back.to_numpy(), df.to_numpy(), rtol=1e-9, atol=1e-8)
    # the noise is uniform within the Table 4 levels
    r = zz20_run.result
    sel = slice(0, None, 50)
    assert np.max(np.abs(rec.x - r.x[sel])) <= 8e-7 * 111120.0 + 1e-6
    assert np.max(np.abs(rec.psi - r.psi[sel])) <= np.radians(1.2e-2) + 1e-9
    assert np.max(np.abs(rec.n - r.n[sel])) * 60 <= 0.2 + 1e-9
    assert np.max(np.abs(rec.psi - r.psi[sel])) > 0  # noise is there
    assert np.all(np.diff(rec.t) == 5.0)


def test_same_seed_same_log(zz20_run):
    pd.testing.assert_frame_equal(zz20_run.log(), zz20_run.log())


@needs_frt()
def test_reads_real_zigzag():
    f = sorted((FRT / "zigzag").glob("*.csv"))[0]
    rec = read_record(f)
    assert set(rec.channels()) >= {"x", "y", "psi", "u", "v", "r", "n", "delta"}
    assert np.all(np.abs(np.diff(rec.psi)) < 0.5)  # unwrapped
    assert rec.meta["length_m"] == 3.0


finite = st.floats(-1e4, 1e4, allow_nan=False, allow_infinity=False)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(finite, finite, st.floats(0, 359.9), st.floats(0, 20), st.floats(0, 100)), min_size=2, max_size=30))
def test_reader_accepts_any_well_formed_log(tmp_path_factory, rows):
    p = tmp_path_factory.mktemp("h") / "log.csv"
    df = pd.DataFrame([(5.0 * i, 35 + a / 1e6, 129 + b / 1e6, h, s, n) for i, (a, b, h, s, n) in enumerate(rows)],
                      columns=LOG_COLUMNS)
    write_csv(p, df, {"trial": "h"})
    rec = read_record(p)
    assert len(rec.t) == len(rows)
    diff = (np.degrees(rec.psi) - df["heading_deg"].to_numpy() + 180.0) % 360.0 - 180.0
    assert np.max(np.abs(diff)) < 1e-6


@settings(max_examples=40, deadline=None)
@given(st.text(max_size=200))
def test_reader_never_crashes_on_garbage(tmp_path_factory, text):
    p = tmp_path_factory.mktemp("g") / "junk.csv"
    p.write_text(text)
    try:
        read_record(p)
    except InputError as e:
        assert str(p) in str(e)


def test_sensor_bias_shifts_the_log(tmp_path):
    import yaml
    from dataclasses import replace

    from trials.runs.trial import SensorBias

    tr = load_trial(CONFIGS / "trials" / "zz10.yaml")
    tr = replace(tr, duration=100.0)
    run = run_trial(tr)
    biased = run_trial(replace(tr, log=replace(tr.log, bias=SensorBias(np.radians(0.5), 0.0, 1.0 / 60))))
    a, b = run.log(), biased.log()
    d = (b["heading_deg"] - a["heading_deg"] + 180) % 360 - 180
    np.testing.assert_allclose(d, 0.5, atol=1e-9)
    np.testing.assert_allclose(b["rpm"] - a["rpm"], 1.0, atol=1e-9)
    # and from YAML
    data = yaml.safe_load((CONFIGS / "trials" / "zz10.yaml").read_text())
    data["ship"] = str(CONFIGS / "ships" / "esso_osaka.yaml")
    data["log"]["bias"] = {"heading": "0.5 deg", "rpm": "1 rpm"}
    p = tmp_path / "t.yaml"
    p.write_text(yaml.safe_dump(data))
    assert load_trial(p).log.bias == SensorBias(np.radians(0.5), 0.0, 1.0 / 60)
