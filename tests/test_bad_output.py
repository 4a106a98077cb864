"""Bad output targets: refused in one line before any computation; write failures (no space,
read-only filesystem) are one line, exit 2; nothing is ever left behind; JSON never holds NaN."""
import errno
import json
import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from trials.files import output
from trials.cli import main
from trials.files.output import StagedFile, StagedOutput, check_output_dir, check_output_file, dump_json

from .conftest import CONFIGS

ZZ20 = str(CONFIGS / "trials" / "zz20.yaml")
ST35 = str(CONFIGS / "trials" / "st35.yaml")


def strict_json(path):
    """The file parsed with NaN / Infinity refused."""
    def refuse(c):
        raise ValueError(f"{path}: {c} in JSON")

    return json.loads(Path(path).read_text(), parse_constant=refuse)


def one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("error: ")
    assert "Traceback" not in err[0]
    return err[0]


def tree(p: Path) -> list:
    return sorted(str(q.relative_to(p)) for q in p.rglob("*"))


# --------------------------------------------------------------------------- refused before any computation


@pytest.fixture
def no_computation(monkeypatch):
    """Every expensive entry point of the commands raises: a refusal must come before them."""
    import trials.papers.artyszuk
    import trials.estimates.estimation
    import trials.estimates.montecarlo
    import trials.analysis.nomoto_report
    import trials.papers.reproduce
    import trials.runs.run
    import trials.planning.sensitivity_report
    import trials.imo.result

    def boom(*a, **k):
        raise AssertionError("computation started before the output target was checked")

    for mod, names in [(trials.runs.run, ["run_trial"]), (trials.imo.result, ["imo"]), (trials.papers.reproduce, ["reproduce"]), (trials.papers.artyszuk, ["reproduce"]),
                       (trials.estimates.estimation, ["load_inputs", "estimate_and_report"]),
                       (trials.analysis.nomoto_report, ["identify_log"]),
                       (trials.planning.sensitivity_report, ["trial_sensitivities", "paper_figures", "crb_table", "design"]),
                       (trials.estimates.montecarlo, ["monte_carlo", "log_filter_monte_carlo", "output_error_monte_carlo",
                                            "summarise"])]:
        for n in names:
            monkeypatch.setattr(mod, n, boom)


@pytest.fixture(scope="module")
def zz20_log(tmp_path_factory):
    d = tmp_path_factory.mktemp("zz20")
    assert main(["simulate", ZZ20, "--out", str(d)]) == 0
    return d / "log.csv"


def _commands(target, log):
    """Every writing command with its output target ``target``."""
    t = str(target)
    return {
        "simulate": ["simulate", ST35, "--out", t],
        "reproduce": ["reproduce", "--out", t],
        "nomoto-paper": ["nomoto-paper", "--out", t],
        "estimate": ["estimate", ZZ20, "--out", t],
        "sensitivity": ["sensitivity", ZZ20, "--out", t],
        "sensitivity --design": ["sensitivity", "--design", "--out", t],
        "montecarlo": ["montecarlo", t, "--seeds", "1"],
        "log-filter": ["log-filter", t, "--seeds", "1"],
        "output-error": ["output-error", t, "--seeds", "1"],
        "imo": ["imo", "esso_osaka", "--out", t],
    }


FOLDER_COMMANDS = list(_commands("x", "y"))


@pytest.mark.parametrize("cmd", FOLDER_COMMANDS)
def test_out_an_existing_file_refused_first(cmd, tmp_path, capsys, no_computation):
    f = tmp_path / "taken.txt"
    f.write_text("keep me")
    assert main(_commands(f, None)[cmd]) == 2
    line = one_error_line(capsys)
    assert str(f) in line and "is a file, not a folder" in line
    assert f.read_text() == "keep me"
    assert tree(tmp_path) == ["taken.txt"]


@pytest.mark.parametrize("cmd", FOLDER_COMMANDS)
def test_out_under_a_file_refused_first(cmd, tmp_path, capsys, no_computation):
    f = tmp_path / "taken.txt"
    f.write_text("keep me")
    assert main(_commands(f / "sub" / "out", None)[cmd]) == 2
    line = one_error_line(capsys)
    assert f"{f} is a file, not a folder" in line
    assert tree(tmp_path) == ["taken.txt"]


def test_json_a_folder_refused_first(tmp_path, capsys, zz20_log, no_computation):
    d = tmp_path / "dir"
    d.mkdir()
    for argv in (["metrics", str(zz20_log), "--json", str(d)],
                 ["nomoto", str(zz20_log), "--length", "325", "--json", str(d)],
                 ["nomoto", str(zz20_log), "--length", "325", "--json", str(tmp_path / "new") + os.sep]):
        assert main(argv) == 2
        line = one_error_line(capsys)
        assert "--json" in line and ("is a folder" in line or "names a folder" in line), line
    (d / "x.png").mkdir()                       # the plot beside the JSON would land on a folder
    assert main(["nomoto", str(zz20_log), "--length", "325", "--json", str(d / "x.json")]) == 2
    assert "x.png is a folder" in one_error_line(capsys)
    assert tree(tmp_path) == ["dir", "dir/x.png"]


def test_json_not_a_regular_file_refused(capsys, zz20_log, no_computation):
    assert main(["metrics", str(zz20_log), "--json", os.devnull]) == 2
    assert "is not a regular file" in one_error_line(capsys)


def test_empty_target_refused(capsys, no_computation):
    assert main(["simulate", ST35, "--out", ""]) == 2
    assert "empty path" in one_error_line(capsys)


def _fail_mkdir_under(monkeypatch, root: Path, err: int):
    """os.mkdir / os.open creating anything directly in ``root`` fails with ``err`` (a read-only or
    full filesystem, for root too)."""
    real_mkdir, real_open = os.mkdir, os.open

    def mkdir(path, *a, **k):
        if Path(path).parent == root:
            raise OSError(err, os.strerror(err), str(path))
        return real_mkdir(path, *a, **k)

    def open_(path, flags, *a, **k):
        if Path(path).parent == root and flags & os.O_CREAT:
            raise OSError(err, os.strerror(err), str(path))
        return real_open(path, flags, *a, **k)

    monkeypatch.setattr(os, "mkdir", mkdir)
    monkeypatch.setattr(os, "open", open_)


@pytest.mark.parametrize("err", [errno.EROFS, errno.EACCES])
def test_unwritable_location_refused_first(err, tmp_path, capsys, monkeypatch, no_computation):
    ro = tmp_path / "ro"
    ro.mkdir()
    _fail_mkdir_under(monkeypatch, ro, err)
    for argv in (["simulate", ST35, "--out", str(ro / "new" / "out")],
                 ["montecarlo", str(ro), "--seeds", "1"],
                 ["estimate", ZZ20, "--out", str(ro)]):
        assert main(argv) == 2
        line = one_error_line(capsys)
        assert f"cannot write in {ro}" in line and os.strerror(err) in line, line
    assert tree(tmp_path) == ["ro"]


def test_check_functions_leave_nothing(tmp_path):
    assert check_output_dir(tmp_path / "a" / "b") == tmp_path / "a" / "b"
    assert check_output_file(tmp_path / "c" / "x.json", also=[tmp_path / "c" / "x.png"]) == tmp_path / "c" / "x.json"
    assert check_output_dir(tmp_path) == tmp_path
    assert tree(tmp_path) == []


# --------------------------------------------------------------------------- every writable target works


def test_folder_under_a_read_only_parent_works(tmp_path, capsys, monkeypatch):
    """A home folder under a read-only parent (and a mount point, the same case): staged inside itself."""
    ro = tmp_path / "ro"
    home = ro / "home"
    home.mkdir(parents=True)
    (home / "old.txt").write_text("kept")
    _fail_mkdir_under(monkeypatch, ro, errno.EROFS)
    assert main(["simulate", ST35, "--out", str(home)]) == 0
    assert "wrote" in capsys.readouterr().out
    assert tree(home) == ["histories.png", "log.csv", "metrics.json", "old.txt", "track.png", "truth.csv"]
    assert (home / "old.txt").read_text() == "kept"
    strict_json(home / "metrics.json")


def test_new_nested_folder_and_json_work(tmp_path, capsys, zz20_log):
    out = tmp_path / "a" / "b" / "m.json"
    assert main(["metrics", str(zz20_log), "--json", str(out)]) == 0
    assert tree(tmp_path) == ["a", "a/b", "a/b/m.json"]
    assert strict_json(out)["kind"] == "zigzag"
    # relative, in the working folder
    monkeypatch_cwd = os.getcwd()
    try:
        os.chdir(tmp_path)
        assert main(["metrics", str(zz20_log), "--json", "here.json"]) == 0
    finally:
        os.chdir(monkeypatch_cwd)
    assert tree(tmp_path) == ["a", "a/b", "a/b/m.json", "here.json"]


def test_cross_device_move_falls_back_to_copy(tmp_path, monkeypatch):
    """A rename that meets another filesystem inside the target (EXDEV) is copied then renamed."""
    real = os.replace
    calls = []

    def replace(src, dst):
        if ".staging-" in str(src) and ".staging-" not in str(dst) and not calls:
            calls.append(dst)
            raise OSError(errno.EXDEV, os.strerror(errno.EXDEV), str(src), None, str(dst))
        return real(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    with StagedOutput(tmp_path / "out") as st:
        st.path("a.txt").write_text("a")
        st.path("sub/b.txt").write_text("b")
    assert calls
    assert tree(tmp_path) == ["out", "out/a.txt", "out/sub", "out/sub/b.txt"]
    assert (tmp_path / "out" / "a.txt").read_text() == "a"


def test_replaced_file_keeps_its_mode(tmp_path):
    f = tmp_path / "x.json"
    f.write_text("{}")
    f.chmod(0o640)
    dump_json({"a": 1}, f)
    assert (f.stat().st_mode & 0o777) == 0o640
    g = tmp_path / "y.json"
    dump_json({"a": 1}, g)
    umask = os.umask(0)
    os.umask(umask)
    assert (g.stat().st_mode & 0o777) == 0o666 & ~umask


# --------------------------------------------------------------------------- failures while writing


def _full_disk(monkeypatch, under: Path, after: int = 1000):
    """Files opened for writing below ``under`` get a disk that is full after ``after`` bytes: their
    writes (at a buffer flush or at close, as with a real full disk) raise ENOSPC."""
    import builtins
    import io

    real_open = builtins.open

    class FullFileIO(io.FileIO):
        written = 0

        def write(self, b):
            self.written += len(b)
            if self.written > after:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            return super().write(b)

    def open_(file, mode="r", buffering=-1, encoding=None, errors=None, newline=None, closefd=True, opener=None):
        if not (isinstance(file, (str, os.PathLike)) and str(Path(file)).startswith(str(under))
                and any(c in mode for c in "wax")):
            return real_open(file, mode, buffering, encoding, errors, newline, closefd, opener)
        raw = FullFileIO(file, next(c for c in mode if c in "wax") + ("+" if "+" in mode else ""))
        buf = io.BufferedWriter(raw)
        if "b" in mode:
            return buf
        return io.TextIOWrapper(buf, encoding=encoding or "utf-8", errors=errors, newline=newline)

    monkeypatch.setattr(builtins, "open", open_)
    monkeypatch.setattr(io, "open", open_)           # pathlib's write_text


def test_no_space_left_while_writing(tmp_path, capsys, monkeypatch):
    base = tmp_path / "base"
    base.mkdir()
    _full_disk(monkeypatch, base)
    out = base / "new" / "out"
    assert main(["simulate", ST35, "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert "No space left on device" in line and str(out) in line and ".staging-" not in line, line
    assert tree(base) == []                       # no staging folder, no partial file, no folder it created


def test_no_space_left_json(tmp_path, capsys, monkeypatch, zz20_log):
    base = tmp_path / "base"
    base.mkdir()
    _full_disk(monkeypatch, base, after=10)
    target = base / "sub" / "m.json"
    assert main(["metrics", str(zz20_log), "--json", str(target)]) == 2
    line = one_error_line(capsys)
    assert "No space left on device" in line and str(target) in line, line
    assert tree(base) == []


def test_read_only_at_commit(tmp_path, capsys, monkeypatch):
    """The final moves fail (EROFS): one line naming the final path, nothing left, old files intact."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "log.csv").write_text("old log")
    real = os.replace

    def replace(src, dst):
        if ".staging-" not in str(dst) and ".replaced-" not in str(dst) and Path(dst).name == "metrics.json":
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(src), None, str(dst))
        return real(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    assert main(["simulate", ST35, "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert "Read-only file system" in line and str(out / "metrics.json") in line, line
    assert tree(out) == ["log.csv"]
    assert (out / "log.csv").read_text() == "old log"   # replaced during the commit, then put back


def test_failure_inside_removes_created_parents(tmp_path):
    with pytest.raises(RuntimeError):
        with StagedOutput(tmp_path / "a" / "b" / "c") as st:
            st.path("x.txt").write_text("x")
            assert (tmp_path / "a" / "b" / "c").is_dir()
            raise RuntimeError("boom")
    assert tree(tmp_path) == []
    keep = tmp_path / "keep"
    keep.mkdir()
    with pytest.raises(RuntimeError):
        with StagedOutput(keep) as st:
            st.path("x.txt").write_text("x")
            raise RuntimeError("boom")
    assert tree(tmp_path) == ["keep"]            # an existing folder stays, empty as it was


def test_file_where_a_folder_is_staged(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "sub").write_text("a file")
    with pytest.raises(output.InputError, match="is a file"):
        with StagedOutput(out) as st:
            st.path("a.txt").write_text("a")
            st.path("sub/b.txt").write_text("b")
    assert tree(out) == ["sub"]


def test_signal_during_commit_undoes_it(tmp_path, monkeypatch):
    """SIGINT arriving while the files are moved in: the commit is undone (old files back), then the
    interrupt is raised.  (Sent to this thread: ``os.kill`` may hand it to another thread, which
    can run its handler after the commit has ended; the next test covers that case.)"""
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.txt").write_text("old a")
    real = output._move
    sent = []

    def move(src, dst):
        if not sent:
            sent.append(1)
            signal.pthread_kill(threading.main_thread().ident, signal.SIGINT)    # held until the commit ends
        return real(src, dst)

    monkeypatch.setattr(output, "_move", move)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    with pytest.raises(KeyboardInterrupt):
        with StagedOutput(out) as st:
            st.path("a.txt").write_text("new a")
            st.path("b.txt").write_text("new b")
    assert sent
    assert tree(out) == ["a.txt"] and (out / "a.txt").read_text() == "old a"


@pytest.mark.parametrize("where", ["other thread", "this thread"])
def test_signal_during_commit_undoes_it_whichever_thread_gets_it(tmp_path, monkeypatch, where):
    """The kernel gives a process-directed SIGINT to any thread that does not block it (numba, BLAS
    and pool threads do not); Python then runs the handler in the main thread at an arbitrary
    point.  Here it lands just after an old file was moved aside, before the undo journal notes it:
    raised there, the old file would be lost.  It must not raise mid-commit: the commit is undone
    (old file back) and the interrupt raised after."""
    stop = threading.Event()
    other = threading.Thread(target=stop.wait, daemon=True)
    other.start()                                  # started with SIGINT unblocked
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.txt").write_text("old a")
    real = os.replace
    sent = []

    def replace(src, dst, *a, **k):
        real(src, dst, *a, **k)
        if not sent and Path(src) == out / "a.txt":          # the old a.txt moved aside
            sent.append(1)
            target = other.ident if where == "other thread" else threading.main_thread().ident
            signal.pthread_kill(target, signal.SIGINT)
            deadline = time.monotonic() + 5.0      # until its handler has run in this thread
            while where == "other thread" and not getattr(output, "_noted", None) and time.monotonic() < deadline:
                time.sleep(0.001)

    monkeypatch.setattr(os, "replace", replace)
    try:
        with pytest.raises(KeyboardInterrupt):
            with StagedOutput(out) as st:
                st.path("a.txt").write_text("new a")
                st.path("b.txt").write_text("new b")
    finally:
        monkeypatch.undo()
        stop.set()
        other.join()
    assert sent
    assert tree(out) == ["a.txt"] and (out / "a.txt").read_text() == "old a"
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_staged_file_failure_leaves_nothing(tmp_path):
    with pytest.raises(RuntimeError):
        with StagedFile(tmp_path / "d" / "x.json") as tmp:
            tmp.write_text("half")
            raise RuntimeError("boom")
    assert tree(tmp_path) == []


# --------------------------------------------------------------------------- JSON without NaN


def test_dump_json_writes_null_for_nan(tmp_path):
    obj = {"a": float("nan"), "b": [1.0, float("inf"), -np.inf], "c": np.float32("nan"), "d": np.array([1.0, np.nan]),
           "e": (np.int64(3), np.bool_(True)), np.int64(7): "key", "f": {"g": np.float64(2.5)}}
    dump_json(obj, tmp_path / "x.json")
    got = strict_json(tmp_path / "x.json")
    assert got == {"a": None, "b": [1.0, None, None], "c": None, "d": [1.0, None], "e": [3, True], "7": "key",
                   "f": {"g": 2.5}}
    with pytest.raises(TypeError):
        dump_json({"x": object()}, tmp_path / "bad.json")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.json"]   # a TypeError writes nothing


def test_estimate_no_plots_claims_no_png(tmp_path, capsys):
    out = tmp_path / "est"
    assert main(["estimate", ZZ20, "--out", str(out), "--no-plots"]) == 0
    text = capsys.readouterr().out
    wrote = [ln for ln in text.splitlines() if ln.startswith("wrote ")]
    assert len(wrote) == 1 and "png" not in wrote[0] and "estimates.json" in wrote[0], wrote
    assert not list(out.glob("*.png"))
    for f in out.glob("*.json"):
        strict_json(f)
    assert not list(out.glob(".*"))


# --------------------------------------------------------------------------- every output option


def _output_options(zz20_log):
    """Every output option of every command, with a command line that gives it ``{}``."""
    log = str(zz20_log)
    return {
        ("simulate", "--out"): ["simulate", ST35, "--out", "{}"],
        ("metrics", "--json"): ["metrics", log, "--json", "{}"],
        ("reproduce", "--out"): ["reproduce", "--out", "{}"],
        ("nomoto", "--json"): ["nomoto", log, "--length", "325", "--json", "{}"],
        ("nomoto-paper", "--out"): ["nomoto-paper", "--out", "{}"],
        ("estimate", "--out"): ["estimate", ZZ20, "--out", "{}"],
        ("sensitivity", "--out"): ["sensitivity", ZZ20, "--out", "{}"],
        ("sensitivity", "--crb-vs-mc"): ["sensitivity", "--crb-vs-mc", "{}", "--out", "x"],
        ("montecarlo", "out"): ["montecarlo", "{}", "--seeds", "1"],
        ("log-filter", "out"): ["log-filter", "{}", "--seeds", "1"],
        ("output-error", "out"): ["output-error", "{}", "--seeds", "1"],
        ("predict", "--json"): ["predict", log, "--ship", "esso_osaka", "--json", "{}"],
        ("predict", "--plots"): ["predict", log, "--ship", "esso_osaka", "--json", "p.json", "--plots", "{}"],
        ("identify", "--out"): ["identify", "--ship", "esso_osaka", "--train", log, "--out", "{}"],
        ("diagnose", "--json"): ["diagnose", log, "--ship", "esso_osaka", "--json", "{}"],
        ("diagnose", "--plots"): ["diagnose", log, "--ship", "esso_osaka", "--json", "d.json", "--plots", "{}"],
        ("diagnose", "--out-ship"): ["diagnose", log, "--ship", "esso_osaka", "--json", "d.json", "--out-ship", "{}"],
        ("imo", "--out"): ["imo", "esso_osaka", "--out", "{}"],
    }


def _parser_output_options() -> set:
    """(command, option) of every output option build_parser has (a new one must join the table above)."""
    from trials.cli import build_parser

    sub = next(a for a in build_parser()._actions if a.choices and isinstance(a.choices, dict))
    found = set()
    for cmd, p in sub.choices.items():
        for a in p._actions:
            name = a.option_strings[0] if a.option_strings else a.dest
            if a.dest in ("out", "json", "plots", "out_ship", "crb_vs_mc") or "output" in (a.help or "").split(" ")[:2]:
                found.add((cmd, name))
    return found


@pytest.mark.parametrize("empty", ["", " "])
def test_every_output_option_refuses_an_empty_path(empty, tmp_path, capsys, monkeypatch, zz20_log, no_computation):
    """`mmg metrics LOG --json ''` wrote nothing and exited 0: an empty path is refused, for every option."""
    monkeypatch.chdir(tmp_path)
    assert _parser_output_options() == set(_output_options(zz20_log))
    for (cmd, opt), argv in _output_options(zz20_log).items():
        assert main([a.replace("{}", empty) for a in argv]) == 2, (cmd, opt)
        line = one_error_line(capsys)
        assert "empty path" in line and (opt if opt.startswith("--") else "out") in line, line
    assert tree(tmp_path) == []


def _closed_pipe_run(argv, cwd, unbuffered: bool, stderr_too: bool = False):
    """``mmg argv`` with its stdout (and stderr) a pipe nobody reads (closed before the first line)."""
    import subprocess
    import sys

    r, w = os.pipe()
    os.close(r)                                         # the reader left: every write is EPIPE
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    env.pop("PYTHONUNBUFFERED", None)
    if unbuffered:
        env["PYTHONUNBUFFERED"] = "1"
    try:
        p = subprocess.run([sys.executable, "-m", "trials.cli", *argv], cwd=cwd, env=env, stdout=w,
                           stderr=w if stderr_too else subprocess.PIPE, timeout=600)
    finally:
        os.close(w)
    return p.returncode, (p.stderr or b"").decode()


@pytest.mark.parametrize("unbuffered", [True, False])
def test_a_closed_stdout_loses_no_file(unbuffered, tmp_path, zz20_log):
    """`mmg metrics LOG --json m.json | head -c 20` was killed (141) before m.json was written: the files
    are all written and the exit is the run's own, for every kind of command (a folder, a JSON, plots)."""
    log = str(zz20_log)
    cases = [(["metrics", log, "--json", "m.json"], ["m.json"]),
             (["simulate", ST35, "--out", "sim"], ["sim/log.csv", "sim/metrics.json", "sim/track.png"]),
             (["nomoto", log, "--length", "325", "--json", "n/n.json", "--no-output-error"], ["n/n.json", "n/n.png"]),
             (["predict", log, "--ship", "esso_osaka", "--json", "p.json", "--plots", "pl"], ["p.json", "pl/log.png"])]
    for argv, files in cases:
        code, err = _closed_pipe_run(argv, tmp_path, unbuffered)
        assert code == 0, (argv, code, err)
        assert "Traceback" not in err and "BrokenPipe" not in err and "Exception ignored" not in err, err
        for f in files:
            assert (tmp_path / f).is_file(), (argv, f, tree(tmp_path))
            if f.endswith(".json"):
                strict_json(tmp_path / f)
    code, _ = _closed_pipe_run(["metrics", log, "--json", "both.json"], tmp_path, unbuffered, stderr_too=True)
    assert code == 0 and strict_json(tmp_path / "both.json")["kind"] == "zigzag"
    assert not [p for p in tmp_path.rglob(".*")]            # no staging or temporary file left


def test_a_folder_holding_other_files_is_reported(tmp_path, capsys, zz20_log):
    """An existing --out keeps an earlier run's files of another command beside the new ones: one note
    line names them; the same command re-run into its own folder replaces its files without a note."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "m.json").write_text("{}")                       # another command's file
    (out / "old").mkdir()
    (out / "old" / "x.csv").write_text("1")
    assert main(["simulate", ST35, "--out", str(out)]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("note: ") and "2 entries this run did not write" in err[0], err
    assert "m.json" in err[0] and "old/" in err[0] and str(out) in err[0]
    assert (out / "m.json").read_text() == "{}" and (out / "old" / "x.csv").read_text() == "1"
    fresh = tmp_path / "fresh"
    assert main(["simulate", ST35, "--out", str(fresh)]) == 0
    assert main(["simulate", ZZ20, "--out", str(fresh)]) == 0      # its own files again: replaced, no note
    assert "note:" not in capsys.readouterr().err
    # the same command leaving fewer files: the earlier run's one left over is named
    assert main(["predict", str(zz20_log), "--ship", "esso_osaka", "--json", str(tmp_path / "p.json"),
                 "--plots", str(fresh)]) == 0
    err = capsys.readouterr().err
    assert "this run did not write" in err and "truth.csv" in err and "log.png" not in err.split("write")[-1]
    # a JSON written into a folder of other files is a file, not a folder this run wrote into: no note
    assert main(["metrics", str(zz20_log), "--json", str(out / "m2.json")]) == 0
    assert main(["nomoto", str(zz20_log), "--length", "325", "--json", str(out / "n.json"), "--no-output-error"]) == 0
    assert "did not write" not in capsys.readouterr().err        # (metrics' own notes on the record may be there)


def test_not_written_looks_only_into_the_folders_written(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "mine.png").write_text("")
    (tmp_path / "a" / "old.png").write_text("")
    (tmp_path / "b" / "c").mkdir(parents=True)
    (tmp_path / "top.txt").write_text("")
    (tmp_path / ".staging-xyz").mkdir()                     # another run in progress
    assert output.not_written(tmp_path, ["a/mine.png"]) == ["a/old.png", "b/", "top.txt"]
    assert output.not_written(tmp_path, ["a/mine.png", "a/old.png", "top.txt"]) == ["b/"]


def test_own_json_being_written_is_not_another_runs_file(tmp_path):
    """A JSON file written beside the figures (``--json DIR/x.json --plots DIR``) is this run's: its temporary
    file, alive while the figures' folder is committed, is not listed as what another run left there; a
    real leftover temporary file of another run still is."""
    (tmp_path / ".old.json.abc.tmp").write_text("{}")
    with StagedFile(tmp_path / "x.json") as tmp:
        tmp.write_text("{}")
        with StagedOutput(tmp_path) as stage:
            stage.path("a.png").write_bytes(b"png")
    assert stage.written == ["a.png"]
    assert stage.others == [".old.json.abc.tmp"]
