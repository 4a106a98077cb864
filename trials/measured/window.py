"""Short-horizon prediction: a record replayed from its measured state over windows restarted along it.

The whole-record open-loop score of :func:`trials.measured.predict.replay_record` mostly measures when
the replay first loses the ship: a heading error made early is carried, and grows, to the end.  The
figure here is the one of a pilot's or a system-identification look-ahead: from the measured state at
t0, t0 + every, t0 + 2 every, ... the model predicts the next ``window_s`` seconds with the record's
measured rudder, revolutions and wind (as :func:`~trials.measured.predict.replay_record` does: the
ship's effects and the run's wind loads, scaled as the run carries them), and each window is scored
by its heading RMS [deg] and its final position error [m, L] against the record.

Windows (:func:`window_bounds`): the k-th starts at the nominal time t0 + k ``every_s`` and holds the
samples up to ``window_s`` seconds later; only windows of their full length are scored, so a record of
length T gives floor((T - window_s) / every_s) + 1 of them.  A record shorter than one window gives one
window of its own length (:attr:`WindowScores.short` says so).  Windows overlap when ``every_s`` <
``window_s``, so each is replayed on its own (the multiple shooting of
:func:`mmg.replay.replay_states` with ``reset`` restarts non-overlapping segments in one call, and a
segment that diverges there leaves every later one non-finite; here it spoils only its own window).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mmg.model import pack
from mmg.replay import ReplayInputs
from mmg.ship import Ship

from .predict import MeasuredRun, Prediction, measured_run, replay_record

__all__ = ["WindowScores", "window_scores", "with_windows", "window_bounds", "WINDOW_S", "EVERY_S", "WINDOW_KEYS"]

WINDOW_S = 60.0
"""Default window length [s]: a minute ahead."""
EVERY_S = 30.0
"""Default interval [s] between window starts."""
WINDOW_KEYS = ("window_s", "every_s", "n_windows", "heading_rms_deg", "position_error_m", "position_error_L")
"""Keys of :meth:`WindowScores.to_json` (``mmg predict``'s ``window`` object of each run), then
``n_diverged``."""
_TOL = 1e-6
"""Tolerance [s] on sample times at a window's edges (times logged as decimal fractions)."""


def window_bounds(t, window_s: float = WINDOW_S, every_s: float = EVERY_S) -> tuple[list[tuple[int, int]], bool]:
    """The windows of a record with sample times ``t`` [s]: ``(first, last)`` sample indices of each, and
    whether the record is shorter than one window (then one window, the whole record).

    Window k covers the samples with t0 + k every_s <= t <= t0 + k every_s + window_s (``t0 = t[0]``);
    it is kept when its nominal end is within the record and it holds 2 samples or more."""
    t = np.asarray(t, float)
    if not (np.isfinite(window_s) and window_s > 0 and np.isfinite(every_s) and every_s > 0):
        raise ValueError(f"window {window_s!r} s and every {every_s!r} s must be finite and positive")
    if t[-1] - t[0] < window_s - _TOL:
        return [(0, len(t) - 1)], True
    out = []
    n = int(np.floor((t[-1] - t[0] - window_s + _TOL) / every_s)) + 1
    for k in range(n):
        a = t[0] + k * every_s
        i0 = int(np.searchsorted(t, a - _TOL, side="left"))
        i1 = int(np.searchsorted(t, a + window_s + _TOL, side="right")) - 1
        if i1 > i0:
            out.append((i0, i1))
    return out, False


def _window_run(run: MeasuredRun, i0: int, i1: int) -> MeasuredRun:
    """``run`` cut to samples ``i0`` .. ``i1`` (its measured states, inputs and wind loads)."""
    s = slice(i0, i1 + 1)
    inp = run.inputs
    return replace(run, meas=run.meas[s], inputs=ReplayInputs(
        t=inp.t[s], delta=inp.delta[s], n=inp.n[s], ext=None if inp.ext is None else inp.ext[s]))


@dataclass(frozen=True)
class WindowScores:
    """A record's short-horizon scores (:func:`window_scores`): one entry per window.

    Attributes
    ----------
    name : str
        The record's name.
    window_s, every_s : float
        Window length and interval between starts [s] asked for.
    start_s, end_s : ndarray
        Each window's first and last sample time [s].
    heading_rms_deg : ndarray
        Heading RMS over each window's samples [deg] (NaN where its replay diverged).
    position_error_m, position_error_L : ndarray
        Distance between the predicted and the measured position at each window's last sample [m], [L].
    short : bool
        The record is shorter than one window: one window of the record's length.
    """

    name: str
    window_s: float
    every_s: float
    start_s: np.ndarray
    end_s: np.ndarray
    heading_rms_deg: np.ndarray
    position_error_m: np.ndarray
    position_error_L: np.ndarray
    short: bool = False

    @property
    def n_windows(self) -> int:
        return len(self.start_s)

    @property
    def n_diverged(self) -> int:
        """Windows whose replay went non-finite (left out of the means)."""
        return int(np.sum(~np.isfinite(self.heading_rms_deg)))

    def mean(self, key: str) -> float:
        """Mean over the windows that stayed finite of ``heading_rms_deg``, ``position_error_m`` or
        ``position_error_L``; NaN when none did."""
        v = np.asarray(getattr(self, key), float)
        v = v[np.isfinite(v)]
        return float(v.mean()) if len(v) else float("nan")

    def to_json(self) -> dict:
        """``{"window_s", "every_s", "n_windows", "heading_rms_deg", "position_error_m",
        "position_error_L", "n_diverged"}``: the means over the windows (:meth:`mean`) [deg, m, L]; the
        window's actual length when the record is shorter than one (``short``)."""
        span = float(self.end_s[0] - self.start_s[0]) if self.short else float(self.window_s)
        return {"window_s": span, "every_s": float(self.every_s), "n_windows": self.n_windows,
                **{k: self.mean(k) for k in WINDOW_KEYS[3:]}, "n_diverged": self.n_diverged}

    def to_pandas(self):
        """One row per window: ``start_s``, ``end_s``, ``heading_rms_deg``, ``position_error_m``, ``position_error_L``."""
        import pandas as pd

        return pd.DataFrame({k: getattr(self, k) for k in ("start_s", "end_s", "heading_rms_deg", "position_error_m",
                                                            "position_error_L")})

    def text(self) -> str:
        """One line: the means with their units, the windows they are over."""
        j = self.to_json()
        what = (f"1 window of the whole {j['window_s']:.4g} s (the record is shorter than {self.window_s:g} s)"
                if self.short else f"{self.n_windows} windows of {self.window_s:g} s every {self.every_s:g} s")
        if self.n_diverged == self.n_windows:
            return f"{self.name}: from the measured state, {what}: every window's replay diverged (no scores)"
        div = f", {self.n_diverged} diverged (left out)" if self.n_diverged else ""
        return (f"{self.name}: from the measured state, {what}{div}: mean heading {j['heading_rms_deg']:.4g} deg RMS, "
                f"mean final position {j['position_error_m']:.4g} m ({j['position_error_L']:.4g} L)")

    def plot(self, pyplot: bool = True):
        """Each window's heading RMS [deg] and final position error [m] against its start time [s]."""
        from ..files.plots import _figure

        fig = _figure((7, 5), pyplot)
        ax1, ax2 = fig.subplots(2, 1, sharex=True)
        ax1.plot(self.start_s, self.heading_rms_deg, "o-", label=f"heading RMS over {self.window_s:g} s")
        ax2.plot(self.start_s, self.position_error_m, "s-", color="C1", label=f"position error after {self.window_s:g} s")
        ax1.set_ylabel("heading RMS (deg)")
        ax2.set_ylabel("position error (m)")
        ax2.set_xlabel("window start (s)")
        for a in (ax1, ax2):
            a.grid(True, alpha=0.3)
            a.legend(loc="best")
        ax1.set_title(f"{self.name}\nprediction from the measured state, {self.window_s:g} s windows every "
                      f"{self.every_s:g} s", fontsize=10)
        return fig


def window_scores(ship: Ship, run, window_s: float = WINDOW_S, every_s: float = EVERY_S, packed=None) -> WindowScores:
    """Replay ``run`` from its measured state at the start of each window (module docstring) and score each.

    Parameters
    ----------
    ship : Ship
        The model (its effects applied as :func:`~trials.measured.predict.replay_record` applies them).
    run : MeasuredRun or TrialRecord
        The record; a :class:`~trials.files.records.TrialRecord` is made ready with
        :func:`~trials.measured.predict.measured_run` (the ship config's wind switch).  Pass the
        ``run`` of a :class:`~trials.measured.predict.Replayed` to score windows exactly as that
        replay was made (an identified model's fitted wind scale and effects:
        :meth:`trials.measured.identify.Identification.replay`).
    window_s, every_s : float
        Window length and interval between window starts [s].
    packed : PackedShip, optional
        The ship already packed; ``pack(ship)`` when omitted.

    Returns
    -------
    WindowScores
    """
    if not isinstance(run, MeasuredRun):
        run = measured_run(ship, run)
    bounds, short = window_bounds(run.t, window_s, every_s)
    packed = packed or pack(ship)
    rows = []
    for i0, i1 in bounds:
        s = replay_record(ship, _window_run(run, i0, i1), packed=packed).scores()
        rows.append((run.t[i0], run.t[i1], s["heading_rms_deg"], s["final_position_error_m"], s["final_position_error_L"]))
    a = np.array(rows, float).reshape(-1, 5)
    return WindowScores(name=run.name, window_s=float(window_s), every_s=float(every_s), start_s=a[:, 0], end_s=a[:, 1],
                        heading_rms_deg=a[:, 2], position_error_m=a[:, 3], position_error_L=a[:, 4], short=short)


def with_windows(ship: Ship, pred: Prediction, window_s: float = WINDOW_S, every_s: float = EVERY_S) -> Prediction:
    """``pred`` (:func:`trials.measured.predict.predict` with ``ship``) with each run's :func:`window_scores`
    (:attr:`~trials.measured.predict.Prediction.windows`: its JSON's ``window``, ``mmg predict``)."""
    packed = pack(ship)
    return replace(pred, windows=[window_scores(ship, r.run, window_s, every_s, packed=packed) for r in pred.runs])
