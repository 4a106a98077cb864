"""A log file's bytes to its ``# key: value`` header and its table: the file's size, its encoding, its line
breaks, rows of the header's width and cells that are finite numbers (named by file line), each refused
with an :class:`~mmg.errors.InputError` naming the file.
"""
from __future__ import annotations

import csv
import io
from array import array
import stat
from pathlib import Path

import numpy as np
import pandas as pd

from mmg.errors import InputError
from mmg.limits import MAX_SAMPLES


MAX_FILE_BYTES = 256 * MAX_SAMPLES
"""Largest file [bytes] a reader opens: :data:`mmg.limits.MAX_SAMPLES` rows of 256 bytes."""


def _parse_meta(lines: list[str]) -> dict:
    meta = {}
    for ln in lines:
        body = ln.lstrip()[1:].strip()
        if ":" in body:
            k, v = body.split(":", 1)
            v = v.strip()
            try:
                v = float(v) if any(ch in v for ch in ".eE") or v.lstrip("-").isdigit() else v
            except ValueError:
                pass
            meta[k.strip()] = v
    return meta


def _read_bytes(path: Path, src: str) -> bytes:
    """The file's bytes: refused when missing, not a regular file, larger than :data:`MAX_FILE_BYTES`,
    unreadable or binary (a NUL byte)."""
    try:
        st = path.stat()
    except FileNotFoundError:
        raise InputError(src, "", "file not found") from None
    except OSError as e:
        raise InputError(src, "", f"cannot read ({e.strerror or e.__class__.__name__})") from None
    if stat.S_ISDIR(st.st_mode):
        raise InputError(src, "", "is a directory, not a log file")
    if not stat.S_ISREG(st.st_mode):
        raise InputError(src, "", "is not a regular file")
    if st.st_size > MAX_FILE_BYTES:
        raise InputError(src, "", f"file of {st.st_size / 1e6:.4g} MB is larger than any record the readers accept "
                                  f"({MAX_FILE_BYTES / 1e6:.4g} MB: mmg.limits.MAX_SAMPLES rows)")
    try:
        data = path.read_bytes()
    except OSError as e:
        raise InputError(src, "", f"cannot read ({e.strerror or e.__class__.__name__})") from None
    nul = data.find(b"\x00")
    if nul >= 0:
        raise InputError(src, "", f"binary file (NUL byte at offset {nul}), not a CSV text")
    return data


def _decode(data: bytes, src: str) -> str:
    """The file's text (UTF-8, an optional byte-order mark dropped)."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise InputError(src, "", f"not UTF-8 text (byte 0x{data[e.start]:02x} at offset {e.start})") from None


def _cells(line: str, lineno: int, src: str) -> list[str]:
    if '"' not in line:
        return line.split(",")
    try:
        return next(csv.reader([line], strict=True))
    except (csv.Error, StopIteration) as e:
        raise InputError(src, f"line {lineno}", f"not a readable CSV row ({e})") from None


def _parse_table(numbered: list[tuple[int, str]], src: str) -> tuple[pd.DataFrame, np.ndarray, list[str]]:
    """The CSV table of the non-comment lines: (frame of the data rows, their file line numbers, notes).

    Rows with a different number of cells than the header are refused; rows whose cells are
    all empty carry no sample and are dropped (and reported in the notes), so that a gap they
    leave shows as a gap in time, and trailing empty rows (a logger that stopped) are harmless.
    """
    rows = [(n, ln) for n, ln in numbered if ln.strip()]
    if not rows:
        raise InputError(src, "", "no data (no header line and no rows)")
    hno, hline = rows[0]
    screen = _Rows(hno, hline, src)
    keep = [ln for n, ln in rows[1:] if screen.row(n, ln)]
    text = "\n".join([hline] + keep)
    df = _frame(io.StringIO(text), len(keep), screen, src)
    return df, np.asarray(screen.lines), screen.notes()


class _Rows:
    """Screens the data rows of a table after its header line ``hline`` (file line ``hno``): a row with
    another number of cells than the header is refused; a row whose cells are all empty carries no sample
    and is left out (said in :meth:`notes`); :attr:`lines` are the file lines of the rows kept."""

    def __init__(self, hno: int, hline: str, src: str):
        self.hno, self.hline, self.src = hno, hline, src
        self.names = [c.strip() for c in _cells(hline, hno, src)]
        seen = set()
        for c in self.names:
            if c and c in seen:
                raise InputError(src, c, f"column appears twice in the header (line {hno})")
            seen.add(c)
        self.ncol = len(self.names)
        self.lines, self.empty = array("l"), []

    def row(self, n: int, ln) -> bool:
        """Whether the row ``ln`` (str or ASCII bytes) of file line ``n`` carries a sample."""
        if (b'"' if isinstance(ln, bytes) else '"') in ln:
            cells = _cells(ln.decode() if isinstance(ln, bytes) else ln, n, self.src)
            k, blank = len(cells), all(not c.strip() for c in cells)
        elif isinstance(ln, bytes):
            k, blank = ln.count(b",") + 1, not ln.replace(b",", b"").strip()
        else:
            k, blank = ln.count(",") + 1, not ln.replace(",", "").strip()
        if blank:
            self.empty.append(len(self.lines))       # position among the data rows
            return False
        if k != self.ncol:
            raise InputError(self.src, f"line {n}", f"{k} cells, but the header (line {self.hno}) has {self.ncol} columns")
        self.lines.append(n)
        return True

    def notes(self) -> list[str]:
        empty, lines = self.empty, self.lines
        notes = []
        if empty:
            trailing = sum(1 for k in empty if k == len(lines))
            leading = sum(1 for k in empty if k == 0)
            inner = len(empty) - trailing - leading
            for count, where in ((leading, "leading"), (inner, "interior"), (trailing, "trailing")):
                if count:
                    notes.append(f"ignored {count} {where} empty row{'s' if count > 1 else ''} (no values)")
        return notes


def _frame(buf, nrows: int, screen: _Rows, src: str) -> pd.DataFrame:
    """The table in ``buf`` (its header line and the ``nrows`` rows kept) as a DataFrame.

    All-number tables (every real record) are parsed straight to floats, in chunks; any other is
    parsed cell by cell as text (so that a bad cell can be named by :meth:`_Table.numeric`)."""
    if not nrows:
        raise InputError(src, "", "no data rows after the header")
    kw = dict(keep_default_na=False, skip_blank_lines=False)
    try:
        try:
            df = pd.read_csv(buf, dtype=float, **kw)
        except ValueError:                  # a cell that is not a number: read as text, named later
            buf.seek(0)
            df = pd.read_csv(buf, low_memory=False, **kw)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, ValueError, OverflowError, csv.Error) as e:
        raise InputError(src, "", f"not a readable CSV ({str(e).splitlines()[0] if str(e) else e.__class__.__name__})") from None
    if len(df) != nrows or df.shape[1] != screen.ncol:
        raise InputError(src, "", "not a readable CSV (quoted cells spanning lines)")
    df.columns = screen.names
    return df


_LINE_BREAKS = (b"\r", b"\x0b", b"\x0c", b"\x1c", b"\x1d", b"\x1e")
"""Bytes other than \\n that ``str.splitlines`` breaks a line at (a file with any is read as text)."""


def _load(path: Path, src: str) -> tuple[dict, pd.DataFrame, np.ndarray, list[str]]:
    """The header values, the table, the file lines of its rows and the notes of a log file.

    An ASCII file with \\n (or \\r\\n) line ends, every real record, is screened line by line from
    its bytes and the rows kept are parsed from one copy of them: a few times the file's size in
    memory at the peak.  Any other is decoded and split as text (the same result, more memory)."""
    data = _read_bytes(path, src)
    crlf = data.count(b"\r\n")
    if not data.isascii() or data.count(b"\r") != crlf or any(c in data for c in _LINE_BREAKS[1:]):
        text = _decode(data, src)
        del data
        lines = text.splitlines()
        meta = _parse_meta([ln for ln in lines if ln.lstrip().startswith("#")])
        numbered = [(i + 1, ln) for i, ln in enumerate(lines) if not ln.lstrip().startswith("#")]
        del text, lines
        return (meta, *_parse_table(numbered, src))
    comments, out, screen, nrows = [], io.BytesIO(), None, 0
    reader = io.BytesIO(data)
    del data                                # the reader holds the only reference: freed with it
    for n, raw in enumerate(reader, 1):
        ln = raw.rstrip(b"\r\n") if crlf else raw.rstrip(b"\n")
        if ln.lstrip().startswith(b"#"):
            comments.append(ln.decode())
        elif not ln.strip():
            continue
        elif screen is None:
            screen = _Rows(n, ln.decode(), src)
            out.write(ln + b"\n")
        elif screen.row(n, ln):
            out.write(ln + b"\n")
            nrows += 1
    del reader
    if screen is None:
        raise InputError(src, "", "no data (no header line and no rows)")
    out.seek(0)
    df = _frame(out, nrows, screen, src)
    return _parse_meta(comments), df, np.asarray(screen.lines), screen.notes()
