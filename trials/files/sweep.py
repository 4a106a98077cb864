"""One way to run many independent simulations in parallel: joblib, with progress.

:func:`run_sweep` maps a picklable, module-level function over a list of tasks and
returns the results in task order.  The backend is chosen by ``backend``:

* ``"serial"``  - a plain loop in this process (the reference; also what tests compare with);
* ``"loky"``    - joblib's process pool on this machine's cores (the default, ``n_jobs=-1``);
* ``"threads"`` - joblib's thread pool (only useful for code that releases the GIL);
* ``"dask"``    - joblib's dask backend: the tasks go to the workers of the current
  ``distributed.Client`` (pass ``client=`` or create one before calling).  Needs the
  optional extra ``pip install mmg-toolkit[dask]`` (``dask[distributed]``).

Progress is one line per finished task on stderr (``[i/N] label (elapsed s)``), written by
the calling process whatever the backend, so it shows for local and distributed runs alike.
The numbers do not depend on the backend: every task is deterministic and runs the same
compiled code (tested: serial == loky == dask).
"""
from __future__ import annotations

import os
import sys
import time
from typing import Callable, Iterable, Sequence

BACKENDS = ("serial", "loky", "threads", "dask")


def default_jobs() -> int:
    """Worker count for the local backends: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - non-Linux
        return max(1, os.cpu_count() or 1)


def _progress(i: int, n: int, label: str, t0: float, stream) -> None:
    if stream is not None:
        print(f"  [{i}/{n}] {label} ({time.perf_counter() - t0:.1f} s)", file=stream, flush=True)


def run_sweep(func: Callable, tasks: Sequence, *, backend: str = "loky", n_jobs: int | None = None,
              labels: Iterable[str] | None = None, progress: bool = True, client=None, stream=None,
              batch_size="auto") -> list:
    """``[func(t) for t in tasks]`` in parallel, in task order, with a progress line per task.

    Parameters
    ----------
    func : module-level callable (picklable) taking one task
    tasks : sequence of picklable task arguments
    backend : "serial", "loky" (default), "threads" or "dask"
    n_jobs : local workers (default: all usable cores); ignored by "serial"
    labels : one label per task for the progress lines (default: the task's repr)
    progress : print progress lines (to ``stream``, default stderr)
    client : a ``distributed.Client`` for the dask backend (default: the current one)
    """
    if backend not in BACKENDS:
        raise ValueError(f"unknown sweep backend {backend!r}; choose from {', '.join(BACKENDS)}")
    tasks = list(tasks)
    n = len(tasks)
    labels = [str(x) for x in labels] if labels is not None else [repr(x)[:60] for x in tasks]
    stream = (stream or sys.stderr) if progress else None
    t0 = time.perf_counter()
    if n == 0:
        return []
    if backend == "serial" or (backend in ("loky", "threads") and (n_jobs == 1 or n == 1)):
        out = []
        for i, task in enumerate(tasks):
            out.append(func(task))
            _progress(i + 1, n, labels[i], t0, stream)
        return out

    from joblib import Parallel, delayed, parallel_backend

    jobs = n_jobs or default_jobs()
    if backend == "dask":
        try:
            import distributed  # noqa: F401  (registers joblib's dask backend)
        except ImportError as e:  # pragma: no cover - depends on the install
            raise RuntimeError("the dask sweep backend needs the optional extra: pip install 'dask[distributed]'") from e
        if client is None:
            from distributed import get_client

            client = get_client()  # raises ValueError when there is no cluster
        ctx = parallel_backend("dask", client=client)
        jobs = -1
    elif backend == "threads":
        ctx = parallel_backend("threading", n_jobs=jobs)
    else:
        ctx = parallel_backend("loky", n_jobs=jobs)
    out: list = [None] * n
    from .output import children_ignore_sigint

    with ctx, children_ignore_sigint():      # workers leave Ctrl-C to the main process (it cleans up)
        gen = Parallel(n_jobs=jobs, return_as="generator_unordered", batch_size=batch_size)(
            delayed(_indexed)(func, i, task) for i, task in enumerate(tasks))
        for done, (i, res) in enumerate(gen, 1):
            out[i] = res
            _progress(done, n, labels[i], t0, stream)
    return out


def _indexed(func, i, task):
    from .pausepoint import pause

    pause("sweep-task")                 # a test hook (trials.files.pausepoint); no-op otherwise
    return i, func(task)
