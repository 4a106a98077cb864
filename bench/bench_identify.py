"""How long ``mmg identify`` takes over every shared FRT-DS-ESSO record (the default options), as a user runs it.

Runs the command as a whole process ``--repeat`` times (a fresh process each, numba's cache warm after the
first) and prints each run's wall time and the median.  The records are looked up as ``mmg reproduce`` does
(``MMG_FRT_DATA``, else ``../shared/data/frt-ds-esso`` beside the repository).

Usage: ``python bench/bench_identify.py [--repeat 1] [--out DIR] [-- EXTRA mmg identify OPTIONS]``.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from trials.files.data import FRT_MISSING, frt_folder  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=1, help="runs to time (default 1)")
    ap.add_argument("--out", default=None, help="output folder (default a temporary one)")
    ap.add_argument("extra", nargs="*", help="more mmg identify options, after --")
    a = ap.parse_args(argv)
    data = frt_folder()
    logs = sorted(str(p) for p in data.glob("*/*.csv")) if data is not None else []
    if not logs:
        print(f"bench_identify: {FRT_MISSING}", file=sys.stderr)
        return 2
    walls = []
    with tempfile.TemporaryDirectory() as tmp:
        out = a.out or str(Path(tmp) / "ident")
        for k in range(a.repeat):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "trials.cli", "identify", "--ship", "esso_osaka_3m", "--train", *logs,
                            "--out", out, *a.extra], check=True, cwd=REPO, stdout=subprocess.DEVNULL)
            walls.append(time.perf_counter() - t0)
            print(f"run {k + 1}: {walls[-1]:.0f} s wall ({len(logs)} records)", flush=True)
    walls.sort()
    print(f"mmg identify over {len(logs)} records: median {walls[len(walls) // 2]:.0f} s wall "
          f"(limit 300 s on this 2-core machine)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
