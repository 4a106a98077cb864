"""Rebuilding the rudder of a logged trial from the trial logic written in its header.

The law itself lives in :mod:`mmg.rudder` (one definition for the simulator and every
estimator); this module reads the log header (kind, rudder, switching heading, steering
gear) that tells which law and constants to apply.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from mmg.errors import InputError
from mmg.model import N_PARAMS, P_DMAX, P_RATE, P_TE
from mmg.rudder import REBUILT_KINDS, reconstruct_rudder
from mmg.units import DEG

from .records import TrialRecord


def manoeuvre_from_meta(meta: dict, source: str = "log") -> tuple[str, dict]:
    """The trial kind and its rudder logic (SI) from a log header."""
    kind = str(meta.get("kind", ""))
    if kind not in REBUILT_KINDS:
        raise InputError(source, "rudder_deg", f"missing column, and the log's header gives no turning/zigzag/stype "
                                               f"trial kind to rebuild the rudder from (kind: {kind or 'missing'})")
    try:
        m = {"rudder": float(meta["rudder_deg"]) * DEG, "first": str(meta.get("first", "starboard"))}
        if kind == "zigzag":
            m["heading"] = float(meta["heading_deg"]) * DEG
        elif kind == "stype":
            m["switch_heading"] = float(meta["switch_heading_deg"]) * DEG
    except KeyError as e:
        raise InputError(source, str(e.args[0]), "missing from the log header; needed to rebuild the rudder") from None
    return kind, m


def steering_from_meta(meta: dict, source: str = "log") -> np.ndarray:
    """A parameter vector holding the steering gear constants written in a log header."""
    p = np.zeros(N_PARAMS)
    try:
        p[P_TE] = float(meta["steering_T_E_s"])
        p[P_RATE] = float(meta["steering_rate_deg_s"]) * DEG
        p[P_DMAX] = float(meta["steering_delta_max_deg"]) * DEG
    except KeyError as e:
        raise InputError(source, str(e.args[0]), "missing from the log header; needed to rebuild the rudder") from None
    return p


def with_rebuilt_rudder(rec: TrialRecord, dt: float = 0.1) -> TrialRecord:
    """The record on a ``dt`` grid with the rudder rebuilt from the trial logic in its header.

    Heading (and the other channels) are interpolated by cubic splines through the log
    samples; the rudder order follows the trial's law on the interpolated heading and the
    rudder angle follows the steering gear, starting from the header's trim rudder.
    """
    from scipy.interpolate import CubicSpline

    from .logio import missing_channel

    kind = str(rec.meta.get("kind", ""))
    if kind not in REBUILT_KINDS:
        raise missing_channel(rec, "delta", f"no rudder angle, and no turning/zigzag/stype trial kind in a header to "
                                            f"rebuild it from (kind: {kind or 'missing'})")
    src = rec.source or "log"
    if rec.psi is None:
        raise missing_channel(rec, "psi", "a rudder can only be rebuilt from a heading channel")
    kind, man = manoeuvre_from_meta(rec.meta, src)
    p = steering_from_meta(rec.meta, src)
    t = np.arange(rec.t[0], rec.t[-1] + 1e-9, dt)
    kw = {"t": t}
    for c in rec.channels():
        kw[c] = CubicSpline(rec.t, getattr(rec, c))(t)
    order, delta = reconstruct_rudder(t, kw["psi"], kind, man, p, float(rec.meta.get("trim_rudder_deg", 0.0)) * DEG)
    kw["delta"] = delta
    return replace(rec, **kw, meta={**rec.meta, "delta_order": order, "rudder": "rebuilt from the trial logic"})
