"""The ``mmg`` command: one entry point, one argument and exit-code convention.

Every subcommand is a thin layer over public library functions (named in its help):
parse, call, print.  Exit status: 0 done; 2 bad input (one line on stderr naming the file
or option and the field; nothing written) or bad arguments; 3 a diverging filter; 130 / 143
interrupted by SIGINT / SIGTERM (one line, nothing left behind).  Library code never calls
:func:`main`.

Layout: one module per subcommand (:mod:`.simulate`, :mod:`.metrics`, :mod:`.reproduce`,
:mod:`.nomoto` with ``nomoto-paper``, :mod:`.estimate`, :mod:`.sensitivity`, :mod:`.montecarlo` with
``log-filter`` and ``output-error``, :mod:`.predict`, :mod:`.identify`, :mod:`.diagnose`, :mod:`.imo`), each
holding its ``cmd_*`` function and its ``add_parser``; :mod:`.common` the argument types they share;
this module the entry point (:func:`main`, :func:`build_parser` over :data:`COMMANDS`), the exit
codes and the signal and console handling; :mod:`.warmup` the numba cache warm-up
(``python -m trials.cli.warmup``).  The top layer: may import everything below it.

Outputs: every command that writes checks its target first (``--out`` a folder that exists
or can be created, ``--json`` a file whose folder can be written; :func:`trials.files.output.check_output_dir`,
:func:`trials.files.output.check_output_file`) and refuses an unusable one in one line before any
computation; it then writes through :class:`trials.files.output.StagedOutput` (a staging folder
inside the target, moved in at the end), so an error, a full disk, a read-only filesystem,
SIGINT or SIGTERM leaves nothing behind: no staging folder, no partial file, no folder it
created.  A write failure (no space, read-only, no permission) is one line naming the path,
exit 2.  An empty path for any output option is refused when the arguments are read
(:func:`_output_path`).  An existing folder is written into (a command re-run into its own
folder replaces its own files); when it holds files this run did not write (an earlier run's,
another command's) one ``note:`` line on stderr names them after the run
(:func:`trials.files.output.others_note`).  Inputs are named after their files in printed lines and
outputs (:func:`trials.files.output.record_labels`).

Outputs apart from inputs: before any work, an output path (``--json``, ``--out-ship``, the files a
``--out`` or ``--plots`` folder is known to receive) that is the same file as an input (records,
``--train``/``--test``, ``--ship``/``--initial``/``--config``, ``--truth``, trial YAMLs; symlinks, relative
paths and hard links resolved) or as another output is refused in one line
(:func:`trials.cli.common.check_outputs_apart`, from the parser's option names).

Notes: the library's logged notes (a reader's "kept as NaN", a skipped effect) are held while the
command reads its inputs (:class:`trials.cli.common.HeldNotes`) and printed once it proceeds (its first
progress line, or its end): a refused run prints its one error line only.

Console output: a reader that leaves early (``mmg ... | head``) costs only the lines it did not
read: stdout and stderr are wrapped (:class:`_ReaderGone`) so that a closed pipe sends the rest
of the console output to ``os.devnull``; the run goes on, writes every file and exits with its
own status (no SIGPIPE, no BrokenPipeError).

Subcommands
-----------
simulate      a trial from its YAML                    (:func:`trials.runs.run.run_trial`)
metrics       turning/zigzag metrics of any record      (:func:`trials.analysis.metrics.record_metrics`)
reproduce     the main job: the papers reproduced       (:func:`trials.papers.reproduce.reproduce`)
nomoto        Nomoto K, T from a zigzag record          (:func:`trials.analysis.nomoto_report.identify_log`)
nomoto-paper  Artyszuk (2018) Tables 1-8                (:func:`trials.papers.artyszuk.reproduce`)
estimate      hull coefficients from logs or trials     (:func:`trials.estimates.estimation.estimate_and_report`)
sensitivity   sensitivities, CRB, trial design          (:mod:`trials.planning.sensitivity_report`)
montecarlo    EKF Monte Carlo over noise seeds          (:func:`trials.estimates.montecarlo.monte_carlo`)
log-filter    raw-log EKF Monte Carlo                   (:func:`trials.estimates.montecarlo.log_filter_monte_carlo`)
output-error  joint output-error Monte Carlo            (:func:`trials.estimates.montecarlo.output_error_monte_carlo`)
identify      identify a ship model from records        (:func:`trials.measured.identify.identify`)
predict       replay records against their own inputs   (:func:`trials.measured.predict.predict`)
diagnose      name the effect the model is missing      (:func:`trials.measured.diagnose.diagnose`)
imo           the IMO manoeuvring standards, uncertain  (:func:`trials.imo.result.imo`)
"""
from __future__ import annotations

import argparse
import errno
import os
import signal
import sys
from contextlib import contextmanager
from pathlib import Path

from mmg.errors import InputError

from . import diagnose, estimate, identify, imo, metrics, montecarlo, nomoto, predict, reproduce, sensitivity, simulate

COMMANDS = (simulate, metrics, reproduce, nomoto, estimate, sensitivity, montecarlo, predict, identify, diagnose, imo)
"""The command modules, in the order ``mmg --help`` lists their subcommands."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (``error: mmg estimate: argument --seed: ...``), exit 2."""

    def error(self, message):
        self.exit(2, f"error: {self.prog}: {message} (see {self.prog} --help)\n")


class Interrupted(BaseException):
    """SIGTERM arrived (SIGINT arrives as KeyboardInterrupt).

    A BaseException, like KeyboardInterrupt, so that library code catching ``Exception`` does
    not swallow it; ``with`` blocks (the output staging) clean up as it passes."""


def _version() -> str:
    from importlib import metadata

    try:
        return metadata.version("mmg-toolkit")
    except metadata.PackageNotFoundError:
        return "unknown (not installed)"


# --------------------------------------------------------------------------- parser


def build_parser() -> argparse.ArgumentParser:
    """The ``mmg`` argument parser (every subcommand, each added by its module in :data:`COMMANDS`)."""
    ap = _Parser(prog="mmg", description="MMG ship manoeuvring: simulate, analyse, identify.")
    ap.add_argument("--version", action="version", version=f"mmg-toolkit {_version()}")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for command in COMMANDS:
        command.add_parser(sub)
    return ap


_signal_state = {"signum": None, "unwinding": False}


def _on_signal(signum, frame):
    """SIGINT -> KeyboardInterrupt, SIGTERM -> Interrupted.  While that exception unwinds (and the
    staging cleans up) a further signal is ignored, so the clean-up is never cut short."""
    if _signal_state["unwinding"]:
        return
    _signal_state.update(signum=signum, unwinding=True)
    import logging
    import warnings

    # from here on only "interrupted": no joblib "tasks executed but not used" warning, no logged
    # "exception calling callback" of a worker pool being shut down
    warnings.simplefilter("ignore")
    logging.disable(logging.CRITICAL)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Interrupted()


def _unraisable(u, _default=sys.unraisablehook):
    """The interrupt's exception raised where Python cannot propagate it (a weakref callback, a
    ``__del__``: "Exception ignored in ...") is not lost: the signal is sent again, so it is
    raised at the next ordinary line instead; other unraisable exceptions as usual."""
    if (u.exc_type is not None and issubclass(u.exc_type, (Interrupted, KeyboardInterrupt))
            and _signal_state["signum"] is not None):
        import threading

        _signal_state["unwinding"] = False
        # sent a moment later, from another thread: sent here, its handler would run (and raise) in this hook
        t = threading.Timer(0.02, os.kill, (os.getpid(), _signal_state["signum"]))
        t.daemon = True
        t.start()
        return
    _default(u)


def _install_handlers() -> dict:
    """Our handler for SIGINT and SIGTERM where they have their default one (main thread only);
    returns the old handlers to restore."""
    import logging
    import threading

    old = {}
    _signal_state.update(signum=None, unwinding=False)
    if threading.current_thread() is not threading.main_thread():
        return old
    old["logging"] = logging.root.manager.disable      # _on_signal silences logging: put back after main()
    defaults = {signal.SIGINT: (signal.default_int_handler,), signal.SIGTERM: (signal.SIG_DFL, None)}
    for sig, dflt in defaults.items():
        if signal.getsignal(sig) in dflt:
            old[sig] = signal.signal(sig, _on_signal)
    if signal.SIGINT in old or signal.SIGTERM in old:
        old["unraisablehook"] = sys.unraisablehook
        sys.unraisablehook = lambda u, _d=sys.unraisablehook: _unraisable(u, _d)
    return old


class _ReaderGone:
    """A console stream (stdout, stderr) that outlives its reader: when the pipe it writes to is
    closed (``mmg ... | head``: EPIPE, a BrokenPipeError with SIGPIPE ignored, as Python has it),
    its file descriptor is pointed at ``os.devnull`` and the write counts as done, so the run goes
    on and writes its files, and the exit status is its own.  Everything else is the stream's."""

    def __init__(self, stream):
        self._stream = stream
        self.gone = False

    def _closed(self) -> None:
        self.gone = True
        try:
            fd = os.open(os.devnull, os.O_WRONLY)
            try:
                os.dup2(fd, self._stream.fileno())       # the buffered rest, and any later flush, go there
            finally:
                os.close(fd)
        except (OSError, ValueError, AttributeError):
            pass

    def _guarded(self, call, *a):
        if self.gone:
            try:
                return call(*a)                          # to os.devnull now (or a stream without a descriptor)
            except (BrokenPipeError, ValueError, OSError):
                return None
        try:
            return call(*a)
        except BrokenPipeError:
            self._closed()
        except OSError as e:
            if e.errno != errno.EPIPE:
                raise
            self._closed()
        return None

    def write(self, text):
        self._guarded(self._stream.write, text)
        return len(text)

    def writelines(self, lines):
        self._guarded(self._stream.writelines, lines)

    def flush(self):
        self._guarded(self._stream.flush)

    def __getattr__(self, name):
        return getattr(self._stream, name)


@contextmanager
def _console_outlives_reader():
    """sys.stdout and sys.stderr wrapped in :class:`_ReaderGone` for the block (flushed and put back after)."""
    old = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = (_ReaderGone(x) if x is not None else x for x in old)
    try:
        yield
    finally:
        for x in (sys.stdout, sys.stderr):
            if isinstance(x, _ReaderGone):
                x.flush()
        sys.stdout, sys.stderr = old


def _interrupted(code: int) -> int:
    print("interrupted", file=sys.stderr)
    return code


def main(argv=None) -> int:
    """Run the ``mmg`` command; returns the exit status (see the module docstring)."""
    import warnings

    old = _install_handlers()          # first: an early signal is already one line, 130 / 143
    try:
        with warnings.catch_warnings(), _console_outlives_reader():   # _on_signal silences warnings: only for this run
            try:
                return _run(argv)
            except KeyboardInterrupt:      # a signal during the last lines of _run's own handling
                return _interrupted(130)
            except Interrupted:
                return _interrupted(143)
    finally:
        hook = old.pop("unraisablehook", None)
        level = old.pop("logging", None)
        for sig, h in old.items():
            signal.signal(sig, h)
        if hook is not None:
            sys.unraisablehook = hook
        if level is not None:
            import logging

            logging.disable(level)
        if argv is None and signal.SIGINT in old and _is_command_line():
            # the run is over (its outputs are in place or gone): a Ctrl-C while Python shuts down
            # (joining the worker pool's threads) would only print a KeyboardInterrupt traceback
            signal.signal(signal.SIGINT, signal.SIG_IGN)


def _is_command_line() -> bool:
    """This process is the ``mmg`` command (console script or ``python -m trials.cli``, which runs
    ``trials.cli.__main__``)."""
    main_mod = sys.modules.get("__main__")
    spec = getattr(main_mod, "__spec__", None)
    return Path(sys.argv[0]).name in ("mmg", "mmg.exe") or (spec is not None and spec.name == "trials.cli.__main__")


def _run(argv) -> int:
    ap = build_parser()
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:            # --help, --version (0) and bad arguments (2, one usage line)
        return int(e.code or 0)
    if not getattr(args, "show", False):
        os.environ.setdefault("MPLBACKEND", "Agg")   # files only; no display needed (cheap: nothing imported)
    from ..files.output import collect_commits, others_note

    import logging

    from .common import HeldNotes, _held

    held = HeldNotes()                     # the library's notes: printed once the command proceeds
    logging.root.addHandler(held)
    _held.append(held)
    try:
        return _run_command(args, collect_commits, others_note)
    finally:
        logging.root.removeHandler(held)
        _held.remove(held)


def _run_command(args, collect_commits, others_note) -> int:
    from .common import check_outputs_apart, release_notes

    try:
        check_outputs_apart(args)          # no output over an input or another output: before any work
        with collect_commits() as committed:
            code = int(args.func(args) or 0)
        release_notes()                    # done: the notes of the inputs it accepted
        for stage in committed:            # the folders written into: what they hold that this run did not write
            note = others_note(stage)
            if note:
                print(note, file=sys.stderr)
        return code
    except (Exception, KeyboardInterrupt, Interrupted) as e:
        code = _interrupt_code(e)
        if code:
            return _interrupted(code)
        if isinstance(e, InputError):
            print(f"error: {e}", file=sys.stderr)
            return 2
        if isinstance(e, OSError) and e.errno in _WRITE_ERRNOS():
            # writing (or reading) a file failed: no space, read-only filesystem, no permission
            from ..files.output import write_error

            print(f"error: {write_error(e) if e.errno in _FULL_OR_READ_ONLY else _os_error_line(e)}", file=sys.stderr)
            return 2
        from ekf.filter import FilterDivergence

        if isinstance(e, FilterDivergence):   # a diverging filter is a result, not a crash
            print(f"error: {e}", file=sys.stderr)
            return 3
        raise


def _interrupt_code(e: BaseException) -> int:
    """130 / 143 when ``e`` is, or was caused by, the interrupt (numba, for one, turns an exception
    raised in a callback into a SystemError), or when any error follows a signal; else 0."""
    seen, x = set(), e
    while x is not None and id(x) not in seen:
        if isinstance(x, KeyboardInterrupt):
            return 130
        if isinstance(x, Interrupted):
            return 143
        seen.add(id(x))
        x = x.__cause__ or x.__context__
    if _signal_state["unwinding"] and _signal_state["signum"] is not None:
        return 130 if _signal_state["signum"] == signal.SIGINT else 143
    return 0


def _WRITE_ERRNOS():
    from ..files.output import WRITE_ERRNOS

    return WRITE_ERRNOS


_FULL_OR_READ_ONLY = {getattr(errno, n) for n in ("ENOSPC", "EROFS", "EDQUOT", "EFBIG") if hasattr(errno, n)}


def _os_error_line(e: OSError) -> str:
    return f"{e.filename or '?'}: {e.strerror or e}"

