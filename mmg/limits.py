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
"""Integration (or filter) steps of one run: 200 000 s at 0.1 s (67 times the paper's 3000 s trials);
about 0.8 GB of memory and a 0.3 GB truth.csv, a minute or two of work."""

MAX_SAMPLES = 2_000_000
"""Samples of one record on an analysis grid (e.g. a log resampled at the filter step)."""

BYTES_PER_STEP = 400
"""Memory of one step of a simulation with its truth table and log (states, orders, time, the truth
DataFrame and its formatting), for the message."""

FILE_BYTES_PER_STEP = 150
"""Bytes of truth.csv per step (measured: 143), for the message."""


def _size(nbytes: float) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if nbytes >= scale:
            return f"{nbytes / scale:.3g} {unit}"
    return f"{nbytes / 1e3:.3g} kB"


def check_steps(duration: float, dt: float, source: str, field: str = "duration", limit: int = MAX_STEPS) -> int:
    """The number of steps of ``duration`` at ``dt`` [s].

    Raises
    ------
    mmg.errors.InputError
        Naming ``source`` and ``field`` when the run is not finite or needs more than ``limit``
        steps; the message says how many steps, how much memory and disk that would take, and
        the longest duration allowed at this step.
    """
    if not (math.isfinite(duration) and math.isfinite(dt) and dt > 0 and duration >= 0):
        raise InputError(source, field, f"duration {duration!r} s at step {dt!r} s is not a finite run")
    n = duration / dt
    if n > limit:
        raise InputError(source, field, f"{duration:g} s at dt = {dt:g} s is {n:.3g} steps, about "
                                        f"{_size(n * BYTES_PER_STEP)} of memory and {_size(n * FILE_BYTES_PER_STEP)} "
                                        f"of truth.csv; at most {limit:,} steps ({limit * dt:g} s at this dt): "
                                        "shorten the duration or lengthen dt")
    return int(round(n))
