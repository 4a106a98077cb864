"""The pandas-free writer prints exactly what ``DataFrame.to_csv`` with the project's float format prints."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trials.files.logwrite import FLOAT_FORMAT, format_table, formattable, header, write_table

floats = st.floats(allow_nan=False, allow_infinity=True, width=64)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 450).flatmap(lambda n: st.lists(st.lists(floats, min_size=n, max_size=n), min_size=1, max_size=4)))
def test_same_bytes_as_pandas(cols):
    table = {f"c{i}": np.array(c, dtype=float) for i, c in enumerate(cols)}
    assert formattable(table)
    assert format_table(table) == pd.DataFrame(table).to_csv(index=False, float_format=FLOAT_FORMAT)


@pytest.mark.parametrize("table", [{"a": np.array([1.0, np.nan]), "b": np.array([0.5, -0.0])},
                                   {"a": np.array([1, 2]), "b": np.array([0.25, 1e-300])}])
def test_nan_and_integers_written_by_pandas(tmp_path, table):
    assert not formattable(table)
    write_table(tmp_path / "t.csv", table, {"trial": "x"})
    assert (tmp_path / "t.csv").read_text() == header({"trial": "x"}) + pd.DataFrame(table).to_csv(
        index=False, float_format=FLOAT_FORMAT)
