"""Run a trial: simulate it, record its log, compute its metrics."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from mmg.integrate import integrate
from mmg.simulation import SimulationResult, prepare
from mmg.units import DEG

from . import metrics as MET
from .logio import M_PER_DEG_LAT, M_PER_DEG_LON, log_frame, truth_frame
from .trial import Trial


@dataclass(frozen=True)
class TrialRun:
    """A simulated trial: the trial, its simulation and what it records."""

    trial: Trial
    result: SimulationResult

    @property
    def sog(self) -> np.ndarray:
        """Speed over ground [m/s] (speed through the water plus any current)."""
        x, y, t = self.result.x, self.result.y, self.result.t
        if not self.trial.disturbances:
            return self.result.U
        return np.hypot(np.gradient(x, t), np.gradient(y, t))

    def log(self) -> pd.DataFrame:
        """The sea-trial log (5 s, noisy) as a DataFrame."""
        r = self.result
        return log_frame(r.t, r.x, r.y, r.psi, self.sog, r.n, self.trial.log)

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

    def truth(self) -> pd.DataFrame:
        """States at every integration step (SI)."""
        r = self.result
        return truth_frame(r.t, r.states, r.orders)

    def metrics(self) -> dict:
        """Manoeuvre metrics for this trial's kind (turning or zigzag; others: summary only)."""
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
        return out


def run_trial(trial: Trial) -> TrialRun:
    """Simulate ``trial`` from its steady approach."""
    pk, eq = prepare(trial.ship, trial.u0, trial.n0, trial.trim, trial.disturbances)
    law = trial.command_law(trim_rudder=eq.delta, psi0=0.0)
    t, states, orders, done = integrate(pk, eq.state(), law, trial.duration, trial.dt)
    return TrialRun(trial, SimulationResult(t, states, orders, eq, done, trial.ship.name, {"trial": trial.name}))

