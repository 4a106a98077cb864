"""Benchmark: a 3000 s 35 deg turn of the Esso Osaka at 0.1 s step.

Prints the median of several runs after the one-time numba compilation, steps
per second and the ratio to real time, and a pure-Python (interpreted) run of
the same right-hand side for the before/after ratio.  Run:

    python bench/bench_simulator.py [--repeat 5]
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from mmg.integrate import CommandLaw, integrate
from mmg.ship import load_ship
from mmg.simulation import prepare
from mmg.units import DEG, KNOT

REPO = Path(__file__).resolve().parents[1]


def python_rk4(pk, x0, dcmd, dt, nsteps):
    """The same RK4 over the same model, run by the interpreter (numba's py_func)."""
    from mmg import model as M

    f = M.rhs.py_func
    x = x0.copy()
    k = [np.zeros(8) for _ in range(4)]
    for _ in range(nsteps):
        f(x, dcmd, *pk.args(), k[0])
        f(x + 0.5 * dt * k[0], dcmd, *pk.args(), k[1])
        f(x + 0.5 * dt * k[1], dcmd, *pk.args(), k[2])
        f(x + dt * k[2], dcmd, *pk.args(), k[3])
        x = x + dt / 6 * (k[0] + 2 * k[1] + 2 * k[2] + k[3])
    return x


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--python-steps", type=int, default=2000, help="steps of the interpreted run (scaled up)")
    a = ap.parse_args()
    ship = load_ship(REPO / "configs" / "ships" / "esso_osaka.yaml")
    pk, eq = prepare(ship, 10 * KNOT)
    law = CommandLaw.schedule([0.0, 3000.0], [35 * DEG, 35 * DEG])
    t0 = time.perf_counter()
    integrate(pk, eq.state(), law, 3000.0, 0.1)
    first = time.perf_counter() - t0
    times = []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        integrate(pk, eq.state(), law, 3000.0, 0.1)
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    steps = 30000
    print(f"Esso Osaka 35 deg turn, 3000 s at dt = 0.1 s ({steps} RK4 steps)")
    print(f"  first call (incl. compilation or cache load): {first:.3f} s")
    print(f"  median of {a.repeat}: {med * 1e3:.1f} ms  ({steps / med:,.0f} steps/s, {3000 / med:,.0f}x real time)")
    print(f"  target <= 50 ms: {'met' if med <= 0.050 else 'NOT met'}")
    t0 = time.perf_counter()
    python_rk4(pk, eq.state(), 35 * DEG, 0.1, a.python_steps)
    py = (time.perf_counter() - t0) * steps / a.python_steps
    print(f"  RK4 loop in Python over the model's Python body (inner force functions still compiled; scaled from {a.python_steps} steps): {py:.2f} s -> compiled is {py / med:,.0f}x faster")


if __name__ == "__main__":
    main()
