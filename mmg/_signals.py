"""SIGINT and SIGTERM held back while a section that must not be cut runs.

One helper for every layer: the simulator's ahead-of-time build (:mod:`mmg._aot`: a C compiler
writing into a folder an interrupt would remove) and the staged outputs of the commands
(:mod:`trials.files.output`: a commit's moves, a clean-up's removals) use the same two blocks.

* :func:`held`: the signals blocked in this thread's mask and delivered when the block ends.
  Processes started inside inherit the mask.
* :func:`deferred`: :func:`held`, and for the same time handlers that only note the signal.  The
  mask alone does not hold a process-directed signal: the kernel hands it to any thread that does
  not block it (numba, BLAS and pool threads do not), and Python then runs its handler in the main
  thread at an arbitrary point.  The noting handler catches that one; on leaving, a noted signal is
  raised again in this thread, where the mask holds it until the block's mask is lifted, so the
  original handler runs then.

Both are no-ops outside the main thread and where the platform has no ``pthread_sigmask``.
"""
from __future__ import annotations

import signal
import threading
from contextlib import contextmanager

SIGNALS = tuple(s for s in (getattr(signal, "SIGINT", None), getattr(signal, "SIGTERM", None)) if s is not None)
"""The signals held by default: SIGINT (a terminal's Ctrl-C) and SIGTERM."""

noted: list[int] = []
"""Signals caught by :func:`deferred`'s noting handler and not yet raised again."""


def can_hold() -> bool:
    """Signals can be held here: the main thread, on a platform with ``pthread_sigmask``."""
    return hasattr(signal, "pthread_sigmask") and threading.current_thread() is threading.main_thread()


@contextmanager
def held(signals=None):
    """SIGINT and SIGTERM (or the ``signals`` given) blocked inside the block and delivered (their
    handlers run) on leaving it.  Processes started inside the block inherit the mask.

    A signal whose handler was already due when the block starts is raised here, before the
    block runs (never inside it).
    """
    if not can_hold():
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, [])        # the mask now (runs any handler due)
    try:
        signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS if signals is None else signals)
    except BaseException:                                     # a handler due raised: nothing blocked stays blocked
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
        raise
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


@contextmanager
def deferred():
    """A section that must not be cut (module docstring): SIGINT and SIGTERM held, whichever thread
    the kernel gives them to, and delivered to their own handlers when the section ends.  A
    handler not set from Python (``signal.getsignal`` is None) is left alone."""
    with held():
        if not can_hold():
            yield
            return
        old = {s: h for s in SIGNALS if (h := signal.getsignal(s)) is not None}
        start = len(noted)
        try:
            for s in old:
                signal.signal(s, lambda signum, frame: noted.append(signum))
            yield
        finally:
            _restore(old, start)


def _restore(old: dict, start: int) -> None:
    """Put back the handlers ``old`` and raise again what was noted since ``start``; a signal whose
    original handler runs (and raises) while this works cannot leave a handler or a note behind."""
    again = noted[start:]
    del noted[start:]                            # first: nothing can leave a stale note
    items = list(old.items())

    def put_back(k: int) -> None:
        if k == len(items):
            for s in dict.fromkeys(again):
                signal.raise_signal(s)           # pending in this thread until the mask is lifted
            return
        try:
            signal.signal(*items[k])
        finally:
            put_back(k + 1)                      # the next handler is restored even if this one's ran and raised

    put_back(0)


def pending() -> bool:
    """A SIGINT or SIGTERM is waiting (held by :func:`deferred` or :func:`held`)."""
    return can_hold() and (bool(noted) or bool(set(signal.sigpending()) & set(SIGNALS)))
