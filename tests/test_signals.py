"""mmg._signals: the one helper that holds SIGINT/SIGTERM for the simulator's build and the outputs."""
import signal
import threading
import time

import pytest

from mmg import _signals


def _other_thread():
    stop = threading.Event()
    t = threading.Thread(target=stop.wait, daemon=True)
    t.start()                                  # started with SIGINT unblocked
    return t, stop


def test_held_delivers_a_signal_to_this_thread_on_leaving():
    ran = []
    with pytest.raises(KeyboardInterrupt):
        with _signals.held():
            signal.pthread_kill(threading.main_thread().ident, signal.SIGINT)
            time.sleep(0.05)
            ran.append("after the signal")          # not cut: the mask holds it
            assert _signals.pending()
    assert ran == ["after the signal"]
    assert not _signals.pending()


def test_deferred_holds_a_signal_another_thread_takes():
    """The mask of this thread does not hold a signal the kernel gives another thread; the noting
    handler does, and the signal reaches the original handler when the section ends."""
    t, stop = _other_thread()
    ran = []
    try:
        with pytest.raises(KeyboardInterrupt):
            with _signals.deferred():
                signal.pthread_kill(t.ident, signal.SIGINT)
                deadline = time.monotonic() + 5.0
                while not _signals.noted and time.monotonic() < deadline:
                    time.sleep(0.001)              # the noting handler runs here, in this thread
                assert _signals.noted == [signal.SIGINT]
                ran.append("section finished")
    finally:
        stop.set()
        t.join()
    assert ran == ["section finished"]
    assert _signals.noted == []
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_deferred_without_a_signal_changes_nothing():
    before = {s: signal.getsignal(s) for s in _signals.SIGNALS}
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    with _signals.deferred():
        pass
    assert {s: signal.getsignal(s) for s in _signals.SIGNALS} == before
    assert signal.pthread_sigmask(signal.SIG_BLOCK, []) == mask


def test_outside_the_main_thread_nothing_is_held():
    out = []

    def work():
        with _signals.deferred():
            out.append(_signals.can_hold())

    t = threading.Thread(target=work)
    t.start()
    t.join()
    assert out == [False]


def test_a_signal_handled_while_the_handlers_are_put_back_leaves_nothing_behind(monkeypatch):
    """A Ctrl-C another thread takes just after SIGINT's own handler is back runs that handler (a
    KeyboardInterrupt) in the middle of the clean-up: SIGTERM's handler must still be put back and no
    note left, or the process would ignore SIGTERM and every later section would think it was cut."""
    real = signal.signal
    fired = []

    def signal_then_interrupt(sig, handler):
        prev = real(sig, handler)
        if sig == signal.SIGINT and handler is signal.default_int_handler and not fired:
            fired.append(1)
            raise KeyboardInterrupt               # what the restored handler does when the Ctrl-C lands here
        return prev

    before = signal.getsignal(signal.SIGTERM)
    monkeypatch.setattr(signal, "signal", signal_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        with _signals.deferred():
            pass
    monkeypatch.undo()
    assert fired
    assert signal.getsignal(signal.SIGTERM) == before and signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert _signals.noted == [] and not _signals.pending()
