"""A record without a channel an effect of the ship config needs (the measured relative wind of a
wind-on ship): every command that replays records skips that effect with one line saying so on
stderr and finishes; none crashes on the missing channel (with an AttributeError in mmg/effects/wind.py,
say).

The records are real FRT-DS-ESSO zigzags with their wind columns dropped (the data set is not made
by this project), cut to 40 s to keep the tests short."""
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from tests.conftest import FRT, needs_frt

pytestmark = needs_frt()


def _zigzag_csv():
    return sorted((FRT / "zigzag").glob("*.csv"))[0]


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    """(with wind, without wind): the first 40 s of a real zigzag, as logged and without its wind columns."""
    d = tmp_path_factory.mktemp("rec")
    df = pd.read_csv(_zigzag_csv())
    df = df[df["t [s]"] <= 40.0]
    windy, calm = d / "windy.csv", d / "calm.csv"
    df.to_csv(windy, index=False)
    df.drop(columns=[c for c in df.columns if c.startswith("wind")]).to_csv(calm, index=False)
    return windy, calm


def _mmg(*args):
    return subprocess.run([sys.executable, "-m", "trials.cli", *map(str, args)], capture_output=True, text=True)


def _skipped_once(r, path):
    """Finished, no traceback, and one stderr line naming the record and the skipped wind."""
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.startswith(f"{path}: wind skipped")]
    assert len(lines) == 1 and "wind_speed_rel" in lines[0], r.stderr


@pytest.mark.parametrize("command", ["identify", "diagnose", "predict"])
def test_cli_skips_the_wind_of_a_record_without_wind_columns(tmp_path, records, command):
    _, calm = records
    if command == "identify":
        r = _mmg("identify", "--ship", "esso_osaka_3m", "--train", calm, "--out", tmp_path / "o", "--free", "w_P0")
    elif command == "diagnose":         # wind in the model from the start, as the ship config has it
        r = _mmg("diagnose", "--ship", "esso_osaka_3m", calm, "--json", tmp_path / "d.json", "--wind", "on")
    else:
        r = _mmg("predict", "--ship", "esso_osaka_3m", calm, "--json", tmp_path / "p.json")
    _skipped_once(r, calm)


def test_measured_run_drops_the_wind_it_cannot_feed_and_keeps_the_rest(records):
    """The one rule (EffectSet.usable) in measured_run: no wind left in the run's effects for a record
    without wind channels; the other effects of the config stay; a windy record keeps its loads."""
    import mmg
    from mmg.effects import effect_set
    from dataclasses import replace
    from trials.files.logio import read_record
    from trials.measured.predict import measured_run

    windy, calm = records
    ship = mmg.load_ship("esso_osaka_3m")
    ship = replace(ship, effects=ship.effect_set().merged(effect_set({"rudder_offset": {"offset_deg": 1.0}})))
    run = measured_run(ship, read_record(calm, length_m=3.0))
    assert run.inputs.ext is None and run.wind == "no wind channels"
    assert run.effects.names() == ["rudder_offset"]
    assert any("wind skipped" in n for n in run.notes)
    w = measured_run(ship, read_record(windy, length_m=3.0))
    assert w.wind == "on" and w.inputs.ext is not None and np.abs(w.inputs.ext).max() > 0
    assert w.effects.names() == ["rudder_offset"]              # the wind is in the loads


def test_diagnose_with_wind_on_gives_the_same_baseline_as_without_wind(records):
    """A record without wind columns: wind on (skipped) and wind off are the same model, so the same
    baseline residuals (before the fix the wind stayed in the model as NaN loads and the baseline
    came out 100 times smaller than the record's misfit)."""
    from trials.measured.diagnose import diagnose

    import mmg

    _, calm = records
    ship = mmg.load_ship("esso_osaka_3m")
    on = diagnose(ship, [calm], wind=True, candidates=[]).rms_before
    off = diagnose(ship, [calm], wind=False, candidates=[]).rms_before
    for c in off:
        assert on[c] == pytest.approx(off[c], rel=1e-9)


def test_identify_mixed_records_fits_the_wind_scale_on_the_windy_one(records):
    """Records with and without wind given together: each is replayed with the wind it has (the
    windy one with its measured loads, the calm one without), and the wind scale stays free."""
    import mmg
    from trials.measured.identify import identify

    windy, calm = records
    said = []
    ident = identify(mmg.load_ship("esso_osaka_3m"), [windy, calm], free=("w_P0", "wind_scale"), say=said.append,
                     max_nfev=3)
    assert [r.wind for r in ident.runs] == ["on", "no wind channels"]
    assert "wind_scale" in ident.fit.values()
