"""The project's own current log: ``mmg simulate`` of the bundled ZZ20 with a 1 kn current
setting towards 60 deg (the 5 s sea-trial log: positions, heading, speed over ground; no u, v),
diagnosed with the ship that made it, at the default fit budgets and at larger ones, to show what
the budget changes (``tests/test_diagnose_own_logs.py`` holds the acceptance test itself).

    python bench/diagnose_own_current.py [--budgets 12:6 40:20]
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
KN = 1852.0 / 3600.0


def make_log(folder: Path) -> Path:
    from mmg.resources import config_path

    spec = yaml.safe_load(open(config_path("trials", "zz20.yaml")))
    spec["effects"] = {"current": {"speed_mps": 1.0 * KN, "direction_deg": 60.0}}
    p = folder / "zz20_current.yaml"
    p.write_text(yaml.safe_dump(spec))
    subprocess.run([sys.executable, "-m", "trials.cli", "simulate", str(p), "--out", str(folder / "out")], check=True,
                   capture_output=True)
    return folder / "out" / "log.csv"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budgets", nargs="+", default=["12:6", "40:20"], help="max_nfev:screen_nfev pairs")
    a = ap.parse_args(argv)
    import mmg
    from trials.measured.diagnose import diagnose

    ship = mmg.load_ship("esso_osaka")
    with tempfile.TemporaryDirectory() as tmp:
        log = make_log(Path(tmp))
        print(f"truth: current {KN:.3f} m/s towards 60 deg (ZZ20, 5 s log, speed over ground only)")
        for b in a.budgets:
            mx, sc = (int(x) for x in b.split(":"))
            t0 = time.perf_counter()
            d = diagnose(ship, [log], max_nfev=mx, screen_nfev=sc)
            vals = "; ".join(f"{e} " + ", ".join(f"{k} {v:.3g}" for k, v in p.items()) for e, p in d.parameters.items())
            print(f"max_nfev {mx}, screen_nfev {sc}: named {d.named or 'nothing'}: {vals or '-'} "
                  f"({time.perf_counter() - t0:.0f} s)", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
