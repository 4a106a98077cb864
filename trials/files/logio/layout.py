"""The column layouts of the supported logs (project log, project truth, FRT-DS-ESSO) and their channels
(:func:`channel_column`, :func:`missing_channel`), and the writing of the project's log and truth files
(:func:`write_csv`, :func:`log_frame`, :func:`truth_frame`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from mmg.errors import InputError

from ..logwrite import FLOAT_FORMAT, formattable, header, log_columns, truth_columns, write_table
from ..records import TrialRecord


FRT_COLUMNS = {"t [s]": "t", "x_position_mid [m]": "x", "y_position_mid [m]": "y",
               "u_velo [m/s]": "u", "vm_velo [m/s]": "v", "psi_hat [rad]": "psi",
               "r_angvelo [rad/s]": "r", "n_prop [rps]": "n", "delta_rudder [rad]": "delta",
               "wind_velo_relative_mid [m/s]": "wind_speed_rel", "wind_dir_relative_mid [rad]": "wind_dir_rel",
               "wind_velo_true [m/s]": "wind_speed_true", "wind_dir_true [rad]": "wind_dir_true"}
MAX_WIND_MPS = 60.0
"""Largest wind speed [m/s] a record may log (a hurricane; beyond it the column is in another unit)."""
FRT_REQUIRED = ("t [s]", "x_position_mid [m]", "y_position_mid [m]", "psi_hat [rad]")

LAYOUT_COLUMNS = {
    "frt-ds-esso": {k: c for c, k in FRT_COLUMNS.items()},
    "log": {"t": "time_s", "x": "lat_deg", "y": "lon_deg", "psi": "heading_deg", "U": "speed_kn", "n": "rpm",
            "delta": "rudder_deg", "wind_speed_rel": "wind_rel_kn", "wind_dir_rel": "wind_rel_deg"},
    "truth": {"t": "time_s", "x": "x_m", "y": "y_m", "psi": "psi_rad", "u": "u_mps", "v": "v_mps", "r": "r_radps",
              "delta": "delta_rad", "n": "n_rps", "wind_speed_rel": "wind_rel_mps", "wind_dir_rel": "wind_rel_rad"},
}
"""The column each channel of a record is read from, per file layout (the record's ``meta["format"]``)."""

LAYOUT_NAMES = {"frt-ds-esso": "FRT-DS-ESSO CSV", "log": "project log", "truth": "truth file"}


def channel_column(rec: TrialRecord, channel: str) -> str:
    """The exact header of ``channel`` in the layout ``rec`` was read from.

    Parameters
    ----------
    rec : TrialRecord
        A record; its ``meta["format"]`` names the layout.
    channel : str
        A channel name of :data:`trials.files.records.CHANNELS` (or ``t``, a wind channel).

    Returns
    -------
    str
        The column header (e.g. ``delta_rudder [rad]``); '' when the layout has no column for the
        channel; the channel's own name for a record not read from a file.
    """
    fmt = rec.meta.get("format")
    if fmt not in LAYOUT_COLUMNS:
        return channel
    return LAYOUT_COLUMNS[fmt].get(channel, "")


def missing_channel(rec: TrialRecord, channel: str, need: str) -> InputError:
    """The error for a channel a command needs and the record lacks, naming its column first.

    Parameters
    ----------
    rec : TrialRecord
        The record.
    channel : str
        The channel missing (see :func:`channel_column`).
    need : str
        What needs it, in plain words (e.g. "a zigzag analysis needs heading and rudder").

    Returns
    -------
    InputError
        Field = the column's exact header; when the layout has no such column, the channel's
        name and the layout's.
    """
    col = channel_column(rec, channel)
    src = rec.source or rec.name or "record"
    if col:
        return InputError(src, col, f"missing column; {need}")
    layout = LAYOUT_NAMES.get(rec.meta.get("format"), str(rec.meta.get("format")))
    return InputError(src, channel, f"the {layout} layout has no column for this channel; {need}")



# --------------------------------------------------------------------------- writing
# (the columns and their printing live in trials.files.logwrite, which needs no pandas)

def _header(meta: dict) -> str:
    return header(meta)


def log_frame(t, x, y, psi, sog, n, spec, rng: np.random.Generator | None = None, wind=None) -> pd.DataFrame:
    """:func:`trials.files.logwrite.log_columns` (the trajectory sampled every ``spec.interval`` seconds,
    uniform noise and sensor biases added) as a DataFrame; same parameters."""
    return pd.DataFrame(log_columns(t, x, y, psi, sog, n, spec, rng, wind=wind))


def write_csv(path: Path, df: pd.DataFrame, meta: dict) -> None:
    """Write a DataFrame with a ``# key: value`` metadata header.

    Float tables without NaN are printed by :func:`trials.files.logwrite.format_table` (the same bytes
    as ``to_csv``, faster); anything else by pandas.
    """
    if df.columns.is_unique and all(isinstance(c, str) for c in df.columns):
        cols = {c: df[c].to_numpy() for c in df.columns}
        if formattable(cols):
            write_table(path, cols, meta)
            return
    with open(path, "w") as fh:
        fh.write(_header(meta))
        df.to_csv(fh, index=False, float_format=FLOAT_FORMAT)


def as_written(df: pd.DataFrame) -> pd.DataFrame:
    """The table with every number as :func:`write_csv` prints it, so that a record built from a
    simulated log in memory equals the same log read back from its file."""
    out = df.copy()
    for c in out.columns:
        if out[c].dtype.kind == "f":
            out[c] = [float(FLOAT_FORMAT % v) for v in out[c].to_numpy()]
    return out


def truth_frame(t, states, orders, wind=None) -> pd.DataFrame:
    """States at the integration step as the truth-file table."""
    return pd.DataFrame(truth_columns(t, states, orders, wind=wind))
