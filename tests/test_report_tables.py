"""The printed tables of ``mmg reproduce`` (report.md) and ``mmg nomoto-paper``: numerical zeros as 0,
no column without a value, every disagreement with the paper explained beside its table."""
import re

import numpy as np
import pandas as pd
import pytest

from trials.papers import artyszuk
from trials.files.output import fmt, numerical_zeros
from trials.papers.reproduce import Report, nomoto_section, table


def md_tables(text: str) -> list[list[list[str]]]:
    """The Markdown tables in ``text``: each a list of rows of cells (header first, rule left out)."""
    tables, cur = [], []
    for ln in text.splitlines() + [""]:
        if ln.startswith("|"):
            if not re.fullmatch(r"\|(-+\|)+", ln.replace(" ", "")):
                cur.append([c.strip() for c in ln.strip().strip("|").split("|")])
        elif cur:
            tables.append(cur)
            cur = []
    return tables


def section(text: str, heading_start: str) -> str:
    """The text from the heading that starts with ``heading_start`` to the next heading."""
    i = next(k for k, ln in enumerate(text.splitlines()) if ln.lstrip("#").strip().startswith(heading_start))
    lines = text.splitlines()[i + 1:]
    j = next((k for k, ln in enumerate(lines) if ln.startswith("#")), len(lines))
    return "\n".join(lines[:j])


def test_numerical_zeros_print_as_zero():
    # round-off beside values of order 0.1-1 (the overshoot yaw rates of Table 1) and a -0.0
    assert [fmt(v) for v in numerical_zeros([-1.5613e-17, 0.17241, -0.25501, 3.4484e-17, -0.0])] == \
        ["0", "0.1724", "-0.255", "0", "0"]
    # a column whose every value is small is not round-off: kept
    assert [fmt(v) for v in numerical_zeros([1.2e-12, -3.4e-12])] == ["1.2e-12", "-3.4e-12"]
    # ... unless an absolute tolerance says so (a percentage error exact in exact arithmetic)
    assert [fmt(v) for v in numerical_zeros([-2.5e-13, 5.2e-13], atol=1e-9)] == ["0", "0"]
    # text, None, NaN and integers are left alone; lists stay one cell each
    out = numerical_zeros(["a", None, np.nan, 0, [1.0, 2.0]])
    assert out[0] == "a" and out[1] is None and np.isnan(out[2]) and out[3] == 0 and out[4] == [1.0, 2.0]
    assert fmt(-0.0) == "0" and fmt(0.0) == "0" and fmt(54.21) == "54.21"


def test_report_table_prints_a_columns_round_off_as_zero():
    md = table([{"q": "rpm", "v": 54.21}, {"q": "max |heading| (deg)", "v": 6.755e-16},
                {"q": "max |U - U0| (kn)", "v": 1.303e-07}], ["q", "v"])
    assert md.splitlines()[2:] == ["| rpm | 54.21 |", "| max |heading| (deg) | 0 |", "| max |U - U0| (kn) | 1.303e-07 |"]


def test_artyszuk_markdown_zeros_and_empty_columns():
    df = pd.DataFrame({"point": ["CR1", "OS1"], "omega' ours": [0.17241, -1.5613e-17],
                       "psi diff %": [-1.7764e-14, 0.04037], "fit % output error": [np.nan, np.nan]})
    rows = md_tables(artyszuk.to_markdown(df))[0]
    assert rows == [["point", "omega' ours", "psi diff %"], ["CR1", "0.17241", "0"], ["OS1", "0", "0.04037"]]


@pytest.fixture(scope="module")
def nomoto_md(tmp_path_factory):
    """Section 6 of report.md as ``mmg reproduce`` writes it (the same fast tables)."""
    doc = Report()
    nomoto_section(doc, tmp_path_factory.mktemp("rep"), full=False)
    return doc.text()


def test_report_table6_explains_the_sign_of_T3(nomoto_md):
    t6 = section(nomoto_md, "Table 6.")
    rows = {r[0]: r for r in md_tables(t6)[0][1:]}
    assert rows["T3"][1] == "28.748" and rows["T3"][2].startswith("-28.7")     # paper +, ours -
    note = t6.split("Note:", 1)[1]
    # the paper's own Table 7 (W = -2.001e-4, W_x3 = -3.881e-5, W_x4 = 1.116e-3): T3 = W_x4 / W_x3 = -28.756
    assert "T3 = -28.75" in note and "sign" in note and "x4 / x3" in note


def test_report_tables_have_no_empty_column_and_name_the_ones_left_out(nomoto_md):
    for t in md_tables(nomoto_md):
        head, body = t[0], t[1:]
        for j, name in enumerate(head):
            assert any(r[j] not in ("n/a", "") for r in body), name
        for r in body:
            for cell in r:
                assert not re.fullmatch(r"-?\d(\.\d+)?e-(1[0-9]|[2-9][0-9])", cell), cell    # no 1e-10 .. 1e-99
    ext = section(nomoto_md, "Table 8 extended:")
    assert "output error" not in md_tables(ext)[0][0][-1]
    assert "Columns left out" in ext and "K % output error" in ext and "mmg nomoto-paper" in ext


def test_every_artyszuk_table_with_paper_values_has_a_note(nomoto_md):
    for title in ("Table 1.", "Table 2.", "Table 3.", "Table 4.", "Table 6.", "Table 7.", "Table 8.", "Classical"):
        assert "Note:" in section(nomoto_md, title), title
