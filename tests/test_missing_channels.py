"""A channel a record does not log: errors name its column by its exact header (the cause) first, and no
command reports it as if measured.  Records are copies of an FRT-DS-ESSO CSV with one column dropped."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from mmg.errors import InputError
from tests.conftest import FRT, needs_frt

ZIGZAG = FRT / "zigzag" / "zigzag_31-Jul-2020_14_03_39.csv"


def _without(tmp_path, column, src=ZIGZAG):
    df = pd.read_csv(src)
    assert column in df.columns
    out = tmp_path / f"no_{column.split()[0]}.csv"
    df.drop(columns=[column]).to_csv(out, index=False)
    return out


@needs_frt()
@pytest.mark.parametrize("argv", [["nomoto", "--length", "3", "--no-output-error"], ["metrics"],
                                  ["diagnose", "--ship", "esso_osaka_3m", "--json", "{out}"]],
                         ids=["nomoto", "metrics", "diagnose"])
def test_missing_rudder_column_is_named_first(tmp_path, capsys, argv):
    """Each command that needs the rudder names the missing column `delta_rudder [rad]` as the error's field."""
    from trials.cli import main

    log = _without(tmp_path, "delta_rudder [rad]")
    argv = [a.replace("{out}", str(tmp_path / "out" / "d.json")) for a in argv]
    assert main([argv[0], str(log), *argv[1:]]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: {log}: delta_rudder [rad]: missing column"), err
    assert not (tmp_path / "out").exists()


def test_rebuilt_rudder_of_a_log_without_kind_names_the_rudder_column():
    """A project log (layout 'log') without rudder_deg and without a trial kind in its header: the error's
    field is the absent column rudder_deg, not the header key."""
    from trials.files.records import TrialRecord
    from trials.files.rudder import manoeuvre_from_meta, with_rebuilt_rudder

    t = np.arange(0.0, 100.0, 5.0)
    rec = TrialRecord(t=t, psi=0 * t, source="log.csv", meta={"format": "log"})
    with pytest.raises(InputError) as e:
        with_rebuilt_rudder(rec)
    assert e.value.field == "rudder_deg" and e.value.message.startswith("missing column")
    with pytest.raises(InputError) as e:
        manoeuvre_from_meta({}, "log.csv")
    assert e.value.field == "rudder_deg"


@needs_frt()
@pytest.mark.parametrize("column, channel, instead", [("r_angvelo [rad/s]", "r", "differentiated from the logged heading"),
                                                     ("vm_velo [m/s]", "v", "")], ids=["r", "v"])
def test_diagnose_says_a_channel_was_not_logged(tmp_path, column, channel, instead):
    """A record without its yaw rate (sway) column: the diagnosis says in its JSON and console lines that the
    channel was not logged, by its column, and what its residual compared instead; a channel compared with
    nothing (v) has no residual RMS (None), not the 0 of a residual never formed."""
    from mmg.resources import ship_path
    from mmg.ship import load_ship
    from trials.measured.diagnose import diagnose, prepare

    ship = load_ship(ship_path("esso_osaka_3m"))
    recs = prepare(ship, [_without(tmp_path, column)])
    d = diagnose(ship, recs, candidates=["heading_bias"], max_nfev=2, screen_nfev=1)
    js = d.to_json()
    entry = next(e for e in js["absent_channels"] if e["channel"] == channel)
    assert entry["column"] == column and entry["record"] == recs[0].name
    assert (instead in entry["compared_instead"]) if instead else entry["compared_instead"] == ""
    line = next(ln for ln in d.summary_lines() if ln.strip().startswith(f"{channel} not logged by"))
    assert column in line and (instead in line if instead else "no residual" in line)
    if not instead:
        assert js["rms_after"][channel] is None and js["rms_config"][channel] is None
    else:
        assert js["rms_after"][channel] > 0
    assert set(recs[0].absent) >= {channel}
