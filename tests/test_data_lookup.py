"""One lookup of the real FRT-DS-ESSO records (trials.files.data.frt_folder) and what a skipped test says."""
from __future__ import annotations

import os
import subprocess
import sys

from trials.files.data import FRT_MISSING, frt_folder

from .conftest import REPO, frt_skip_summary, needs_frt


def test_an_empty_folder_is_no_data_and_the_reason_says_how_to_point_to_it(tmp_path, monkeypatch):
    monkeypatch.setenv("MMG_FRT_DATA", str(tmp_path))
    assert frt_folder() is None
    assert "MMG_FRT_DATA=" in FRT_MISSING
    line = frt_skip_summary([f"Skipped: {FRT_MISSING}", "Skipped: something else", FRT_MISSING])
    assert line.startswith("2 tests skipped: FRT-DS-ESSO records not found") and "MMG_FRT_DATA=" in line
    assert frt_skip_summary(["Skipped: something else"]) is None


def test_a_folder_with_records_is_found_and_the_variable_wins(tmp_path, monkeypatch):
    (tmp_path / "zigzag").mkdir()
    (tmp_path / "zigzag" / "zz.csv").write_text("t\n0\n")
    monkeypatch.setenv("MMG_FRT_DATA", str(tmp_path))
    assert frt_folder() == tmp_path
    monkeypatch.setenv("MMG_FRT_DATA", str(tmp_path / "absent"))
    assert frt_folder() is None


@needs_frt()
def test_marked_probe():
    """Runs where the records are; skipped (with the summary line) in the run below."""
    assert frt_folder() is not None


def test_a_run_without_the_data_names_the_skipped_tests_and_how_to_set_the_folder(tmp_path):
    env = {**os.environ, "MMG_FRT_DATA": str(tmp_path), "MMG_TEST_WARMUP": "0"}
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rs",
                          f"{__file__}::test_marked_probe"], cwd=REPO, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "1 skipped" in out.stdout
    assert f"1 test skipped: {FRT_MISSING}" in out.stdout, out.stdout
