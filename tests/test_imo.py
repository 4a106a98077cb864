"""``mmg imo`` / ``mmg.imo``: the IMO manoeuvring criteria (MSC.137(76)) and their uncertainty.

The limits are checked against the standard's table written out here (not read from the code), the
full-scale Esso Osaka's figures against the same manoeuvres simulated through ``mmg.simulate`` from
the bundled trial YAMLs and the trial builders (another path: other durations, other construction),
the CLI's JSON against the schema the issue spells out.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

import mmg
from trials.cli import main

# ----------------------------------------------------------------- the standard, written out independently
# IMO Resolution MSC.137(76), Annex 5.3: (L/V [s], 10/10 first overshoot limit, second) [deg]
ZZ10_TABLE = [
    (5.0, 10.0, 25.0),
    (9.99, 10.0, 25.0),
    (10.0, 10.0, 25.0),          # 5 + 10/2, 17.5 + 7.5: continuous at 10 s
    (20.0, 15.0, 32.5),          # 5 + 10,   17.5 + 15
    (29.0, 19.5, 39.25),         # 5 + 14.5, 17.5 + 21.75
    (30.0, 20.0, 40.0),
    (40.0, 20.0, 40.0),
    (63.2, 20.0, 40.0),
]
FIXED = {"advance": 4.5, "tactical diameter": 5.0, "initial turning track reach": 2.5,
         "20/20 first overshoot": 25.0}
UNITS = {"advance": "L", "tactical diameter": "L", "initial turning track reach": "L", "10/10 first overshoot": "deg",
         "10/10 second overshoot": "deg", "20/20 first overshoot": "deg", "stopping track reach": "L"}
PER_SIDE = ("advance", "tactical diameter", "initial turning track reach", "10/10 first overshoot",
            "10/10 second overshoot", "20/20 first overshoot")
EXPECTED_NAMES = {f"{c}, {s}" for c in PER_SIDE for s in ("starboard", "port")} | {"stopping track reach"}


@pytest.mark.parametrize("LV, first, second", ZZ10_TABLE)
def test_limits_follow_the_standard(LV, first, second):
    from trials.analysis.metrics import imo_criteria
    from trials.imo.standard import criteria

    lim = {c.name: c.limit for c in criteria(LV)}
    assert set(lim) == EXPECTED_NAMES
    for s in ("starboard", "port"):
        assert lim[f"10/10 first overshoot, {s}"] == pytest.approx(first, abs=1e-12)
        assert lim[f"10/10 second overshoot, {s}"] == pytest.approx(second, abs=1e-12)
        for name, v in FIXED.items():
            assert lim[f"{name}, {s}"] == v
    assert lim["stopping track reach"] == 15.0
    # the older per-ship table (mmg reproduce) reads the same limits: one definition of each
    old = {r["criterion"]: r["limit"] for r in imo_criteria(LV, 1.0, {"advance_L": 1.0}, {"overshoots_deg": [1.0, 1.0]},
                                                              {"overshoots_deg": [1.0]})}
    assert old["10/10 first overshoot (deg)"] == pytest.approx(first, abs=1e-12)
    assert old["10/10 second overshoot (deg)"] == pytest.approx(second, abs=1e-12)
    assert old["advance (L)"] == 4.5 and old["tactical diameter (L)"] == 5.0
    assert old["20/20 first overshoot (deg)"] == 25.0


# ----------------------------------------------------------------- the CLI on the full-scale ship

@pytest.fixture(scope="module")
def cli_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("imo") / "out"
    code = main(["imo", "esso_osaka", "--out", str(out)])
    assert code == 0
    return out, json.loads((out / "imo.json").read_text())


def _simulated(trial):
    m = mmg.simulate(trial).metrics()
    ov = m.get("overshoots_deg") or []
    return m, ov


def test_figures_equal_those_of_simulate(cli_run):
    """The turning and zigzag figures of imo.json are those of the same manoeuvres through mmg.simulate:
    starboard from the bundled YAMLs (3000 s runs), port from the trial builders."""
    _, doc = cli_run
    got = {c["name"]: c["value"] for c in doc["criteria"]}
    ship = mmg.load_ship("esso_osaka")
    kw = {"speed": "10 kn", "duration": "3000 s"}
    runs = {"starboard": (_simulated("st35"), _simulated("zz10"), _simulated("zz20")),
            "port": (_simulated(mmg.turning(ship, rudder="-35 deg", **kw)),
                     _simulated(mmg.zigzag(ship, rudder="10 deg", heading="10 deg", first="port", **kw)),
                     _simulated(mmg.zigzag(ship, rudder="20 deg", heading="20 deg", first="port", **kw)))}
    for side, ((st, _), (z10, ov10), (_, ov20)) in runs.items():
        want = {"advance": st["advance_L"], "tactical diameter": st["tactical_diameter_L"],
                "initial turning track reach": z10["distance_to_second_execute_L"],
                "10/10 first overshoot": ov10[0], "10/10 second overshoot": ov10[1], "20/20 first overshoot": ov20[0]}
        for name, v in want.items():
            assert got[f"{name}, {side}"] == pytest.approx(v, rel=1e-9, abs=1e-12), (name, side)
    # and the verdicts are those values against the standard's limits (L/V = 325 m / 10 kn = 63.2 s)
    lim = {**FIXED, "10/10 first overshoot": 20.0, "10/10 second overshoot": 40.0}
    for c in doc["criteria"]:
        if c["name"] != "stopping track reach":
            assert c["verdict"] == ("pass" if c["value"] <= lim[c["name"].split(",")[0]] else "fail")


def test_cli_writes_the_exact_schema(cli_run):
    out, doc = cli_run
    assert list(doc) == ["ship", "criteria"]
    assert doc["ship"] == "Esso Osaka"
    assert {c["name"] for c in doc["criteria"]} == EXPECTED_NAMES
    assert len(doc["criteria"]) == len(EXPECTED_NAMES)
    for c in doc["criteria"]:
        assert list(c) == ["name", "value", "unit", "limit", "interval", "probability", "verdict"]
        assert c["unit"] == UNITS[c["name"].split(",")[0]]
        assert c["interval"] is None and c["probability"] is None
        if c["name"] == "stopping track reach":
            assert c["value"] is None and c["verdict"] == "not available" and c["limit"] == 15.0
        else:
            assert isinstance(c["value"], float) and c["verdict"] in ("pass", "fail")
    md = (out / "imo.md").read_text()
    assert "MSC.137(76)" in md and "MSC/Circ.1053" in md and "four-quadrant" in md
    for name in EXPECTED_NAMES:
        assert f"| {name} |" in md
    assert (out / "tracks.png").stat().st_size > 10000 and (out / "zigzags.png").stat().st_size > 10000


@pytest.mark.parametrize("argv, names", [
    (["imo", "no_such_ship"], "no_such_ship"),
    (["imo", "esso_osaka", "--speed", "10"], "--speed"),
    (["imo", "esso_osaka", "--speed", "-2 kn"], "--speed"),
    (["imo", "esso_osaka_3m"], "--speed"),                    # no bundled trial gives its speed
    (["imo", "esso_osaka", "--samples", "4"], "--samples"),   # no covariance in the bundled ship
])
def test_bad_input_is_one_line(argv, names, tmp_path, capsys):
    out = tmp_path / "o"
    assert main(argv + ["--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and names in err[0]
    assert not out.exists()
