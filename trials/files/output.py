"""Outputs written all-or-nothing, checked before any work, and JSON without NaN.

* :func:`check_output_dir` / :func:`check_output_file` refuse an unusable ``--out`` folder or
  ``--json`` file in one :class:`~mmg.errors.InputError` line (an existing file where a folder is
  wanted and the reverse, a path under a file, a place nothing can be created in: read-only,
  no permission) *before* any computation.  They create nothing and leave nothing.
* :class:`StagedOutput` stages a folder's files *inside the target itself*
  (``out/.staging-XXXX``: the same filesystem, so a mount point or a folder under a read-only
  parent works), moves them into ``out`` on success and, on any failure, SIGINT or SIGTERM,
  removes the staging folder, every file it had already moved (the files they replaced are put
  back) and every folder it created (``out`` itself and missing parents).
* :class:`StagedFile` does the same for one file: a temporary file beside the target, renamed
  onto it.  :func:`dump_json` writes through it.
* An ``OSError`` while writing (no space left, read-only filesystem, no permission) comes out as
  one :class:`~mmg.errors.InputError` naming the final path (never the staging one).
* An existing folder is written into (a command re-run into its own folder replaces its own
  files); after the commit :attr:`StagedOutput.others` lists what the folder holds that this
  run did not write (an earlier run's files, another command's), which the ``mmg`` command
  reports in one ``note:`` line (:func:`collect_commits`, :func:`others_note`).
* :func:`record_labels`: the name of each input record in printed lines and output files,
  after its file (two files of one stem told apart by their folders).

JSON: :func:`dump_json` writes NaN and +-Infinity as ``null`` (JSON has no NaN; a value is NaN
here when it is undefined, e.g. an overshoot that never happened or a fit that failed), so
every file parses with ``json.loads(text, parse_constant=<refuse>)``; numpy scalars and arrays
become numbers and lists.

Signals: the moves of a commit and the removals of a clean-up run with SIGINT and SIGTERM
blocked (they are delivered right after), so an interrupt never leaves half a commit or half a
clean-up behind; an interrupt that arrives while a commit runs undoes that commit.
"""
from __future__ import annotations

import errno
import json
import math
import os
import shutil
import signal
import stat
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from mmg._signals import can_hold as _can_hold
from mmg._signals import deferred as _critical
from mmg._signals import held as signals_held
from mmg._signals import noted as _noted  # noqa: F401  (the list the noting handler fills; tests read it)
from mmg._signals import pending as _signal_pending
from mmg.errors import InputError

from .pausepoint import pause as _pause
from .pausepoint import wanted as _pause_wanted

#: errno values of a target that cannot be written (reported as one InputError line, exit 2).
WRITE_ERRNOS = frozenset(getattr(errno, n) for n in ("ENOSPC", "EROFS", "EACCES", "EPERM", "EDQUOT", "EFBIG",
                                                      "EXDEV", "ENAMETOOLONG", "ENOTDIR", "EISDIR", "EMLINK", "EIO")
                         if hasattr(errno, n))

# --------------------------------------------------------------------------- signals held
# (:mod:`mmg._signals`: one helper for the simulator's build and these outputs)


@contextmanager
def children_ignore_sigint():
    """Processes started inside the block (pool workers: joblib's loky, dask) start with SIGINT
    blocked and keep it so, so a terminal's Ctrl-C, sent to the whole process group, reaches only
    this process, which stops them (no traceback from each starting worker).

    SIGINT is blocked in this thread only for the block (a mask is inherited by child processes
    and kept across ``exec``); a Ctrl-C meanwhile still reaches this process (another thread takes
    it, or it waits until the block ends).  A no-op outside the main thread.
    """
    if not _can_hold():
        yield
        return
    try:      # started now: starting it inside the block would unblock SIGINT (3.11's ensure_running does)
        from multiprocessing import resource_tracker

        resource_tracker.ensure_running()
    except Exception:                               # pragma: no cover - platform without it
        pass
    with signals_held([signal.SIGINT]):
        yield


# --------------------------------------------------------------------------- checks before any work


def _shown(path) -> str:
    return os.fspath(path)


def _abs(path) -> Path:
    return Path(os.path.abspath(os.fspath(path)))


def _nearest_existing(p: Path) -> Path:
    while not os.path.lexists(p):
        p = p.parent
    return p


def _check_can_create_in(folder: Path, option: str, shown: str) -> None:
    """``folder`` exists, or can be created: its nearest existing ancestor is a folder we can write in."""
    a = _nearest_existing(folder)
    if not a.is_dir():
        what = "a file" if a.exists() else "a broken link"
        raise InputError(option, shown, f"{a} is {what}, not a folder")
    try:
        with _critical():
            os.rmdir(tempfile.mkdtemp(prefix=".mmg-write-check-", dir=a))
    except OSError as e:
        raise InputError(option, shown, f"cannot write in {a} ({e.strerror or e})") from None


def check_output_dir(path, option: str = "--out") -> Path:
    """Refuse an output folder that cannot be written, before any work; returns it as an absolute path.

    Refused (one :class:`InputError`, ``option: path: why``): an empty path, an existing file
    or broken link, a path under a file, a folder (or its nearest existing parent) that nothing
    can be created in (read-only filesystem, no permission; tested by creating and removing
    a folder there, so it holds for root too).  An existing folder is fine (files of the same
    name are replaced when the run succeeds).  Nothing is created or left behind.
    """
    shown = _shown(path)
    if not shown.strip():
        raise InputError(option, repr(shown), "empty path")
    p = _abs(path)
    if os.path.lexists(p) and not p.is_dir():
        raise InputError(option, shown, "is a file, not a folder" if p.exists() else "is a broken link")
    _check_can_create_in(p, option, shown)
    return p


def check_output_file(path, option: str = "--json", also=()) -> Path:
    """Refuse an output file that cannot be written, before any work; returns it as an absolute path.

    Refused: an empty path or one ending in a path separator, an existing folder or other
    non-regular file (a device, a FIFO), a path under a file, a folder nothing can be created
    in (the file is written beside itself and renamed, so its folder must be writable).
    ``also``: further files written beside it (e.g. the plot ``x.png`` of ``x.json``), checked
    the same way.  An existing regular file is fine (replaced when the run succeeds).
    """
    shown = _shown(path)
    if not shown.strip():
        raise InputError(option, repr(shown), "empty path")
    if shown.endswith(("/", os.sep)):
        raise InputError(option, shown, "names a folder; give a file name")
    p = _abs(path)
    for q in (p, *(_abs(a) for a in also)):
        if q.is_dir():
            raise InputError(option, shown, f"{q} is a folder, not a file" if q != p else "is a folder, not a file")
        if os.path.lexists(q) and not q.is_file():
            raise InputError(option, shown, f"{q} is not a regular file" if q != p else "is not a regular file")
    _check_can_create_in(p.parent, option, shown)
    return p


# --------------------------------------------------------------------------- staging


def _make_dirs(d: Path) -> list[Path]:
    """Create ``d`` and its missing parents; returns the folders created (outermost first).
    On an error the ones created are removed again before it propagates."""
    d = _abs(d)
    missing = []
    p = d
    while not os.path.lexists(p):
        missing.append(p)
        p = p.parent
    created = []
    try:
        for q in reversed(missing):
            try:
                os.mkdir(q)
            except FileExistsError:
                if not q.is_dir():
                    raise
                continue                     # made by someone else meanwhile: not ours to remove
            created.append(q)
    except BaseException:
        _remove_dirs(created)
        raise
    return created


def _remove_dirs(created) -> None:
    """Remove the folders we created, innermost first, where they are (still) empty."""
    for q in reversed(list(created)):
        try:
            os.rmdir(q)
        except OSError:
            pass


def _umask_mode() -> int:
    m = os.umask(0)
    os.umask(m)
    return 0o666 & ~m


def _move(src: Path, dst: Path) -> None:
    """Rename ``src`` onto ``dst``; across filesystems (a mount point inside the target) copy it to a
    temporary file beside ``dst`` and rename that."""
    try:
        os.replace(src, dst)
    except OSError as e:
        if e.errno != errno.EXDEV:
            raise
        fd, tmp = tempfile.mkstemp(prefix=f".{dst.name}.", suffix=".tmp", dir=dst.parent)
        os.close(fd)
        try:
            shutil.copy2(src, tmp)
            os.replace(tmp, dst)
        except BaseException:
            _unlink(tmp)
            raise
        _unlink(src)


def _unlink(p) -> None:
    try:
        os.unlink(p)
    except OSError:
        pass


def write_error(exc: OSError, shown=None) -> InputError:
    """The one-line :class:`InputError` of an ``OSError`` met while writing: the path and the reason."""
    where = shown or exc.filename or "output"
    reason = exc.strerror or str(exc)
    return InputError(str(where), "", f"cannot write ({reason}); nothing was written")


class StagedOutput:
    """An output folder written all-or-nothing.

    Files are written through :meth:`path` (or into :attr:`dir`) into a staging folder
    ``out/.staging-XXXX`` inside the target (created with any missing parents when the block
    is entered), and moved into ``out`` when the ``with`` block ends without an exception.
    On an exception (an error, KeyboardInterrupt, the CLI's SIGTERM exception), a failed move
    or a signal during the moves, everything is undone: the staging folder is removed, files
    already moved are removed (files they replaced are restored) and so are the folders it
    created, ``out`` included.  An ``OSError`` of writing comes out as one :class:`InputError`
    naming the final path.  Stagings nest (a StagedOutput on a path inside another's staging
    folder commits into it).

    Use it as a context manager; :meth:`path` outside a ``with`` block opens the staging
    folder, and then :meth:`commit` or :meth:`abort` must follow.

    After the commit, :attr:`written` lists the files moved in and :attr:`others` what ``out``
    holds besides them (:func:`not_written`; left empty with ``report=False``, for a folder that
    only holds one output file, and for a staging nested in another).
    """

    check = staticmethod(check_output_dir)

    def __init__(self, out: str | Path, report: bool = True):
        self.out = Path(out)
        self.report = report                   # False: a folder holding one output file among others' files
        self.tmp: Path | None = None
        self.written: list[str] = []           # relative paths moved into ``out`` by the commit
        self.others: list[str] = []            # what ``out`` holds that this run did not write (after commit)
        self._created: list[Path] = []
        self._done = False

    # ----------------------------------------------------------------- staging folder
    def open(self) -> "StagedOutput":
        """Create ``out`` (and missing parents) and the staging folder in it; idempotent."""
        if self.tmp is not None:
            return self
        _pause("staging")                      # a test hook (trials.files.pausepoint); no-op otherwise
        if os.path.lexists(self.out) and not self.out.is_dir():
            raise InputError(str(self.out), "", "is a file, not a folder")
        with _critical():
            try:
                self._created = _make_dirs(self.out)
                try:
                    self.tmp = _abs(tempfile.mkdtemp(prefix=".staging-", dir=self.out))
                except BaseException:
                    _remove_dirs(self._created)
                    self._created = []
                    raise
            except NotADirectoryError:
                raise InputError(str(self.out), "", "a part of this path is a file, not a folder") from None
            except FileExistsError:
                raise InputError(str(self.out), "", "is a file, not a folder") from None
            except OSError as e:
                raise write_error(e, self.out) from None
        _pause("staged")
        return self

    @property
    def dir(self) -> Path:
        """The staging folder (write there directly, or through :meth:`path`)."""
        return self.open().tmp

    def path(self, name: str) -> Path:
        """Where to write the output file ``name`` (may contain folders: ``"ekf/comparison.csv"``)."""
        p = self.dir / name
        if _pause_wanted("staged-file") and any(f.is_file() for f in self.tmp.rglob("*")):
            _pause("staged-file")
        p.parent.mkdir(parents=True, exist_ok=True)
        return p

    def final(self, p) -> Path:
        """The final path of a staged path (``out/.staging-XXXX/a/b`` -> ``out/a/b``)."""
        p = Path(os.fsdecode(p)) if isinstance(p, bytes) else Path(p)
        if self.tmp is not None:
            try:
                return self.out / _abs(p).relative_to(self.tmp)
            except ValueError:
                pass
        return p

    # ----------------------------------------------------------------- commit / abort
    def commit(self) -> None:
        """Move every staged file into ``out`` (all or none; see the class)."""
        if self._done:
            return
        self.open()
        journal: list[tuple] = []                # ("dir", path) | ("file", dst, backup or None)
        with _critical():
            try:
                if _signal_pending():
                    raise _Pending()
                entries = sorted(self.tmp.rglob("*"))
                backups = Path(tempfile.mkdtemp(prefix=".replaced-", dir=self.tmp))
                for src in entries:
                    rel = src.relative_to(self.tmp)
                    dst = self.out / rel
                    if src.is_dir() and not src.is_symlink():
                        if not os.path.lexists(dst):
                            os.mkdir(dst)
                            journal.append(("dir", dst))
                        elif not dst.is_dir():
                            raise InputError(str(dst), "", "is a file; cannot write a folder there")
                        continue
                    if dst.is_dir() and not dst.is_symlink():
                        raise InputError(str(dst), "", "is a folder; cannot replace it with a file")
                    backup = None
                    if os.path.lexists(dst):
                        backup = backups / f"{len(journal)}"
                        os.replace(dst, backup)
                    journal.append(("file", dst, backup))
                    _move(src, dst)
                    self.written.append(rel.as_posix())
                if _signal_pending():              # interrupted while moving: undo, then the signal acts
                    raise _Pending()
            except BaseException as e:
                self._rollback(journal)
                self.written = []
                self._cleanup(remove_created=True)
                if not isinstance(e, _Pending):
                    if isinstance(e, OSError):
                        raise write_error(e, self.final(e.filename) if e.filename else self.out) from None
                    raise
                interrupted = True              # leaving the held block delivers the signal
            else:
                interrupted = False
                self._cleanup(remove_created=False)
        if interrupted:                         # the signal's handler did not raise: say so all the same
            raise InputError(str(self.out), "", "interrupted while moving the files in; nothing was written")
        if self.report and not _nested(self.out):
            self.others = not_written(self.out, self.written)
            if _collector is not None:
                _collector.append(self)

    def abort(self) -> None:
        """Remove the staging folder and every folder this staging created (nothing is left)."""
        if self._done:
            return
        with _critical():
            self._cleanup(remove_created=True)

    def _rollback(self, journal) -> None:
        for entry in reversed(journal):
            try:
                if entry[0] == "dir":
                    os.rmdir(entry[1])
                elif entry[2] is not None:
                    os.replace(entry[2], entry[1])
                else:
                    _unlink(entry[1])
            except OSError:
                pass

    def _cleanup(self, remove_created: bool) -> None:
        if self.tmp is not None:
            shutil.rmtree(self.tmp, ignore_errors=True)
        if remove_created:
            _remove_dirs(self._created)
        self._done = True

    def __enter__(self):
        try:
            return self.open()
        except BaseException:      # e.g. a signal held while the staging folder was made, delivered as
            self.abort()           # open() returns: no __exit__ will run, so remove it (and the folders) here
            raise

    def __exit__(self, exc_type, exc, tb):
        try:
            if exc_type is None:
                self.commit()
            else:
                self.abort()
        except BaseException:
            self.abort()
            raise
        if isinstance(exc, OSError) and not isinstance(exc, InputError) and _is_write_error(exc, self):
            raise write_error(exc, self.final(exc.filename) if exc.filename else self.out) from None
        return False


class _Pending(BaseException):
    """A signal arrived during a commit (internal)."""


def _is_write_error(exc: OSError, stage: StagedOutput | None = None) -> bool:
    if exc.errno in WRITE_ERRNOS:
        return True
    if stage is not None and stage.tmp is not None and exc.filename:
        try:
            _abs(os.fsdecode(exc.filename)).relative_to(stage.tmp)
            return True
        except (ValueError, TypeError):
            return False
    return False


def _nested(out: Path) -> bool:
    """``out`` lies inside another staging folder (its files are that staging's, reported by it)."""
    return any(part.startswith(".staging-") for part in _abs(out).parts)


def not_written(out, written, limit: int = 10000) -> list[str]:
    """What the folder ``out`` holds that is not in ``written`` (paths relative to ``out``, ``/``-separated).

    Only the folders a file of ``written`` went into are looked into: a folder this run wrote
    nothing in is one entry ``name/``; staging folders of runs in progress are left out.  At most
    ``limit`` entries are looked at (a run into a large folder stays quick).
    """
    out = Path(out)
    mine = set(written)
    visited = {""} | {"/".join(w.split("/")[:k]) for w in mine for k in range(1, w.count("/") + 1)}
    found: list[str] = []

    def walk(rel: str) -> None:
        try:
            with os.scandir(out / rel if rel else out) as it:
                entries = sorted(it, key=lambda e: e.name)
        except OSError:
            return
        for e in entries:
            if len(found) >= limit:
                return
            r = f"{rel}/{e.name}" if rel else e.name
            if e.name.startswith((".staging-", ".mmg-write-check-")) or r in mine or _live_staged_file(out / r):
                continue
            if e.is_dir(follow_symlinks=False):
                if r in visited:
                    walk(r)
                else:
                    found.append(r + "/")
            else:
                found.append(r)

    walk("")
    return found


_collector: list | None = None


@contextmanager
def collect_commits():
    """Inside the block every committed :class:`StagedOutput` (not nested in another) is appended to
    the list this yields, to report what their folders hold besides the run's files."""
    global _collector
    old, _collector = _collector, []
    try:
        yield _collector
    finally:
        _collector = old


def others_note(stage: "StagedOutput", show: int = 6) -> str | None:
    """One line saying what the folder of a committed ``stage`` holds that this run did not write
    (an earlier run's or another command's files), or None when it holds only this run's files."""
    o = stage.others
    if not o:
        return None
    names = ", ".join(o[:show]) + (f" and {len(o) - show} more" if len(o) > show else "")
    return (f"note: {stage.out} also holds {len(o)} entr{'y' if len(o) == 1 else 'ies'} this run did not write "
            f"(an earlier run's or another command's; this run wrote {len(stage.written)}): {names}")


def record_labels(sources) -> list[str]:
    """A name for each input record, after its file, unique and in the order given.

    The file's stem (``ST35`` for ``runs/ST35.csv``); records whose stems are the same are told
    apart by as many of their folders as it takes (``day1/ST35``, ``day2/ST35``), then by the
    file's suffix; the same file given again gets ``_2``, ``_3``, ...  Used for the printed
    lines and output files (``<label>.png``, a ``/`` in it is a sub-folder) of ``mmg predict``,
    ``mmg diagnose`` and ``mmg identify``.
    """
    paths = [_abs(os.fspath(s)) for s in sources]

    def candidate(p: Path, level: int) -> str:
        parts = p.parts[1:] or (p.name,)
        k = len(parts)
        if level < k:                          # stem, then parent/stem, ...
            return "/".join(parts[k - 1 - level:k - 1] + (p.stem or p.name,))
        level -= k                             # then with the suffix: ST35.csv, day1/ST35.csv, ...
        return "/".join(parts[max(k - 1 - level, 0):])

    labels = [candidate(p, 0) for p in paths]
    for stem in sorted({lab for lab in labels if labels.count(lab) > 1}):
        group = [i for i, lab in enumerate(labels) if lab == stem]
        distinct = {paths[i] for i in group}
        if len(distinct) == 1:                 # one file given again: numbered below
            continue
        top = max(2 * len(paths[i].parts) for i in group)
        for level in range(1, top + 1):
            cand = {paths[i]: candidate(paths[i], level) for i in group}
            if len(set(cand.values())) == len(distinct):
                break
        for i in group:
            labels[i] = cand[paths[i]]
    used: set = set()
    out = []
    for lab in labels:                         # the same file again: _2, _3, ...
        k, new = 1, lab
        while new in used:
            k += 1
            new = f"{lab}_{k}"
        used.add(new)
        out.append(new)
    return out


_live_tmps: set = set()                        # this process's StagedFile temporaries not yet renamed or removed


def _live_staged_file(p: Path) -> bool:
    """Whether ``p`` is the temporary file of a :class:`StagedFile` of this process still being written."""
    return _abs(p) in _live_tmps


class StagedFile:
    """One file written all-or-nothing: ``with StagedFile(target) as tmp: write tmp`` writes a
    temporary file beside ``target`` (its missing folders created) and renames it onto
    ``target`` on success; on any failure or interrupt the temporary file and the folders
    created are removed.  An existing target keeps its permission bits."""

    def __init__(self, target: str | Path):
        self.target = Path(target)
        self.tmp: Path | None = None
        self._created: list[Path] = []

    def __enter__(self) -> Path:
        with _critical():
            try:
                self._created = _make_dirs(self.target.parent)
                try:
                    fd, tmp = tempfile.mkstemp(prefix=f".{self.target.name}.", suffix=".tmp", dir=self.target.parent)
                except BaseException:
                    _remove_dirs(self._created)
                    raise
            except OSError as e:
                raise write_error(e, self.target) from None
            os.close(fd)
            self.tmp = Path(tmp)
            _live_tmps.add(_abs(self.tmp))
            try:
                mode = stat.S_IMODE(os.stat(self.target).st_mode) if self.target.is_file() else _umask_mode()
                os.chmod(self.tmp, mode)
            except OSError:
                pass
        return self.tmp

    def __exit__(self, exc_type, exc, tb):
        _live_tmps.discard(_abs(self.tmp))
        with _critical():
            interrupted = exc_type is None and _signal_pending()
            if exc_type is None and not interrupted:
                try:
                    os.replace(self.tmp, self.target)
                except OSError as e:
                    self._abort()
                    raise write_error(e, self.target) from None
            else:
                self._abort()
        if interrupted:                          # the signal's handler did not raise: say so all the same
            raise InputError(str(self.target), "", "interrupted before it was renamed into place; nothing was written")
        if isinstance(exc, OSError) and not isinstance(exc, InputError) and (
                exc.errno in WRITE_ERRNOS or exc.filename in (str(self.tmp), self.tmp)):
            raise write_error(exc, self.target) from None
        return False

    def _abort(self) -> None:
        _unlink(self.tmp)
        _remove_dirs(self._created)


# --------------------------------------------------------------------------- JSON


def json_safe(o):
    """``o`` with numpy scalars/arrays as Python numbers/lists, tuples as lists and NaN, +-Infinity
    as None (JSON null)."""
    if isinstance(o, dict):
        return {(k.item() if isinstance(k, np.generic) else k): json_safe(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [json_safe(v) for v in o]
    if isinstance(o, np.ndarray):
        return json_safe(o.tolist())
    if isinstance(o, np.generic):
        o = o.item()
    if isinstance(o, float) and not math.isfinite(o):
        return None
    return o


def _json_default(o):
    if isinstance(o, (np.floating, np.integer, np.bool_)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"{type(o).__name__} is not JSON serialisable")


def dumps_json(obj) -> str:
    """``obj`` as indented JSON text; NaN and +-Infinity written as null (never as NaN/Infinity)."""
    return json.dumps(json_safe(obj), indent=2, default=_json_default, allow_nan=False) + "\n"


def dump_json(obj, path: Path) -> None:
    """Write ``obj`` as JSON to ``path`` (a temporary file beside it, renamed): numpy values as
    numbers and lists, NaN and +-Infinity as null, so the file parses with a strict
    ``json.loads(text, parse_constant=...)``."""
    text = dumps_json(obj)                 # serialise first: a TypeError leaves no file
    with StagedFile(path) as tmp:
        tmp.write_text(text)


class Folder:
    """A plain output folder with the ``.path(name)`` interface of :class:`StagedOutput` (created on use)."""

    def __init__(self, out: str | Path):
        self.out = Path(out)

    def path(self, name: str) -> Path:
        p = self.out / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return p


def out_path(out):
    """``out`` when it already has ``.path(name)`` (a :class:`StagedOutput`), else a :class:`Folder` on it."""
    return out if hasattr(out, "path") else Folder(out)


ZERO_REL = 1e-9
"""A printed table's numerical zero: a value within this fraction of its column's largest magnitude."""


def numerical_zeros(values, rel: float = ZERO_REL, atol: float = 0.0) -> np.ndarray:
    """The numbers of one table column with its numerical zeros made exact zeros, for printing.

    A value is a numerical zero when ``|x| <= max(rel * max|column|, atol)``: round-off left where the
    exact result is 0 (an overshoot point's yaw rate of -1.6e-17, a heading error of 6.8e-16 deg
    beside 54 rpm).  ``atol`` is for columns whose values are all round-off (a percentage error
    that is exactly 0 in exact arithmetic: 1e-9 %); -0.0 becomes 0.0.  Non-numbers (None, text)
    are left as they are; NaN stays NaN.

    Parameters
    ----------
    values : sequence
        One column.
    rel : float
        Tolerance relative to the column's largest finite magnitude.
    atol : float
        Absolute tolerance.

    Returns
    -------
    ndarray of object
        The column, numbers with their zeros exact.
    """
    values = list(values)
    out = np.empty(len(values), dtype=object)      # filled one by one: lists stay cells
    out[:] = values
    num = [i for i, v in enumerate(out) if isinstance(v, (int, float, np.integer, np.floating))
           and not isinstance(v, (bool, np.bool_))]
    mags = [abs(float(out[i])) for i in num if np.isfinite(float(out[i]))]
    tol = max(rel * max(mags, default=0.0), atol)
    for i in num:
        x = float(out[i])
        if np.isfinite(x) and abs(x) <= tol and not isinstance(out[i], (int, np.integer)):
            out[i] = 0.0
    return out


def fmt(v, nd: int = 4) -> str:
    """A value for a printed table: 4 significant digits, lists as [a, b, ...], None as '-',
    zero (also -0.0) as '0'."""
    if v is None:
        return "-"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(f"{x:.{min(nd, 2)}f}" for x in v) + "]"
    if isinstance(v, (float, np.floating)):
        return "0" if v == 0 else f"{v:.{nd}g}"
    return str(v)


def write_trial_outputs(run, stage, show: bool = False) -> dict:
    """log.csv, truth.csv, metrics.json, track.png, histories.png of one simulated trial; returns the metrics."""
    from .logwrite import log_columns, truth_columns, write_table
    from .plots import plot_histories, plot_track

    stage = out_path(stage)
    meta = run.log_meta()
    r = run.result
    # the columns of run.log() and run.truth(), written without building DataFrames (no pandas import)
    wind = run.apparent_wind()
    write_table(stage.path("log.csv"), log_columns(r.t, r.x, r.y, r.psi, run.sog, r.n, run.trial.log, wind=wind), meta)
    write_table(stage.path("truth.csv"), truth_columns(r.t, r.states, r.orders, wind=wind), meta)
    m = run.metrics()
    dump_json(m, stage.path("metrics.json"))
    sh = run.trial.ship.particulars
    plot_track(r.t, r.x, r.y, r.psi, sh.L, sh.B, f"{run.trial.name} ({run.trial.ship.name})", stage.path("track.png"), show=show)
    plot_histories(r.t, r.psi, r.delta, r.r, r.U, r.n, f"{run.trial.name} ({run.trial.ship.name})",
                   stage.path("histories.png"), delta_order=r.orders, show=show)
    return m
