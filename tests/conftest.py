import signal
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
