"""Replay a measured record against its own rudder and propeller history (``mmg predict``).

:func:`replay_record` simulates one record open-loop from its first measured state (or from a
start time) with its measured rudder angle and propeller revolutions prescribed
(:mod:`mmg.replay`: steering gear and engine bypassed) and, when the ship config switches wind
on and the record has the relative-wind channels, the wind loads of :mod:`mmg.wind` from the
measured relative wind.  It reads every record :func:`trials.files.logio.read_record` reads:

* FRT-DS-ESSO files (model or full scale, checked against the ship's length): u, v, r, x, y,
  heading, rudder, revolutions and wind all logged;
* project truth files: the same channels, no wind;
* project sea-trial logs (position, heading, speed, rpm): the rudder is rebuilt from the
  header's trial logic (:func:`trials.files.rudder.with_rebuilt_rudder`), the initial yaw rate from
  the heading and the initial sway velocity taken as zero.

Each run is scored by the RMS differences over the record of heading [deg], yaw rate [deg/s]
and speed [m/s] and by the final position error [m and ship lengths] (:meth:`Replayed.scores`).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from mmg.errors import InputError
from mmg.model import pack
from mmg.replay import STATE, ReplayInputs, replay_states
from mmg.ship import Ship

from ..files.records import WIND_CHANNELS, TrialRecord

__all__ = ["MeasuredRun", "Replayed", "Prediction", "measured_run", "replay_record", "predict", "run_effects",
           "SCORE_KEYS"]

_log = logging.getLogger(__name__)

SCORE_KEYS = ("heading_rms_deg", "yaw_rate_rms_degps", "speed_rms_mps", "final_position_error_m", "final_position_error_L")
"""Keys of :meth:`Replayed.scores`, as ``mmg predict`` writes them for each run."""


@dataclass(frozen=True)
class MeasuredRun:
    """A record made ready for replay: the measured states and the prescribed inputs.

    Parameters
    ----------
    name, source : str
        The record's name and file.
    meas : ndarray (N, 6)
        Measured u, v [m/s], r [rad/s], x, y [m], psi [rad] (:data:`mmg.replay.STATE`) at ``inputs.t``.
    inputs : ReplayInputs
        Rudder [rad], revolutions [rps], external (wind) loads [N, N, N m].
    wind : str
        ``"on"`` (wind loads from the measured relative wind), ``"off"`` (the ship config has it
        off) or why it is not applied (``"no wind channels"``).
    notes : list of str
        How channels the record lacks were made up (rebuilt rudder, zero sway, ...).
    effects : mmg.effects.EffectSet or None
        The ship config's effects the replay applies besides the measured-wind loads (a current,
        a rudder offset, a heading bias, shallow water, a steady wind): in the packed ship, the
        replay's start state (:meth:`~mmg.effects.EffectSet.to_model`) and its output
        (:meth:`~mmg.effects.EffectSet.to_logged`).
    speed_only : bool
        The record logs the speed over ground, not u and v (``meas`` u is that speed, v zero):
        fits compare the predicted speed over ground with it and leave v out
        (:attr:`ekf.identify.Segmented.speed_only`).
    """

    name: str
    source: str
    meas: np.ndarray
    inputs: ReplayInputs
    wind: str = "off"
    notes: list = field(default_factory=list)
    effects: object = None
    speed_only: bool = False

    @property
    def t(self) -> np.ndarray:
        return self.inputs.t


def run_effects(ship: Ship, wind: bool | None = None):
    """The ship config's effects (:attr:`mmg.ship.Ship.effects`) with the wind switched as ``wind``
    says (None: as the config has it; True: on, at the config's scale; False: off)."""
    import mmg.effects as E

    es = ship.effect_set()
    if wind is None:
        return es
    if not wind:
        return es.without("wind")
    if ship.wind is None:
        raise InputError(ship.source or ship.name, "wind", "wind was asked for but the ship config has no wind section")
    if es.get("wind") is None:
        es = es.merged(E.effect_set({"wind": ship.wind.values()}))
    return es


def _wind_loads(ship: Ship, rec: TrialRecord, es) -> tuple[np.ndarray | None, str]:
    """Wind loads [N, N, N m] from the record's measured relative wind, and what was done."""
    from mmg.effects import Wind

    w = es.get("wind")
    if w is None:
        return None, "off"
    if Wind.steady(w):
        return None, f"steady {w['true_speed_mps']:g} m/s from {w['true_from_deg']:g} deg (config)"
    from ..files.logio import require_finite

    require_finite(rec, ("wind_speed_rel", "wind_dir_rel"), "the replay with the measured wind")
    from mmg.effects import Context

    ctx = Context(t=np.asarray(rec.t, float), delta=rec.delta, n=rec.n, ship=ship,
                  channels={c: getattr(rec, c) for c in ("wind_speed_rel", "wind_dir_rel")})
    return Wind.external(w, ctx), "on"                 # the wind effect's loads, defined once


def measured_run(ship: Ship, rec: TrialRecord, start: float | None = None, wind: bool | None = None) -> MeasuredRun:
    """The record as measured states and prescribed inputs (see the module docstring).

    Parameters
    ----------
    ship : Ship
    rec : TrialRecord
    start : float, optional
        Start time [s] of the replay; the record's first sample when omitted.
    wind : bool, optional
        Apply the wind loads; default: as the ship config says (``ship.wind.enabled``).
    """
    from ..files.logio import require_finite

    notes = []
    src = rec.source or rec.name
    require_finite(rec, ("x", "y", "psi", "U", "u", "v", "r", "delta", "n"), "the replay")
    if rec.delta is None:
        from ..files.rudder import with_rebuilt_rudder

        rec = with_rebuilt_rudder(rec, dt=min(0.5, float(np.median(np.diff(rec.t)))))
        notes.append("rudder rebuilt from the header's trial logic")
    if start is not None:
        if not rec.t[0] <= start < rec.t[-1]:
            raise InputError(src, "--start", f"{start:g} s is outside the record ({rec.t[0]:g} to {rec.t[-1]:g} s)")
        rec = rec.slice_time(start, np.inf)
    if len(rec.t) < 3:
        raise InputError(src, "t", "fewer than 3 samples to replay")
    if rec.n is None:
        raise InputError(src, "n", "no propeller revolutions channel: the replay needs n(t)")
    for c in ("x", "y", "psi"):
        if getattr(rec, c) is None:
            raise InputError(src, c, "missing channel: the replay is scored against the track and heading")
    r = rec.r if rec.r is not None else np.gradient(rec.psi, rec.t)
    if rec.r is None:
        notes.append("yaw rate from the heading")
    if rec.u is not None and rec.v is not None:
        u, v = rec.u, rec.v
    else:
        u, v = rec.speed(), np.zeros_like(rec.t)
        notes.append("u taken as the speed over ground, v as zero (the record has no u, v); "
                     "fits compare the predicted speed over ground with it and leave v out")
    meas = np.column_stack([u, v, r, rec.x, rec.y, rec.psi]).astype(float)
    es, skipped = run_effects(ship, wind).usable({c: getattr(rec, c) for c in WIND_CHANNELS})
    for name, why in skipped:                        # one rule for every command (EffectSet.usable)
        notes.append(f"{name} skipped: {why}")
        _log.warning(f"{src}: {name} skipped: {why}")
    ext, w = _wind_loads(ship, rec, es)
    if "wind" in dict(skipped):
        w = "no wind channels"
    if ext is not None:
        es = es.without("wind")                      # in the loads already
    return MeasuredRun(name=rec.name, source=rec.source, meas=meas,
                       inputs=ReplayInputs(t=np.asarray(rec.t, float), delta=np.asarray(rec.delta, float),
                                           n=np.asarray(rec.n, float), ext=ext), wind=w, notes=notes,
                       effects=es if es.items else None, speed_only=rec.u is None or rec.v is None)


@dataclass(frozen=True)
class Replayed:
    """One record replayed: measured and predicted states.

    Attributes
    ----------
    run : MeasuredRun
    pred : ndarray (N, 6)
        Predicted u, v, r, x, y, psi (:data:`mmg.replay.STATE`).
    L, B : float
        Ship length and beam [m] (scores in ship lengths, outlines in plots).
    """

    run: MeasuredRun
    pred: np.ndarray
    L: float
    B: float

    @cached_property
    def diverged_at(self) -> float | None:
        """Time [s] of the first predicted sample that is not finite (the replay diverged there and
        :meth:`scores` are NaN), or None when the whole record replayed."""
        bad = ~np.isfinite(self.pred).all(axis=1)
        return float(self.run.t[np.argmax(bad)]) if bad.any() else None

    @cached_property
    def divergence(self) -> dict | None:
        """Where the replay diverged, as a finding: ``{"t_s": time [s] of the first non-finite predicted
        sample, "last_t_s": the last finite sample's time [s] (None when the first is not finite),
        "last_state": that sample's predicted u, v [m/s], r [rad/s], x, y [m], psi [rad] by name
        (:data:`mmg.replay.STATE`), "measured_state": the measured state there}``; None when the whole
        record replayed.  :meth:`scores` are NaN over a window the divergence falls in: read this too."""
        if self.diverged_at is None:
            return None
        i = int(np.argmax(~np.isfinite(self.pred).all(axis=1)))
        j = i - 1 if i > 0 else None
        state = (lambda row: {c: float(x) for c, x in zip(STATE, row)})   # noqa: E731
        return {"t_s": float(self.run.t[i]), "last_t_s": None if j is None else float(self.run.t[j]),
                "last_state": None if j is None else state(self.pred[j]),
                "measured_state": state(self.run.meas[i])}

    def scores(self, until_s: float | None = None) -> dict:
        """RMS over the record of heading [deg], yaw rate [deg/s], speed [m/s]; final position
        error [m] and [L] (keys :data:`SCORE_KEYS`); NaN where the replay diverged (within the window:
        :attr:`divergence` says where).  ``until_s``: only the first ``until_s`` seconds from the
        record's first sample (the final position error is then the one at the window's end)."""
        m, p = self.run.meas, self.pred
        if until_s is not None:
            keep = self.run.t <= self.run.t[0] + float(until_s) + 1e-9
            m, p = m[keep], p[keep]
        if not np.isfinite(p).all():
            return dict.fromkeys(SCORE_KEYS, float("nan"))
        dpsi = np.degrees(p[:, 5] - m[:, 5])
        dr = np.degrees(p[:, 2] - m[:, 2])
        dU = np.hypot(p[:, 0], p[:, 1]) - np.hypot(m[:, 0], m[:, 1])
        e = float(np.hypot(p[-1, 3] - m[-1, 3], p[-1, 4] - m[-1, 4]))
        rms = lambda a: float(np.sqrt(np.mean(a * a)))  # noqa: E731
        return {"heading_rms_deg": rms(dpsi), "yaw_rate_rms_degps": rms(dr), "speed_rms_mps": rms(dU),
                "final_position_error_m": e, "final_position_error_L": e / self.L}

    def to_pandas(self):
        """Measured and predicted states against time [s] (columns ``u_meas``, ``u_pred``, ...; SI)."""
        import pandas as pd

        d = {"delta": self.run.inputs.delta, "n": self.run.inputs.n}
        for j, c in enumerate(STATE):
            d[f"{c}_meas"] = self.run.meas[:, j]
            d[f"{c}_pred"] = self.pred[:, j]
        return pd.DataFrame(d, index=pd.Index(self.run.t, name="t"))

    def plot(self, pyplot: bool = True):
        """Track (ship outlines) and time histories, measured against predicted; returns the figure."""
        from .predict_plots import replay_figure

        return replay_figure(self, pyplot=pyplot)


def replay_record(ship: Ship, rec: TrialRecord | MeasuredRun, start: float | None = None,
                  wind: bool | None = None, packed=None) -> Replayed:
    """Replay one record open-loop from its first measured state (see the module docstring).

    Parameters
    ----------
    ship : Ship
    rec : TrialRecord or MeasuredRun
    start : float, optional
        Start time [s]; the first sample when omitted.
    wind : bool, optional
        Override the ship config's wind switch.
    packed : PackedShip, optional
        The ship already packed (a candidate's coefficients); ``pack(ship)`` when omitted.

    Returns
    -------
    Replayed
    """
    run = rec if isinstance(rec, MeasuredRun) else measured_run(ship, rec, start, wind)
    packed = packed or pack(ship)
    es = run.effects
    if es is None:
        pred = replay_states(packed, run.inputs, run.meas[0])
    else:
        from ekf.identify import model_states

        start = model_states(es, run.meas[:1], run.speed_only)[0]
        pred = es.to_logged(replay_states(es.pack(packed, ship), run.inputs, start))
    return Replayed(run=run, pred=pred, L=ship.particulars.L, B=ship.particulars.B)


@dataclass(frozen=True)
class Prediction:
    """Several records replayed with one ship: :attr:`runs` in the order given; :attr:`windows`, when
    made (:func:`trials.measured.window.with_windows`), each run's short-horizon scores
    (:class:`trials.measured.window.WindowScores`), in the same order."""

    runs: list
    windows: list | None = None

    def to_json(self, horizon_s: float | None = None) -> dict:
        """``{"runs": [{"name": ..., "file": ..., "heading_rms_deg": ..., ...}, ...]}`` (``mmg predict --json``;
        ``name``: the run's name, after its file, as printed and as its plot is named).  With
        ``horizon_s`` each run also has ``"first": {"horizon_s": ..., <the same scores over the first
        horizon_s seconds>}`` (:meth:`Replayed.scores` ``until_s``: a short-horizon figure); with
        :attr:`windows`, ``"window"``: the means over the windows restarted from the measured state
        (:meth:`trials.measured.window.WindowScores.to_json`)."""
        def row(k, r):
            d = {"name": r.run.name, "file": r.run.source, **r.scores()}
            if horizon_s is not None:
                d["first"] = {"horizon_s": float(horizon_s), **r.scores(until_s=horizon_s)}
            if self.windows is not None:
                d["window"] = self.windows[k].to_json()
            return d

        return {"runs": [row(k, r) for k, r in enumerate(self.runs)]}

    def to_pandas(self):
        """One row of scores per run, indexed by the run's name (after its file: unique)."""
        import pandas as pd

        return pd.DataFrame([{"name": r.run.name, "wind": r.run.wind, **r.scores()} for r in self.runs]).set_index("name")


def predict(ship: Ship, paths, start: float | None = None, wind: bool | None = None, progress=None) -> Prediction:
    """Read and replay each record of ``paths`` (:func:`replay_record`); a bad record raises
    :class:`~mmg.errors.InputError` naming it.  Every record is read and made ready
    (:func:`measured_run`: channels, ``start``, wind) before the first is replayed, so a bad one
    is refused before any work.

    Parameters
    ----------
    ship : Ship
    paths : sequence of str or Path
        Records (FRT-DS-ESSO CSVs, project logs, truth files).
    start : float, optional
        Start time [s] of every replay.
    wind : bool, optional
        Override the ship config's wind switch.
    progress : callable, optional
        ``progress(i, n, name)`` after each replay (the run's name, after its file).

    Returns
    -------
    Prediction
        Each run named after its file (:func:`trials.files.output.record_labels`: ``ST35`` for
        ``ST35.csv``; two files of one stem as ``day1/ST35``, ``day2/ST35``).
    """
    from dataclasses import replace

    from ..files.output import record_labels
    from ..files.shipcheck import read_for_ship

    paths = list(paths)
    # a record of another ship: refused, not replayed as this one
    measured = [replace(measured_run(ship, read_for_ship(path, ship), start, wind), name=label)
                for path, label in zip(paths, record_labels(paths))]
    packed = pack(ship)
    runs = []
    for i, run in enumerate(measured):
        runs.append(replay_record(ship, run, packed=packed))
        if progress:
            progress(i + 1, len(paths), run.name)
    return Prediction(runs=runs)
