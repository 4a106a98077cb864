"""Trial definitions from YAML: the manoeuvre, the approach, the log to record.

A trial file (``configs/trials/*.yaml``) names its ship (a bundled name such as
``esso_osaka``, or a ship YAML path relative to the trial file),
the approach condition, the manoeuvre, the integration step and duration, the
sea-trial log to write and optional disturbances.  Every dimensional value carries
its unit (``"10 kn"``, ``"35 deg"``, ``"0.1 s"``); unknown keys, wrong units,
missing fields and out-of-range values are refused with one line naming the
file and the field.

Manoeuvre kinds
---------------
turning   rudder (signed: + starboard), execute time
zigzag    rudder, heading (the switching heading change), first side
stype     rudder, switch_heading psi_S, first side (Rhee & Kim section 6.1: turn until the
          heading change reaches psi_S, reverse to full opposite rudder until it is back to 0,
          reverse again, and so on)
sine      amplitude, period: delta* = A sin(2 pi t / period)   (Rhee & Kim Fig. 8)
sawtooth  amplitude, period: the order ramps from -A to +A over a period, then is reversed
          at once (the steering gear's rate limit shapes the reversal) (Fig. 9)
schedule  table of [time_s, rudder_deg] or [time_s, rudder_deg, rpm] rows, inline or from a CSV
          file with columns time_s, rudder_deg[, rpm]; linear interpolation
stopping  full astern from the approach (IMO MSC.137(76) 5.3.4): the rudder held at ``rudder``
          (default midships), the revolutions ordered from the approach ones to ``astern_ratio``
          times them astern along a ramp of ``reversal`` seconds from ``execute`` (default
          120 s at full scale, 120 / sqrt(lambda) s on a model of scale lambda:
          :func:`mmg.engine_order.reversal_time`) (:class:`mmg.engine_order.AsternOrder`, its constants and sources); the revolutions are
          prescribed whatever the ship's engine (no four-quadrant torque is needed); the run ends
          when the ship is stopped (surge speed down to 1 % of the approach speed)
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Annotated, Literal, Optional, Union

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

import mmg.effects as E
from mmg.engine_order import ASTERN_RPM_RATIO, reversal_time
from mmg.errors import InputError
from mmg.limits import MAX_SAMPLES, check_steps
from mmg.ship import Ship, field_path, load_ship, one_line, pydantic_message, read_yaml
from mmg.units import (DEG, KNOT, LONGITUDE_RANGE, MAX_CURRENT, MAX_FROUDE, MAX_HEADING_CHANGE, MAX_LATITUDE, MAX_RPM,
                       MAX_RUDDER, MAX_RUDDER_OFFSET, MAX_SHIP_SPEED, to_si)

from .approach import _check_approach_rpm, _polyval
from .definition import LogSpec, SensorBias, Trial


def _q(dimension):
    def check(v):
        to_si(v, dimension)
        return v

    return check


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


class _Approach(_Strict):
    speed: str
    rpm: str = "solve"
    trim: bool = True

    @field_validator("speed")
    @classmethod
    def _speed(cls, v):
        to_si(v, "speed", 0.0, MAX_SHIP_SPEED, lo_open=True)
        return v

    @field_validator("rpm")
    @classmethod
    def _rpm(cls, v):
        if v != "solve":
            to_si(v, "revolutions", 0.0, MAX_RPM, lo_open=True)
        return v


Side = Literal["starboard", "port"]


class _Turning(_Strict):
    kind: Literal["turning"]
    rudder: str
    execute: str = "0 s"
    _c = field_validator("rudder")(_q("angle"))


class _Zigzag(_Strict):
    kind: Literal["zigzag"]
    rudder: str
    heading: str
    first: Side = "starboard"
    _c = field_validator("rudder", "heading")(_q("angle"))


class _SType(_Strict):
    kind: Literal["stype"]
    rudder: str
    switch_heading: str
    first: Side = "starboard"
    _c = field_validator("rudder", "switch_heading")(_q("angle"))


class _Periodic(_Strict):
    kind: Literal["sine", "sawtooth"]
    amplitude: str
    period: str
    _a = field_validator("amplitude")(_q("angle"))
    _p = field_validator("period")(_q("time"))


class _Schedule(_Strict):
    kind: Literal["schedule"]
    table: Optional[list[list[float]]] = None
    file: Optional[str] = None


class _Stopping(_Strict):
    kind: Literal["stopping"]
    rudder: str = "0 deg"
    astern_ratio: float = ASTERN_RPM_RATIO
    reversal: Optional[str] = None            # the ship's: mmg.engine_order.reversal_time
    execute: str = "0 s"
    _c = field_validator("rudder")(_q("angle"))
    _t = field_validator("reversal", "execute")(_q("time"))


_Manoeuvre = Annotated[Union[_Turning, _Zigzag, _SType, _Periodic, _Schedule, _Stopping], Field(discriminator="kind")]


class _Noise(_Strict):
    lat: str = "8.0e-7 deg"
    lon: str = "4.0e-7 deg"
    heading: str = "1.2e-2 deg"
    speed: str = "0 kn"
    rpm: str = "0.2 rpm"
    _a = field_validator("lat", "lon", "heading")(_q("angle"))
    _s = field_validator("speed")(_q("speed"))
    _r = field_validator("rpm")(_q("revolutions"))


class _Bias(_Strict):
    heading: str = "0 deg"
    speed: str = "0 kn"
    rpm: str = "0 rpm"
    _a = field_validator("heading")(_q("angle"))
    _s = field_validator("speed")(_q("speed"))
    _r = field_validator("rpm")(_q("revolutions"))


class _Log(_Strict):
    interval: str = "5 s"
    seed: int = Field(default=0, ge=0, le=2**63 - 1)
    start_lat: str = "35.0 deg"
    start_lon: str = "129.0 deg"
    noise: _Noise = _Noise()
    bias: _Bias = _Bias()
    _i = field_validator("interval")(_q("time"))
    _l = field_validator("start_lat", "start_lon")(_q("angle"))


class _Current(_Strict):
    speed: str
    direction: str
    _s = field_validator("speed")(_q("speed"))
    _d = field_validator("direction")(_q("angle"))


class _Disturbances(_Strict):
    current: Optional[_Current] = None
    rudder_offset: str = "0 deg"
    _r = field_validator("rudder_offset")(_q("angle"))


class _TrialFile(_Strict):
    name: str
    ship: str
    description: str = ""
    approach: _Approach
    duration: str
    dt: str
    manoeuvre: _Manoeuvre
    log: _Log = _Log()
    disturbances: _Disturbances = _Disturbances()
    effects: Optional[dict] = None
    _t = field_validator("duration", "dt")(_q("time"))


def _loc(err) -> str:
    loc = list(err.get("loc", ()))
    # drop pydantic's union-tag element (e.g. manoeuvre.turning.rudder -> manoeuvre.rudder)
    if len(loc) > 1 and loc[0] == "manoeuvre" and loc[1] in ("turning", "zigzag", "stype", "sine", "sawtooth", "schedule",
                                                    "stopping"):
        loc.pop(1)
    return field_path(loc)


MAX_SCHEDULE_BYTES = 64 * 2**20
"""A schedule CSV larger than this (64 MiB, some two million rows) is refused unread."""

_TABLE_COLUMNS = ("time_s", "rudder_deg", "rpm")


def _read_table(path: Path, source: str) -> np.ndarray:
    """The schedule CSV's time_s, rudder_deg[, rpm] as floats; InputError naming the CSV and its column."""
    import pandas as pd

    csv = str(path)
    try:
        size = path.stat().st_size
    except FileNotFoundError:
        raise InputError(source, "manoeuvre.file", f"schedule file {path} not found") from None
    except (OSError, ValueError) as e:
        raise InputError(source, "manoeuvre.file", f"schedule file {path} cannot be read ({one_line(e)})") from None
    if path.is_dir():
        raise InputError(source, "manoeuvre.file", f"schedule file {path} is a directory, not a CSV file")
    if size > MAX_SCHEDULE_BYTES:
        raise InputError(csv, "", f"{size / 2**20:.0f} MiB is larger than the {MAX_SCHEDULE_BYTES // 2**20} MiB "
                                  "a schedule may have")
    try:
        df = pd.read_csv(path, comment="#", encoding="utf-8", skipinitialspace=True)
    except UnicodeDecodeError:
        raise InputError(csv, "", "not a UTF-8 text file: is it binary?") from None
    except pd.errors.EmptyDataError:
        raise InputError(csv, "", "empty: expected columns time_s, rudder_deg[, rpm]") from None
    except pd.errors.ParserError as e:
        raise InputError(csv, "", f"not a regular CSV table ({one_line(e)})") from None
    except (OSError, ValueError) as e:
        raise InputError(csv, "", f"cannot be read ({one_line(e)})") from None
    cols = [str(c) for c in df.columns]
    for c in cols:
        if c not in _TABLE_COLUMNS:
            raise InputError(csv, c, f"unknown column; known: {', '.join(_TABLE_COLUMNS)}")
    if len(set(cols)) != len(cols):
        raise InputError(csv, "", "a column is repeated")
    for c in ("time_s", "rudder_deg"):
        if c not in cols:
            raise InputError(csv, c, "missing column")
    use = [c for c in _TABLE_COLUMNS if c in cols]
    out = np.empty((len(df), len(use)))
    for j, c in enumerate(use):
        col = df[c]
        vals = None
        if col.dtype != bool:
            try:
                vals = col.to_numpy(dtype=float)
            except (ValueError, TypeError, OverflowError):
                pass
        if vals is None:  # find the first cell that is not a number (a word, True, a number beyond float)
            for i, cell in enumerate(col):
                try:
                    ok = not isinstance(cell, (bool, np.bool_)) and np.isfinite(float(cell))
                except (ValueError, TypeError, OverflowError):
                    ok = False
                if not ok:
                    raise InputError(csv, c, f"data row {i + 1}: {_short(cell)} is not a finite number")
            raise InputError(csv, c, "not a column of numbers")
        bad = ~np.isfinite(vals)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            cell = col.iloc[i]
            what = "is empty" if pd.isna(cell) else f"{_short(cell)} is not a finite number"
            raise InputError(csv, c, f"data row {i + 1} {what}")
        out[:, j] = vals
    return out


def _short(value) -> str:
    r = repr(value)
    return one_line(r if len(r) <= 40 else r[:37] + "...")


_UNIT_HINT = {
    "rudder": "deg", "heading": "deg", "switch_heading": "deg", "amplitude": "deg", "direction": "deg",
    "rudder_offset": "deg", "lat": "deg", "lon": "deg", "start_lat": "deg", "start_lon": "deg",
    "speed": "kn", "rpm": "rpm", "duration": "s", "dt": "s", "period": "s", "execute": "s", "interval": "s",
    "reversal": "s",
}


def _message(err) -> str:
    """Pydantic's message, made plain; a number where a quantity is expected names the unit to add."""
    return pydantic_message(err, _UNIT_HINT)


def _resolve_ship(spec: str, base: Path, src: str) -> Path:
    """A trial's ``ship:`` entry: a bundled ship name, or a path relative to ``base``."""
    from mmg.resources import _looks_like_path, bundled, config_dir

    try:
        if _looks_like_path(spec):
            p = Path(spec).expanduser()
            p = (p if p.is_absolute() else base / p).resolve()
            if p.is_dir():
                raise InputError(src, "ship", f"ship file {spec} is a directory, not a ship YAML (looked in {p})")
            if not p.is_file():
                raise InputError(src, "ship", f"ship file {spec} not found (looked in {p})")
            return p
        p = config_dir() / "ships" / f"{spec}.yaml"
        if p.is_file():
            return p
        if (base / spec).is_file():
            return (base / spec).resolve()
    except (OSError, ValueError, RuntimeError) as e:  # a name too long, a NUL byte, '~nosuchuser'
        raise InputError(src, "ship", f"{_short(spec)} is not a usable ship name or path ({one_line(e)})") from None
    raise InputError(src, "ship", f"no bundled ship {spec!r} (bundled: {', '.join(bundled('ships'))}); "
                                  "or give a path to a ship YAML, relative to the trial file")


def load_trial(source: str | Path | Mapping) -> Trial:
    """Read and validate a trial (and the ship it names).

    Parameters
    ----------
    source : str, os.PathLike or mapping
        A bundled trial name (``"zz20"``, ``"st35"``: the stem of a file in
        ``configs/trials``), a path to a trial YAML, or a mapping with a trial YAML's
        content.  The trial's ``ship:`` is a bundled ship name (``esso_osaka``) or a path,
        relative to the trial file (for a mapping: to the working directory).

    Returns
    -------
    Trial

    Raises
    ------
    mmg.errors.InputError
        An unknown name, a missing file, or an invalid field (one line naming the file
        and the field; an error in the ship file names the ship file).
    """
    if isinstance(source, Mapping):
        return trial_from_dict(source)
    from mmg.resources import trial_path

    path = trial_path(source)
    return trial_from_dict(read_yaml(path), source=str(path), base=path.parent)


MIN_DT = 1e-4
"""Smallest integration step [s] (0.1 ms); the largest is the ship's steering-gear time constant T_E."""

MIN_STEPS_PER_PERIOD = 10
"""A sine or sawtooth period must span at least this many integration steps."""

NOISE_MAX = {"lat": 0.01 * DEG, "lon": 0.01 * DEG, "heading": 10 * DEG, "speed": 5 * KNOT, "rpm": 100 / 60}
"""Largest log noise amplitude per channel (SI): lat, lon 0.01 deg (1.1 km), heading 10 deg, speed 5 kn,
rpm 100 rpm; the same bounds apply to |bias|."""

_DIM = {"lat": "angle", "lon": "angle", "heading": "angle", "speed": "speed", "rpm": "revolutions"}


def _si(src: str, field: str, value, dimension: str, lo=None, hi=None, **kw) -> float:
    """:func:`mmg.units.to_si`, its refusal an InputError naming ``src`` and ``field``."""
    try:
        return to_si(value, dimension, lo, hi, **kw)
    except ValueError as e:
        raise InputError(src, field, str(e)) from None


def _trial_file(data, src: str, ship: Ship | None) -> _TrialFile:
    """The mapping validated (types, keys); with ``ship`` given, ``ship:`` may be omitted."""
    if not isinstance(data, Mapping):
        raise InputError(src, "", f"expected a mapping of trial fields, got {type(data).__name__}")
    data = dict(data)
    if ship is not None:
        if not isinstance(ship, Ship):
            raise InputError(src, "ship", f"expected a Ship, got {type(ship).__name__}")
        data["ship"] = data.get("ship") or ship.name
    try:
        return _TrialFile.model_validate(data)
    except ValidationError as e:
        err = e.errors()[0]
        raise InputError(src, _loc(err), _message(err)) from None


def _run_size(f: _TrialFile, src: str) -> tuple[float, float]:
    """(duration, dt) [s], refused before the ship is read or anything allocated."""
    duration = _si(src, "duration", f.duration, "time", 0.0, None, lo_open=True)
    dt = _si(src, "dt", f.dt, "time", MIN_DT, None)
    if dt > duration:
        raise InputError(src, "dt", f"{f.dt} is longer than the duration ({f.duration})")
    check_steps(duration, dt, src, "duration")
    return duration, dt


def _trial_ship(f: _TrialFile, ship: Ship | None, base: Path, src: str, dt: float) -> tuple[Ship, str, str]:
    """(the ship, its file or "", its label in messages); dt checked against its steering gear."""
    if ship is None:
        ship_path = _resolve_ship(f.ship, base, src)
        ship = load_ship(ship_path)
        ship_path = str(ship_path)
    else:
        ship_path = ""
    label = f"{ship.name} ({ship_path})" if ship_path else ship.name
    T_E = ship.steering.T_E
    if dt > T_E * (1 + 1e-9):
        raise InputError(src, "dt", f"{f.dt} is longer than the steering gear's time constant T_E = {T_E:g} s of "
                                    f"{label}: the step must resolve it (RK4 is unstable beyond 2.8 T_E)")
    return ship, ship_path, label


def _approach(f: _TrialFile, ship: Ship, label: str, src: str) -> tuple[float, float | None]:
    """(u0 [m/s], n0 [rps] or None to solve), checked against the ship's propeller and engine data."""
    u0 = _si(src, "approach.speed", f.approach.speed, "speed", 0.0, MAX_SHIP_SPEED, lo_open=True)
    L = ship.particulars.L
    fn = u0 / np.sqrt(9.81 * L)
    if fn > MAX_FROUDE:
        raise InputError(src, "approach.speed", f"{f.approach.speed} is a Froude number of {fn:.3g} for the {L:g} m "
                                                f"{label}; above {MAX_FROUDE:g} no displacement ship sails "
                                                "(probably the wrong unit)")
    pr = ship.propeller
    for name, poly in (("t_P", pr.t_P), ("w_P0", pr.w_P0)):
        v = _polyval(poly, u0)
        if not 0.0 <= v < 1.0:
            raise InputError(src, "approach.speed", f"at {f.approach.speed} the ship's {name}(u) polynomial gives "
                                                    f"{v:.4g}, outside [0, 1): the speed is outside the range of "
                                                    f"the propeller data of {label}")
    if ship.engine.mode == "constant_power":
        shp = _polyval(ship.engine.SHP_0, u0)
        if not shp > 0.0:
            raise InputError(src, "approach.speed", f"at {f.approach.speed} the constant-power engine's SHP_0(u) "
                                                    f"gives {shp:.4g} hp; it needs positive power (the speed is "
                                                    f"outside the engine data of {label})")
    n0 = None if f.approach.rpm == "solve" else _si(src, "approach.rpm", f.approach.rpm, "revolutions", 0.0, MAX_RPM,
                                                    lo_open=True)
    return u0, n0


def _manoeuvre(f: _TrialFile, ship: Ship, label: str, src: str, run: tuple[float, float], base: Path):
    """(kind, its fields in SI); rudder angles within the steering gear's limit; run = (duration, dt)."""
    duration, dt = run
    dmax = ship.steering.delta_max
    man = f.manoeuvre.model_dump()
    kind = man.pop("kind")
    conv: dict = {}
    for k, v in man.items():
        field = f"manoeuvre.{k}"
        if k in ("rudder", "amplitude"):
            x = _si(src, field, v, "angle", -MAX_RUDDER, MAX_RUDDER)
            if abs(x) > dmax + 1e-12:
                raise InputError(src, field, f"{v} exceeds the steering gear limit of {dmax / DEG:g} deg of {label}")
            if k == "rudder" and kind in ("zigzag", "stype") and not x > 0:
                raise InputError(src, field, f"must be positive, got {v!r} (the first side is set by 'first')")
            conv[k] = x
        elif k in ("heading", "switch_heading"):
            conv[k] = _si(src, field, v, "angle", 0.0, MAX_HEADING_CHANGE, lo_open=True)
        elif k == "period":
            conv[k] = _si(src, field, v, "time", MIN_STEPS_PER_PERIOD * dt, None,
                          why=f"at least {MIN_STEPS_PER_PERIOD} steps of dt = {dt:g} s, so the order is resolved")
        elif k == "execute":
            conv[k] = _si(src, field, v, "time", 0.0, duration, hi_open=True,
                          why=f"the execute time must lie in [0, {duration:g} s), within the run")
        elif k == "reversal":
            conv[k] = (reversal_time(ship.froude_scale) if v is None else      # a model's: Froude-scaled
                       _si(src, field, v, "time", 0.0, 3600.0, why="a reversal from ahead to astern takes 0-60 min"))
        elif k == "astern_ratio":
            if not 0.0 < v <= 1.5:
                raise InputError(src, field, f"{v!r}: the full-astern revolutions are a fraction (0, 1.5] of the "
                                             f"approach ones")
            conv[k] = float(v)
        else:
            conv[k] = v
    if kind == "schedule":
        conv = {"table": _schedule(conv, ship, label, duration, base, src)}
    return kind, conv


def _log_spec(f: _TrialFile, src: str, run: tuple[float, float]) -> LogSpec:
    """log: SI, interval a multiple of dt at most the duration; run = (duration, dt)."""
    duration, dt = run
    lg = f.log
    interval = _si(src, "log.interval", lg.interval, "time", 0.0, duration, lo_open=True,
                   why=f"a positive interval at most the duration {f.duration}")
    ratio = interval / dt
    if round(ratio) < 1 or abs(ratio - round(ratio)) > 1e-6:
        raise InputError(src, "log.interval", f"must be a positive multiple of dt ({f.dt}), got {lg.interval!r}")
    start_lat = _si(src, "log.start_lat", lg.start_lat, "angle", -MAX_LATITUDE, MAX_LATITUDE,
                    why="a latitude is within +-90 deg")
    start_lon = _si(src, "log.start_lon", lg.start_lon, "angle", *LONGITUDE_RANGE, why="a longitude is -180 to 360 deg")
    noise = {c: _si(src, f"log.noise.{c}", getattr(lg.noise, c), _DIM[c], 0.0, NOISE_MAX[c]) for c in _DIM}
    bias = {c: _si(src, f"log.bias.{c}", getattr(lg.bias, c), _DIM[c], -NOISE_MAX[c], NOISE_MAX[c])
            for c in ("heading", "speed", "rpm")}
    return LogSpec(interval, lg.seed, start_lat, start_lon, noise["lat"], noise["lon"], noise["heading"],
                   noise["speed"], noise["rpm"], SensorBias(bias["heading"], bias["speed"], bias["rpm"]))


def _disturbances(f: _TrialFile, src: str) -> E.EffectSet:
    """disturbances: the uniform current and the rudder offset as the ``current`` and ``rudder_offset``
    effects (:mod:`mmg.effects`); a zero offset is no effect."""
    items = []
    d = f.disturbances
    if d.current is not None:
        speed = _si(src, "disturbances.current.speed", d.current.speed, "speed", 0.0, MAX_CURRENT,
                    why="a current runs at 0-20 kn (its sense is the direction)")
        towards = _si(src, "disturbances.current.direction", d.current.direction, "angle", -2 * np.pi, 2 * np.pi)
        items.append((E.Current, {"speed_mps": speed, "direction_deg": math.degrees(towards)}))
    off = _si(src, "disturbances.rudder_offset", d.rudder_offset, "angle", -MAX_RUDDER_OFFSET, MAX_RUDDER_OFFSET)
    if off != 0.0:
        items.append((E.RudderOffset, {"offset_deg": math.degrees(off)}))
    return E.EffectSet(tuple(items))


def trial_from_dict(data: Mapping, source: str = "<dict>", base: str | Path | None = None,
                    ship: Ship | None = None) -> Trial:
    """Validate a trial mapping (a trial YAML's content) and build the :class:`Trial`.

    Besides types, keys and units, every value is checked against plausible bounds (a value
    outside them is refused as probably the wrong unit), and against the ship:

    * approach speed 0-60 kn, Froude number U/sqrt(gL) at most 1, the ship's t_P(u) and
      w_P0(u) within [0, 1) and (constant power) SHP_0(u) > 0 at that speed; rpm 0-6000 rpm, and
      one that can drive that approach (:func:`_check_approach_rpm`: the propeller pushing ahead;
      a constant-power engine's rpm within 5 % of the one the straight run needs; a constant-rpm
      motor's rpm within a factor 2 of it, either way, and driving the ship to a speed within its
      propeller data);
    * dt 0.1 ms to the ship's steering-gear time constant T_E (RK4 on the gear's first-order
      lag is unstable beyond 2.8 T_E); dt <= duration; at most :data:`mmg.limits.MAX_STEPS`
      steps (refused before anything is allocated, saying how much it would need);
    * rudder and amplitude within the steering-gear limit (and 90 deg); a zigzag or S-type
      rudder and switching heading positive (the side is ``first``), the heading at most
      360 deg; a period of at least 10 steps; execute in [0, duration);
    * a schedule: at least two rows, all of 2 or all of 3 numbers, finite, times strictly
      increasing from 0 or later and starting before the end; an rpm column (0-6000 rpm) only
      for a constant-rpm engine (a constant-power engine would ignore it);
    * log: interval a multiple of dt, at most the duration; seed 0 or more; start latitude
      within +-90 deg, longitude -180 to 360 deg; noise 0 or more and |bias| at most
      :data:`NOISE_MAX`;
    * current 0-20 kn towards a direction within +-360 deg; rudder offset within +-10 deg.

    Parameters
    ----------
    data : mapping
        The trial's fields, as in a trial YAML.
    source : str
        Names the trial in error messages and in :attr:`Trial.path`.
    base : path, optional
        Folder that relative paths (``ship:``, ``manoeuvre.file``) are relative to;
        default the working directory.
    ship : Ship, optional
        Use this ship instead of the one ``data["ship"]`` names (which may then be omitted).

    Returns
    -------
    Trial

    Raises
    ------
    mmg.errors.InputError
        One line naming ``source`` and the field at fault (the ship file and its field when
        the ship file is at fault; a schedule CSV and its column when that is).
    """
    src = str(source)
    base = Path.cwd() if base is None else Path(base)
    f = _trial_file(data, src, ship)
    run = duration, dt = _run_size(f, src)
    ship, ship_path, label = _trial_ship(f, ship, base, src, dt)
    u0, n0 = _approach(f, ship, label, src)
    kind, conv = _manoeuvre(f, ship, label, src, run, base)
    log = _log_spec(f, src, run)
    dist = _disturbances(f, src)
    # effects (mmg.effects), besides the ship's; each value given in one place only
    effects = _trial_effects(f, ship, src, label, legacy=_legacy_statements(f, dist, log.bias.heading, src))
    if dist.items:                   # the disturbances: section's effects with the effects: section's
        effects = dist.merged(effects)
    if n0 is not None:
        _check_approach_rpm(src, f.approach, ship, label, u0, n0, effects)
    hb = ship.effect_set().merged(effects).get("heading_bias")
    if hb is not None:               # a compass error: on the logged heading, as log.bias.heading
        log = replace(log, bias=replace(log.bias, heading=log.bias.heading + float(np.radians(hb["bias_deg"]))))
    return Trial(
        name=f.name, path=src, ship=ship, ship_path=ship_path, description=f.description,
        u0=u0, n0=n0, trim=f.approach.trim, duration=duration, dt=dt, kind=kind, manoeuvre=conv, log=log,
        effects=effects,
    )


_LEGACY = {"current": "disturbances.current", "rudder_offset": "disturbances.rudder_offset",
           "heading_bias": "log.bias.heading"}
"""The older trial keys of three effects (the same physics as ``effects.<name>``)."""


def _legacy_statements(f: _TrialFile, dist: E.EffectSet, heading_bias: float, src: str) -> list:
    """The effect values the trial's older keys state: ``(effect, parameter, file, field, value)``.

    A key counts when it is written, whatever its value (``rudder_offset: 0 deg`` states a zero offset)."""
    out = []
    cur, off = dist.get("current"), dist.get("rudder_offset") or {"offset_deg": 0.0}
    if cur is not None:
        out += [("current", "speed_mps", src, "disturbances.current.speed", cur["speed_mps"]),
                ("current", "direction_deg", src, "disturbances.current.direction", cur["direction_deg"])]
    if "rudder_offset" in f.disturbances.model_fields_set:
        out.append(("rudder_offset", "offset_deg", src, "disturbances.rudder_offset", off["offset_deg"]))
    if "bias" in f.log.model_fields_set and "heading" in f.log.bias.model_fields_set:
        out.append(("heading_bias", "bias_deg", src, "log.bias.heading", float(np.degrees(heading_bias))))
    return out


def _trial_effects(f: _TrialFile, ship: Ship, src: str, label: str, legacy: list):
    """The trial's ``effects:`` as an EffectSet (None: none), every effect value given in one place.

    Refused, in one line naming both places: an effect both in ``effects:`` and in its older key
    (``disturbances.current``, ``disturbances.rudder_offset``, ``log.bias.heading``); an older key
    for an effect the ship config has (the ship's would act in the simulator, the key in the log);
    an effect value stated by the trial and by the ship file (``effects.wind.scale`` here and
    ``wind.scale`` there), even equal.  An effect in both configs otherwise takes the values each
    states (the ship's wind scale with the trial's steady wind)."""
    from mmg.effects import EffectSet, effect_set, refuse_twice, statements

    own = ship.effect_set()
    for eff, _, _, _, _ in legacy:
        if own.get(eff) is not None:
            raise InputError(src, _LEGACY[eff], f"also given as effects.{eff} of the ship config {label}: give it in one place")
    if f.effects is None:
        return None
    effects = effect_set(f.effects, "effects", src)
    for eff, _, _, _, _ in legacy:
        if effects.get(eff) is not None:
            raise InputError(src, f"effects.{eff}", f"also given as {_LEGACY[eff]}: give it in one place")
    mine = statements(f.effects, effects, "effects", src)
    shipped = [st for st in ship.stated if own.get(st[0]) is not None or st[0] == "wind"]   # scale, shape factors
    refuse_twice(shipped + mine, src)
    if effects.get("wind") is not None and ship.wind is None:
        raise InputError(src, "effects.wind", f"the wind effect needs a ship with a wind section; {label} has none")
    items = []
    for cls, vals in effects.items:                    # the values each config states, together
        base = dict(own.get(cls.name) or {})
        base.update({p: v for e, p, _, _, v in shipped if e == cls.name})
        base.update({p: v for e, p, _, _, v in mine if e == cls.name})
        items.append((cls, {**vals, **base}))
    return EffectSet(tuple(items)) if items else None


def _schedule(man: dict, ship: Ship, label: str, duration: float, base: Path, src: str) -> np.ndarray:
    """A schedule's table in SI (rows of s, rad(, rps)), from ``table`` or ``file``, checked."""
    if (man.get("table") is None) == (man.get("file") is None):
        raise InputError(src, "manoeuvre", "a schedule needs exactly one of 'table' or 'file'")
    if man.get("table") is not None:
        rows = man["table"]
        where, cols = src, ("manoeuvre.table",) * 3
        if len(rows) < 2:
            raise InputError(src, "manoeuvre.table", "needs at least two rows of [time_s, rudder_deg(, rpm)]")
        if len(rows) > MAX_SAMPLES:
            raise InputError(src, "manoeuvre.table", f"{len(rows):,} rows; at most {MAX_SAMPLES:,}")
        width = len(rows[0])
        for i, r in enumerate(rows):
            if len(r) not in (2, 3) or len(r) != width:
                raise InputError(src, f"manoeuvre.table.{i}", f"row of {len(r)} values; every row must be "
                                                              "[time_s, rudder_deg] or every row [time_s, rudder_deg, rpm]")
        tab = np.asarray(rows, dtype=float)
    else:
        try:
            path = base / man["file"]
        except (TypeError, ValueError) as e:
            raise InputError(src, "manoeuvre.file", f"not a usable path ({one_line(e)})") from None
        tab = _read_table(path, src)
        where, cols = str(path), _TABLE_COLUMNS
        if len(tab) < 2:
            raise InputError(where, "", "needs at least two rows of time_s, rudder_deg(, rpm)")
    if not np.all(np.isfinite(tab)):
        raise InputError(where, cols[0], "contains NaN or infinite values")
    t = tab[:, 0]
    if np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise InputError(where, cols[0], f"time_s must be strictly increasing ({t[i - 1]:g} then {t[i]:g})")
    if t[0] < 0 or t[0] >= duration:
        raise InputError(where, cols[0], f"the first time {t[0]:g} s must lie in [0, {duration:g} s), within the run")
    dmax = ship.steering.delta_max
    if np.any(np.abs(tab[:, 1]) > dmax / DEG + 1e-9):
        raise InputError(where, cols[1], f"rudder beyond the steering gear limit of {dmax / DEG:g} deg of {label}")
    tab = tab.copy()
    tab[:, 1] *= DEG
    if tab.shape[1] > 2:
        if ship.engine.mode != "constant_rpm":
            raise InputError(where, cols[2], f"an rpm order, but the {ship.engine.mode.replace('_', '-')} engine of "
                                             f"{label} would ignore it: drop the rpm column or use a constant-rpm ship")
        rpm = tab[:, 2]
        if np.any(rpm <= 0) or np.any(rpm > MAX_RPM * 60):
            raise InputError(where, cols[2], f"rpm must be positive and at most {MAX_RPM * 60:g} rpm "
                                             f"(got {rpm.min():g} to {rpm.max():g})")
        tab[:, 2] /= 60.0
    return tab
