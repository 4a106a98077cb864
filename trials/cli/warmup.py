"""Fill numba's on-disk cache once, on all cores: ``python -m trials.cli.warmup [--jobs N]``.

Every compiled function of the project is cached (``cache=True``), but a fresh install or a CI
run starts with an empty cache and pays the compilation on its first calls, in one process on
one core.  This module compiles the same specialisations ahead of time by running short
versions of the everyday workloads, split into groups that share little compiled code, each
group in its own process:

* ``simulate``: the trial simulator (turning, zigzag, schedule laws), the straight-run
  equilibrium, the rudder reconstruction, the sensitivities (:mod:`trials.planning.fisher`) and the
  replay of measured records (:mod:`mmg.replay`);
* ``ekf``: the augmented EKF of the paper (:mod:`ekf.filter`, complex-step Jacobians) on a
  short simulated zigzag;
* ``log-filter``: the raw-log EKF (:mod:`ekf.log_filter`) and the output-error fit (not in
  the default set, see :data:`DEFAULT_GROUPS`);
* ``filter``: only the augmented EKF's compiled pass (:func:`ekf.filter.run_filter`), on a
  three-step dummy record (compilation depends on the argument types, not the values);
* ``jacobian``: only the paper filter's exact Jacobian step (:func:`ekf.kernels.jacobian_step`,
  two thirds of the pass's compilation): ``mmg estimate`` on a cold cache compiles it on the
  second core while it simulates the inputs with the JIT's kernel and compiles the pass's other
  parts (:func:`warm_filter_parts`) on the first;
* ``aot``: only the simulator's compiled module (:mod:`mmg._aot`);
* ``replay``: only the replay of a record from its measured inputs (:mod:`mmg.replay`);
* ``reference``: the previous implementations the tests and ``bench/bench_ekf.py`` compare the
  filters against (``reference=True``: brute-force complex-step Jacobians, allocating updates).

The test suite (``tests/conftest.py``) runs :data:`SUITE_GROUPS` in one process on the second
core while its first tests run, when it finds the cache cold.

:func:`compiling_in_background` runs one group in a child process while the caller does other
work: ``mmg estimate`` with a cold cache compiles the filter on the second core while it builds
the simulator (:mod:`mmg._aot`) and simulates the trial on the first.

The processes write into the same cache (numba's cache files are written atomically, one
index per function); the command's own later runs then load instead of compiling.  Exit
status 0, or 1 if a group failed (its traceback on stderr).
"""
from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time
from contextlib import contextmanager
from dataclasses import replace

GROUPS = ("ekf", "simulate", "log-filter", "reference", "filter", "jacobian", "replay", "aot")
"""Warm-up groups, longest first (so that with fewer processes than groups the long one starts
at once)."""
DEFAULT_GROUPS = ("ekf", "simulate")
"""The groups run by default: one per core of a 2-core CI machine.  ``log-filter`` (the
output-error fit runs the paper EKF first, so it repeats much of ``ekf``) on request."""
SUITE_GROUPS = ("filter", "replay", "ekf", "reference", "log-filter", "simulate")
"""The groups the test suite warms in the background, in the order its tests first need them (the
simulator's own kernel is built by the suite's first tests, :mod:`mmg._aot`)."""

SHORT_S = 60.0
"""Duration [s] of the short trials the groups run: long enough for every branch the
specialisations depend on (compilation depends on argument types only, not on the length)."""


def _short(name: str, duration: float = SHORT_S):
    from trials.runs.trial import load_trial

    return replace(load_trial(name), duration=duration)


def warm_simulate() -> None:
    """The simulator, the equilibrium, the rudder rebuild, the sensitivities, the replay."""
    import numpy as np

    from mmg.rudder import reconstruct_rudder
    from mmg.simulation import prepare
    from trials.runs.run import run_trial

    for name in ("st35", "zz10"):
        run = run_trial(_short(name))
    pk, _ = prepare(run.trial.ship, run.trial.u0)
    t = np.arange(0.0, 10.0, 1.0)
    reconstruct_rudder(t, np.zeros_like(t), "zigzag", {"rudder": 0.1, "heading": 0.1}, pk.p)
    from trials.planning import fisher

    fisher.tangent(_short("zz20", 30.0))
    fisher.tangent(_short("zz20", 30.0), rudder_timing=True)


def warm_ekf() -> None:
    """The augmented EKF (paper filter) of one short zigzag."""
    from trials.estimates.estimation import estimate

    estimate(_short("zz20", 100.0))


def warm_log_filter() -> None:
    """The raw-log EKF and the output-error fit of one short zigzag."""
    from trials.estimates.estimation import estimate

    estimate(_short("zz20", 100.0), method="output-error")
    _log_filter_pass()


def warm_filter() -> None:
    """The augmented EKF's compiled pass on a three-step dummy record of the Esso Osaka (the same
    argument types as every real pass: :func:`ekf.filter.run_filter` makes them contiguous float64 /
    int64 arrays)."""
    from ekf.filter import FilterDivergence, run_filter

    try:
        run_filter(*_filter_args())
    except FilterDivergence:                       # a dummy record may diverge: the pass is compiled either way
        pass


def _filter_args():
    """run_filter's arguments for a three-step dummy record of the Esso Osaka (the argument types
    of every real pass: run_filter makes them contiguous float64 / int64 arrays)."""
    import numpy as np

    from ekf.data import estimable_names
    from mmg.model import pack
    from mmg.ship import load_ship

    ship = load_ship("esso_osaka")
    pk = pack(ship)
    names = estimable_names(ship)
    slots = np.array([list(ship.hull.names).index(n) for n in names], dtype=np.int64)
    nz = 4 + len(names)
    t = np.array([0.0, 1.0, 2.0])
    meas = np.tile([5.0, 0.0, 0.0, 1.0], (3, 1))
    z0 = np.r_[5.0, 0.0, 0.0, 1.0, pk.hull_coef[slots]]
    return pk, slots, t, meas, np.zeros(3), z0, np.eye(nz) * 1e-6, np.eye(4) * 1e-4


def warm_jacobian() -> None:
    """The paper filter's Jacobian step (:func:`ekf.kernels.jacobian_step`), called with the argument
    types of the compiled pass."""
    from ekf import propagate
    from ekf.kernels import jacobian_step
    from mmg._jit import interpreted

    pk, slots, t, meas, delta, z0, P0, R = _filter_args()
    ws = interpreted(propagate.workspace)(len(z0), pk.hull_coef)     # as ekf.filter.run_filter makes them
    jacobian_step(z0, (0.0, 0.0, 0.0, 0.0), (propagate.SLOTS, propagate.NS, slots, -1), 1.0, pk.args()[:4], ws)


def warm_jacobian_real_parts() -> None:
    """The real-valued code the Jacobian step calls (the model's force helpers, through the real
    :func:`mmg.model.dynamics`, and the analytic hull columns :func:`mmg.model.rhs_hull_jacobian`),
    with the Jacobian step's argument types.  A cold ``mmg estimate`` compiles them in the command
    while its child is still compiling the all-complex dynamics, so the child loads them from the
    cache instead of compiling them after it."""
    from ekf import propagate
    from mmg._jit import interpreted
    from mmg.model import dynamics, inverse_mass, rhs_hull_jacobian

    pk, slots, t, meas, delta, z0, P0, R = _filter_args()
    p, poly, hull_axis, hull_term = pk.args()[:4]
    ws = interpreted(propagate.workspace)(len(z0), pk.hull_coef)     # the step's own work arrays
    hc, xr, B, w = ws[10], ws[11], ws[18], ws[19]
    xr[0] = 5.0
    dynamics(5.0, 0.0, 0.0, 0.0, 1.0, p, poly, hull_axis, hull_term, hc, w)
    rhs_hull_jacobian(xr, p, hull_axis, hull_term, slots, interpreted(inverse_mass)(p, w), B)


def warm_filter_parts() -> None:
    """The paper filter pass's parts other than its Jacobian step (the covariance propagation, the
    checks, the Joseph update and their work arrays), called with the pass's argument types."""
    import numpy as np

    from ekf.filter import _check
    from ekf.kernels import fpft, joseph_update_ws, make_update_workspace
    from ekf.propagate import NS
    from mmg._jit import interpreted

    pk, slots, t, meas, delta, z0, P0, R = _filter_args()
    nz = len(z0)
    uw = interpreted(make_update_workspace)(nz, meas.shape[1])     # as run_filter makes it
    P = P0.copy()
    fpft(np.eye(nz), P, NS, np.empty((nz, nz)), P)
    _check(z0, P)
    joseph_update_ws(z0.copy(), P, meas[1], R, uw)


def warm_aot() -> None:
    """The simulator's ahead-of-time compiled module (:mod:`mmg._aot`), built if it is not."""
    from mmg import _aot

    _aot.kernels()


def warm_replay() -> None:
    """The replay of a record from its measured rudder and revolutions (:func:`mmg.replay.replay`)."""
    import numpy as np

    from mmg.model import pack
    from mmg.replay import ReplayInputs, replay
    from mmg.ship import load_ship

    t = np.arange(0.0, 2.0, 0.1)
    replay(pack(load_ship("esso_osaka_3m")), ReplayInputs(t, np.zeros_like(t), np.full_like(t, 10.0)),
           [0.3, 0.0, 0.0, 0.0, 0.0, 0.0])


@contextmanager
def _reference(module, name: str):
    """Inside: ``module.name`` (a compiled pass) runs its previous implementation (``reference=True``)."""
    import functools

    orig = getattr(module, name)
    setattr(module, name, functools.partial(orig, reference=True))
    try:
        yield
    finally:
        setattr(module, name, orig)


def warm_reference() -> None:
    """The filters' previous implementations (``reference=True``), which the tests and
    ``bench/bench_ekf.py`` compare the compiled passes against."""
    import ekf.filter as ekf_filter
    import ekf.log_filter as ekf_log_filter

    with _reference(ekf_filter, "filter_kernel"):
        warm_filter()
    with _reference(ekf_log_filter, "log_filter_kernel"):
        _log_filter_pass()


def _log_filter_pass() -> None:
    """The raw-log EKF over a short simulated zigzag's log."""
    from ekf.estimate import load_config
    from ekf.filter import FilterDivergence
    from ekf.log_filter import run_log_filter
    from trials.estimates.estimation import data_from_trial

    cfg = load_config()
    data = data_from_trial(_short("zz20", 60.0), cfg, seed=1)
    try:
        run_log_filter(data, data.record, cfg, passes=1)
    except FilterDivergence:                       # compiled either way
        pass


def filter_cache_cold() -> bool:
    """Whether numba's on-disk cache has no entry yet for the filter's pass (a fresh install or CI run)."""
    try:
        from ekf.filter import filter_kernel

        return not os.path.exists(filter_kernel.dispatcher._cache._cache_file._index_path)
    except Exception:                              # another numba's internals: assume warm, compile in-process
        return False


_RUN = {"simulate": warm_simulate, "ekf": warm_ekf, "log-filter": warm_log_filter, "filter": warm_filter,
        "replay": warm_replay, "reference": warm_reference, "jacobian": warm_jacobian, "aot": warm_aot}


@contextmanager
def compiling_in_background(*groups: str, when: bool = True):
    """Run warm-up ``groups`` one after another in a child process (when ``when``) while the
    ``with`` body runs.

    Yields a function ``join(group=None)``: it waits until ``group`` is compiled (call it before the
    work that needs that code: the work then loads it from the cache instead of compiling it again),
    or for the whole child when ``group`` is None.  The child writes only into numba's cache (and
    :mod:`mmg._aot`'s module); it is stopped when the body raises (an interrupt, an error) and
    waited for on a normal exit.  If a group fails, the caller simply compiles in its own process."""
    proc = None
    if when:
        cmd = [sys.executable, "-m", "trials.cli.warmup", "--serial"]
        for g in groups:
            cmd += ["--group", g]
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                text=True)
    finished: set[str] = set()

    def end() -> None:
        if not proc.stderr.closed:
            proc.stderr.read()
            proc.stderr.close()
        proc.wait()

    def join(group: str | None = None) -> None:
        if proc is None:
            return
        while group is not None and group not in finished and not proc.stderr.closed:
            line = proc.stderr.readline()
            if not line:                           # the child ended (or failed before the group)
                break
            if line.startswith("mmg warmup: "):
                finished.add(line.split()[2])
        if group is None or group not in finished:
            end()

    join.process = proc                            # (for the caller's and the tests' eyes)
    try:
        yield join
    except BaseException:
        if proc is not None:
            if proc.poll() is None:
                proc.terminate()
            end()
        raise
    join()


def run_group(name: str) -> float:
    """Run one group in this process; returns its wall time [s]."""
    t0 = time.perf_counter()
    _RUN[name]()
    return time.perf_counter() - t0


def warmup(groups=DEFAULT_GROUPS, jobs: int | None = None, quiet: bool = False) -> int:
    """Run the warm-up ``groups`` in up to ``jobs`` processes at once (default: the CPU count).

    Returns the number of groups that failed.
    """
    jobs = max(1, jobs or os.cpu_count() or 1)
    pending = list(groups)
    running: list[tuple[str, subprocess.Popen, float]] = []
    failed = 0
    t0 = time.perf_counter()
    while pending or running:
        while pending and len(running) < jobs:
            g = pending.pop(0)
            running.append((g, subprocess.Popen([sys.executable, "-m", "trials.cli.warmup", "--group", g]),
                            time.perf_counter()))
        g, proc, ts = running.pop(0)
        rc = proc.wait()
        failed += rc != 0
        if not quiet:
            print(f"mmg warmup: {g} {'done' if rc == 0 else 'FAILED'} in {time.perf_counter() - ts:.1f} s",
                  file=sys.stderr)
    if not quiet:
        print(f"mmg warmup: {len(groups)} groups in {time.perf_counter() - t0:.1f} s on {jobs} processes",
              file=sys.stderr)
    return failed


def warmup_serial(groups=DEFAULT_GROUPS, quiet: bool = False) -> int:
    """Run the warm-up ``groups`` one after another in this process (on one core; what the groups
    share is compiled or loaded once).  A group that fails is reported and the next one runs.

    Returns the number of groups that failed.
    """
    import traceback

    failed = 0
    for g in groups:
        try:
            dt = run_group(g)
        except Exception:
            failed += 1
            print(f"mmg warmup: {g} FAILED\n{traceback.format_exc()}", file=sys.stderr, flush=True)
            continue
        if not quiet:
            print(f"mmg warmup: {g} done in {dt:.1f} s", file=sys.stderr, flush=True)
    return failed


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m trials.cli.warmup", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--jobs", type=int, default=None, help="processes at once (default: the CPU count)")
    ap.add_argument("--group", choices=GROUPS, action="append",
                    help="run only this group, in this process (repeatable)")
    ap.add_argument("--serial", action="store_true",
                    help="run the groups one after another in this process (one core)")
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args(argv)
    # stopped by its parent (compiling_in_background): unwind, so that a build in progress removes
    # its temporary folder (mmg._aot.build) instead of leaving it in the cache
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    if a.serial:
        return 1 if warmup_serial(tuple(a.group or DEFAULT_GROUPS), a.quiet) else 0
    if a.group and len(a.group) == 1:
        run_group(a.group[0])
        return 0
    return 1 if warmup(tuple(a.group or DEFAULT_GROUPS), a.jobs, a.quiet) else 0


if __name__ == "__main__":
    sys.exit(main())
