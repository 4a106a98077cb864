"""Run a trial: simulate it, record its log, compute its metrics.

:func:`run_trial` (``mmg.simulate``) returns a :class:`TrialRun`: the trial, its time
history and what is derived from it (metrics, a DataFrame, figures, the sea-trial log).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from mmg.errors import InputError
from mmg.engine_order import prescribed_revolutions
from mmg.integrate import integrate
from mmg.model import STATE_NAMES
from mmg.simulation import SimulationResult, prepare
from mmg.units import DEG, KNOT, M_PER_DEG_LAT, M_PER_DEG_LON

from ..analysis import metrics as MET
from .trial import Trial


@dataclass(frozen=True)
class TrialRun:
    """A simulated trial: the trial, its time history and what it records.

    Returned by ``mmg.simulate(trial)`` (:func:`run_trial`).  The states at every
    integration step are attributes (SI): ``t`` (also ``time``) [s], ``u``, ``v`` [m/s],
    ``r`` [rad/s], ``x``, ``y`` [m] (north, east), ``psi`` [rad] (continuous, not wrapped),
    ``delta`` [rad], ``n`` [rps], ``orders`` (rudder order) [rad], ``U`` [m/s], ``sog``
    [m/s]; ``states`` is the (N, 8) array in the order of ``state_names``.

    Attributes
    ----------
    trial : Trial
        What was simulated.
    result : mmg.simulation.SimulationResult
        The raw time history (and the approach ``equilibrium``).

    Examples
    --------
    >>> import mmg
    >>> res = mmg.simulate(mmg.load_trial("zz20"))
    >>> res.metrics()["overshoots_deg"][:2]      # doctest: +SKIP
    >>> df = res.to_pandas()                      # time-indexed states
    >>> fig = res.plot("track")                   # matplotlib Figure
    >>> log = res.log(seed=1)                     # the noisy 5 s sea-trial log
    """

    trial: Trial
    result: SimulationResult

    state_names = STATE_NAMES

    def __getattr__(self, name):
        if name in STATE_NAMES:
            return self.result.states[:, STATE_NAMES.index(name)]
        raise AttributeError(f"{type(self).__name__!s} has no attribute {name!r}")

    def __repr__(self) -> str:
        done = "" if self.completed else ", stopped early"
        return (f"<TrialRun {self.trial.name!r} ({self.trial.kind}) of {self.trial.ship.name!r}: "
                f"{self.t[-1]:g} s of {self.trial.duration:g} s, {len(self.t)} steps of {self.trial.dt:g} s{done}>")

    @property
    def t(self) -> np.ndarray:
        """Time [s] at every integration step."""
        return self.result.t

    time = t

    @property
    def states(self) -> np.ndarray:
        """(N, 8) states [u, v, r, x, y, psi, delta, n] in SI."""
        return self.result.states

    @property
    def orders(self) -> np.ndarray:
        """Rudder order [rad]."""
        return self.result.orders

    @property
    def U(self) -> np.ndarray:
        """Speed through the water [m/s]."""
        return self.result.U

    @property
    def completed(self) -> bool:
        """False when the integration stopped before the trial's duration."""
        return bool(self.result.completed)

    @property
    def equilibrium(self):
        """The steady approach the run starts from (:class:`mmg.equilibrium.Equilibrium`)."""
        return self.result.equilibrium

    @property
    def ship(self):
        """The ship (:class:`mmg.ship.Ship`)."""
        return self.trial.ship

    @property
    def sog(self) -> np.ndarray:
        """Speed over ground [m/s] (speed through the water plus any current)."""
        x, y, t = self.result.x, self.result.y, self.result.t
        if self.trial.current()[0] == 0.0:
            return self.result.U
        return np.hypot(np.gradient(x, t), np.gradient(y, t))

    def apparent_wind(self):
        """The apparent wind at midship of a steady-wind run, at every integration step, or None.

        Returns
        -------
        (V_rel, gamma) : tuple of ndarray, or None
            Speed [m/s] and direction it comes FROM, from the bow, clockwise [rad, 0 to 2 pi)
            (the FRT-DS-ESSO convention of ``wind_dir_relative_mid``), from the true wind of the
            ``wind`` effect and the ship's velocity over ground (:func:`mmg.wind.relative_wind_from_true`);
            None without a steady wind.
        """
        w = self.trial.steady_wind()
        if w is None:
            return None
        from mmg.wind import relative_wind_from_true

        r = self.result
        cs, cd = self.trial.current()
        ug = r.u + cs * np.cos(cd - r.psi)
        vg = r.v + cs * np.sin(cd - r.psi)
        V, g = relative_wind_from_true(w[0], w[1], ug, vg, r.psi)
        return V, np.mod(g, 2 * np.pi)

    def to_pandas(self) -> "pd.DataFrame":
        """The time history as a DataFrame indexed by time ``t`` [s].

        Returns
        -------
        pandas.DataFrame
            One row per integration step.  Columns in SI: ``u``, ``v`` [m/s], ``r`` [rad/s],
            ``x``, ``y`` [m] (north, east), ``psi`` [rad] (continuous), ``delta`` [rad],
            ``n`` [rps], ``delta_order`` [rad], ``U`` [m/s] (speed through the water),
            ``sog`` [m/s] (over ground), ``beta`` [rad] (drift angle, atan2(-v, u)).
            Derived, in the units their names say: ``psi_deg`` (heading change, continuous),
            ``heading_deg`` (compass heading 0-360), ``delta_deg``, ``delta_order_deg``,
            ``r_deg_s``, ``beta_deg``, ``U_kn``, ``rpm``.  ``df.attrs`` holds the trial
            name, kind and ship.
        """
        r = self.result
        import pandas as pd

        df = pd.DataFrame(r.states, columns=list(STATE_NAMES), index=pd.Index(r.t, name="t"))
        df["delta_order"] = r.orders
        df["U"] = r.U
        df["sog"] = self.sog
        df["beta"] = np.arctan2(-r.v, r.u)
        df["psi_deg"] = r.psi / DEG
        df["heading_deg"] = np.mod(r.psi / DEG, 360.0)
        df["delta_deg"] = r.delta / DEG
        df["delta_order_deg"] = r.orders / DEG
        df["r_deg_s"] = r.r / DEG
        df["beta_deg"] = df["beta"] / DEG
        df["U_kn"] = r.U / KNOT
        df["rpm"] = r.n * 60.0
        df.attrs.update({"trial": self.trial.name, "kind": self.trial.kind, "ship": self.trial.ship.name})
        return df

    def plot(self, kind: str = "histories", show: bool = False, ax=None, every_s: float | None = None):
        """Plot the run.

        Parameters
        ----------
        kind : {"histories", "track"}, default "histories"
            ``"histories"``: heading, rudder (angle and order), yaw rate, speed and rpm
            against time, five panels; ``"track"``: the track in ship lengths, east right,
            north up, with ship outlines.
        show : bool, default False
            Call ``matplotlib.pyplot.show()``.
        ax : matplotlib.axes.Axes or sequence of 5 Axes, optional
            Draw into existing axes (one for the track, five for the histories); default
            a new pyplot figure.
        every_s : float, optional
            Track only: time between ship outlines [s].

        Returns
        -------
        matplotlib.figure.Figure

        Raises
        ------
        mmg.errors.InputError
            An unknown ``kind``, or the wrong number of axes.
        """
        from ..files import plots

        r, sh = self.result, self.trial.ship.particulars
        title = f"{self.trial.name} ({self.trial.ship.name})"
        if kind == "track":
            if ax is not None and np.ndim(ax) != 0:
                raise InputError("plot", "ax", "the track needs one Axes")
            fig = plots.track_figure(r.t, r.x, r.y, r.psi, sh.L, sh.B, title, every_s=every_s, ax=ax)
        elif kind == "histories":
            try:
                fig = plots.histories_figure(r.t, r.psi, r.delta, r.r, r.U, r.n, title,
                                             delta_order=r.orders, ax=ax)
            except ValueError as e:
                raise InputError("plot", "ax", str(e)) from None
        else:
            raise InputError("plot", "kind", f"unknown plot kind {kind!r} (use 'histories' or 'track')")
        if show:
            import matplotlib.pyplot as plt

            plt.show()
        return fig

    def log(self, seed: int | None = None) -> "pd.DataFrame":
        """The sea-trial log: the track sampled at the log interval, with sensor noise and bias.

        Parameters
        ----------
        seed : int, optional
            Seed of the noise; default the trial's ``log.seed``.  The same seed gives the
            same log.

        Returns
        -------
        pandas.DataFrame
            Columns ``time_s``, ``lat_deg``, ``lon_deg``, ``heading_deg`` (0-360),
            ``speed_kn`` (over ground), ``rpm`` (see :mod:`trials.files.logio`).
        """
        r = self.result
        spec = self.trial.log if seed is None else dataclasses.replace(self.trial.log, seed=int(seed))
        from ..files.logio import log_frame      # pandas only when a log is asked for

        return log_frame(r.t, r.x, r.y, r.psi, self.sog, r.n, spec, wind=self.apparent_wind())

    def record(self, interval: float | None = None, noise=None, seed: int | None = None):
        """The run as an on-board system logs it (the FRT-DS-ESSO channels), with its effects in it.

        What :func:`trials.files.logio.read_record` gives for a measured FRT-DS-ESSO file: u, v over
        ground resolved in the logged heading, r, x, y, the logged heading (with a heading bias),
        the rudder angle and revolutions as measured (the rudder indicator does not see a rudder
        offset), and with a steady wind the apparent wind at midship (and the true wind).  The
        effects of the ship and the trial (:meth:`trials.runs.trial.Trial.effect_set`) act exactly as in
        the replay and the estimators (:meth:`mmg.effects.EffectSet.to_logged`).

        Parameters
        ----------
        interval : float, optional
            Sampling interval [s], a multiple of the step; default the trial's ``log.interval``.
        noise : sequence of 6 floats, optional
            Standard deviations of white noise on u, v [m/s], r [rad/s], x, y [m], psi [rad];
            default none.
        seed : int, optional
            Seed of the noise (default the trial's ``log.seed``).

        Returns
        -------
        trials.files.records.TrialRecord
        """
        from ..files.records import logged_record

        r, tr = self.result, self.trial
        step = max(1, int(round((interval or tr.log.interval) / tr.dt)))
        sel = slice(0, len(r.t), step)
        w = self.apparent_wind()
        rng = None if noise is None else np.random.default_rng(tr.log.seed if seed is None else seed)
        return logged_record(r.t[sel], r.states[sel, :6], r.delta[sel], r.n[sel], tr.logged_effects(), noise, rng,
                             None if w is None else (w[0][sel], w[1][sel]), name=tr.name, ship=tr.ship.name,
                             source=f"simulation of {tr.name}", meta={"format": "simulation", "trial": tr.name})

    def log_meta(self) -> dict:
        """Header of the log and truth files."""
        eq = self.result.equilibrium
        lg = self.trial.log
        return {**self.trial.summary(), "config": self.trial.path, "seed": lg.seed,
                "start_lat_deg": np.degrees(lg.start_lat), "start_lon_deg": np.degrees(lg.start_lon),
                "m_per_deg_lat": M_PER_DEG_LAT, "m_per_deg_lon": M_PER_DEG_LON,
                "interval_s": lg.interval, "dt_s": self.trial.dt, "length_m": self.trial.ship.particulars.L,
                "approach_rpm": round(eq.n * 60, 4), "trim_rudder_deg": round(eq.delta / DEG, 8),
                "steering_T_E_s": self.trial.ship.steering.T_E,
                "steering_rate_deg_s": self.trial.ship.steering.rate_max / DEG,
                "steering_delta_max_deg": self.trial.ship.steering.delta_max / DEG,
                "noise": f"uniform: lat {np.degrees(lg.noise_lat):g} deg, lon {np.degrees(lg.noise_lon):g} deg, "
                         f"heading {np.degrees(lg.noise_heading):g} deg, speed {lg.noise_speed / 0.514444:g} kn, "
                         f"rpm {lg.noise_rpm * 60:g} rpm",
                "bias": f"heading {np.degrees(lg.bias.heading):g} deg, speed {lg.bias.speed / 0.514444:g} kn, "
                        f"rpm {lg.bias.rpm * 60:g} rpm"}

    def truth(self) -> "pd.DataFrame":
        """The truth file's table: states at every integration step (SI).

        Returns
        -------
        pandas.DataFrame
            Columns ``time_s``, ``u_mps``, ``v_mps``, ``r_radps``, ``delta_rad``,
            ``delta_order_rad``, ``x_m``, ``y_m``, ``psi_rad``, ``n_rps`` (a plain index).
        """
        r = self.result
        from ..files.logio import truth_frame

        return truth_frame(r.t, r.states, r.orders, wind=self.apparent_wind())

    def metrics(self) -> dict:
        """Manoeuvre metrics for this trial's kind.

        Returns
        -------
        dict
            Always: ``trial``, ``kind``, ``ship``, ``approach_speed_kn``, ``approach_rpm``,
            ``trim_rudder_deg``, ``completed``, ``duration_s``, ``final_heading_change_deg``.
            Turning: advance, transfer, tactical diameter etc. (:func:`trials.analysis.metrics.turning_metrics`);
            zigzag and S-type: overshoots, times etc. (:func:`trials.analysis.metrics.zigzag_metrics`,
            e.g. ``overshoots_deg``); stopping: track and head reach, lateral deviation, time to stop
            (:func:`trials.analysis.metrics.stopping_metrics`).
        """
        r, tr = self.result, self.trial
        L = tr.ship.particulars.L
        out = {"trial": tr.name, "kind": tr.kind, "ship": tr.ship.name,
               "approach_speed_kn": tr.u0 / 0.514444, "approach_rpm": r.equilibrium.n * 60,
               "trim_rudder_deg": r.equilibrium.delta / DEG, "completed": r.completed,
               "duration_s": float(r.t[-1]), "final_heading_change_deg": float((r.psi[-1] - r.psi[0]) / DEG)}
        if tr.kind == "turning":
            out.update(MET.turning_metrics(r.t, r.x, r.y, r.psi, r.U, L, t_execute=tr.manoeuvre["execute"]))
        elif tr.kind in ("zigzag", "stype"):
            out.update(MET.zigzag_metrics(r.t, r.psi, order=r.orders, U=r.U, L=L))
        elif tr.kind == "stopping":
            out.update(MET.stopping_metrics(r.t, r.x, r.y, r.psi, r.u, r.v, L, t_execute=tr.manoeuvre["execute"]))
        return MET.fill_from_trial(out, tr.summary())


def prepare_trial(trial: Trial):
    """The packed ship and steady approach (:func:`mmg.simulation.prepare`) of ``trial``: the same for
    every trial of one ship, approach and effects (``run_trial(t, prepared=...)`` reuses it)."""
    return prepare(trial.ship, trial.u0, trial.n0, trial.trim, trial.effects)


def run_trial(trial, prepared=None) -> TrialRun:
    """Simulate a trial from its steady approach.

    Parameters
    ----------
    trial : Trial, str, os.PathLike or mapping
        A :class:`Trial`, or anything :func:`trials.runs.trial.load_trial` accepts (a bundled
        trial name such as ``"zz20"``, a trial YAML path, a mapping).
    prepared : (PackedShip, Equilibrium), optional
        :func:`prepare_trial` of a trial with the same ship, approach and effects (several
        manoeuvres of one ship solve their approach once); default solved here.

    Returns
    -------
    TrialRun
    """
    if not isinstance(trial, Trial):
        from .trial import load_trial

        trial = load_trial(trial)
    pk, eq = prepare_trial(trial) if prepared is None else prepared
    if trial.kind == "stopping":                 # revolutions ordered astern: the shaft equation is not integrated
        pk = prescribed_revolutions(pk)
    law = trial.command_law(trim_rudder=eq.delta, psi0=0.0, n0=eq.n)
    t, states, orders, done = integrate(pk, eq.state(), law, trial.duration, trial.dt)
    return TrialRun(trial, SimulationResult(t, states, orders, eq, done, trial.ship.name, {"trial": trial.name}))

