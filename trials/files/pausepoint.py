"""A test hook: a command waits at a named point so that a test can signal it there, whatever the
machine's speed (tests/test_interrupt.py).

``MMG_TEST_PAUSE=POINT:FOLDER`` makes a process that reaches :func:`pause` with that ``POINT`` write
the empty file ``FOLDER/POINT.<pid>`` and then wait (sleeping, up to ``WAIT_S`` seconds, then go on) so
the test sends its signal while the command is known to be there.  Each process waits once per point.
Nothing else reads the variable; unset (anywhere but in those tests) :func:`pause` returns at once and
costs one dictionary look-up.

The points:

``staging``
    :meth:`trials.files.output.StagedOutput.open`, before it creates anything (a signal there must leave
    nothing behind);
``staged``
    the same, right after the staging folder ``OUT/.staging-XXXX`` is made;
``staged-file``
    :meth:`trials.files.output.StagedOutput.path` once the staging folder holds a file (the command has
    written at least one of its outputs);
``sweep-task``
    a worker of :func:`trials.files.sweep.run_sweep` starting its first task (in each worker process).
"""
from __future__ import annotations

import os
import time
from pathlib import Path

ENV = "MMG_TEST_PAUSE"
WAIT_S = 120.0
_done: set = set()


def wanted(point: str) -> bool:
    """True when the test hook asks this process to wait at ``point`` (and it has not yet)."""
    spec = os.environ.get(ENV)
    return bool(spec) and spec.partition(":")[0] == point and point not in _done


def pause(point: str) -> None:
    """Wait at ``point`` when ``MMG_TEST_PAUSE`` names it (see the module); else return at once."""
    if not wanted(point):
        return
    _done.add(point)
    folder = Path(os.environ[ENV].partition(":")[2])
    (folder / f"{point}.{os.getpid()}").touch()
    end = time.monotonic() + WAIT_S
    while time.monotonic() < end:            # the signal's handler raises out of this sleep
        time.sleep(0.02)
