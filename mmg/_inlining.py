"""Where the compiled model's force helpers are inlined: numba's ``inline=`` cost model.

The helpers (:func:`mmg.model.rhs`, :func:`mmg.model.kinematics`, :func:`mmg.model.rudder`, ...,
:func:`mmg.terms.term_value`) are inlined into the hot integration loops named in
:data:`HOT_LOOPS`, where the state and stage values then stay in registers across the whole
right-hand side (the simulator's RK4 loop runs 1.9x faster than with calls, ``bench/bench_kernel.py``; the
replay of measured records, :func:`mmg.replay.replay_states`, ``bench/bench_replay.py``), and
called everywhere else.  Inlining them everywhere would multiply the compile time of the
estimators' many complex-step specialisations (a cold ``mmg estimate`` 25 s -> 69 s).

Cached code that inlines (or calls) code of another file follows an edit of that file because
the cache folder is named by a hash of the whole package (:func:`mmg._jit.source_key`).
"""
from __future__ import annotations

HOT_LOOPS = frozenset({"simulate_kernel", "_replay"})
"""Names of the compiled functions the helpers are inlined into."""


def hot_loops_only(expr, caller_ir, callee_ir) -> bool:
    """numba inline cost model: inline the call when the caller is one of :data:`HOT_LOOPS`
    (a call left in a helper inlined there is inlined too: the caller is then the loop)."""
    return caller_ir.func_id.func_name in HOT_LOOPS
