"""Trial definitions from YAML: the manoeuvre, the approach, the log to record.

A trial file (``configs/trials/*.yaml``) names its ship file (relative to itself),
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
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal, Optional, Union

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from mmg.disturbances import RudderOffset, SensorBias, UniformCurrent
from mmg.errors import InputError
from mmg.integrate import CommandLaw
from mmg.ship import Ship, load_ship, read_yaml
from mmg.units import DEG, to_si


def _q(dimension):
    def check(v):
        to_si(v, dimension)
        return v

    return check


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _Approach(_Strict):
    speed: str
    rpm: str = "solve"
    trim: bool = True

    @field_validator("speed")
    @classmethod
    def _speed(cls, v):
        if to_si(v, "speed") <= 0:
            raise ValueError(f"approach speed must be positive, got {v!r}")
        return v

    @field_validator("rpm")
    @classmethod
    def _rpm(cls, v):
        if v != "solve" and to_si(v, "revolutions") <= 0:
            raise ValueError(f"rpm must be positive or 'solve', got {v!r}")
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


_Manoeuvre = Annotated[Union[_Turning, _Zigzag, _SType, _Periodic, _Schedule], Field(discriminator="kind")]


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
    seed: int = 0
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
    """A validated trial (SI units). ``manoeuvre`` keeps the kind and its parameters."""

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

    def command_law(self, trim_rudder: float = 0.0, psi0: float = 0.0) -> CommandLaw:
        """The compiled-loop command law for this manoeuvre (see :mod:`mmg.integrate`)."""
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
        if self.kind in ("sine", "sawtooth"):
            t = np.arange(0.0, self.duration + self.dt / 2, self.dt)
            return CommandLaw.schedule(t, periodic_order(self.kind, t, m["amplitude"], m["period"]))
        tab = m["table"]
        n = tab[:, 2] if tab.shape[1] > 2 else None
        return CommandLaw.schedule(tab[:, 0], tab[:, 1], n)

    def summary(self) -> dict:
        """Trial parameters for a log header (degrees and knots, as at the edges)."""
        out = {"trial": self.name, "kind": self.kind, "ship": self.ship.name,
               "approach_speed_kn": self.u0 * 3600 / 1852}
        for k, v in self.manoeuvre.items():
            if k in ("rudder", "heading", "switch_heading", "amplitude"):
                out[f"{k}_deg"] = v / DEG
            elif k in ("period", "execute"):
                out[f"{k}_s"] = v
            elif k == "first":
                out[k] = v
        return out


def periodic_order(kind: str, t: np.ndarray, amplitude: float, period: float) -> np.ndarray:
    """Rudder order [rad] of the sine or sawtooth manoeuvre at times ``t`` [s]."""
    if kind == "sine":
        return amplitude * np.sin(2 * np.pi * t / period)
    phase = np.mod(t / period + 0.5, 1.0)
    return amplitude * (2.0 * phase - 1.0)


def _loc(err) -> str:
    loc = [str(p) for p in err.get("loc", ())]
    # drop pydantic's union-tag element (e.g. manoeuvre.turning.rudder -> manoeuvre.rudder)
    if len(loc) > 1 and loc[0] == "manoeuvre" and loc[1] in ("turning", "zigzag", "stype", "sine", "sawtooth", "schedule"):
        loc.pop(1)
    return ".".join(loc)


def _read_table(path: Path, source: str) -> np.ndarray:
    import pandas as pd

    try:
        df = pd.read_csv(path, comment="#")
    except FileNotFoundError:
        raise InputError(source, "manoeuvre.file", f"schedule file {path} not found") from None
    need = ["time_s", "rudder_deg"]
    for c in need:
        if c not in df.columns:
            raise InputError(str(path), c, "missing column")
    cols = need + (["rpm"] if "rpm" in df.columns else [])
    return df[cols].to_numpy(dtype=float)


def load_trial(path: str | Path) -> Trial:
    """Read and validate a trial YAML (and the ship file it names)."""
    path = Path(path)
    src = str(path)
    data = read_yaml(path)
    try:
        f = _TrialFile.model_validate(data)
    except ValidationError as e:
        err = e.errors()[0]
        msg = err["msg"].removeprefix("Value error, ")
        raise InputError(src, _loc(err), msg) from None
    ship_path = (path.parent / f.ship).resolve()
    if not ship_path.exists():
        raise InputError(src, "ship", f"ship file {f.ship} not found (looked in {ship_path})")
    ship = load_ship(ship_path)
    dmax = ship.steering.delta_max
    man = f.manoeuvre.model_dump()
    kind = man.pop("kind")
    conv = {}
    for k, v in man.items():
        if k in ("rudder", "heading", "switch_heading", "amplitude"):
            conv[k] = to_si(v, "angle")
        elif k in ("period", "execute"):
            conv[k] = to_si(v, "time")
        else:
            conv[k] = v
    for k in ("rudder", "amplitude"):
        if k in conv and abs(conv[k]) > dmax + 1e-12:
            raise InputError(src, f"manoeuvre.{k}",
                             f"{man[k]} exceeds the steering gear limit of {dmax / DEG:g} deg of {ship.name}")
    for k in ("heading", "switch_heading", "period"):
        if k in conv and conv[k] <= 0:
            raise InputError(src, f"manoeuvre.{k}", f"must be positive, got {man[k]}")
    if kind == "schedule":
        if (conv.get("table") is None) == (conv.get("file") is None):
            raise InputError(src, "manoeuvre", "a schedule needs exactly one of 'table' or 'file'")
        tab = np.asarray(conv["table"], dtype=float) if conv.get("table") is not None else \
            _read_table(path.parent / conv["file"], src)
        if tab.ndim != 2 or tab.shape[1] not in (2, 3) or len(tab) < 2:
            raise InputError(src, "manoeuvre.table", "needs at least two rows of [time_s, rudder_deg(, rpm)]")
        if not np.all(np.isfinite(tab)):
            raise InputError(src, "manoeuvre.table", "contains NaN or infinite values")
        if np.any(np.diff(tab[:, 0]) <= 0):
            raise InputError(src, "manoeuvre.table", "time_s must be strictly increasing")
        if np.any(np.abs(tab[:, 1]) > dmax / DEG + 1e-9):
            raise InputError(src, "manoeuvre.table", f"rudder beyond the steering gear limit of {dmax / DEG:g} deg")
        tab = tab.copy()
        tab[:, 1] *= DEG
        if tab.shape[1] > 2:
            tab[:, 2] /= 60.0
        conv = {"table": tab}
    duration, dt = to_si(f.duration, "time"), to_si(f.dt, "time")
    if dt <= 0 or duration <= 0:
        raise InputError(src, "dt" if dt <= 0 else "duration", "must be positive")
    if dt > duration:
        raise InputError(src, "dt", "is longer than the duration")
    lg = f.log
    interval = to_si(lg.interval, "time")
    ratio = interval / dt
    if interval <= 0 or abs(ratio - round(ratio)) > 1e-6:
        raise InputError(src, "log.interval", f"must be a positive multiple of dt ({f.dt})")
    nz = lg.noise
    log = LogSpec(interval, lg.seed, to_si(lg.start_lat, "angle"), to_si(lg.start_lon, "angle"),
                  to_si(nz.lat, "angle"), to_si(nz.lon, "angle"), to_si(nz.heading, "angle"),
                  to_si(nz.speed, "speed"), to_si(nz.rpm, "revolutions"),
                  SensorBias(to_si(lg.bias.heading, "angle"), to_si(lg.bias.speed, "speed"),
                             to_si(lg.bias.rpm, "revolutions")))
    dist = []
    d = f.disturbances
    if d.current is not None:
        dist.append(UniformCurrent(to_si(d.current.speed, "speed"), to_si(d.current.direction, "angle")))
    off = to_si(d.rudder_offset, "angle")
    if off != 0.0:
        dist.append(RudderOffset(off))
    return Trial(
        name=f.name, path=src, ship=ship, ship_path=str(ship_path), description=f.description,
        u0=to_si(f.approach.speed, "speed"),
        n0=None if f.approach.rpm == "solve" else to_si(f.approach.rpm, "revolutions"),
        trim=f.approach.trim, duration=duration, dt=dt, kind=kind, manoeuvre=conv, log=log,
        disturbances=tuple(dist),
    )


def degrees(x: float) -> float:
    """rad -> deg (for reports)."""
    return x / DEG

