"""The straight-run solver interpreted against compiled: what running ``mmg.model.rhs`` and
``forces`` by the interpreter (:func:`mmg._jit.interpreted`, what :func:`mmg.equilibrium.straight_run`
does) costs a warm simulation, and how far its solution is from the compiled functions'.

    python bench/bench_straight_run.py [--repeat 20]

Prints the median time of a straight run (Esso Osaka at 10 kn, constant power) each way, their
ratio, and the largest relative difference of the solved rpm, sway velocity and trim rudder.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import mmg.equilibrium as E  # noqa: E402
from mmg.model import forces, rhs  # noqa: E402
from mmg.ship import load_ship  # noqa: E402
from mmg.units import KNOT  # noqa: E402


def timed(ship, repeat):
    E.straight_run(ship, 10 * KNOT)                 # compiled / cloned once, not timed
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        eq = E.straight_run(ship, 10 * KNOT)
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), eq


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=20)
    a = ap.parse_args(argv)
    ship = load_ship("esso_osaka")
    ti, ei = timed(ship, a.repeat)
    interpreted_functions = E.model_functions
    E.model_functions = lambda: (rhs, forces)       # the JIT-compiled functions
    try:
        tc, ec = timed(ship, a.repeat)
    finally:
        E.model_functions = interpreted_functions
    diff = max(abs(getattr(ei, f) - getattr(ec, f)) / max(abs(getattr(ec, f)), 1e-12) for f in ("n", "v", "delta"))
    print(f"straight run (Esso Osaka, 10 kn): interpreted {ti * 1e3:.2f} ms, compiled {tc * 1e3:.2f} ms "
          f"(median of {a.repeat}), ratio {ti / tc:.1f}; solutions differ by {diff:.1e} (relative, n, v, delta)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
