from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
CONFIGS = REPO / "configs"
FRT = REPO.parent / "shared" / "data" / "frt-ds-esso"


@pytest.fixture(scope="session")
def esso():
    from mmg.ship import load_ship

    return load_ship(CONFIGS / "ships" / "esso_osaka.yaml")


def needs_frt():
    return pytest.mark.skipif(not FRT.is_dir(), reason="FRT-DS-ESSO data folder ../shared/data/frt-ds-esso absent")
