"""The output-error fit's thread pools are kept for the process; a forked child (the main job runs
a report section in one) must not inherit them: their threads are not copied, so a map on an
inherited pool waits for ever.  Found when the main job ran in the same process as an earlier
output-error fit (the test suite): the forked section hung."""
import multiprocessing as mp
import sys

import pytest

import importlib

fit = importlib.import_module("ekf.output_error.fit")

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="no fork")


def _child(send):
    send.send(list(fit._pool(2).map(lambda x: x * x, range(5))))
    send.close()


def test_a_forked_child_gets_working_pools():
    import threading

    go = threading.Event()
    jobs = [fit._pool(2).submit(go.wait, 5.0) for _ in range(2)]   # the parent's pool with both threads made
    go.set()
    [j.result() for j in jobs]
    ctx = mp.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    p = ctx.Process(target=_child, args=(send,), daemon=True)
    p.start()
    send.close()
    try:
        assert recv.poll(20.0), "the forked child's map on the output-error pool did not return"
        assert recv.recv() == [0, 1, 4, 9, 16]
    finally:
        if p.is_alive():
            p.terminate()
        p.join()
