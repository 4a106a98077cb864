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

import os
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Annotated, Literal, Optional, Union

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from mmg.disturbances import RudderOffset, SensorBias, UniformCurrent
from mmg.engine_order import ASTERN_RPM_RATIO, AsternOrder, reversal_time
from mmg.errors import InputError
from mmg.integrate import CommandLaw
from mmg.limits import MAX_SAMPLES, check_steps
from mmg.ship import Ship, field_path, load_ship, one_line, pydantic_message, read_yaml
from mmg.units import (DEG, KNOT, LONGITUDE_RANGE, MAX_CURRENT, MAX_FROUDE, MAX_HEADING_CHANGE, MAX_LATITUDE,
                       MAX_RPM, MAX_RUDDER, MAX_RUDDER_OFFSET, MAX_SHIP_SPEED, to_si)


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


@dataclass(frozen=True)
class LogSpec:
    """How the sea-trial log is recorded (SI: s, rad, m/s, rps)."""

    interval: float
    seed: int
    start_lat: float
    start_lon: float
    noise_lat: float
    noise_lon: float
    noise_heading: float
    noise_speed: float
    noise_rpm: float
    bias: SensorBias = SensorBias()


@dataclass(frozen=True)
class Trial:
    """A validated trial, in SI units.

    Build one with :func:`load_trial` (a bundled name, a YAML file or a mapping) or with
    the builders :func:`zigzag`, :func:`turning`, :func:`stype`, :func:`schedule`,
    :func:`make_trial`; run it with ``mmg.simulate(trial)`` (:func:`trials.runs.run.run_trial`).

    Attributes
    ----------
    name, description : str
        From the trial file.
    path : str
        Where the trial came from (a file path, ``"<dict>"`` or ``"<zigzag>"`` etc.).
    ship : mmg.ship.Ship
        The ship.
    ship_path : str
        The ship YAML it was read from ("" when the builder was given a Ship object).
    u0 : float
        Approach speed [m/s].
    n0 : float or None
        Approach propeller speed [rps]; None: solved for the approach speed.
    trim : bool
        Start from the trim rudder and drift that cancel the ship's Y_0, N_0.
    duration, dt : float
        Simulated time and integration step [s].
    kind : str
        ``"turning"``, ``"zigzag"``, ``"stype"``, ``"sine"``, ``"sawtooth"`` or ``"schedule"``.
    manoeuvre : dict
        The manoeuvre's parameters in SI (angles in rad, times in s; a schedule's
        ``table`` as rows of [s, rad(, rps)]).
    log : LogSpec
        How the sea-trial log is recorded.
    disturbances : tuple
        Current and rudder offset of the ``disturbances:`` section (:mod:`mmg.disturbances`).
    effects : mmg.effects.EffectSet or None
        The ``effects:`` section (:mod:`mmg.effects`: ``current``, ``wind``, ``rudder_offset``,
        ``heading_bias``, ``shallow_water``), added to the ship's own effects
        (:attr:`mmg.ship.Ship.effects`; an effect in both has the values each config states, a
        value stated in both is refused).  A heading
        bias acts on the log (as ``log.bias.heading``), a steady wind also adds the apparent-wind
        columns to the log.
    """

    name: str
    path: str
    ship: Ship
    ship_path: str
    description: str
    u0: float
    n0: Optional[float]
    trim: bool
    duration: float
    dt: float
    kind: str
    manoeuvre: dict
    log: LogSpec
    disturbances: tuple
    effects: Optional[object] = None

    def __post_init__(self):
        # also for dataclasses.replace(trial, duration=...): refuse a run too big to allocate
        check_steps(self.duration, self.dt, self.path or "Trial", "duration")

    def astern_order(self) -> AsternOrder:
        """The engine order of a ``stopping`` trial (:class:`mmg.engine_order.AsternOrder`)."""
        m = self.manoeuvre
        return AsternOrder(m["astern_ratio"], m["reversal"], m["execute"])

    def command_law(self, trim_rudder: float = 0.0, psi0: float = 0.0, n0: float | None = None) -> CommandLaw:
        """The compiled-loop command law for this manoeuvre (see :mod:`mmg.integrate`); a ``stopping``
        trial needs the approach revolutions ``n0`` [rps] its astern order starts from."""
        m = self.manoeuvre
        side = 1.0 if m.get("first", "starboard") == "starboard" else -1.0
        if self.kind == "turning":
            te = m["execute"]
            if te > 0:
                return CommandLaw.schedule([0.0, te, te + 1e-9, self.duration],
                                           [trim_rudder, trim_rudder, m["rudder"], m["rudder"]])
            return CommandLaw.schedule([0.0, self.duration], [m["rudder"], m["rudder"]])
        if self.kind == "zigzag":
            a, h = m["rudder"], m["heading"]
            return CommandLaw.heading_switch(a, h, -h, side, psi0=psi0)
        if self.kind == "stype":
            a, h = m["rudder"], m["switch_heading"]
            hi, lo = (h, 0.0) if side > 0 else (0.0, -h)
            return CommandLaw.heading_switch(a, hi, lo, side, psi0=psi0)
        if self.kind == "stopping":
            if n0 is None:
                raise ValueError("a stopping trial's command law needs the approach revolutions n0")
            t, n = self.astern_order().table(n0, self.duration)
            return CommandLaw.schedule(t, np.full_like(t, m["rudder"]), n)
        if self.kind in ("sine", "sawtooth"):
            t = np.arange(0.0, self.duration + self.dt / 2, self.dt)
            return CommandLaw.schedule(t, periodic_order(self.kind, t, m["amplitude"], m["period"]))
        tab = m["table"]
        n = tab[:, 2] if tab.shape[1] > 2 else None
        return CommandLaw.schedule(tab[:, 0], tab[:, 1], n)

    def __repr__(self) -> str:
        man = []
        for k, v in self.manoeuvre.items():
            if k in ("rudder", "heading", "switch_heading", "amplitude"):
                man.append(f"{k}={v / DEG:g} deg")
            elif k in ("period", "execute", "reversal"):
                man.append(f"{k}={v:g} s")
            elif k == "astern_ratio":
                man.append(f"{k}={v:g}")
            elif k == "table":
                man.append(f"table={len(v)} rows")
            elif k == "first":
                man.append(f"first={v}")
        return (f"Trial({self.name!r}, {self.kind}: {', '.join(man)}; ship={self.ship.name!r}, "
                f"speed={self.u0 * 3600 / 1852:.4g} kn, duration={self.duration:g} s, dt={self.dt:g} s)")

    def effect_set(self):
        """All effects of the run: the ship's and the trial's (:class:`mmg.effects.EffectSet`)."""
        return self.ship.effect_set().merged(self.effects)

    def steady_wind(self):
        """(true speed [m/s], direction it comes from [rad], scale) of a steady wind, or None."""
        w = self.effect_set().get("wind")
        if w is None or not w["true_speed_mps"] > 0:
            return None
        return w["true_speed_mps"], np.radians(w["true_from_deg"]), w["scale"]

    def current(self):
        """(speed [m/s], direction it sets towards [rad]) of the run's current, (0, 0) without one."""
        c = self.logged_effects().get("current")          # the disturbances: alias builds the same effect
        if c is not None:
            return c["speed_mps"], float(np.radians(c["direction_deg"]))
        return 0.0, 0.0

    def logged_effects(self):
        """Every effect of the run as the log sees it: :meth:`effect_set` plus the ``disturbances:``
        section and ``log.bias.heading`` as their effects (:meth:`mmg.disturbances.Disturbance.effect`)."""
        from mmg.effects import EffectSet

        es = self.effect_set()
        extra = [d.effect() for d in self.disturbances]
        if self.log.bias.heading and es.get("heading_bias") is None:
            extra.append(self.log.bias.effect())
        return es.merged(EffectSet(tuple(extra)))

    def summary(self) -> dict:
        """Trial parameters for a log header (degrees and knots, as at the edges)."""
        out = {"trial": self.name, "kind": self.kind, "ship": self.ship.name,
               "approach_speed_kn": self.u0 * 3600 / 1852}
        for k, v in self.manoeuvre.items():
            if k in ("rudder", "heading", "switch_heading", "amplitude"):
                out[f"{k}_deg"] = v / DEG
            elif k in ("period", "execute", "reversal"):
                out[f"{k}_s"] = v
            elif k in ("first", "astern_ratio"):
                out[k] = v
        return out


def periodic_order(kind: str, t: np.ndarray, amplitude: float, period: float) -> np.ndarray:
    """Rudder order [rad] of the sine or sawtooth manoeuvre at times ``t`` [s]."""
    if kind == "sine":
        return amplitude * np.sin(2 * np.pi * t / period)
    phase = np.mod(t / period + 0.5, 1.0)
    return amplitude * (2.0 * phase - 1.0)


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


def _polyval(c, x: float) -> float:
    return float(np.polyval(np.asarray(c, float)[::-1], x))


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


def _disturbances(f: _TrialFile, src: str) -> list:
    """disturbances: the uniform current and the rudder offset, SI."""
    dist = []
    d = f.disturbances
    if d.current is not None:
        dist.append(UniformCurrent(
            _si(src, "disturbances.current.speed", d.current.speed, "speed", 0.0, MAX_CURRENT,
                why="a current runs at 0-20 kn (its sense is the direction)"),
            _si(src, "disturbances.current.direction", d.current.direction, "angle", -2 * np.pi, 2 * np.pi)))
    off = _si(src, "disturbances.rudder_offset", d.rudder_offset, "angle", -MAX_RUDDER_OFFSET, MAX_RUDDER_OFFSET)
    if off != 0.0:
        dist.append(RudderOffset(off))
    return dist


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
    if n0 is not None:
        _check_approach_rpm(src, f.approach, ship, label, u0, n0, dist, effects)
    hb = ship.effect_set().merged(effects).get("heading_bias")
    if hb is not None:               # a compass error: on the logged heading, as log.bias.heading
        log = replace(log, bias=replace(log.bias, heading=log.bias.heading + float(np.radians(hb["bias_deg"]))))
    return Trial(
        name=f.name, path=src, ship=ship, ship_path=ship_path, description=f.description,
        u0=u0, n0=n0, trim=f.approach.trim, duration=duration, dt=dt, kind=kind, manoeuvre=conv, log=log,
        disturbances=tuple(dist), effects=effects,
    )


APPROACH_RPM_TOLERANCE = 0.05
"""How far (relative) a constant-power engine's ``approach.rpm`` may be from the rpm the straight run
at ``approach.speed`` needs (the engine's power is SHP_0 at that speed: the rpm follows from it)."""


CONSTANT_RPM_FACTOR_MAX = 2.0
"""How far (a factor, either way) a constant-rpm motor's ``approach.rpm`` may be from the rpm the straight
run at ``approach.speed`` needs: the MMG-2015 KVLCC2 convention (the model-scale self-propulsion point,
17.95 rps where the model's own straight run at 1.179 m/s needs 11.85 rps) is a factor 1.51; beyond 2 the
ship runs away from its approach during the trial (3000 rpm at 1.179 m/s: 3.58 m/s), so the trial's
approach speed and its metrics would describe another run."""


def zero_thrust_advance_ratio(ship: Ship) -> float:
    """The advance ratio J where the open-water K_T(J) first falls to zero (inf if it never does):
    beyond it the propeller no longer pushes ahead and the K_T, K_Q polynomials are extrapolations."""
    roots = np.roots(np.asarray(ship.propeller.K_T, float)[::-1]) if len(ship.propeller.K_T) > 1 else []
    pos = [float(r.real) for r in roots if abs(r.imag) < 1e-12 and r.real > 0]
    return min(pos) if pos else float("inf")


def _surge(ship: Ship, n: float, effects, slots):
    """du/dt [m/s^2] of the straight run (no drift, rudder amidships) at surge speed u and rpm ``n``, a function of u."""
    from mmg.equilibrium import _accels
    from mmg.model import pack

    pk = pack(ship, 0.0, slots)
    pk = effects.pack(pk, ship) if effects is not None else pk
    return lambda u: _accels(pk, u, 0.0, 0.0, n)[0]


def _check_approach_rpm(src: str, ap, ship: Ship, label: str, u0: float, n0: float, dist, effects) -> None:
    """InputError naming ``approach.rpm`` unless the given rpm can drive the approach at ``approach.speed``.

    * At the approach the propeller must push ahead: its advance ratio J = u (1 - w_P0(u)) / (n D)
      below the zero-thrust J of K_T (a lower rpm, or one of the wrong sign, is refused);
    * a constant-power engine delivers SHP_0(u) at the approach speed, so the rpm is the one the
      straight run needs (within :data:`APPROACH_RPM_TOLERANCE`; the simulator calibrates the
      propeller's torque at it, and a far one would rescale K_Q by the cube of the ratio);
    * a constant-rpm motor holds the rpm: the ship starts at the approach speed and runs up or
      down to the speed that rpm gives (the MMG 2015 convention of a model-scale self-propulsion
      rpm), which must be within :data:`CONSTANT_RPM_FACTOR_MAX` (either way) of the rpm the straight
      run needs and drive it to a speed within the ship's data (Froude number, t_P(u), w_P0(u) in [0, 1))."""
    from mmg.disturbances import as_effects
    from mmg.equilibrium import straight_run

    extra, slots = as_effects(dist)                         # as mmg.simulation.prepare builds them
    es = ship.effect_set().merged(extra).merged(effects)
    es = es if es.items else None
    pr = ship.propeller
    rpm = f"{ap.rpm} ({n0 * 60:.4g} rpm)" if not ap.rpm.strip().endswith("rpm") else ap.rpm
    try:
        need = straight_run(ship, u0, None, True, slots, es).n
    except ValueError:
        return                                               # no straight run at all: the simulator says so
    needs = f"the straight run at {ap.speed} needs {need * 60:.4g} rpm"
    J0, Jz = u0 * (1 - _polyval(pr.w_P0, u0)) / (n0 * pr.D), zero_thrust_advance_ratio(ship)
    if J0 >= Jz:
        raise InputError(src, "approach.rpm", f"{rpm} at {ap.speed} is an advance ratio J = {J0:.3g}, beyond the "
                                              f"zero-thrust J = {Jz:.3g} of {label}'s propeller: it would not push "
                                              f"ahead; {needs} (or write 'solve')")
    if ship.engine.mode == "constant_power":
        if abs(n0 / need - 1) > APPROACH_RPM_TOLERANCE:
            raise InputError(src, "approach.rpm", f"{rpm} cannot hold {ap.speed} with the constant-power engine of "
                                                  f"{label} (its power is SHP_0 at that speed): {needs} (within "
                                                  f"{APPROACH_RPM_TOLERANCE:.0%}; or write 'solve')")
        return
    if not 1 / CONSTANT_RPM_FACTOR_MAX <= n0 / need <= CONSTANT_RPM_FACTOR_MAX:
        raise InputError(src, "approach.rpm", f"{rpm} is {n0 / need:.3g} times the rpm of the straight run at "
                                              f"{ap.speed} with the constant-rpm motor of {label}: {needs}; the ship "
                                              f"would run {'up' if n0 > need else 'down'} from its approach speed "
                                              f"during the trial (at most a factor {CONSTANT_RPM_FACTOR_MAX:g} either "
                                              f"way; or write 'solve')")
    surge = _surge(ship, n0, es, slots)
    top = MAX_FROUDE * np.sqrt(9.81 * ship.particulars.L)
    if surge(top) > 0:
        raise InputError(src, "approach.rpm", f"{rpm} would drive {label} beyond a Froude number of {MAX_FROUDE:g} "
                                              f"({top:.3g} m/s); {needs}")
    lo, hi = u0, top
    if surge(u0) < 0:                                       # slows down: the speed it gives is below u0
        lo, hi = 0.0, u0
        if surge(1e-6 * u0) < 0:
            return                                          # coasts to rest: physical, nothing to check
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if surge(mid) > 0 else (lo, mid)
    u_n = 0.5 * (lo + hi)
    for name, poly in (("t_P", pr.t_P), ("w_P0", pr.w_P0)):
        if not 0.0 <= _polyval(poly, u_n) < 1.0:
            raise InputError(src, "approach.rpm", f"{rpm} drives {label} to {u_n:.4g} m/s, where its {name}(u) is "
                                                  f"{_polyval(poly, u_n):.3g}, outside [0, 1): beyond the propeller "
                                                  f"data; {needs}")


_LEGACY = {"current": "disturbances.current", "rudder_offset": "disturbances.rudder_offset",
           "heading_bias": "log.bias.heading"}
"""The older trial keys of three effects (the same physics as ``effects.<name>``)."""


def _legacy_statements(f: _TrialFile, dist: list, heading_bias: float, src: str) -> list:
    """The effect values the trial's older keys state: ``(effect, parameter, file, field, value)``.

    A key counts when it is written, whatever its value (``rudder_offset: 0 deg`` states a zero offset)."""
    out = []
    d = f.disturbances
    for c in dist:
        if isinstance(c, UniformCurrent):
            out += [("current", "speed_mps", src, "disturbances.current.speed", c.speed),
                    ("current", "direction_deg", src, "disturbances.current.direction", float(np.degrees(c.direction)))]
    if "rudder_offset" in d.model_fields_set:
        off = next((c.offset for c in dist if isinstance(c, RudderOffset)), 0.0)
        out.append(("rudder_offset", "offset_deg", src, "disturbances.rudder_offset", float(np.degrees(off))))
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


# --------------------------------------------------------------------------- builders

def make_trial(ship: Ship | str | Path, manoeuvre: Mapping, *, speed: str, duration: str, dt: str = "0.1 s",
               rpm: str = "solve", trim: bool = True, log: Mapping | None = None,
               disturbances: Mapping | None = None, effects: Mapping | None = None, name: str | None = None,
               description: str = "") -> Trial:
    """Build a trial in code, through the same validation as a trial YAML.

    Every dimensional value is a string with its unit, as in the YAML (``"10 kn"``,
    ``"20 deg"``, ``"3000 s"``).  Plain numbers are refused (is ``20`` degrees or
    radians?) with :class:`mmg.errors.InputError`, and so are units of the wrong kind
    (``rudder="20 m"``).

    Parameters
    ----------
    ship : Ship, str or os.PathLike
        A :class:`mmg.ship.Ship`, a bundled ship name (``"esso_osaka"``) or a ship YAML path
        (relative to the working directory).
    manoeuvre : mapping
        The YAML's ``manoeuvre:`` section, e.g. ``{"kind": "sine", "amplitude": "35 deg",
        "period": "600 s"}``.
    speed : str
        Approach speed, e.g. ``"10 kn"``.
    duration : str
        Simulated time, e.g. ``"3000 s"``.
    dt : str, default "0.1 s"
        Integration step.
    rpm : str, default "solve"
        Approach propeller speed (``"54 rpm"``) or ``"solve"``: the rpm that holds ``speed``.
    trim : bool, default True
        Start from the trim rudder and drift that cancel the ship's Y_0, N_0.
    log : mapping, optional
        The YAML's ``log:`` section (``interval``, ``seed``, ``start_lat``, ``noise``, ``bias``).
    disturbances : mapping, optional
        The YAML's ``disturbances:`` section (``current``, ``rudder_offset``).
    effects : mapping, optional
        The YAML's ``effects:`` section, ``{name: {parameter: value}}`` of :mod:`mmg.effects`,
        e.g. ``{"wind": {"true_speed_mps": 10, "true_from_deg": 45}}``.
    name : str, optional
        The trial's name; default from the manoeuvre.
    description : str, default ""

    Returns
    -------
    Trial

    Raises
    ------
    mmg.errors.InputError
        A missing or invalid field, a wrong unit, a rudder beyond the steering gear limit.
    """
    if not isinstance(manoeuvre, Mapping) or "kind" not in manoeuvre:
        raise InputError("make_trial", "manoeuvre", "expected a mapping with a 'kind'")
    kind = str(manoeuvre["kind"])
    data = {"name": name or _default_name(manoeuvre), "description": description,
            "approach": {"speed": speed, "rpm": rpm, "trim": trim},
            "duration": duration, "dt": dt, "manoeuvre": dict(manoeuvre)}
    if log is not None:
        data["log"] = dict(log)
    if disturbances is not None:
        data["disturbances"] = dict(disturbances)
    if effects is not None:
        data["effects"] = {k: (dict(v) if isinstance(v, Mapping) else v) for k, v in dict(effects).items()}
    if isinstance(ship, Ship):
        return trial_from_dict(data, source=f"<{kind}>", ship=ship)
    if not isinstance(ship, (str, os.PathLike)):
        raise InputError(f"<{kind}>", "ship", f"expected a Ship, a bundled ship name or a path, got {type(ship).__name__}")
    data["ship"] = os.fspath(ship)
    return trial_from_dict(data, source=f"<{kind}>")


def _default_name(m: Mapping) -> str:
    k = m.get("kind")
    if k == "zigzag":
        return f"zigzag {m.get('rudder')}/{m.get('heading')}"
    if k == "turning":
        return f"turning {m.get('rudder')}"
    if k == "stype":
        return f"S-type {m.get('switch_heading')}"
    if k in ("sine", "sawtooth"):
        return f"{k} {m.get('amplitude')}, {m.get('period')}"
    return str(k)


def zigzag(ship: Ship | str | Path, *, rudder: str, heading: str | None = None, speed: str, duration: str,
           first: str = "starboard", **kw) -> Trial:
    """A zigzag trial: rudder to ``rudder`` until the heading has changed by ``heading``, reverse.

    Parameters
    ----------
    ship : Ship, str or os.PathLike
        A Ship, a bundled ship name or a ship YAML path.
    rudder : str
        Rudder angle, e.g. ``"20 deg"``.
    heading : str, optional
        Heading change at which the rudder is reversed; default ``rudder`` (a 20/20 zigzag).
    speed, duration : str
        Approach speed (``"10 kn"``) and simulated time (``"3000 s"``).
    first : {"starboard", "port"}, default "starboard"
        The side of the first rudder order.
    **kw
        ``dt``, ``rpm``, ``trim``, ``log``, ``disturbances``, ``effects``, ``name``, ``description`` of
        :func:`make_trial`.

    Returns
    -------
    Trial

    Examples
    --------
    >>> zz = zigzag("esso_osaka", rudder="20 deg", heading="20 deg", speed="10 kn", duration="3000 s")
    """
    man = {"kind": "zigzag", "rudder": rudder, "heading": rudder if heading is None else heading, "first": first}
    return make_trial(ship, man, speed=speed, duration=duration, **kw)


def turning(ship: Ship | str | Path, *, rudder: str, speed: str, duration: str, execute: str = "0 s",
            **kw) -> Trial:
    """A turning circle: hold ``rudder`` (signed, + starboard) from ``execute`` on.

    Parameters
    ----------
    ship : Ship, str or os.PathLike
        A Ship, a bundled ship name or a ship YAML path.
    rudder : str
        Rudder angle, + starboard, e.g. ``"35 deg"`` or ``"-35 deg"``.
    speed, duration : str
        Approach speed and simulated time.
    execute : str, default "0 s"
        When the rudder order is given.
    **kw
        See :func:`make_trial`.

    Returns
    -------
    Trial
    """
    return make_trial(ship, {"kind": "turning", "rudder": rudder, "execute": execute},
                      speed=speed, duration=duration, **kw)


def stype(ship: Ship | str | Path, *, rudder: str, switch_heading: str, speed: str, duration: str,
          first: str = "starboard", **kw) -> Trial:
    """An S-type trial (Rhee & Kim section 6.1): reverse at ``switch_heading`` and back at 0.

    Parameters
    ----------
    ship : Ship, str or os.PathLike
    rudder, switch_heading : str
        Rudder angle and switching heading change psi_S, e.g. ``"35 deg"``, ``"120 deg"``.
    speed, duration : str
    first : {"starboard", "port"}, default "starboard"
    **kw
        See :func:`make_trial`.

    Returns
    -------
    Trial
    """
    man = {"kind": "stype", "rudder": rudder, "switch_heading": switch_heading, "first": first}
    return make_trial(ship, man, speed=speed, duration=duration, **kw)


def schedule(ship: Ship | str | Path, *, table=None, file: str | Path | None = None, speed: str,
             duration: str, **kw) -> Trial:
    """A scheduled rudder (and rpm) order, linearly interpolated.

    Parameters
    ----------
    ship : Ship, str or os.PathLike
    table : array_like, optional
        Rows of ``[time_s, rudder_deg]`` or ``[time_s, rudder_deg, rpm]`` (plain numbers in the
        units the column names say, as in the YAML).
    file : path, optional
        A CSV with columns ``time_s, rudder_deg[, rpm]`` instead of ``table``.
    speed, duration : str
    **kw
        See :func:`make_trial`.

    Returns
    -------
    Trial
    """
    man: dict = {"kind": "schedule"}
    if table is not None:
        man["table"] = np.asarray(table, dtype=float).tolist()
    if file is not None:
        man["file"] = os.fspath(file)
    return make_trial(ship, man, speed=speed, duration=duration, **kw)


def stopping(ship: Ship | str | Path, *, speed: str, duration: str, astern_ratio: float = ASTERN_RPM_RATIO,
             reversal: str | None = None, rudder: str = "0 deg", execute: str = "0 s", **kw) -> Trial:
    """A full-astern stopping trial (IMO MSC.137(76) 5.3.4): the revolutions ordered astern, the rudder held.

    Parameters
    ----------
    ship : Ship, str or os.PathLike
    speed, duration : str
        Approach speed (``"10 kn"``) and the longest simulated time (the run ends when the ship is stopped).
    astern_ratio : float, default :data:`mmg.engine_order.ASTERN_RPM_RATIO`
        Full-astern revolutions over the approach ones.
    reversal : str, optional
        Duration of the linear ramp from the approach revolutions to the full-astern ones; default
        :func:`mmg.engine_order.reversal_time` of the ship (120 s at full scale, 120 / sqrt(lambda) s on a
        model of scale lambda: its config's ``full_scale:`` section).
    rudder : str, default "0 deg"
        Rudder held through the test (midships).
    execute : str, default "0 s"
        When the astern order is given.
    **kw
        See :func:`make_trial`.

    Returns
    -------
    Trial
    """
    man = {"kind": "stopping", "rudder": rudder, "astern_ratio": float(astern_ratio), "execute": execute}
    if reversal is not None:
        man["reversal"] = reversal
    return make_trial(ship, man, speed=speed, duration=duration, **kw)


def degrees(x: float) -> float:
    """rad -> deg (for reports)."""
    return x / DEG

