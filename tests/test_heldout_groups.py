"""bench/heldout_groups.py's table: per-kind and overall means of held-out heading RMS and their ratios,
checked against sums done by hand on made-up numbers; the folds keep a run's cuts together and share
no record."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from .conftest import load_bench


def _load():
    return load_bench("heldout_groups")


def _row(fold, record, kind, s, i):
    return {"fold": fold, "record": record, "kind": kind, "scaled_deg": s, "identified_deg": i}


def test_kind_means_and_ratios_are_the_hand_sums():
    hg = _load()
    rows = [_row("A", "b1", "berthing", 10.0, 4.0), _row("A", "r1", "random", 120.0, 60.0),
            _row("B", "r2", "random", 60.0, 90.0), _row("B", "b2", "berthing", 20.0, 6.0)]
    t = hg.heldout_table(rows)
    assert list(t.kinds) == ["random", "berthing"]                     # KINDS' order, not the rows'
    # random: scaled (120 + 60) / 2 = 90, identified (60 + 90) / 2 = 75, ratio 1.2
    assert t.kinds["random"]["scaled_deg"] == pytest.approx(90.0)
    assert t.kinds["random"]["identified_deg"] == pytest.approx(75.0)
    assert t.kinds["random"]["ratio"] == pytest.approx(1.2)
    # berthing: 15 over 5 = 3
    assert t.kinds["berthing"]["ratio"] == pytest.approx(3.0)
    # all four records: 210 / 4 over 160 / 4
    assert t.overall["ratio"] == pytest.approx(210.0 / 160.0)
    # every kind alike: (90 + 15) / (75 + 5)
    assert t.overall["kind_mean_ratio"] == pytest.approx(105.0 / 80.0)
    assert t.overall["n"] == 4 and t.overall["n_diverged"] == 0
    # identified lower on r1, b1, b2; medians of (10, 20, 60, 120) and (4, 6, 60, 90)
    assert t.overall["n_better"] == 3 and t.kinds["random"]["n_better"] == 1
    assert (t.overall["scaled_median_deg"], t.overall["identified_median_deg"]) == pytest.approx((40.0, 33.0))
    assert t.kinds["berthing"]["identified_median_deg"] == pytest.approx(5.0)


def test_a_diverged_replay_is_counted_and_left_out_of_both_means():
    hg = _load()
    t = hg.heldout_table([_row("A", "r1", "random", 100.0, math.nan), _row("A", "r2", "random", 40.0, 20.0)])
    d = t.kinds["random"]
    assert d["n"] == 2 and d["n_diverged"] == 1
    assert (d["scaled_deg"], d["identified_deg"], d["ratio"]) == pytest.approx((40.0, 20.0, 2.0))
    assert t.to_json()["rows"][0]["identified_deg"] is None
    assert "| random | 2 | 1 | 40.0 | 20.0 | 2.00x | 1 | 40.0 | 20.0 |" in t.to_markdown()


def test_rows_from_predict_match_by_file_not_by_order():
    hg = _load()
    scaled = {"runs": [{"file": "/d/random/x.csv", "heading_rms_deg": 100.0},
                       {"file": "/d/berthing/y.csv", "heading_rms_deg": 9.0}]}
    ident = {"runs": [{"file": "/d/berthing/y.csv", "heading_rms_deg": 3.0},
                      {"file": "/d/random/x.csv", "heading_rms_deg": None}]}
    rows = hg.rows_from_predict("B", scaled, ident)
    assert rows[0]["record"] == "x" and rows[0]["kind"] == "random" and math.isnan(rows[0]["identified_deg"])
    assert rows[1] == _row("B", "y", "berthing", 9.0, 3.0)
    with pytest.raises(ValueError, match="x.csv"):
        hg.rows_from_predict("B", scaled, {"runs": ident["runs"][:1]})


def test_folds_share_no_record_and_keep_the_cuts_of_one_run_together():
    hg = _load()
    a, b = set(hg.FOLDS["A"]), set(hg.FOLDS["B"])
    assert not a & b
    cuts = {p for p in a | b if "06-Aug-2020_16_24_25" in p}
    assert len(cuts) == 4 and (cuts <= a or cuts <= b)
    assert {Path(p).parent.name for p in a | b} == {"random", "berthing"}
