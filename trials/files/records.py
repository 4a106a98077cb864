"""The in-memory trial record every reader returns and every analysis consumes.

A :class:`TrialRecord` holds time series in SI units (seconds, metres, radians,
metres per second, revolutions per second).  Channels a source does not carry
are ``None``.  Heading is always unwrapped (continuous), so analyses never have
to care whether the source wrapped it to (-pi, pi] or [0, 2 pi).
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Optional

import numpy as np

CHANNELS = ("x", "y", "psi", "U", "u", "v", "r", "delta", "n")
"""Optional channels of a record, besides time ``t``.

x, y   position of midship, earth-fixed, x north and y east [m]
psi    heading, unwrapped [rad]
U      speed over ground [m/s]
u, v   surge and sway velocity at midship [m/s]
r      yaw rate [rad/s]
delta  rudder angle, positive to starboard [rad]
n      propeller revolutions [rps]
"""

WIND_CHANNELS = ("wind_speed_rel", "wind_dir_rel", "wind_speed_true", "wind_dir_true")
"""Optional wind channels, as the FRT-DS-ESSO files log them (:mod:`mmg.wind` for the conventions).

wind_speed_rel, wind_dir_rel     apparent (relative) wind at midship [m/s, rad]
wind_speed_true, wind_dir_true   true wind [m/s, rad]
"""


@dataclass(frozen=True)
class TrialRecord:
    """A manoeuvre as recorded: time plus whichever channels the source had.

    Parameters
    ----------
    t : ndarray
        Time [s], strictly increasing.
    name : str
        Trial name (e.g. ``"zz10"`` or the source file's stem).
    ship : str
        Ship name.
    source : str
        Where it came from (file path, or ``"simulation"``).
    x, y, psi, U, u, v, r, delta, n : ndarray or None
        Channels, see :data:`CHANNELS`.
    wind_speed_rel, wind_dir_rel, wind_speed_true, wind_dir_true : ndarray or None
        Wind channels, see :data:`WIND_CHANNELS`.
    meta : dict
        Free-form metadata (seed, start position, trial kind, ...).
    """

    t: np.ndarray
    name: str = ""
    ship: str = ""
    source: str = ""
    x: Optional[np.ndarray] = None
    y: Optional[np.ndarray] = None
    psi: Optional[np.ndarray] = None
    U: Optional[np.ndarray] = None
    u: Optional[np.ndarray] = None
    v: Optional[np.ndarray] = None
    r: Optional[np.ndarray] = None
    delta: Optional[np.ndarray] = None
    n: Optional[np.ndarray] = None
    wind_speed_rel: Optional[np.ndarray] = None
    wind_dir_rel: Optional[np.ndarray] = None
    wind_speed_true: Optional[np.ndarray] = None
    wind_dir_true: Optional[np.ndarray] = None
    meta: dict = field(default_factory=dict)

    def channels(self) -> tuple[str, ...]:
        """Names of the channels present in this record."""
        return tuple(c for c in CHANNELS + WIND_CHANNELS if getattr(self, c) is not None)

    def speed(self) -> np.ndarray:
        """Speed [m/s]: ``U`` if recorded, else sqrt(u^2 + v^2), else from the track."""
        if self.U is not None:
            return self.U
        if self.u is not None and self.v is not None:
            return np.hypot(self.u, self.v)
        if self.u is not None:
            return np.abs(self.u)
        if self.x is not None and self.y is not None:
            return np.hypot(np.gradient(self.x, self.t), np.gradient(self.y, self.t))
        raise ValueError(f"record {self.name!r} has no channel to compute speed from")

    def yaw_rate(self) -> np.ndarray:
        """Yaw rate [rad/s]: ``r`` if recorded, else a central difference of ``psi``."""
        if self.r is not None:
            return self.r
        if self.psi is None:
            raise ValueError(f"record {self.name!r} has neither r nor psi")
        return np.gradient(self.psi, self.t)

    def to_pandas(self):
        """The channels as a DataFrame indexed by time [s] (SI units)."""
        import pandas as pd

        data = {c: getattr(self, c) for c in self.channels()}
        return pd.DataFrame(data, index=pd.Index(self.t, name="t"))

    def slice_time(self, t0: float, t1: float) -> "TrialRecord":
        """The part of the record with t0 <= t <= t1."""
        m = (self.t >= t0) & (self.t <= t1)
        kw = {f.name: getattr(self, f.name) for f in fields(self)}
        for c in ("t",) + CHANNELS + WIND_CHANNELS:
            if kw[c] is not None:
                kw[c] = kw[c][m]
        return TrialRecord(**kw)

    def equals(self, other: "TrialRecord", rtol: float = 0.0, atol: float = 0.0) -> bool:
        """Channel-by-channel equality (within tolerances) plus same names and metadata."""
        if self.channels() != other.channels() or (self.name, self.ship) != (other.name, other.ship):
            return False
        for c in ("t",) + self.channels():
            a, b = getattr(self, c), getattr(other, c)
            if a.shape != b.shape or not np.allclose(a, b, rtol=rtol, atol=atol):
                return False
        return True


def logged_record(t, states, delta, n, effects, noise=None, rng=None, wind_rel=None, **fields) -> TrialRecord:
    """The one record generator: model states as an on-board system logs them, with hidden effects.

    ``states`` (N, 6) model u, v, r, x, y, psi (:data:`mmg.replay.STATE`) become the logged ones through
    ``effects`` (:meth:`mmg.effects.EffectSet.to_logged`: u, v over ground resolved in the logged
    heading, the heading with its bias), plus white noise of std ``noise`` (6 values; none when None)
    drawn from ``rng``; with ``wind_rel`` (relative speed [m/s], direction [rad], dataset convention)
    the relative and true wind channels (the true wind from the relative one and the motion over
    ground).  Used by :meth:`trials.runs.run.TrialRun.record` and :func:`trials.measured.diagnose.synthetic_record`;
    ``fields`` (name, source, meta, ...) go to the :class:`TrialRecord`."""
    s = np.asarray(states, float)
    lg = effects.to_logged(s)
    if noise is not None:
        lg = lg + (rng or np.random.default_rng(0)).standard_normal(lg.shape) * np.asarray(noise, float)
    ch = {}
    if wind_rel is not None:
        from mmg.wind import true_wind_from_relative

        og = effects.without(*[e.name for e, _ in effects.items if e.kind == "measurement"]).to_logged(s)
        ch["wind_speed_rel"], ch["wind_dir_rel"] = wind_rel
        ch["wind_speed_true"], ch["wind_dir_true"] = true_wind_from_relative(ch["wind_speed_rel"], ch["wind_dir_rel"],
                                                                             og[:, 0], og[:, 1], og[:, 5])
    return TrialRecord(t=t, u=lg[:, 0], v=lg[:, 1], r=lg[:, 2], x=lg[:, 3], y=lg[:, 4], psi=lg[:, 5],
                       U=np.hypot(lg[:, 0], lg[:, 1]), delta=delta, n=n, **fields, **ch)
