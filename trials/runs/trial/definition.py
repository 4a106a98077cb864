"""The validated trial in SI units: :class:`Trial` (the manoeuvre, the approach, the integration, the
log and the effects, with what the simulator asks of them), :class:`LogSpec` (how the sea-trial log
is recorded) with its :class:`SensorBias`, and :func:`periodic_order`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from mmg.engine_order import AsternOrder
from mmg.errors import InputError
from mmg.integrate import CommandLaw
from mmg.limits import check_steps
from mmg.ship import Ship
from mmg.units import DEG, is_finite_number


@dataclass(frozen=True)
class SensorBias:
    """Constant bias of logged channels: heading [rad], speed [m/s], rpm [rps] (finite numbers).

    It acts on the written log only; the heading part is the ``heading_bias`` effect
    (:class:`mmg.effects.HeadingBias`) of the logged heading (:meth:`Trial.logged_effects`)."""

    heading: float = 0.0
    speed: float = 0.0
    rpm: float = 0.0

    def __post_init__(self):
        for name in ("heading", "speed", "rpm"):
            v = getattr(self, name)
            if not is_finite_number(v):
                raise InputError("SensorBias", name, f"must be a finite number, got {v!r:.40}")


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
    effects : mmg.effects.EffectSet or None
        The trial's effects (:mod:`mmg.effects`: ``current``, ``wind``, ``rudder_offset``,
        ``heading_bias``, ``shallow_water``): its ``effects:`` section with the current and rudder
        offset of its ``disturbances:`` section, added to the ship's own effects
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
        c = self.effect_set().get("current")
        if c is not None:
            return c["speed_mps"], float(np.radians(c["direction_deg"]))
        return 0.0, 0.0

    def logged_effects(self):
        """Every effect of the run as the log sees it: :meth:`effect_set` plus ``log.bias.heading`` as
        the ``heading_bias`` effect."""
        from mmg.effects import EffectSet, HeadingBias

        es = self.effect_set()
        if self.log.bias.heading and es.get("heading_bias") is None:
            es = es.merged(EffectSet(((HeadingBias, {"bias_deg": math.degrees(self.log.bias.heading)}),)))
        return es

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
