import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

# A suite started in the background by a non-interactive shell (``pytest ... &``, nohup) inherits
# SIGINT ignored, and so would every command the Ctrl-C tests start (an ignored signal stays ignored
# across exec, as it should for a user's background job): give this process Python's handler, so its
# children start with the default disposition the tests assume.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

REPO = Path(__file__).resolve().parents[1]
CONFIGS = REPO / "configs"
from trials.files.data import FRT_MISSING, frt_folder, frt_place  # noqa: E402

FRT_FOUND = frt_folder()
"""The FRT-DS-ESSO folder (:func:`trials.files.data.frt_folder`), None when no records are found."""
FRT = frt_place()


def load_bench(name: str):
    """The script ``bench/<name>.py`` imported as module ``bench_<name>`` (registered in ``sys.modules``,
    so its dataclasses resolve their annotations)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(f"bench_{name}", REPO / "bench" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod
"""Where the records are (or would be): tests marked :func:`needs_frt` run only when they are found."""


@pytest.fixture(scope="session")
def esso():
    from mmg.ship import load_ship

    return load_ship(CONFIGS / "ships" / "esso_osaka.yaml")


def needs_frt():
    """The ``needs_frt`` marker: the test is skipped, naming how to point to the data, when
    :func:`trials.files.data.frt_folder` finds no FRT-DS-ESSO records."""
    return pytest.mark.needs_frt


@pytest.fixture(scope="session")
def frt():
    """The FRT-DS-ESSO folder; the test is skipped when no records are found."""
    if FRT_FOUND is None:
        pytest.skip(FRT_MISSING)
    return FRT_FOUND


def pytest_collection_modifyitems(config, items):
    if FRT_FOUND is not None:
        return
    skip = pytest.mark.skip(reason=FRT_MISSING)
    for item in items:
        if item.get_closest_marker("needs_frt") is not None:
            item.add_marker(skip)


def frt_skip_summary(reasons) -> str | None:
    """The one summary line naming the tests skipped for want of the FRT-DS-ESSO records among the skip
    ``reasons`` (one string per skipped test), None when there were none."""
    n = sum(FRT_MISSING in str(r) for r in reasons)
    return f"{n} test{'s' if n != 1 else ''} skipped: {FRT_MISSING}" if n else None


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    reasons = [rep.longrepr[2] if isinstance(rep.longrepr, tuple) else rep.longrepr
               for rep in terminalreporter.stats.get("skipped", [])]
    line = frt_skip_summary(reasons)
    if line:
        terminalreporter.write_line(line, yellow=True)


# --------------------------------------------------------------------------- cold numba cache
# A fresh install or a CI run starts with numba's on-disk cache empty, and the first test to call
# each compiled pass compiles it, on one core, while the other core idles.  When the cache is cold,
# the filters', replay's and sensitivities' specialisations are compiled by
# ``python -m trials.cli.warmup --serial`` on the second core while the first tests run (they build the
# simulator's own module; trials.cli.warmup.SUITE_GROUPS, in the order the tests need them): a later
# test loads them from the cache.  It writes only into numba's cache and is stopped when the run
# ends; MMG_TEST_WARMUP=0 turns it off.
_warmup = None


def pytest_configure(config):
    global _warmup
    config.addinivalue_line("markers", "needs_frt: runs only where the real FRT-DS-ESSO records are found (MMG_FRT_DATA)")
    if os.environ.get("MMG_TEST_WARMUP", "1") == "0" or config.option.collectonly:
        return
    from trials.cli.warmup import SUITE_GROUPS, filter_cache_cold

    if not filter_cache_cold():
        return
    cmd = [sys.executable, "-m", "trials.cli.warmup", "--serial", "--quiet"]
    for g in SUITE_GROUPS:
        cmd += ["--group", g]
    _warmup = subprocess.Popen(cmd, cwd=REPO, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)


def pytest_unconfigure(config):
    if _warmup is not None and _warmup.poll() is None:     # a short or interrupted run: not needed any more
        _warmup.terminate()
        _warmup.wait()


@pytest.fixture
def diagnose_rules(tmp_path, monkeypatch):
    """A function ``set(**values)`` that puts a copy of the packaged diagnosis rules
    (``configs/calibration/diagnose_rules.yaml``) with those entries' values changed in use through
    ``MMG_DIAGNOSE_RULES`` and returns its path; the packaged rules are in use again after the test."""
    import yaml

    from trials.measured.diagnose import rules as R

    def put(**values):
        doc = yaml.safe_load((R.config_dir() / "calibration" / "diagnose_rules.yaml").read_text())
        for k, v in values.items():
            doc[k]["value"] = v
        p = tmp_path / "diagnose_rules.yaml"
        p.write_text(yaml.safe_dump(doc))
        monkeypatch.setenv(R.ENV, str(p))
        R.rules.cache_clear()
        return p

    yield put
    monkeypatch.delenv(R.ENV, raising=False)
    R.rules.cache_clear()
