"""bench/before_after.py: which numbers it reads from the CLI's outputs, which it leaves out, and
that it finds a changed number among equal ones (on hand-written outputs; the script's own run on
two git revisions is in its docstring)."""
from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from .conftest import load_bench

BENCH = Path(__file__).resolve().parents[1] / "bench"


@pytest.fixture(scope="module")
def ba():
    return load_bench("before_after")


def values(numbers):
    return [v for _, v in numbers]


def test_numbers_of_a_console_line(ba):
    line = ("turn_14-Sep-2020_14_16_04: heading 12.05 deg RMS, w_P0 -1.5e-3, final position 1.894 m "
            "(0.6315 L), 95 %: 0.551-0.632 deg, [3/16], 1/2 rho, dT/dt +0.954")
    assert values(ba.text_numbers(line)) == [12.05, -0.0015, 1.894, 0.6315, 95.0, 0.551, 0.632, 3.0, 16.0,
                                             1.0, 2.0, 0.954]


def test_timings_paths_and_dates_are_left_out(ba):
    line = ("identified 22 parameters in 131 s: iteration 4: cost 39635 (24 s) [2/16] 1 samples (5.5 s) "
            "wrote /tmp/before_after_x1/after/identify/ship.yaml on 2026-12-04 13:51:45")
    assert values(ba.text_numbers(line)) == [22.0, 4.0, 39635.0, 2.0, 16.0, 1.0]


def test_json_walk_keeps_physical_seconds_and_drops_the_runs_timing(ba):
    doc = {"seconds": 66.8, "named": True, "rms": {"u": 0.0147}, "warnings": ["Y_rr changed sign: 0.04686 to -0.49"],
           "straight_runs": [{"samples": 11, "seconds": 10.0}], "runs": [{"seconds": 3.1, "z": 2.5}]}
    assert ba.tree_numbers(doc) == [("/named", 1.0), ("/rms/u", 0.0147), ("/warnings/0 line 1", 0.04686),
                                    ("/warnings/0 line 1", -0.49), ("/straight_runs/0/samples", 11.0),
                                    ("/straight_runs/0/seconds", 10.0), ("/runs/0/z", 2.5)]


def test_equal_is_exact_unless_a_tolerance_is_given(ba):
    a, b = 0.1 + 0.2, 0.3                       # differ in the last bit: 5.55e-17
    assert not ba.equal(a, b)
    assert ba.equal(a, b, rtol=1e-15)
    assert not ba.equal(1.0, 1.001, rtol=1e-4)
    assert ba.equal(math.nan, math.nan) and not ba.equal(math.nan, 0.0)
    assert ba.equal(math.inf, math.inf) and not ba.equal(math.inf, -math.inf, rtol=1.0)


def test_text_compare_counts_a_missing_number(ba):
    n, diffs = ba.compare_numbers([("line 1", 1.0), ("line 2", 2.0)], [("line 1", 1.0)])
    assert n == 2 and len(diffs) == 1 and diffs[0][0].startswith("count 2 before, 1 after")


def test_keyed_compare_names_the_changed_and_the_missing_path(ba):
    before = [("/a", 1.0), ("/b", 2.0), ("/c line 1", 3.0), ("/c line 1", 4.0)]
    after = [("/a", 1.0), ("/b", 2.5), ("/c line 1", 3.0), ("/c line 1", 4.0), ("/d", 5.0)]
    n, diffs = ba.compare_numbers(before, after, keyed=True)
    assert n == 5
    assert diffs == [("/b", 2.0, 2.5), ("/d", None, 5.0)]


def test_compare_command_finds_the_one_changed_number(ba, tmp_path):
    """Two runs whose outputs differ in timings, paths, one JSON number and one printed number."""
    runs = {}
    for side, (t, x, printed) in {"before": (12, 0.5913091790829833, "0.591"),
                                  "after": (30, 0.5913091790829834, "0.592")}.items():
        out = tmp_path / side / "diagnose_dev_01"
        out.mkdir(parents=True)
        (out / "stdout.txt").write_text(f"heading_bias bias {printed} deg (95 %: 0.551-0.632 deg)\n"
                                        f"wrote {out}/diagnosis.json in {t} s\n")
        (out / "stderr.txt").write_text("")
        (out / "diagnosis.json").write_text(json.dumps({"parameters": {"heading_bias": {"bias_deg": x}},
                                                        "seconds": t * 1.01, "files": [str(out)]}))
        (out / "figure.png").write_bytes(b"\x89PNG")
        runs[side] = ba.Command("diagnose", "diagnose_dev_01", [], {"exit": 0, "seconds": t, "folder": str(out)})
    r = ba.compare_command(runs["before"], runs["after"], rtol=0.0)
    assert r["outputs"] == 3                      # stdout, stderr, the JSON; the figure is not read
    assert r["numbers"] == 4 + 1                  # 0.591, 95, 0.551, 0.632 printed; bias_deg
    where = sorted(d[0] for d in r["differences"])
    assert len(where) == 2
    assert where[0].endswith("diagnosis.json /parameters/heading_bias/bias_deg")
    assert where[1].endswith("stdout.txt line 1")
    assert ba.compare_command(runs["before"], runs["after"], rtol=1e-15)["differences"][0][1:] == (0.591, 0.592)


def test_a_tree_the_package_does_not_import_from_is_refused(ba, tmp_path, capsys):
    """The commands must run the tree's own code: a folder without it (the package found elsewhere,
    through PYTHONPATH) stops the script with exit 2."""
    repo = BENCH.parent
    env = ba.child_env(repo, tmp_path)
    ba.check_import(repo, env)                  # the checkout itself: its own code
    with pytest.raises(SystemExit) as stopped:
        ba.check_import(tmp_path, env)
    assert stopped.value.code == 2
    assert f"does not import from {tmp_path}" in capsys.readouterr().err
