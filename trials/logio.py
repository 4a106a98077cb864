"""Sea-trial logs: writing them as a real trial records them, and reading any supported log.

Formats
-------
* **Project log** (``log.csv``): what Rhee & Kim's simulation prints (section 2.2): every
  ``interval`` seconds ``time_s, lat_deg, lon_deg, heading_deg, speed_kn, rpm``, with
  uniform noise of the Table 4 levels from a seeded generator.  Heading is printed as a
  gyro does, in [0, 360).  Positions use the paper's metres per degree (1852 x 60 for
  latitude, 1526.16 x 60 for longitude).  A ``# key: value`` header carries the ship, the
  trial, its parameters, the start position and the seed.
* **Project truth** (``truth.csv``): the states at every integration step, in SI:
  ``time_s, u_mps, v_mps, r_radps, delta_rad, delta_order_rad, x_m, y_m, psi_rad, n_rps``.
* **FRT-DS-ESSO** (Osaka University free-running model tests): 10 Hz CSV with columns
  ``t [s], x_position_mid [m], u_velo [m/s], y_position_mid [m], vm_velo [m/s], psi_hat [rad]
  (wrapped), r_angvelo [rad/s], n_prop [rps], delta_rudder [rad], wind...``.

:func:`read_record` recognises the format from the header and returns a
:class:`~trials.records.TrialRecord`; malformed files (missing columns, NaN, gaps,
time not increasing) raise :class:`~mmg.errors.InputError` naming the file and field.
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd

from mmg.errors import InputError
from mmg.units import DEG, KNOT, M_PER_DEG_LAT, M_PER_DEG_LON

from .records import TrialRecord

LOG_COLUMNS = ("time_s", "lat_deg", "lon_deg", "heading_deg", "speed_kn", "rpm")
TRUTH_COLUMNS = ("time_s", "u_mps", "v_mps", "r_radps", "delta_rad", "delta_order_rad",
                 "x_m", "y_m", "psi_rad", "n_rps")
FRT_COLUMNS = {"t [s]": "t", "x_position_mid [m]": "x", "y_position_mid [m]": "y",
               "u_velo [m/s]": "u", "vm_velo [m/s]": "v", "psi_hat [rad]": "psi",
               "r_angvelo [rad/s]": "r", "n_prop [rps]": "n", "delta_rudder [rad]": "delta"}
FRT_REQUIRED = ("t [s]", "x_position_mid [m]", "y_position_mid [m]", "psi_hat [rad]")


# --------------------------------------------------------------------------- writing

def _header(meta: dict) -> str:
    return "".join(f"# {k}: {v}\n" for k, v in meta.items())


def log_frame(t, x, y, psi, sog, n, spec, rng: np.random.Generator | None = None) -> pd.DataFrame:
    """Sample the trajectory every ``spec.interval`` seconds and add uniform noise.

    Parameters
    ----------
    t, x, y, psi, sog, n : arrays at the integration step
        Time [s], position north/east [m], heading [rad], speed over ground [m/s], rpm [rps].
    spec : trials.trial.LogSpec
        Interval, start position, noise levels (half-widths of the uniform noise), seed and
        constant sensor biases (heading, speed, rpm; :class:`mmg.disturbances.SensorBias`).
    rng : numpy Generator, optional
        Defaults to ``np.random.default_rng(spec.seed)``.
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
    hdg = np.mod(np.degrees(psi[sel] + b.heading) + noise(np.degrees(spec.noise_heading)), 360.0)
    spd = (sog[sel] + b.speed) / KNOT + noise(spec.noise_speed / KNOT)
    rpm = (n[sel] + b.rpm) * 60.0 + noise(spec.noise_rpm * 60.0)
    return pd.DataFrame({"time_s": ts, "lat_deg": lat, "lon_deg": lon, "heading_deg": hdg,
                         "speed_kn": spd, "rpm": rpm})


FLOAT_FORMAT = "%.12g"
"""How the log and truth files print numbers (12 significant digits)."""


def write_csv(path: Path, df: pd.DataFrame, meta: dict) -> None:
    """Write a DataFrame with a ``# key: value`` metadata header."""
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


def truth_frame(t, states, orders) -> pd.DataFrame:
    """States at the integration step as the truth-file table."""
    return pd.DataFrame({
        "time_s": t, "u_mps": states[:, 0], "v_mps": states[:, 1], "r_radps": states[:, 2],
        "delta_rad": states[:, 6], "delta_order_rad": orders, "x_m": states[:, 3],
        "y_m": states[:, 4], "psi_rad": states[:, 5], "n_rps": states[:, 7],
    })


# --------------------------------------------------------------------------- reading

def _parse_meta(lines: list[str]) -> dict:
    meta = {}
    for ln in lines:
        body = ln[1:].strip()
        if ":" in body:
            k, v = body.split(":", 1)
            v = v.strip()
            try:
                v = float(v) if any(ch in v for ch in ".eE") or v.lstrip("-").isdigit() else v
            except ValueError:
                pass
            meta[k.strip()] = v
    return meta


def _check(df: pd.DataFrame, cols, source: str, time_col: str, max_gap: float | None = None):
    for c in cols:
        if c not in df.columns:
            raise InputError(source, c, "missing column")
    for c in cols:
        vals = pd.to_numeric(df[c], errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(vals))
        if bad.size:
            raise InputError(source, c, f"non-numeric or NaN value at data row {bad[0] + 1}")
    t = df[time_col].to_numpy(dtype=float)
    if len(t) < 2:
        raise InputError(source, time_col, "fewer than two samples")
    dt = np.diff(t)
    bad = np.flatnonzero(dt <= 0)
    if bad.size:
        raise InputError(source, time_col, f"time is not strictly increasing at data row {bad[0] + 2} (t = {t[bad[0] + 1]:g} s)")
    med = float(np.median(dt))
    limit = max_gap if max_gap is not None else 3.0 * med
    gap = np.flatnonzero(dt > limit + 1e-9)
    if gap.size:
        raise InputError(source, time_col, f"gap of {dt[gap[0]]:g} s at t = {t[gap[0]]:g} s (sampling {med:g} s)")


def unwrap_heading(psi_wrapped: np.ndarray) -> np.ndarray:
    """Continuous heading [rad] from a wrapped one, starting on the branch (-pi, pi]."""
    psi = np.unwrap(psi_wrapped)
    return psi - 2 * np.pi * np.round(psi[0] / (2 * np.pi))


def read_record(path: str | Path) -> TrialRecord:
    """Read a project log, a project truth file or an FRT-DS-ESSO CSV into a TrialRecord."""
    path = Path(path)
    src = str(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise InputError(src, "", "file not found") from None
    except (UnicodeDecodeError, IsADirectoryError) as e:
        raise InputError(src, "", f"cannot read as text ({e.__class__.__name__})") from None
    lines = text.splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    meta = _parse_meta(head)
    body = "\n".join(ln for ln in lines if not ln.startswith("#"))
    if not body.strip():
        raise InputError(src, "", "no data")
    try:
        df = pd.read_csv(io.StringIO(body))
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as e:
        raise InputError(src, "", f"not a readable CSV ({str(e).splitlines()[0]})") from None
    return record_from_frame(df, meta, src, default_name=path.stem)


def record_from_frame(df: pd.DataFrame, meta: dict, source: str = "simulation", default_name: str = "") -> TrialRecord:
    """A TrialRecord from a table in one of the supported column layouts and its header ``meta``.

    The one conversion behind :func:`read_record`; the estimators' in-memory path
    (:func:`trials.estimation.data_from_trial`) uses it on a simulated log and truth table
    directly, so a simulated record and the same record read back from its files agree.
    """
    src = source
    cols = set(df.columns)
    name = str(meta.get("trial", default_name))
    ship = str(meta.get("ship", ""))
    if "t [s]" in cols or "psi_hat [rad]" in cols:
        return _read_frt(df, src, Path(src))
    if "u_mps" in cols or "psi_rad" in cols:
        _check(df, TRUTH_COLUMNS, src, "time_s")
        a = {c: df[c].to_numpy(dtype=float) for c in TRUTH_COLUMNS}
        return TrialRecord(t=a["time_s"], name=name, ship=ship, source=src, x=a["x_m"], y=a["y_m"],
                           psi=a["psi_rad"], U=np.hypot(a["u_mps"], a["v_mps"]), u=a["u_mps"],
                           v=a["v_mps"], r=a["r_radps"], delta=a["delta_rad"], n=a["n_rps"],
                           meta={**meta, "format": "truth", "delta_order": a["delta_order_rad"]})
    if "lat_deg" in cols or "heading_deg" in cols or "time_s" in cols:
        _check(df, LOG_COLUMNS, src, "time_s")
        a = {c: df[c].to_numpy(dtype=float) for c in LOG_COLUMNS}
        lat0 = float(meta.get("start_lat_deg", a["lat_deg"][0]))
        lon0 = float(meta.get("start_lon_deg", a["lon_deg"][0]))
        mlat = float(meta.get("m_per_deg_lat", M_PER_DEG_LAT))
        mlon = float(meta.get("m_per_deg_lon", M_PER_DEG_LON))
        extra = {}
        if "rudder_deg" in cols:
            extra["delta"] = df["rudder_deg"].to_numpy(dtype=float) * DEG
        return TrialRecord(t=a["time_s"], name=name, ship=ship, source=src,
                           x=(a["lat_deg"] - lat0) * mlat, y=(a["lon_deg"] - lon0) * mlon,
                           psi=unwrap_heading(np.radians(a["heading_deg"])), U=a["speed_kn"] * KNOT,
                           n=a["rpm"] / 60.0, meta={**meta, "format": "log"}, **extra)
    missing = sorted(set(LOG_COLUMNS) - cols)
    raise InputError(src, missing[0] if missing else "", "missing column (not a project log, truth file or FRT-DS-ESSO CSV)")


def _read_frt(df: pd.DataFrame, src: str, path: Path) -> TrialRecord:
    present = [c for c in FRT_COLUMNS if c in df.columns]
    _check(df, list(FRT_REQUIRED) + [c for c in present if c not in FRT_REQUIRED], src, "t [s]")
    a = {FRT_COLUMNS[c]: df[c].to_numpy(dtype=float) for c in present}
    psi = unwrap_heading(a.pop("psi"))
    u, v = a.get("u"), a.get("v")
    U = np.hypot(u, v) if u is not None and v is not None else None
    meta = {"format": "frt-ds-esso", "ship": "Esso Osaka 3 m model", "length_m": 3.0}
    return TrialRecord(t=a.pop("t"), name=path.stem, ship="Esso Osaka 3 m model", source=src,
                       psi=psi, U=U, meta=meta, **a)
