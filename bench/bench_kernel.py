"""Benchmark: the project's compiled integrator against the hand-specialised reference kernel.

Runs the Esso Osaka trials ST35 (35 deg turn) and ZZ10 (10/10 zigzag), 3000 s at 0.1 s, with
:func:`mmg.integrate.simulate_kernel` (the project's general model) and
:func:`kernel_reference.reference_kernel` (the same equations written out for this ship,
``bench/kernel_reference.py``), interleaved, and prints per trial the medians, the ratio
model / reference (median of the per-pair ratios of thread CPU time) and the largest relative difference of the
two state histories (each column scaled by its largest magnitude).  Target: ratio <= 1.3,
difference <= 1e-12.  Run:

    PYTHONPATH=. python bench/bench_kernel.py [--repeat 15]
"""
from __future__ import annotations

import argparse
import inspect
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from kernel_reference import check_ship, reference_kernel  # noqa: E402

from mmg.integrate import simulate_kernel  # noqa: E402
from mmg.simulation import prepare  # noqa: E402
from trials.runs.trial import load_trial  # noqa: E402

REPO = Path(__file__).resolve().parents[1]


def setup(name: str):
    """(model call, reference call, number of steps) of a bundled trial."""
    trial = load_trial(REPO / "configs" / "trials" / f"{name}.yaml")
    pk, eq = prepare(trial.ship, trial.u0, trial.n0, trial.trim, trial.effects)
    check_ship(trial.ship, pk)
    law = trial.command_law(trim_rudder=eq.delta, psi0=0.0)
    nsteps = int(round(trial.duration / trial.dt))
    x0 = np.asarray(eq.state(), dtype=float)
    p, poly, ha, ht, hc = pk.args()
    out = {}
    # older versions allocate their work arrays inside (no ``work`` argument): keep them runnable
    extra = (np.empty((6, 8)),) if "work" in inspect.signature(simulate_kernel.py_func).parameters else ()

    def model():
        s, o = np.empty((nsteps + 1, 8)), np.empty(nsteps + 1)
        k = simulate_kernel(x0, float(trial.dt), nsteps, p, poly, ha, ht, hc,
                            law.kind, law.params, law.t, law.delta, law.n, s, o, *extra)
        out["model"] = s[:k]

    def reference():
        s, o = np.empty((nsteps + 1, 8)), np.empty(nsteps + 1)
        k = reference_kernel(x0, float(trial.dt), nsteps, p, poly, hc,
                             law.kind, law.params, law.t, law.delta, law.n, s, o)
        out["reference"] = s[:k]

    return model, reference, out, nsteps


def timed(f) -> float:
    """CPU time [s] of the calling thread in ``f()`` (on a shared machine the wall time also
    counts the time the thread waits for a core)."""
    t0 = time.thread_time()
    f()
    return time.thread_time() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--trials", nargs="+", default=["st35", "zz10"])
    a = ap.parse_args()
    worst_ratio, worst_diff = 0.0, 0.0
    for name in a.trials:
        model, reference, out, nsteps = setup(name)
        model()                                   # compile / load the caches
        reference()
        m, r = out["model"], out["reference"]
        if m.shape != r.shape:
            raise SystemExit(f"{name}: model ran {len(m)} rows, reference {len(r)}")
        scale = np.maximum(np.abs(r).max(axis=0), 1e-300)
        diff = float((np.abs(m - r) / scale).max())
        tm, tr, ratios = [], [], []
        for k in range(a.repeat):
            pair = (model, reference) if k % 2 == 0 else (reference, model)
            t = {f: timed(f) for f in pair}
            tm.append(t[model])
            tr.append(t[reference])
            ratios.append(t[model] / t[reference])
        ratio = statistics.median(ratios)
        worst_ratio, worst_diff = max(worst_ratio, ratio), max(worst_diff, diff)
        print(f"{name}: {nsteps} RK4 steps; model {statistics.median(tm) * 1e3:.1f} ms, "
              f"reference {statistics.median(tr) * 1e3:.1f} ms, ratio {ratio:.2f} "
              f"(median of {a.repeat} interleaved pairs); max relative difference {diff:.1e}")
    print(f"worst ratio {worst_ratio:.2f} (target <= 1.3: {'met' if worst_ratio <= 1.3 else 'NOT met'}); "
          f"worst difference {worst_diff:.1e} (<= 1e-12: {'met' if worst_diff <= 1e-12 else 'NOT met'})")


if __name__ == "__main__":
    main()
