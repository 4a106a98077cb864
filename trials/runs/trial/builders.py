"""Trials made in Python rather than read from a file: :func:`make_trial` (a ship, a manoeuvre mapping and
unit strings, checked as a trial file is) and the shortcuts :func:`zigzag`, :func:`turning`, :func:`stype`,
:func:`schedule`, :func:`stopping`.
"""
from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from mmg.engine_order import ASTERN_RPM_RATIO
from mmg.errors import InputError
from mmg.ship import Ship
from mmg.units import DEG

from .definition import Trial
from .load import trial_from_dict


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
