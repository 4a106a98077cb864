"""Time the augmented EKF: one pass over 3000 s at 0.1 s (30 000 steps), median of 5 after
compilation, on the current path (transition Jacobian F by the tangent-linear RK4 of
``ekf.kernels.jacobian_step``, allocation-free Joseph update ``ekf.kernels.joseph_update_ws``)
and on the previous one (``filter_kernel(..., reference=True)``: F by the brute-force complex
step of ``jacobian_step_reference``, one complex RK4 step per column, and the allocating
``ekf.filter.joseph_update``), in the same run, and the full 4-trial single-seed Rhee & Kim
reproduction.

    python bench/bench_ekf.py [--skip-reproduce]

Prints both pass times and their ratio, the time of F alone on both paths (over the pass's own
30 000 states), and how far apart the two passes' estimates are (~1e-12 relative: both are exact
to rounding).  The two paths are timed alternately (old, new, old, new, ...) so that a change of
machine load hits both.
"""
from __future__ import annotations

import argparse
import contextlib
import functools
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from numba import njit

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import ekf.filter as ekf_filter  # noqa: E402
from ekf.estimate import P0_for, R_for, initial_state, load_config  # noqa: E402
from ekf.filter import NS, SLOTS, run_filter, workspace  # noqa: E402
from ekf.kernels import jacobian_step, jacobian_step_reference  # noqa: E402
from trials.estimates.estimation import data_from_trial  # noqa: E402

REPEATS = 5


@contextlib.contextmanager
def previous_path(on: bool):
    """Inside (when ``on``): ``run_filter`` runs the previous implementation (``reference=True``)."""
    orig = ekf_filter.filter_kernel
    if on:
        ekf_filter.filter_kernel = functools.partial(orig, reference=True)
    try:
        yield
    finally:
        ekf_filter.filter_kernel = orig


@njit
def _jacobians(zs, delta, dt, p, poly, hull_axis, hull_term, idx, ws, reference):
    """F at each state zs[k - 1] of a pass (as the filter's predict computes it)."""
    for k in range(1, zs.shape[0]):
        if reference:
            jacobian_step_reference(zs[k - 1], (delta[k - 1], delta[k], 0.0, 0.0), (SLOTS, NS, idx, -1), dt,
                                    (p, poly, hull_axis, hull_term), ws)
        else:
            jacobian_step(zs[k - 1], (delta[k - 1], delta[k], 0.0, 0.0), (SLOTS, NS, idx, -1), dt,
                          (p, poly, hull_axis, hull_term), ws)


def timed_jacobians(res, data, reference: bool) -> float:
    m = data.meas
    p, poly, ha, ht, hc = data.packed.args()
    ws = workspace(res.z.shape[1], hc)
    zs, delta = np.ascontiguousarray(res.z), np.ascontiguousarray(m.delta, dtype=float)
    t0 = time.perf_counter()
    _jacobians(zs, delta, float(m.t[1] - m.t[0]), p, poly, ha, ht, np.asarray(data.slots, np.int64), ws, reference)
    return time.perf_counter() - t0


def timed_pass(args, name: str, reference: bool):
    """(wall-clock [s], CPU time of this process [s], result) of one pass."""
    with previous_path(reference):
        t0, c0 = time.perf_counter(), time.process_time()
        res = run_filter(*args, trial=name)
        return time.perf_counter() - t0, time.process_time() - c0, res


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--skip-reproduce", action="store_true")
    a = ap.parse_args()
    cfg = load_config()
    with tempfile.TemporaryDirectory() as td:
        data = data_from_trial("zz20", cfg)
        m = data.meas
        args = (data.packed, data.slots, m.t, m.z(), m.delta, initial_state(data, cfg),
                P0_for(cfg, data.names, data.reference), R_for(cfg, data.name))
        first = {ref: timed_pass(args, data.name, ref)[0] for ref in (True, False)}
        times = {True: [], False: []}
        cpu = {True: [], False: []}
        res = {}
        for _ in range(REPEATS):
            for ref in (True, False):
                dt, dc, res[ref] = timed_pass(args, data.name, ref)
                times[ref].append(dt)
                cpu[ref].append(dc)
        old, new = statistics.median(times[True]), statistics.median(times[False])
        cold, cnew = statistics.median(cpu[True]), statistics.median(cpu[False])
        for ref in (True, False):
            timed_jacobians(res[ref], data, ref)                  # compile
        jac = {True: [], False: []}
        for _ in range(REPEATS):
            for ref in (True, False):
                jac[ref].append(timed_jacobians(res[ref], data, ref))
        jo, jn = statistics.median(jac[True]), statistics.median(jac[False])
        steps = f"{len(m.t) - 1} steps ({m.t[-1]:.0f} s at {m.t[1] - m.t[0]:.1f} s)"
        print(f"EKF pass, {steps}, median of {REPEATS} after compilation (first call incl. compilation/cache load):")
        print(f"  previous path (complex-step F, 64 complex model evaluations a step; allocating update): "
              f"{old:.3f} s (min {min(times[True]):.3f} s; first {first[True]:.2f} s)")
        print(f"  current path (tangent-linear RK4 F, 16 complex evaluations of the dynamics a step):    "
              f"{new:.3f} s (min {min(times[False]):.3f} s; first {first[False]:.2f} s)")
        print(f"  ratio previous / current: {old / new:.2f} (of the minima {min(times[True]) / min(times[False]):.2f}; "
              f"of the median CPU times {cold:.3f} s / {cnew:.3f} s: {cold / cnew:.2f})")
        print(f"  F alone at the pass's {len(m.t) - 1} states: previous {jo:.3f} s ({100 * jo / old:.0f} % of its pass), "
              f"current {jn:.3f} s ({100 * jn / new:.0f} % of its pass), ratio {jo / jn:.2f}")
        zo, zn = res[True].z, res[False].z
        rel_final = np.max(np.abs(zn[-1, 4:] - zo[-1, 4:]) / np.abs(zo[-1, 4:]))
        rel_hist = np.max(np.abs(zn - zo).max(axis=0) / np.abs(zo).max(axis=0))
        Po, Pn = res[True].P, res[False].P
        d = np.sqrt(np.diag(Po))
        rel_P = np.max(np.abs(Pn - Po) / np.outer(d, d))
        print(f"  estimates current vs previous, max relative difference: final coefficients {rel_final:.1e}, "
              f"whole history {rel_hist:.1e} (per state, of its largest value), final P {rel_P:.1e} "
              f"(of sqrt(P_ii P_jj))")
        if not a.skip_reproduce:
            from trials.estimates.rhee_kim import reproduce_rhee_kim

            t0 = time.perf_counter()
            reproduce_rhee_kim(Path(td) / "rk", plots=False, verbose=False)
            print(f"Rhee & Kim reproduction (ST35, ZZ10, ZZ20, S-type 120; simulate + preprocess + EKF + "
                  f"reports without figures): {time.perf_counter() - t0:.2f} s")


if __name__ == "__main__":
    main()
