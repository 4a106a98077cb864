"""bench/version_folds.py: another version's fit runs that version's code (not the checkout's), a fit past
its time limit is stopped and reported, the per-kind means are the hand sums, and a run in other folds is
named."""
from __future__ import annotations

from pathlib import Path

from .conftest import load_bench


def _load():
    return load_bench("version_folds")


def _fake_version(root: Path, body: str) -> Path:
    """A version root whose ``trials.cli.main`` runs ``body`` (``args``: its command-line arguments)."""
    (root / "trials").mkdir(parents=True)
    (root / "trials" / "__init__.py").write_text("")
    (root / "trials" / "cli.py").write_text("import sys\n\ndef main():\n    args = sys.argv[1:]\n" + body)
    return root


def test_the_fit_runs_the_given_versions_code(tmp_path):
    vf = _load()
    body = ("    out = args[args.index('--out') + 1]\n    import os, trials\n    os.makedirs(out)\n"
            "    open(out + '/ship.yaml', 'w').write(trials.__file__ + ' ' + ' '.join(args))\n    return 0\n")
    root = _fake_version(tmp_path / "v", body)
    res = vf.fit_fold(root, ["a.csv", "b.csv"], tmp_path / "run", ship="s3m", timeout_min=5)
    assert res["status"] == "done"
    assert res["trials_file"] == str(root / "trials" / "__init__.py")
    written = Path(res["ship_yaml"]).read_text()
    assert written.startswith(str(root / "trials" / "__init__.py"))       # the fake, not this checkout's trials
    assert "identify --ship s3m --train a.csv b.csv --out" in written


def test_a_fit_past_its_limit_is_stopped_and_reported(tmp_path):
    vf = _load()
    root = _fake_version(tmp_path / "v", "    import time\n    time.sleep(600)\n")
    res = vf.fit_fold(root, ["a.csv"], tmp_path / "run", timeout_min=0.02)
    assert res["status"] == "timeout" and res["ship_yaml"] is None
    failed = vf.fit_fold(_fake_version(tmp_path / "w", "    return 3\n"), ["a.csv"], tmp_path / "run2")
    assert failed["status"] == "failed (exit 3)" and failed["ship_yaml"] is None


def _rec(name, s, i, ws, wi):
    return {"name": name, "scaled": {"heading_rms_deg": s, "window_heading_rms_deg": ws},
            "identified": {"heading_rms_deg": i, "window_heading_rms_deg": wi}}


def test_kind_means_are_the_hand_sums_over_the_same_records():
    vf = _load()
    mine = [_rec("random_a", 100.0, 40.0, 12.0, 10.0), _rec("random_b", 80.0, 60.0, 14.0, 8.0),
            _rec("turn_c", 30.0, 20.0, 6.0, 5.0)]
    # the other run has one more random record, outside the folds scored here: left out of its mean
    other = {"records": [_rec("random_a", 100.0, 70.0, 12.0, 9.0), _rec("random_b", 80.0, 30.0, 14.0, 7.0),
                         _rec("random_z", 80.0, 500.0, 14.0, 99.0), _rec("turn_c", 30.0, 25.0, 6.0, 4.0)]}
    rows = {r[0]: r for r in vf.kind_rows(mine, {"other": other})}
    # random: scaled (100 + 80) / 2 = 90, windows 13; mine (40 + 60) / 2 = 50, windows 9; other (70 + 30) / 2 = 50, 8
    assert rows["random"] == ["random", "2", "90.0 / 13.0", "50.0 / 9.0", "50.0 / 8.0"]
    assert rows["turn"] == ["turn", "1", "30.0 / 6.0", "20.0 / 5.0", "25.0 / 4.0"]
    assert set(rows) == {"random", "turn"}


def test_a_run_in_other_folds_is_named():
    vf = _load()
    folds = [(["x/b.csv"], ["x/a.csv"]), (["x/a.csv"], ["x/b.csv"])]
    same = {"records": [{"name": "a", "fold": 0}, {"name": "b", "fold": 1}]}
    moved = {"records": [{"name": "a", "fold": 1}, {"name": "b", "fold": 1}, {"name": "c", "fold": 0}]}
    assert vf.fold_check(folds, same) == []
    assert vf.fold_check(folds, moved) == ["a", "c"]


def test_the_versions_own_predict_is_read_per_record(tmp_path):
    vf = _load()
    body = ("    import json\n    out = args[args.index('--json') + 1]\n"
            "    assert args[0] == 'predict' and args[args.index('--wind') + 1] == 'on'\n"
            "    json.dump({'runs': [{'file': 'x/random_a.csv', 'heading_rms_deg': 12.5},\n"
            "                        {'file': 'x/turn_b.csv', 'heading_rms_deg': float('nan')}]}, open(out, 'w'))\n"
            "    return 0\n")
    root = _fake_version(tmp_path / "v", body)
    (tmp_path / "run").mkdir()
    got = vf.version_predict(root, tmp_path / "ship.yaml", ["x/random_a.csv", "x/turn_b.csv"], tmp_path / "run")
    assert got == {"random_a": 12.5, "turn_b": None}
