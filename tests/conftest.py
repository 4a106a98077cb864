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
FRT = REPO.parent / "shared" / "data" / "frt-ds-esso"


@pytest.fixture(scope="session")
def esso():
    from mmg.ship import load_ship

    return load_ship(CONFIGS / "ships" / "esso_osaka.yaml")


def needs_frt():
    return pytest.mark.skipif(not FRT.is_dir(), reason="FRT-DS-ESSO data folder ../shared/data/frt-ds-esso absent")


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
