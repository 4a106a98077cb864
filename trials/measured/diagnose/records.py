"""Records for ``mmg diagnose``: read and segmented (:func:`prepare`), and made with hidden effects
(:func:`synthetic_record`, :func:`write_frt_csv`) for the trial-design advice, the tests and the
benches."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from mmg.errors import InputError
from mmg.model import G, pack
from mmg.ship import Ship

from .rules import module_rule, rule

__all__ = ["Prepared", "prepare", "absent_channels", "synthetic_record", "Manoeuvre", "RecordNoise", "write_frt_csv",
           "RESTART_SMOOTH", "leading_straight_run", "noise_level"]

_RULES = {"RESTART_SMOOTH": "restart_smooth", "STRAIGHT_YAW": "straight_yaw", "STRAIGHT_RUDDER_DEG": "straight_rudder_deg",
          "STRAIGHT_TRIM_DEG": "straight_trim_deg", "STRAIGHT_MIN_SAMPLES": "straight_min_samples",
          "STRAIGHT_WIND": "straight_wind"}
"""The module's names of numbers of the diagnosis rules (:mod:`.rules`), read-only: ``RESTART_SMOOTH``, the
window [sqrt(L/g)] of the quadratic Savitzky-Golay smoothing of the logged state every segment restarts from
(3.3 s for the 3 m model, 35 s at 325 m: a restart from one noisy sample leaves a transient through the
segment that a current or heading bias, which shift the restart states, would partly fit); and the limits of
a straight run (:func:`leading_straight_run`): ``STRAIGHT_YAW``, the largest non-dimensional yaw rate
|r| L / U of its samples; ``STRAIGHT_RUDDER_DEG``, the largest move [deg] of the rudder from its first logged
angle; ``STRAIGHT_TRIM_DEG``, the largest |first logged rudder angle| [deg] (a trim helm, not a record that
opens with the helm already over); ``STRAIGHT_MIN_SAMPLES``, its fewest samples; ``STRAIGHT_WIND``, the
largest mean relative wind speed over it as a fraction of the ship's speed (a wind sets a ship on a drift
that the model's wind loads would have to predict to a tenth of a degree)."""
__getattr__ = module_rule(__name__, _RULES)

# --------------------------------------------------------------------------- records


@dataclass
class Prepared:
    """One record made ready: the segmented record (with its effect context), notes, and the residual
    channels it does not log (:func:`absent_channels`)."""

    name: str
    source: str
    seg: object
    notes: list = field(default_factory=list)
    absent: dict = field(default_factory=dict)


def absent_channels(rec) -> dict:
    """The residual channels (u, v, r) a record does not log, and what the replay is compared with instead.

    Parameters
    ----------
    rec : TrialRecord
        The record as read.

    Returns
    -------
    dict
        ``{channel: {"column": the layout's exact header ('' when the layout has none),
        "compared_instead": what its residual compares ('' when nothing: the channel is left out)}}``.
    """
    from ...files.logio import channel_column

    out = {}
    if rec.r is None:
        out["r"] = "the yaw rate differentiated from the logged heading"
    if rec.u is None or rec.v is None:
        sog = ("the logged speed over ground" if rec.U is not None else
               "|u| as the speed over ground" if rec.u is not None else "the speed over ground from the track")
        if rec.u is None:
            out["u"] = f"the replayed speed over ground with {sog}"
        if rec.v is None:
            out["v"] = ""
    return {c: {"column": channel_column(rec, c), "compared_instead": w} for c, w in out.items()}


def prepare(ship: Ship, items, wind: bool | None = False, segment_s: float | None = None,
            straight_run: bool = True) -> list[Prepared]:
    """Read and prepare the records (paths, :class:`trials.files.records.TrialRecord` or ready
    :class:`Prepared`); a malformed one raises :class:`~mmg.errors.InputError` naming it.  Each is
    named after its file (:func:`trials.files.output.record_labels`), in the JSON and the plots.
    With ``straight_run``, a record's leading steady straight run (:func:`leading_straight_run`)
    is marked for the fit."""
    from dataclasses import replace

    from ekf.identify import Segmented, segment_resets
    from mmg.effects import Context

    from ...files.logio import require_finite
    from ..predict import measured_run
    from ...files.records import TrialRecord
    from ...files.output import record_labels
    from ...files.shipcheck import read_for_ship

    L = ship.particulars.L
    seg_s = segment_s or rule("segment_length") * math.sqrt(L / G)
    items = list(items)
    labels = record_labels([it.source if isinstance(it, Prepared) else
                            (it.source or it.name) if isinstance(it, TrialRecord) else it for it in items])
    out = []
    for it, label in zip(items, labels):
        if isinstance(it, Prepared):
            out.append(it)
            continue
        # a record of another ship is refused, not diagnosed
        rec = it if isinstance(it, TrialRecord) else read_for_ship(it, ship)
        require_finite(rec, ("wind_speed_rel", "wind_dir_rel"), "mmg diagnose")     # the wind it diagnoses
        run = replace(measured_run(ship, rec, wind=wind), name=label)     # named after its file, unique
        bad = ~np.isfinite(run.meas).all(axis=1)
        if bad.any():
            raise InputError(run.source or run.name, "", f"{int(bad.sum())} rows with NaN: not usable")
        ch = {c: getattr(rec, c) for c in ("wind_speed_rel", "wind_dir_rel")}
        if run.inputs.delta is not None and len(run.inputs.t) != len(rec.t):     # rebuilt rudder: resampled
            ch = {c: None for c in ch}
        ctx = Context(t=run.t, delta=run.inputs.delta, n=run.inputs.n, channels=ch, ship=ship)
        # a record without u, v is replayed in one piece: a restart would need the drift it does not log
        seg = Segmented(run.name, run.meas, run.inputs, segment_resets(run.t, math.inf if run.speed_only else seg_s),
                        context=ctx,
                        start=_smoothed(run.t, run.meas, rule("restart_smooth") * math.sqrt(L / G)),
                        fixed=run.effects, speed_only=run.speed_only,
                        straight=_straight(run, rec, ch, L) if straight_run else None)
        out.append(Prepared(run.name, run.source or run.name, seg, list(run.notes), absent_channels(rec)))
    return out


def _straight(run, rec, ch: dict, L: float):
    """The run's :func:`leading_straight_run`; None for a record without sway or rudder, or whose logged
    wind was not carried through a resampling (its wind over the straight run unknown)."""
    if run.speed_only or run.inputs.delta is None or len(run.inputs.delta) != len(run.meas):
        return None
    if ch["wind_speed_rel"] is None and getattr(rec, "wind_speed_rel", None) is not None:
        return None
    return leading_straight_run(run.meas, run.inputs.delta, L, ch["wind_speed_rel"])


def noise_level(meas: np.ndarray) -> np.ndarray:
    """Noise level per column of the logged (N, 6) states: std of the 2nd difference / sqrt(6)
    (white noise on a smooth signal), robust (MAD)."""
    d2 = np.diff(meas, 2, axis=0)
    mad = np.median(np.abs(d2 - np.median(d2, axis=0)), axis=0) * 1.4826
    return mad / math.sqrt(6.0)


def leading_straight_run(meas: np.ndarray, delta: np.ndarray, L: float, wind_speed_rel=None):
    """The record's leading steady straight run (:class:`ekf.identify.StraightRun`), or None.

    Its samples are the first ones while the rudder stays within :data:`STRAIGHT_RUDDER_DEG` of its first
    angle (itself a trim helm, within :data:`STRAIGHT_TRIM_DEG` of amidships) and the yaw rate within
    :data:`STRAIGHT_YAW` U / L; at least :data:`STRAIGHT_MIN_SAMPLES`
    of them, and a mean relative wind (when logged) of at most :data:`STRAIGHT_WIND` times the
    ship's speed.  Its sigma: the record's own sway noise (:func:`noise_level`) over the run's
    samples with the hull's drift std :data:`ekf.identify.STRAIGHT_RUN_DRIFT_SD` times the speed.

    Parameters
    ----------
    meas : (N, 6) array
        Logged u, v [m/s], r [rad/s], x, y [m], heading [rad].
    delta : (N,) array
        Logged rudder angle [rad].
    L : float
        Ship length [m].
    wind_speed_rel : (N,) array, optional
        Logged relative wind speed [m/s].
    """
    from ekf.identify import STRAIGHT_RUN_DRIFT_SD, StraightRun

    meas = np.asarray(meas, float)
    d = np.asarray(delta, float)
    U = float(np.hypot(meas[0, 0], meas[0, 1]))
    n_min = rule("straight_min_samples")
    if len(meas) < n_min + 2 or not U > 0 or abs(d[0]) > math.radians(rule("straight_trim_deg")):
        return None
    steady = ((np.abs(d - d[0]) <= math.radians(rule("straight_rudder_deg")))
              & (np.abs(meas[:, 2]) * L / U <= rule("straight_yaw")))
    n = int(np.argmin(steady)) if not steady.all() else len(steady)
    if n < n_min:
        return None
    wind = rule("straight_wind") * U
    if wind_speed_rel is not None and float(np.mean(np.abs(np.asarray(wind_speed_rel, float)[:n]))) > wind:
        return None
    sigma = math.hypot(float(noise_level(meas)[1]) / math.sqrt(n), U * STRAIGHT_RUN_DRIFT_SD)
    return StraightRun(n=n, sigma=sigma)


def _smoothed(t: np.ndarray, meas: np.ndarray, window_s: float) -> np.ndarray:
    """The logged states smoothed by a quadratic Savitzky-Golay filter over ``window_s`` (heading
    unwrapped, on its logged branch): the states the segments restart from."""
    from scipy.signal import savgol_filter

    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    w = int(round(window_s / dt)) | 1
    w = min(w, (len(t) - 1) | 1 if len(t) % 2 == 0 else len(t))
    if w < 5:
        return meas
    out = savgol_filter(meas, w, 2, axis=0, mode="interp")
    psi = np.unwrap(meas[:, 5])
    out[:, 5] = meas[:, 5] + savgol_filter(psi, w, 2, mode="interp") - psi
    return out



# --------------------------------------------------------------------------- synthetic records


@dataclass(frozen=True)
class Manoeuvre:
    """The manoeuvre a synthetic record logs (:func:`synthetic_record`).

    Attributes
    ----------
    kind : str
        ``"turning"`` or ``"zigzag"``.
    rudder_deg : float
        Rudder angle [deg]; negative turns to port (a zigzag: port first).
    speed : float or None
        Approach speed [m/s]; None: 0.09 sqrt(g L).
    duration : float or None
        Length of the record [s]; None: 120 sqrt(L/g) for a turning, 160 sqrt(L/g) for a zigzag.
    dt : float
        Sampling interval of the record [s].
    heading_deg : float or None
        A zigzag's switching heading change [deg]; None: ``|rudder_deg|``.
    t_execute : float or None
        Time of the rudder execute [s]; None: 5 sqrt(L/g) for a turning, 0 for a zigzag.
    """

    kind: str
    rudder_deg: float = 20.0
    speed: float | None = None
    duration: float | None = None
    dt: float = 0.5
    heading_deg: float | None = None
    t_execute: float | None = None

    def law(self, L: float):
        """The rudder's command law and the record's length.

        Parameters
        ----------
        L : float
            Ship length [m] (the default times scale with sqrt(L/g)).

        Returns
        -------
        law : mmg.integrate.CommandLaw
            The rudder schedule (turning) or the heading-switching autopilot (zigzag).
        T : float
            The record's length [s].

        Raises
        ------
        ValueError
            An unknown ``kind``.
        """
        from mmg.integrate import CommandLaw

        s = math.sqrt(L / G)
        a = math.radians(self.rudder_deg)
        if self.kind == "turning":
            T = self.duration or 120.0 * s
            te = 5.0 * s if self.t_execute is None else self.t_execute
            return CommandLaw.schedule([0.0, te, te + 1e-6, max(T, te + 1.0)], [0.0, 0.0, a, a]), T
        if self.kind == "zigzag":
            h = abs(a) if self.heading_deg is None else math.radians(self.heading_deg)
            law = CommandLaw.heading_switch(abs(a), h, -h, 1.0 if a >= 0 else -1.0, psi0=0.0,
                                            t_start=self.t_execute or 0.0)
            return law, self.duration or 160.0 * s
        raise ValueError(self.kind)


@dataclass(frozen=True)
class RecordNoise:
    """The white noise on a synthetic record's logged states (:func:`synthetic_record`).

    Attributes
    ----------
    widths : sequence of 6 floats or None
        Per column u [m/s], v [m/s], r [rad/s], x [m], y [m], psi [rad]: the standard deviations (``"normal"``)
        or the half-widths (``"uniform"``); None: small, 0.002 U for u and v, 1.2e-4 sqrt(g/L) for r,
        0.002 L for x and y, 0.05 deg for psi.
    dist : str
        ``"normal"`` or ``"uniform"``.
    seed : int
        Seed of the noise draws.
    """

    widths: tuple | None = None
    dist: str = "normal"
    seed: int = 0

    def scales(self, U0: float, L: float) -> np.ndarray:
        """The widths (6,) in SI, the default's at approach speed ``U0`` [m/s] and ship length ``L`` [m]."""
        if self.widths is not None:
            return np.array(self.widths)
        return np.array([0.002 * U0, 0.002 * U0, 1.2e-4 * math.sqrt(G / L), 0.002 * L, 0.002 * L, math.radians(0.05)])


def synthetic_record(ship: Ship, manoeuvre, effects=None, truth_ship: Ship | None = None, true_wind=(0.0, 0.0),
                     noise: RecordNoise | None = None, name: str | None = None, wind_loads=None):
    """A record as a trial would log it, with hidden effects: a turning or zigzag of ``truth_ship``
    simulated closed loop (the rudder orders from its own heading), then replayed with its rudder and
    revolutions and the ``effects`` and logged (u, v over ground resolved in the logged heading, heading
    with its bias) with white noise.

    A steady true wind in the effects (``true_speed_mps`` > 0) acts in the closed-loop run too, so a
    zigzag's rudder answers the wind as a helmsman's would.

    Parameters
    ----------
    ship : Ship
        The config ship (the ship that sails where ``truth_ship`` is None).
    manoeuvre : Manoeuvre or str
        The manoeuvre; a kind alone (``"turning"``, ``"zigzag"``) for its defaults.
    effects : mmg.effects.EffectSet or dict, optional
        The hidden effects (``{name: {parameter: value}}``); a wind effect's loads come from the constant
        ``true_wind`` by a fixed-point iteration on the relative wind.
    truth_ship : Ship, optional
        The ship that sails (default ``ship``).
    true_wind : (float, float)
        True wind speed [m/s] and the direction it comes from [rad].
    noise : RecordNoise, optional
        The noise on the logged states (default :class:`RecordNoise`'s: small, normal, seed 0).
    name : str, optional
        The record's name and source (default ``"synthetic_<kind>"``).
    wind_loads : callable, optional
        ``(V_rel [m/s], gamma [rad]) -> (X, Y [N], N [N m])``: replaces the wind effect's loads in the logged
        states (a ship whose wind loads follow another curve); the closed-loop run that makes the rudder
        history keeps the effect's own.

    Returns
    -------
    trials.files.records.TrialRecord
        With rudder, revolutions and, when wind is on, the relative and true wind channels.
    """
    import mmg.effects as E
    from mmg.simulation import simulate

    from ...files.records import logged_record

    m = Manoeuvre(manoeuvre) if isinstance(manoeuvre, str) else manoeuvre
    noise = RecordNoise() if noise is None else noise
    if noise.dist not in ("normal", "uniform"):
        raise ValueError(f"noise dist {noise.dist!r}: 'normal' or 'uniform'")
    es = effects if isinstance(effects, E.EffectSet) else E.effect_set(effects or {})
    truth = truth_ship or ship
    L = truth.particulars.L
    U0 = m.speed or 0.09 * math.sqrt(G * L)
    law, T = m.law(L)
    # the closed-loop run that makes the rudder history has the effects that act on the dynamics
    # through the parameter vector (current, rudder offset, a steady true wind); the record's states
    # are the replay's below
    acts = lambda c, v: bool(c.slots(v)) or (c.name == "wind" and c.steady(v))  # noqa: E731
    sim = simulate(truth, law, T, min(m.dt, 0.05 * math.sqrt(L / G)), U0, trim=False,
                   effects=E.EffectSet(tuple(it for it in es.items if acts(*it))))
    t = np.arange(0.0, T + 1e-9, m.dt)
    idx = np.minimum(np.searchsorted(sim.t, t - 1e-9), len(sim.t) - 1)
    delta, n = sim.states[idx, 6], sim.states[idx, 7]
    pk = es.pack(pack(truth, sim.equilibrium.power_W), truth)
    states, wind_rel = _replayed(pk, es, truth, (t, delta, n), sim.states[0, :6].copy(), true_wind, wind_loads)
    sd = noise.scales(U0, L)
    label = name or f"synthetic_{m.kind}"
    if noise.dist == "uniform":
        rec = logged_record(t, states, delta, n, es, None, None, wind_rel, name=label, source=label,
                            meta={"format": "synthetic"})
        return _uniform_noise(rec, sd, np.random.default_rng(noise.seed))
    return logged_record(t, states, delta, n, es, sd, np.random.default_rng(noise.seed), wind_rel,
                         name=label, source=label, meta={"format": "synthetic"})


def _replayed(pk, es, truth: Ship, inputs, s0, true_wind, wind_loads):
    """(states, relative wind) of the replay of ``inputs`` = (t, delta, n) from ``s0`` on the packed ship
    ``pk`` with the effects ``es``: with a wind effect, its loads from the relative wind that the true
    wind and the replayed motion over ground give, iterated four times (``wind_loads`` in place of the
    effect's where given); else no wind (None)."""
    import mmg.effects as E
    from mmg.replay import ReplayInputs, replay_states
    from mmg.wind import relative_wind_from_true

    t, delta, n = inputs
    states = replay_states(pk, ReplayInputs(t, delta, n), s0)
    wind_eff = [(c, v) for c, v in es.items if c.name == "wind"]
    if not wind_eff:
        return states, None
    Vt, dt_ = true_wind
    rest = E.EffectSet(tuple(it for it in es.items if it[0].name != "wind"))
    for _ in range(4):
        # the anemometer is aboard: the relative wind from the true one and the true motion over ground
        og = E.EffectSet(tuple(it for it in rest.items if it[0].kind != "measurement")).to_logged(states)
        Vr, ang = relative_wind_from_true(Vt, dt_, og[:, 0], og[:, 1], states[:, 5])
        wind_rel = (Vr, np.mod(ang, 2 * np.pi))
        ctx = E.Context(t=t, delta=delta, n=n, channels=dict(zip(("wind_speed_rel", "wind_dir_rel"), wind_rel)),
                        ship=truth)
        ext = (wind_eff[0][0].external(wind_eff[0][1], ctx) if wind_loads is None
               else np.column_stack(wind_loads(Vr, ang)))
        states = replay_states(pk, ReplayInputs(t, delta, n, ext), s0)
    return states, wind_rel


def _uniform_noise(rec, half_widths, rng):
    """``rec`` with uniform noise of ``half_widths`` (u, v, r, x, y, psi) on its logged states."""
    from dataclasses import replace

    cols = ("u", "v", "r", "x", "y", "psi")
    new = {c: getattr(rec, c) + rng.uniform(-1.0, 1.0, len(rec.t)) * float(w) for c, w in zip(cols, half_widths)}
    return replace(rec, U=np.hypot(new["u"], new["v"]), **new)


def write_frt_csv(rec, path) -> None:
    """Write a record in the FRT-DS-ESSO column layout (what :func:`trials.files.logio.read_record` reads)."""
    import pandas as pd

    cols = {"t [s]": rec.t, "x_position_mid [m]": rec.x, "u_velo [m/s]": rec.u, "y_position_mid [m]": rec.y,
            "vm_velo [m/s]": rec.v, "psi_hat [rad]": np.mod(rec.psi, 2 * np.pi), "r_angvelo [rad/s]": rec.r,
            "n_prop [rps]": rec.n, "delta_rudder [rad]": rec.delta}
    if rec.wind_speed_rel is not None:
        cols.update({"wind_velo_relative_mid [m/s]": rec.wind_speed_rel, "wind_dir_relative_mid [rad]": rec.wind_dir_rel,
                     "wind_velo_true [m/s]": rec.wind_speed_true, "wind_dir_true [rad]": rec.wind_dir_true})
    pd.DataFrame(cols).to_csv(path, index=False)
