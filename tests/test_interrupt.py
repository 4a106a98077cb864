"""SIGTERM and SIGINT while a command works: one line ``interrupted``, exit 143 / 130, nothing left.

The commands run as real processes (the installed ``mmg`` script); the signal is sent while they
work: once their staging folder exists (it is made before the computation starts) and at least
1.5 s after the start, and the test checks the process was still running at that moment.
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


def run_and_signal(args, watch: Path, sig, base: Path, min_delay=1.5, group=False, timeout=300):
    """Start ``mmg args``, wait until ``watch`` holds a staging folder and ``min_delay`` s passed,
    send ``sig`` (to the process, or its whole process group as a terminal's Ctrl-C does); return
    (exit code, stdout, stderr)."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    p = subprocess.Popen(mmg_argv() + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=base,
                         env=env, start_new_session=True)
    t0 = time.monotonic()
    try:
        while not (watch.is_dir() and list(watch.glob(".staging-*"))):
            assert p.poll() is None, f"mmg {args[0]} ended before it staged anything: {p.communicate()}"
            assert time.monotonic() - t0 < timeout, "no staging folder appeared"
            time.sleep(0.02)
        time.sleep(max(0.0, min_delay - (time.monotonic() - t0)) + 0.2)
        assert p.poll() is None, f"mmg {args[0]} finished before the signal: the test proves nothing"
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


def long_st35(folder: Path) -> Path:
    """ST35 run for 30000 s: its log, truth file and plots take seconds to write, so the signal
    surely meets the command while it stages (the 3000 s run now finishes within the test's delay)."""
    text = (CONFIGS / "trials" / "st35.yaml").read_text().replace("duration: 3000 s", "duration: 30000 s")
    assert "duration: 30000 s" in text
    p = folder / "st35_long.yaml"
    p.write_text(text)                     # "ship: esso_osaka" is the bundled ship by name
    return p


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_simulate_interrupted(sig, tmp_path):
    base = tmp_path / "base"
    base.mkdir()
    out = base / "DIR"
    r = run_and_signal(["simulate", str(long_st35(tmp_path)), "--out", str(out)], out, sig, base)
    assert_interrupted(*r, sig, base)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_estimate_interrupted(sig, tmp_path):
    base = tmp_path / "base"
    base.mkdir()
    out = base / "DIR"
    r = run_and_signal(["estimate", str(CONFIGS / "trials" / "zz20.yaml"), "--out", str(out)], out, sig, base)
    assert_interrupted(*r, sig, base)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_nomoto_interrupted(sig, tmp_path, zz20_log):
    base = tmp_path / "base"
    base.mkdir()
    out = base / "DIR"
    r = run_and_signal(["nomoto", str(zz20_log), "--length", "325", "--json", str(out / "x.json")], out, sig, base)
    assert_interrupted(*r, sig, base)


def test_signal_before_staging(tmp_path):
    """A SIGTERM 0.8 s after the start (the command still importing, reading its input or simulating:
    a warm 3000 s ST35 now finishes in about 1.5 s, so the 30000 s one, whose files take seconds)."""
    base = tmp_path / "base"
    base.mkdir()
    p = subprocess.Popen(mmg_argv() + ["simulate", str(long_st35(tmp_path)), "--out", str(base / "DIR")],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(0.8)
    assert p.poll() is None
    p.send_signal(signal.SIGTERM)
    out, err = p.communicate(timeout=300)
    assert_interrupted(p.returncode, out, err, signal.SIGTERM, base)


def test_montecarlo_interrupted_workers_leave_nothing(tmp_path):
    """SIGTERM to a Monte Carlo on two loky workers: nothing left, and the workers are gone."""
    base = tmp_path / "base"
    base.mkdir()
    out = base / "DIR"
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    p = subprocess.Popen(mmg_argv() + ["montecarlo", str(out), "--seeds", "1", "--jobs", "2"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=env, start_new_session=True)
    t0 = time.monotonic()
    while not list(out.glob(".staging-*")) or len(_group(p.pid)) < 3:       # main + 2 workers
        assert p.poll() is None and time.monotonic() - t0 < 300, p.communicate()
        time.sleep(0.05)
    time.sleep(1.0)
    assert p.poll() is None
    p.send_signal(signal.SIGTERM)
    out_, err = p.communicate(timeout=300)
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
    :func:`trials.output.children_ignore_sigint` never see it (no traceback from each of them);
    the main process gets it, and with mmg's handler nothing else is printed (joblib's warning
    and logged callback errors as the pool is shut down)."""
    r = _python("""
        import os, signal, sys, time
        from joblib import Parallel, delayed, parallel_backend
        from trials import cli
        from trials.output import children_ignore_sigint

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
    out = base / "DIR"
    r = run_and_signal(["montecarlo", str(out), "--seeds", "1", "--jobs", "2"], out, signal.SIGINT, base, min_delay=1.0,
                       group=True)
    assert_interrupted(*r, signal.SIGINT, base)
