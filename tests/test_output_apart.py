"""No output over an input, nor two outputs on one path (V4): every command refuses, in one line and
before any work, an output file (``--json``, ``--out-ship``, the files a ``--out`` or ``--plots``
folder receives) that is the same file as an input (records, ``--ship``, ``--initial``, ``--train``,
``--test``, ...) or as another output; relative paths, symlinks and hard links resolved."""
import os
import shutil
from pathlib import Path

import pytest

from trials.cli import main

from .conftest import CONFIGS, FRT, needs_frt

SHIP = CONFIGS / "ships" / "esso_osaka_3m.yaml"


def zigzag():
    return sorted((FRT / "zigzag").glob("*.csv"))[0]


@pytest.fixture
def work(tmp_path, monkeypatch):
    """A folder with a copy of a real record (rec.csv) and of the 3 m ship (s.yaml), the current folder."""
    monkeypatch.chdir(tmp_path)
    shutil.copy(zigzag(), tmp_path / "rec.csv")
    shutil.copy(SHIP, tmp_path / "s.yaml")
    os.symlink("rec.csv", tmp_path / "link.csv")
    os.link(tmp_path / "s.yaml", tmp_path / "hard.yaml")
    return tmp_path


def refused(capsys, argv, *kept):
    """argv refused: exit 2, one error line naming an output option; the files ``kept`` unchanged."""
    before = {p: Path(p).read_bytes() for p in kept}
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: --"), err
    assert "Traceback" not in err[0]
    for p, b in before.items():
        assert Path(p).read_bytes() == b, f"{p} was overwritten"
    return err[0]


CASES = [
    ["predict", "--ship", "esso_osaka_3m", "--json", "rec.csv", "rec.csv"],
    ["predict", "--ship", "esso_osaka_3m", "--json", "./sub/../rec.csv", "rec.csv"],
    ["predict", "--ship", "esso_osaka_3m", "--json", "link.csv", "rec.csv"],         # a symlink to the input
    ["predict", "--ship", "s.yaml", "--json", "s.yaml", "rec.csv"],                   # the ship config
    ["predict", "--ship", "s.yaml", "--json", "hard.yaml", "rec.csv"],                # a hard link to it
    ["metrics", "--json", "rec.csv", "rec.csv"],
    ["metrics", "--json", "link.csv", "rec.csv"],
    ["diagnose", "--ship", "esso_osaka_3m", "--json", "same.yaml", "--out-ship", "same.yaml", "rec.csv"],
    ["diagnose", "--ship", "s.yaml", "--json", "d.json", "--out-ship", "s.yaml", "rec.csv"],
    ["diagnose", "--ship", "s.yaml", "--json", "d.json", "--out-ship", "rec.csv", "rec.csv"],
    ["identify", "--ship", "ship.yaml", "--train", "rec.csv", "--out", "."],          # DIR/ship.yaml is the input
    ["identify", "--ship", "s.yaml", "--train", "rec.csv", "--test", "report.md", "--out", "."],
]


@needs_frt()
@pytest.mark.parametrize("argv", CASES, ids=[" ".join(c[:1] + c[3:6]) for c in CASES])
def test_output_over_an_input_refused(work, capsys, argv):
    shutil.copy(SHIP, work / "ship.yaml")
    (work / "report.md").write_text("a user's notes\n")
    (work / "sub").mkdir()
    line = refused(capsys, argv, "rec.csv", "s.yaml", "ship.yaml", "report.md")
    assert "destroy the input" in line or "also the output" in line
    assert not (work / "same.yaml").exists() and not (work / "d.json").exists()


@needs_frt()
def test_bundled_ship_yaml_is_an_input(work, capsys):
    """The bundled ship's own YAML, named by its path, is an input too."""
    from mmg.resources import ship_path

    p = str(ship_path("esso_osaka_3m"))
    refused(capsys, ["predict", "--ship", "esso_osaka_3m", "--json", p, "rec.csv"], p)


def test_distinct_paths_still_run_the_check_only():
    """Distinct outputs and inputs pass the check (the command then does its own work)."""
    from trials.cli import build_parser
    from trials.cli.common import check_outputs_apart

    args = build_parser().parse_args(["predict", "--ship", str(SHIP), "--json", "x.json", str(SHIP.parent)])
    check_outputs_apart(args)
