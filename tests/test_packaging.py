"""Packaging: the bundled configs are found in a checkout, an editable install and a wheel.

The fast tests check the checkout (this tree) and ``pyproject.toml``; the slow ones build
a wheel from a copy of the tree and install it (and an editable install of the copy) in
fresh virtual environments, then look the configs up from an empty folder.
"""
import fnmatch
import os
import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

import mmg
from mmg import resources

from .conftest import CONFIGS, REPO

PYPROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())
KINDS = ("ships", "trials", "estimation", "nomoto", "design")


def _config_files():
    return sorted(p for p in CONFIGS.rglob("*") if p.is_file() and "__pycache__" not in p.parts)


def test_config_dir_is_the_checkout_configs_here():
    # this tree is a checkout or an editable install: the configs are the top-level folder
    assert Path(mmg.__file__).resolve().is_relative_to(REPO)
    d = mmg.config_dir()
    assert d == CONFIGS.resolve()
    for kind in KINDS:
        assert (d / kind).is_dir(), kind


def test_every_config_is_found_through_resources():
    files = [p for p in _config_files() if p.suffix in (".yaml", ".csv")]
    assert len(files) >= 16
    for p in files:
        rel = p.relative_to(CONFIGS)
        found = resources.config_path(*rel.parts)
        assert found.read_bytes() == p.read_bytes(), rel
        assert resources.config_path(rel.as_posix()) == found
    assert resources.bundled("ships") == sorted(p.stem for p in (CONFIGS / "ships").glob("*.yaml"))
    for stem in resources.bundled("ships"):
        assert resources.ship_path(stem) == CONFIGS.resolve() / "ships" / f"{stem}.yaml"
        assert mmg.load_ship(stem).name
    for stem in resources.bundled("trials"):
        assert resources.trial_path(stem) == CONFIGS.resolve() / "trials" / f"{stem}.yaml"
        t = mmg.load_trial(stem)
        assert Path(t.ship_path).is_file() and Path(t.ship_path).is_relative_to(mmg.config_dir())


def test_missing_config_is_one_clear_line():
    with pytest.raises(mmg.InputError, match=r"^configs/ships/nope\.yaml: no such bundled config") as e:
        mmg.config_path("ships", "nope.yaml")
    assert "\n" not in str(e.value)
    with pytest.raises(mmg.InputError, match="unknown config kind"):
        resources.bundled("boats")


def test_paths_are_taken_as_paths(tmp_path):
    assert resources.ship_path(tmp_path / "x.yaml") == tmp_path / "x.yaml"
    assert resources.trial_path("some/dir/zz20") == Path("some/dir/zz20")
    assert resources.trial_path("zz20.yaml") == Path("zz20.yaml")  # a file name, not the bundled zz20


def test_pyproject_ships_every_package_and_config():
    st = PYPROJECT["tool"]["setuptools"]
    assert st["package-dir"]["mmg.configs"] == "configs"
    pkgs = set(st["packages"])
    on_disk = {".".join(p.parent.relative_to(REPO).parts) for top in ("mmg", "ekf", "trials")
               for p in (REPO / top).rglob("__init__.py") if "__pycache__" not in p.parts}
    missing = on_disk - pkgs
    assert not missing, f"add {sorted(missing)} to [tool.setuptools] packages in pyproject.toml"
    patterns = st["package-data"]["mmg.configs"]
    for p in _config_files():
        rel = p.relative_to(CONFIGS).as_posix()
        if p.name == "__init__.py":
            continue
        assert any(fnmatch.fnmatch(rel, pat) or fnmatch.fnmatch(rel, pat.removeprefix("**/"))
                   for pat in patterns), f"configs/{rel} would not ship: add its pattern to package-data"


def test_checkout_without_install(tmp_path):
    """Only the source folder on sys.path, no site-packages (python -S): the checkout's configs."""
    code = ("import sys; sys.path.insert(0, sys.argv[1]); import mmg, mmg.resources as r; "
            "print(mmg.__version__); print(r.config_dir()); print(r.trial_path('zz20'))")
    out = subprocess.run([sys.executable, "-S", "-c", code, str(REPO)], capture_output=True, text=True,
                         cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    version, cdir, zz20 = out.stdout.split("\n")[:3]
    # the checkout's egg-info (left by an earlier install) may be on the path: then its version
    assert version in ("0+unknown", PYPROJECT["project"]["version"])
    assert Path(cdir) == CONFIGS.resolve()
    assert Path(zz20) == CONFIGS.resolve() / "trials" / "zz20.yaml"


# --------------------------------------------------------------------------- slow: real installs

_IGNORE = shutil.ignore_patterns(".git", "build", "dist", "*.egg-info", "__pycache__", ".pytest_cache",
                                 "out", "*.pyc", ".hypothesis")

_PROBE = """
import sys, pathlib, mmg
from mmg import resources
d = mmg.config_dir()
print("mmg", pathlib.Path(mmg.__file__).resolve())
print("configs", d)
for kind in ("ships", "trials", "estimation", "nomoto", "design"):
    assert (d / kind).is_dir(), kind
print("n", sum(1 for _ in d.rglob("*.yaml")))
t = mmg.load_trial("zz20")
print("ship", t.ship_path)
res = mmg.simulate(mmg.turning("kvlcc2_l7", rudder="35 deg", speed="10 kn", duration="60 s"))
print("ok", res.t[-1], len(res.log()))
"""


def _probe(python: Path, cwd: Path) -> dict:
    out = subprocess.run([str(python), "-c", _PROBE], capture_output=True, text=True, cwd=cwd,
                         env={k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")})
    assert out.returncode == 0, out.stdout + out.stderr
    return dict(line.split(" ", 1) for line in out.stdout.splitlines() if " " in line)


def _pip(python: Path, *args, cwd=None):
    out = subprocess.run([str(python), "-m", "pip", "--disable-pip-version-check", *args],
                         capture_output=True, text=True, cwd=cwd)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]


@pytest.fixture(scope="module")
def source_copy(tmp_path_factory):
    src = tmp_path_factory.mktemp("src") / "mmg-toolkit"
    shutil.copytree(REPO, src, ignore=_IGNORE)
    return src


@pytest.mark.slow
def test_wheel_contains_configs_and_finds_them_when_installed(source_copy, tmp_path):
    whl_dir = tmp_path / "whl"
    _pip(Path(sys.executable), "wheel", "--no-deps", str(source_copy), "-w", str(whl_dir), cwd=tmp_path)
    (whl,) = whl_dir.glob("mmg_toolkit-*.whl")
    names = set(zipfile.ZipFile(whl).namelist())
    for p in _config_files():
        if p.suffix in (".yaml", ".csv"):
            assert f"mmg/configs/{p.relative_to(CONFIGS).as_posix()}" in names, p
    assert not any(n.startswith("configs/") for n in names)  # no top-level 'configs' package
    for top in ("mmg", "ekf", "trials"):
        for p in (REPO / top).rglob("*.py"):
            if "__pycache__" not in p.parts:
                assert p.relative_to(REPO).as_posix() in names, p
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    _pip(py, "install", str(whl))  # dependencies from the configured index
    empty = tmp_path / "empty"
    empty.mkdir()
    got = _probe(py, empty)
    site = Path(subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               capture_output=True, text=True, check=True).stdout.strip())
    assert Path(got["mmg"]).is_relative_to(site)
    assert Path(got["configs"]) == site / "mmg" / "configs"
    assert Path(got["ship"]) == site / "mmg" / "configs" / "ships" / "esso_osaka.yaml"
    assert int(got["n"]) == sum(1 for p in _config_files() if p.suffix == ".yaml")
    assert got["ok"].startswith("60")
    assert (venv / "bin" / "mmg").exists()


@pytest.mark.slow
def test_editable_install_finds_the_checkout_configs(source_copy, tmp_path):
    venv = tmp_path / "venv"
    # the dependencies from this interpreter's site-packages; only the copy is installed
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    py = venv / "bin" / "python"
    _pip(py, "install", "--no-deps", "-e", str(source_copy), cwd=tmp_path)
    empty = tmp_path / "empty"
    empty.mkdir()
    got = _probe(py, empty)
    assert Path(got["mmg"]).is_relative_to(source_copy.resolve())
    assert Path(got["configs"]) == (source_copy / "configs").resolve()
    assert Path(got["ship"]) == (source_copy / "configs" / "ships" / "esso_osaka.yaml").resolve()
