"""Bounds on the work one run may ask for, checked before anything is allocated.

A trial, a log or an option that would need more than these is refused with one line that
says how much it would need and which field to change (:class:`mmg.errors.InputError`).
3000 s at 0.1 s, the paper's trials, is 30 000 steps; the bounds leave two orders of
magnitude of room and keep a run within about 1 GB.
"""
from __future__ import annotations

import math

from .errors import InputError

MAX_STEPS = 2_000_000
"""Integration (or filter) steps of one run: 200 000 s at 0.1 s; about 150 MB of states."""

MAX_SAMPLES = 2_000_000
"""Samples of one record on an analysis grid (e.g. a log resampled at the filter step)."""

BYTES_PER_STEP = 8 * 8 * 10
"""Rough memory of one step of a simulation with its truth table and log (for the message)."""


def check_steps(duration: float, dt: float, source: str, field: str = "duration", limit: int = MAX_STEPS) -> int:
    """The number of steps of ``duration`` at ``dt`` [s]; InputError when it is not finite or above ``limit``."""
    if not (math.isfinite(duration) and math.isfinite(dt) and dt > 0 and duration >= 0):
        raise InputError(source, field, f"duration {duration!r} s at step {dt!r} s is not a finite run")
    n = duration / dt
    if n > limit:
        raise InputError(source, field, f"{duration:g} s at {dt:g} s is {n:.3g} steps ({n * BYTES_PER_STEP / 1e9:.3g} GB); "
                                        f"at most {limit:,} steps: shorten the duration or lengthen the step")
    return int(round(n))
