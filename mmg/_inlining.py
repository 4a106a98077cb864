"""Where the compiled model's force helpers are inlined: numba's ``inline=`` cost model.

The helpers (:func:`mmg.model.rhs`, :func:`mmg.model.kinematics`, :func:`mmg.model.rudder`, ...,
:func:`mmg.terms.term_value`) are inlined into the hot integration loops named in
:data:`HOT_LOOPS`, where the state and stage values then stay in registers across the whole
right-hand side (the simulator's RK4 loop runs 1.9x faster than with calls, ``bench/bench_kernel.py``; the
replay of measured records, :func:`mmg.replay.replay_states`, ``bench/bench_replay.py``), and
called everywhere else.  Inlining them everywhere would multiply the compile time of the
estimators' many complex-step specialisations (a cold ``mmg estimate`` 25 s -> 69 s).

A compiled function that inlines code from another file (the hot loops here, the EKF's
:func:`ekf.kernels.jacobian_step` and its all-complex dynamics) is built as a closure over
:func:`source_stamp`, so that numba's on-disk cache, keyed by the function's own file, follows an
edit of the model.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

HOT_LOOPS = frozenset({"simulate_kernel", "_replay"})
"""Names of the compiled functions the helpers are inlined into."""


def hot_loops_only(expr, caller_ir, callee_ir) -> bool:
    """numba inline cost model: inline the call when the caller is one of :data:`HOT_LOOPS`
    (a call left in a helper inlined there is inlined too: the caller is then the loop)."""
    return caller_ir.func_id.func_name in HOT_LOOPS


INLINED_SOURCES = ("_inlining.py", "model.py", "nondim.py", "rudder.py", "terms.py", "wind.py")
"""The files of :mod:`mmg` whose compiled functions the hot loops inline (or call)."""


def source_stamp() -> int:
    """A 60-bit hash of :data:`INLINED_SOURCES`.  The hot loops are compiled as closures over it:
    numba keys a cached function by its own file's time stamp and its closure's values, so an edit
    of the model's file alone would otherwise leave the loops' cached, inlined copy of the old
    model in use."""
    h = hashlib.sha256()
    here = Path(__file__).resolve().parent
    for name in INLINED_SOURCES:
        f = here / name
        if f.is_file():                           # (an install without sources has nothing to go stale)
            h.update(f.read_bytes())
    return int(h.hexdigest()[:15], 16)
