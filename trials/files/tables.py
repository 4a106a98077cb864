"""Plain-text tables for consoles and figures: columns as wide as their widest cell, two spaces apart."""
from __future__ import annotations

__all__ = ["text_table"]

SEP = "  "
"""Between two columns: at least two spaces, whatever the values."""


def text_table(header, rows, align=None, indent: str = "") -> list[str]:
    """Lines of a table whose columns fit every cell, :data:`SEP` apart.

    Parameters
    ----------
    header : sequence of str
        Column titles.
    rows : iterable of sequences
        Cells (converted with ``str``); a row may be shorter than the header (its last cells blank).
    align : str, optional
        One character per column, ``"<"`` (left) or ``">"`` (right); default: the first column
        left, the others right.
    indent : str
        Put before every line.

    Returns
    -------
    list of str
        The header line, then one line per row (trailing blanks stripped).
    """
    header = [str(h) for h in header]
    body = [[str(c) for c in r] + [""] * (len(header) - len(r)) for r in rows]
    align = align or "<" + ">" * (len(header) - 1)
    width = [max(len(r[j]) for r in [header] + body) for j in range(len(header))]
    return [(indent + SEP.join(f"{c:{a}{w}}" for c, a, w in zip(r, align, width))).rstrip() for r in [header] + body]
