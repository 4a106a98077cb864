"""Writing sea-trial logs and truth files without pandas (the formats: :mod:`trials.files.logio`).

:mod:`trials.files.logio` re-exports these and wraps the columns in DataFrames (``log_frame``,
``truth_frame``, ``write_csv``); ``mmg simulate`` writes through this module directly, so it
imports neither pandas nor the readers.  :func:`format_table` prints exactly what
``DataFrame.to_csv(index=False, float_format=FLOAT_FORMAT)`` prints for a table of finite
floats (byte for byte), four to five times faster: one ``%`` per block of rows instead of a
formatter call per cell.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mmg.units import KNOT, M_PER_DEG_LAT, M_PER_DEG_LON
from mmg.effects.heading_bias import HeadingBias

LOG_COLUMNS = ("time_s", "lat_deg", "lon_deg", "heading_deg", "speed_kn", "rpm")
TRUTH_COLUMNS = ("time_s", "u_mps", "v_mps", "r_radps", "delta_rad", "delta_order_rad",
                 "x_m", "y_m", "psi_rad", "n_rps")

FLOAT_FORMAT = "%.12g"
"""How the log and truth files print numbers (12 significant digits)."""

_BLOCK_ROWS = 200
"""Rows formatted by one ``%`` (one format string of that many rows)."""


def header(meta: dict) -> str:
    """The ``# key: value`` metadata header."""
    return "".join(f"# {k}: {v}\n" for k, v in meta.items())


WIND_LOG_COLUMNS = ("wind_rel_kn", "wind_rel_deg")
"""Optional log columns of a steady-wind run: apparent wind speed [kn] and the direction it comes
from, relative to the bow, clockwise [deg, 0-360] (as a ship's anemometer shows them)."""
WIND_TRUTH_COLUMNS = ("wind_rel_mps", "wind_rel_rad")
"""The same in the truth file, SI (direction 0 to 2 pi)."""


def log_columns(t, x, y, psi, sog, n, spec, rng: np.random.Generator | None = None,
                wind=None) -> dict[str, np.ndarray]:
    """The log's columns (:data:`LOG_COLUMNS`): the trajectory every ``spec.interval`` seconds with uniform noise.

    Parameters
    ----------
    t, x, y, psi, sog, n : arrays at the integration step
        Time [s], position north/east [m], heading [rad], speed over ground [m/s], rpm [rps].
    spec : trials.runs.trial.LogSpec
        Interval, start position, noise levels (half-widths of the uniform noise), seed and
        constant sensor biases (heading, speed, rpm; :class:`trials.runs.trial.SensorBias`).
    rng : numpy Generator, optional
        Defaults to ``np.random.default_rng(spec.seed)``.
    wind : (V_rel, gamma) arrays at the integration step, optional
        The apparent wind (:meth:`trials.runs.run.TrialRun.apparent_wind`): adds :data:`WIND_LOG_COLUMNS`
        (noise-free: the anemometer's own error is not modelled).
    """
    rng = np.random.default_rng(spec.seed) if rng is None else rng
    step = int(round(spec.interval / (t[1] - t[0])))
    sel = slice(0, len(t), step)
    ts = t[sel]
    k = len(ts)

    def noise(level):
        return rng.uniform(-level, level, k) if level > 0 else np.zeros(k)

    lat = np.degrees(spec.start_lat) + x[sel] / M_PER_DEG_LAT + noise(np.degrees(spec.noise_lat))
    lon = np.degrees(spec.start_lon) + y[sel] / M_PER_DEG_LON + noise(np.degrees(spec.noise_lon))
    b = spec.bias
    hdg = np.mod(np.degrees(HeadingBias.logged_heading(psi[sel], b.heading)) + noise(np.degrees(spec.noise_heading)), 360.0)
    spd = (sog[sel] + b.speed) / KNOT + noise(spec.noise_speed / KNOT)
    rpm = (n[sel] + b.rpm) * 60.0 + noise(spec.noise_rpm * 60.0)
    out = {"time_s": ts, "lat_deg": lat, "lon_deg": lon, "heading_deg": hdg, "speed_kn": spd, "rpm": rpm}
    if wind is not None:
        out["wind_rel_kn"] = np.asarray(wind[0])[sel] / KNOT
        out["wind_rel_deg"] = np.mod(np.degrees(np.asarray(wind[1])[sel]), 360.0)
    return out


def truth_columns(t, states, orders, wind=None) -> dict[str, np.ndarray]:
    """The truth file's columns (:data:`TRUTH_COLUMNS`): the states at the integration step, and
    :data:`WIND_TRUTH_COLUMNS` when ``wind`` (as :func:`log_columns`) is given."""
    out = {"time_s": t, "u_mps": states[:, 0], "v_mps": states[:, 1], "r_radps": states[:, 2],
           "delta_rad": states[:, 6], "delta_order_rad": orders, "x_m": states[:, 3],
           "y_m": states[:, 4], "psi_rad": states[:, 5], "n_rps": states[:, 7]}
    if wind is not None:
        out["wind_rel_mps"] = np.asarray(wind[0])
        out["wind_rel_rad"] = np.mod(np.asarray(wind[1]), 2 * np.pi)
    return out


def formattable(columns: dict) -> bool:
    """True when :func:`format_table` prints these columns as pandas would: floats, no NaN."""
    for v in columns.values():
        a = np.asarray(v)
        if a.ndim != 1 or a.dtype.kind != "f" or np.isnan(a).any():
            return False
    return len({len(v) for v in columns.values()}) <= 1


def format_table(columns: dict) -> str:
    """The CSV text (header line and rows) of equally long float columns, each number ``FLOAT_FORMAT``.

    The bytes of ``pd.DataFrame(columns).to_csv(index=False, float_format=FLOAT_FORMAT)`` when
    :func:`formattable` holds (pandas writes NaN as an empty cell; this would not).
    """
    names = list(columns)
    m = len(names)
    table = np.column_stack([np.asarray(columns[c], dtype=float) for c in names]) if m else np.zeros((0, 0))
    n = table.shape[0]
    flat = table.ravel().tolist()
    row = ",".join([FLOAT_FORMAT] * m) + "\n"
    out = [",".join(names) + "\n"]
    k = _BLOCK_ROWS
    block = row * k
    full = n // k
    for i in range(full):
        out.append(block % tuple(flat[i * k * m:(i + 1) * k * m]))
    if n > full * k:
        out.append((row * (n - full * k)) % tuple(flat[full * k * m:]))
    return "".join(out)


def write_table(path: Path, columns: dict, meta: dict) -> None:
    """Write columns with a ``# key: value`` metadata header, as ``DataFrame.to_csv`` with
    :data:`FLOAT_FORMAT` prints them: by :func:`format_table` when :func:`formattable`, else
    by pandas itself (NaN as an empty cell, integer columns)."""
    if formattable(columns):
        text = header(meta) + format_table(columns)
    else:
        import pandas as pd

        text = header(meta) + pd.DataFrame(columns).to_csv(index=False, float_format=FLOAT_FORMAT)
    with open(path, "w") as fh:
        fh.write(text)
