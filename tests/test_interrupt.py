"""SIGTERM and SIGINT while a command works: one line ``interrupted``, exit 143 / 130, nothing left.

The commands run as real processes (the installed ``mmg`` script); the signal is sent at a point the
test controls, whatever the machine's speed: ``MMG_TEST_PAUSE`` (:mod:`trials.files.pausepoint`) makes the
command wait at a named point (its staging folder made, a file of its output written, a sweep worker
started, ...) and say so with a marker file; the test signals once the marker is there, while the command
is known to wait (it would go on after 120 s).
"""
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from trials.cli import Interrupted, _interrupt_code

from .conftest import CONFIGS, REPO

CODES = {signal.SIGTERM: 143, signal.SIGINT: 130}


def mmg_argv() -> list:
    script = Path(sys.executable).with_name("mmg")
    return [str(script)] if script.is_file() else [sys.executable, "-m", "trials.cli"]


def start_paused(args, point: str, markers: Path, cwd=None, group: bool = True):
    """Start ``mmg args`` told to wait at ``point`` (:mod:`trials.files.pausepoint`); returns the process."""
    markers.mkdir(parents=True, exist_ok=True)
    env = {**os.environ, "PYTHONUNBUFFERED": "1", "MMG_TEST_PAUSE": f"{point}:{markers}"}
    return subprocess.Popen(mmg_argv() + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd,
                            env=env, start_new_session=group)


def wait_for_markers(p, point: str, markers: Path, count: int = 1, timeout: float = 300) -> None:
    """Wait until ``count`` processes wait at ``point`` (their marker files); the command must still run."""
    t0 = time.monotonic()
    while len(list(markers.glob(f"{point}.*"))) < count:
        assert p.poll() is None, f"the command ended before it reached {point!r}: {p.communicate()}"
        assert time.monotonic() - t0 < timeout, f"no process reached {point!r}"
        time.sleep(0.02)
    assert p.poll() is None


def run_and_signal(args, point: str, sig, base: Path, markers: Path, group=False, count=1, timeout=300):
    """Start ``mmg args`` (in ``base``), wait until it waits at ``point``, send ``sig`` (to the process, or
    its whole process group as a terminal's Ctrl-C does); return (exit code, stdout, stderr)."""
    p = start_paused(args, point, markers, cwd=base)
    try:
        wait_for_markers(p, point, markers, count, timeout)
        (os.killpg(p.pid, sig) if group else p.send_signal(sig))
        out, err = p.communicate(timeout=timeout)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    return p.returncode, out, err


def assert_interrupted(code, out, err, sig, base: Path):
    assert code == CODES[sig], (code, out, err)
    assert err.strip().splitlines() == ["interrupted"], err
    assert "wrote" not in out
    assert not list(base.rglob("*")), list(base.rglob("*"))      # no staging folder, no DIR, nothing


@pytest.fixture(scope="module")
def zz20_log(tmp_path_factory):
    d = tmp_path_factory.mktemp("log")
    subprocess.run(mmg_argv() + ["simulate", str(CONFIGS / "trials" / "zz20.yaml"), "--out", str(d / "zz20")],
                   check=True, capture_output=True)
    return d / "zz20" / "log.csv"


@pytest.mark.parametrize("point", ["staged", "staged-file"])
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_simulate_interrupted(sig, point, tmp_path):
    """Once its staging folder exists, and once it holds a written file."""
    base = tmp_path / "base"
    base.mkdir()
    r = run_and_signal(["simulate", str(CONFIGS / "trials" / "st35.yaml"), "--out", str(base / "DIR")], point, sig,
                       base, tmp_path / "markers")
    assert_interrupted(*r, sig, base)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_estimate_interrupted(sig, tmp_path):
    base = tmp_path / "base"
    base.mkdir()
    r = run_and_signal(["estimate", str(CONFIGS / "trials" / "zz20.yaml"), "--out", str(base / "DIR")], "staged-file",
                       sig, base, tmp_path / "markers")
    assert_interrupted(*r, sig, base)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_nomoto_interrupted(sig, tmp_path, zz20_log):
    base = tmp_path / "base"
    base.mkdir()
    r = run_and_signal(["nomoto", str(zz20_log), "--length", "325", "--json", str(base / "DIR" / "x.json")],
                       "staged", sig, base, tmp_path / "markers")       # staged before the identification
    assert_interrupted(*r, sig, base)


def test_signal_before_staging(tmp_path):
    """A SIGTERM after the trial is read, before the staging folder exists: nothing made, nothing left."""
    base = tmp_path / "base"
    base.mkdir()
    r = run_and_signal(["simulate", str(CONFIGS / "trials" / "st35.yaml"), "--out", str(base / "DIR")], "staging",
                       signal.SIGTERM, base, tmp_path / "markers")
    assert_interrupted(*r, signal.SIGTERM, base)


def test_montecarlo_interrupted_workers_leave_nothing(tmp_path):
    """SIGTERM to a Monte Carlo while both loky workers run a task: nothing left, and the workers are gone."""
    base = tmp_path / "base"
    base.mkdir()
    out = base / "DIR"
    markers = tmp_path / "markers"
    p = start_paused(["montecarlo", str(out), "--seeds", "1", "--jobs", "2"], "sweep-task", markers)
    try:
        wait_for_markers(p, "sweep-task", markers, count=2)        # each worker waits in its first task
        assert list(out.glob(".staging-*"))
        p.send_signal(signal.SIGTERM)
        out_, err = p.communicate(timeout=300)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    assert_interrupted(p.returncode, out_, err, signal.SIGTERM, base)
    t1 = time.monotonic()
    while _group(p.pid, running_only=True) and time.monotonic() - t1 < 30:
        time.sleep(0.2)
    assert not _group(p.pid, running_only=True)


def _group(pgid: int, running_only=False) -> list:
    """Processes of process group ``pgid`` (not zombies when ``running_only``)."""
    pids = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            stat = (d / "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()
        if int(fields[2]) == pgid and not (running_only and fields[0] == "Z"):
            pids.append(int(d.name))
    return pids


def test_pause_point_is_inert_without_the_variable(monkeypatch, tmp_path):
    """The hook does nothing unless MMG_TEST_PAUSE names the point (it returns at once)."""
    from trials.files import pausepoint

    monkeypatch.delenv(pausepoint.ENV, raising=False)
    monkeypatch.setattr(pausepoint, "_done", set())
    t0 = time.monotonic()
    pausepoint.pause("staged")
    monkeypatch.setenv(pausepoint.ENV, f"staging:{tmp_path}")
    pausepoint.pause("staged")                        # another point named: no wait, no marker
    assert time.monotonic() - t0 < 1.0 and not list(tmp_path.iterdir())


# --------------------------------------------------------------------------- the mechanics


def _python(code: str, **kw):
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, cwd=REPO,
                          timeout=120, **kw)


def test_interrupt_in_a_weakref_callback_is_not_lost():
    """The handler's exception raised where Python cannot propagate it (a weakref callback:
    "Exception ignored in ...") is raised again at the next ordinary line, silently."""
    r = _python("""
        import os, signal, sys, weakref
        from trials import cli
        cli._install_handlers()
        class A: pass
        def cb(_):
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(1000): pass          # the handler runs here: an unraisable exception
        a = A(); ref = weakref.ref(a, cb); del a
        try:
            for _ in range(10 ** 7): pass
            print("not interrupted")
        except cli.Interrupted:
            print("interrupted")
    """)
    assert r.stdout.strip() == "interrupted" and r.stderr == "", r


def test_interrupt_wrapped_by_a_library_is_recognised():
    """numba turns an exception raised in a callback into SystemError(...) from Interrupted."""
    try:
        try:
            raise Interrupted()
        except Interrupted as e:
            raise SystemError("returned a result with an exception set") from e
    except SystemError as e:
        assert _interrupt_code(e) == 143
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise RuntimeError("during handling")
    except RuntimeError as e:
        assert _interrupt_code(e) == 130
    assert _interrupt_code(ValueError("plain")) == 0


def test_pool_workers_started_in_children_ignore_sigint_miss_ctrl_c():
    """A terminal's Ctrl-C goes to the whole process group: workers started inside
    :func:`trials.files.output.children_ignore_sigint` never see it (no traceback from each of them);
    the main process gets it, and with mmg's handler nothing else is printed (joblib's warning
    and logged callback errors as the pool is shut down)."""
    r = _python("""
        import os, signal, sys, time
        from joblib import Parallel, delayed, parallel_backend
        from trials import cli
        from trials.files.output import children_ignore_sigint

        def work(i):
            time.sleep(0.5)
            return i

        if __name__ == "__main__":
            cli._install_handlers()                  # as mmg does
            try:
                with parallel_backend("loky", n_jobs=2):
                    with children_ignore_sigint():
                        gen = Parallel(n_jobs=2, return_as="generator_unordered")(delayed(work)(i) for i in range(40))
                    time.sleep(0.1)                  # workers are starting (importing)
                    os.killpg(0, signal.SIGINT)      # Ctrl-C
                    for _ in gen:
                        pass
                print("not interrupted")
            except KeyboardInterrupt:
                print("interrupted")
    """, start_new_session=True)
    assert r.stdout.strip() == "interrupted", r
    assert r.stderr == "", r.stderr


@pytest.mark.slow
def test_montecarlo_ctrl_c_to_the_process_group(tmp_path):
    """Ctrl-C in a terminal (SIGINT to the whole group, workers included): one line, 130, nothing left."""
    base = tmp_path / "base"
    base.mkdir()
    r = run_and_signal(["montecarlo", str(base / "DIR"), "--seeds", "1", "--jobs", "2"], "sweep-task", signal.SIGINT,
                       base, tmp_path / "markers", group=True, count=2)
    assert_interrupted(*r, signal.SIGINT, base)
