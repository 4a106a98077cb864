"""Sea-trial logs: writing them as a real trial records them, and reading any supported log, as a package
of rooms whose public names it re-exports: :mod:`.layout` the column layouts and the writing (:func:`write_csv`),
:mod:`.read` a file's bytes to its header and table, :mod:`.checks` the limits and the checks of each
channel and of the channels against each other (its docstring lists the formats and every refusal),
:mod:`.record` the table to a :class:`~trials.files.records.TrialRecord` per format (:func:`read_record`).
"""
from __future__ import annotations

from mmg.units import M_PER_DEG_LAT, M_PER_DEG_LON

from .layout import (FRT_COLUMNS, MAX_WIND_MPS, FRT_REQUIRED, LAYOUT_COLUMNS, LAYOUT_NAMES, channel_column,
                     missing_channel, log_frame, write_csv, as_written, truth_frame)
from .read import MAX_FILE_BYTES
from .checks import (MAX_SPAN_S, FRT_INTERVAL_S, FRT_STEP_RANGE, STEP_RTOL, DENSE_STEP_S, _step_within, FRT_LENGTH_M,
                     MAX_RUDDER, MAX_YAW_RATE, MAX_FROUDE, MAX_RPS, MAX_MAGNITUDE, G, require_finite, WIND_KMH,
                     SPEED_UNITS, SCALE_OK, SPEED_TOL, velocity_track_fit, wind_scale_fit)
from .record import unwrap_heading, read_record, record_from_frame
from ..logwrite import FLOAT_FORMAT, LOG_COLUMNS

