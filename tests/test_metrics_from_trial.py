"""A metric the trial defines is filled from the trial when the record lacks the channel it is measured from:
``rudder_deg`` of a simulated turn (execute set by the trial) and of every log without a rudder column."""
from __future__ import annotations

import json

import pytest
import yaml

from .conftest import CONFIGS


def _commanded_deg(name):
    """The rudder the trial YAML commands, read from the file by hand ("35 deg")."""
    text = yaml.safe_load((CONFIGS / "trials" / f"{name}.yaml").read_text())["manoeuvre"]["rudder"]
    value, unit = text.split()
    assert unit == "deg"
    return float(value)


@pytest.mark.parametrize("name", ["st35", "stype120"])
def test_rudder_deg_filled_from_the_trial(name, tmp_path, capsys):
    """``mmg simulate`` writes the commanded rudder as rudder_deg (not null, not '-'), and ``mmg metrics`` of the
    log it wrote (which has no rudder column) gives the same from the log's header, with a note saying so;
    no metric of the completed trial is null."""
    from trials.cli import main

    assert main(["simulate", str(CONFIGS / "trials" / f"{name}.yaml"), "--out", str(tmp_path / "sim")]) == 0
    out = capsys.readouterr().out
    m = json.loads((tmp_path / "sim" / "metrics.json").read_text())
    assert m["rudder_deg"] == pytest.approx(_commanded_deg(name))
    row = next(ln for ln in out.splitlines() if ln.split() and ln.split()[0] == "rudder_deg")
    assert row.split()[1] != "-"
    assert [k for k, v in m.items() if v is None] == []
    assert main(["metrics", str(tmp_path / "sim" / "log.csv"), "--json", str(tmp_path / "m.json")]) == 0
    r = json.loads((tmp_path / "m.json").read_text())
    assert r["rudder_deg"] == pytest.approx(_commanded_deg(name))
    assert any("rudder_deg is the trial's commanded" in n for n in r["notes"])


def test_metrics_refuses_a_trial_kind_it_does_not_measure(tmp_path, capsys):
    """A crash-stop log: the error names the header's kind (the cause), not a zigzag's missing rudder."""
    from trials.cli import main

    assert main(["simulate", str(CONFIGS / "trials" / "crash_stop.yaml"), "--out", str(tmp_path / "sim")]) == 0
    capsys.readouterr()
    log = tmp_path / "sim" / "log.csv"
    assert main(["metrics", str(log)]) == 2
    assert capsys.readouterr().err.strip() == (f"error: {log}: kind: the header's trial kind is stopping: mmg metrics "
                                               "measures turning, zigzag and S-type trials (pass --kind to read the "
                                               "record as one)")
