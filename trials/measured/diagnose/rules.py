"""The tuned numbers of ``mmg diagnose`` (its thresholds, gates, budgets and windows), read from the packaged
``configs/calibration/diagnose_rules.yaml``, where each is written once with its unit, its meaning and where it
came from.  The environment variable ``MMG_DIAGNOSE_RULES`` names another file (a whole file, every entry).

The naming floors and residual floors are not here: they are the calibration
(:func:`trials.measured.diagnose.decision.calibration`, ``configs/calibration/diagnose.yaml``).
"""
from __future__ import annotations

import math
import os
from functools import lru_cache

from mmg.resources import config_dir

__all__ = ["ENV", "SCHEMA", "ENTRIES", "INTEGER_ENTRIES", "rules", "rule", "rules_path", "module_rule"]

ENV = "MMG_DIAGNOSE_RULES"
"""The environment variable that names a rules file in place of the packaged one."""

SCHEMA = {"bic_threshold": float, "z_threshold": float, "weak_bic": float, "r_confounded": float,
          "std_ratio_confounded": float, "confused_min": float, "unexplained_factor": float, "mismatch_z": float,
          "drift_fall_min": float, "restart_smooth": float, "segment_length": float, "stride_spacing": float,
          "screen_nfev": int, "max_nfev": int, "side_rudder_deg": float, "side_share": float,
          "straight_yaw": float, "straight_rudder_deg": float, "straight_trim_deg": float,
          "straight_min_samples": int, "straight_wind": float, "min_passing": int, "residual_quantile": float}
"""``{entry: type of its value}``: the entries a rules file holds, every one (the code reads each), the one
place the code names them; ``int``: a count, a whole number of at least 1."""

ENTRIES = tuple(SCHEMA)
"""The entries' names (:data:`SCHEMA`)."""

INTEGER_ENTRIES = tuple(name for name, kind in SCHEMA.items() if kind is int)
"""Entries whose value is a count: a whole number (:data:`SCHEMA`)."""

_TEXT = ("unit", "meaning", "source")


def rules_path():
    """The rules file in use: ``MMG_DIAGNOSE_RULES``'s, else the packaged one.

    Returns
    -------
    pathlib.Path
        The file (not checked to exist: :func:`rules` does).
    """
    from pathlib import Path

    env = os.environ.get(ENV)
    return Path(env) if env else config_dir() / "calibration" / "diagnose_rules.yaml"


@lru_cache(maxsize=1)
def rules() -> dict:
    """``{entry: value}`` of the rules file (:func:`rules_path`), read and checked once per process (clear
    with ``rules.cache_clear()``).  A file that is missing or not YAML, an entry missing, unknown, without a
    finite number as its ``value`` (a whole one for :data:`INTEGER_ENTRIES`) or without its ``unit``,
    ``meaning`` and ``source``: one-line :class:`~mmg.errors.InputError` naming the file and the entry.

    Returns
    -------
    dict
        ``{entry: value}``, every entry of :data:`ENTRIES`: an int for :data:`INTEGER_ENTRIES`, else a float,
        in the unit the file gives it.

    Raises
    ------
    mmg.errors.InputError
        The file is missing or malformed (the message names the file and the entry).
    """
    import yaml

    from mmg.errors import InputError

    p = rules_path()
    if not p.is_file():
        raise InputError(str(p), ENV, "no such diagnosis rules file")
    try:
        data = yaml.safe_load(p.read_text())
    except yaml.YAMLError as e:
        raise InputError(str(p), "", f"not a rules YAML: {str(e).splitlines()[0]}") from None
    if not isinstance(data, dict):
        raise InputError(str(p), "", "a rules file maps entry -> {value, unit, meaning, source}")
    for name in data:
        if name not in ENTRIES:
            raise InputError(str(p), str(name), f"not an entry of the diagnosis rules ({', '.join(ENTRIES)})")
    return {name: _checked(p, name, data.get(name)) for name in ENTRIES}


def _checked(p, name: str, ent):
    """The value of entry ``name`` of file ``p`` (module rules of :func:`rules`)."""
    from mmg.errors import InputError

    if ent is None:
        raise InputError(str(p), name, "missing (every entry of the diagnosis rules is needed)")
    if not isinstance(ent, dict):
        raise InputError(str(p), name, "expected {value: number, unit, meaning, source}")
    for key in _TEXT:
        if not isinstance(ent.get(key), str) or not ent[key].strip():
            raise InputError(str(p), f"{name}.{key}", "missing (a text)")
    v = ent.get("value")
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise InputError(str(p), f"{name}.value", f"{v!r} is not a finite number")
    if SCHEMA[name] is int:
        if v != int(v) or v < 1:
            raise InputError(str(p), f"{name}.value", f"{v!r} is not a whole number of at least 1")
        return int(v)
    return float(v)


def rule(name: str):
    """The value of rules entry ``name`` (:data:`ENTRIES`), from :func:`rules`.

    Parameters
    ----------
    name : str
        An entry of the rules file (e.g. ``"z_threshold"``).

    Returns
    -------
    float or int
        Its value, in the unit the file gives it.

    Raises
    ------
    KeyError
        ``name`` is not an entry.
    """
    return rules()[name]


def module_rule(module_name: str, names: dict):
    """A module ``__getattr__`` that gives the module's constant names of ``names`` ({NAME: entry}) as
    read-only views of :func:`rule`, read when asked for (a rules file named after import counts).

    Parameters
    ----------
    module_name : str
        The module's ``__name__`` (for the AttributeError of another name).
    names : dict
        ``{module constant name: rules entry}``.

    Returns
    -------
    callable
        ``__getattr__(attr)``, to be assigned as the module's ``__getattr__``.
    """
    def __getattr__(attr):
        if attr in names:
            return rule(names[attr])
        raise AttributeError(f"module {module_name!r} has no attribute {attr!r}")
    return __getattr__
