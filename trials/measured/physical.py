"""Is an identified model still physical?  The checks ``mmg identify`` makes after its fit.

Two, over the operating range its training records cover:

* **Energy.**  With the propeller stopped and the rudder amidships the water can only take energy
  from the ship (:mod:`mmg.dissipation`).  The model is checked at the states the records log
  (u, v, r; at most :data:`MAX_STATES` of them) and over the box their ranges span
  (:func:`mmg.dissipation.state_box`); where it gains energy the hull coefficients that feed the
  motion are named.  The prior is checked too: a failure the prior already has is the hull form's
  (the Kijima polynomial at large r' = r L / U, pivoting at low speed), not the fit's.
* **Replays.**  Every training record is replayed open loop with the identified model; a replay
  that leaves the finite numbers is a divergence, reported with its time and its last finite state
  (:class:`Divergence`), never as a NaN score alone.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mmg.dissipation import PowerCheck, power_check, state_box

__all__ = ["Divergence", "PhysicalCheck", "divergence_of", "physical_check", "logged_states", "MAX_STATES"]

MAX_STATES = 2000
"""The logged states checked (evenly subsampled over all the records)."""


@dataclass(frozen=True)
class Divergence:
    """An open-loop replay that left the finite numbers.

    Attributes
    ----------
    record : str
    time_s : float
        Time [s] of the first non-finite predicted sample (from the record's start).
    state : dict
        The predicted state where the replay began to run away (the last sample within twice the
        record's range of speed and yaw rate): t [s from the start], u, v [m/s], r [deg/s], x, y [m],
        psi [deg].
    inputs : dict
        The rudder [deg] and propeller revolutions [rps] logged there.
    """

    record: str
    time_s: float
    state: dict
    inputs: dict

    def describe(self) -> str:
        s = ", ".join(f"{k} {v:.3g}" for k, v in self.state.items())
        i = ", ".join(f"{k} {v:.3g}" for k, v in self.inputs.items())
        return f"{self.record}: the replay diverged (non-finite at {self.time_s:.1f} s); it left the record's range at {s} ({i})"

    def to_dict(self) -> dict:
        return {"record": self.record, "time_s": self.time_s, "state": self.state, "inputs": self.inputs}


def divergence_of(rep) -> Divergence | None:
    """The :class:`Divergence` of a :class:`trials.measured.predict.Replayed`, or None when it replayed.
    Its time is the first non-finite sample's; its state and inputs are those where the replay first
    left twice the record's own range (speed over ground, yaw rate), where it began to run away
    (the last finite state is astronomically large)."""
    if rep.divergence is None:                 # (its first non-finite sample: Replayed.divergence)
        return None
    t, m, p = rep.run.t, rep.run.meas, rep.pred
    with np.errstate(invalid="ignore"):
        out = ((np.hypot(p[:, 0], p[:, 1]) > 2.0 * np.nanmax(np.hypot(m[:, 0], m[:, 1])))
               | (np.abs(p[:, 2]) > 2.0 * np.nanmax(np.abs(m[:, 2]))) | ~np.isfinite(p).all(axis=1))
    k = max(int(np.argmax(out)) - 1, 0)
    last = p[k]
    state = {"t_s": t[k] - t[0], "u_mps": last[0], "v_mps": last[1], "r_degps": np.degrees(last[2]),
             "x_m": last[3], "y_m": last[4], "psi_deg": np.degrees(last[5])}
    inputs = {"rudder_deg": np.degrees(rep.run.inputs.delta[k]), "n_rps": rep.run.inputs.n[k]}
    return Divergence(rep.run.name, float(rep.divergence["t_s"] - t[0]), {k_: float(v) for k_, v in state.items()},
                      {k_: float(v) for k_, v in inputs.items()})


@dataclass(frozen=True)
class PhysicalCheck:
    """The checks of one identified model (module docstring).

    Attributes
    ----------
    logged, box : PowerCheck
        The energy balance of the identified model at the logged states and over their box.
    prior_logged, prior_box : PowerCheck
        The same of the prior (the model the fit started from).
    divergences : list of Divergence
        The training records whose replay with the identified model diverged.
    """

    logged: PowerCheck
    box: PowerCheck
    prior_logged: PowerCheck
    prior_box: PowerCheck
    divergences: list = field(default_factory=list)

    @property
    def passes(self) -> bool:
        return self.logged.passes and self.box.passes and not self.divergences

    def warnings(self) -> list[str]:
        """One line per failed check, naming the coefficients (energy) or the record, time and state."""
        out = []
        for what, c, prior in (("at the states the records log", self.logged, self.prior_logged),
                               ("over the range they span", self.box, self.prior_box)):
            if not c.passes:
                whose = ("the prior does too (the hull form's)" if not prior.passes else "the prior does not (the fit's)")
                out.append(f"energy {what}: {c.describe()}; {whose}")
        return out + [d.describe() for d in self.divergences]

    def to_dict(self) -> dict:
        return {"passes": self.passes, "logged": self.logged.to_dict(), "box": self.box.to_dict(),
                "prior_logged": self.prior_logged.to_dict(), "prior_box": self.prior_box.to_dict(),
                "divergences": [d.to_dict() for d in self.divergences]}


def logged_states(runs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(u [m/s], v [m/s], r [rad/s]) of every finite logged state of the records ``runs``, evenly subsampled
    to at most :data:`MAX_STATES`: the states the physical checks look at."""
    uvr = np.concatenate([r.meas[:, :3] for r in runs])
    uvr = uvr[np.isfinite(uvr).all(axis=1)]
    if len(uvr) > MAX_STATES:
        uvr = uvr[np.linspace(0, len(uvr) - 1, MAX_STATES).astype(int)]
    return uvr[:, 0], uvr[:, 1], uvr[:, 2]


def physical_check(ship, prior, runs, replays=()) -> PhysicalCheck:
    """:class:`PhysicalCheck` of the identified ``ship`` against its ``prior`` over the records
    ``runs`` (:class:`trials.measured.predict.MeasuredRun`); ``replays``: their open-loop replays with
    ``ship`` (:class:`trials.measured.predict.Replayed`) for the divergence check."""
    states = logged_states(runs)
    box = state_box(*states)
    divs = [d for d in (divergence_of(r) for r in replays) if d is not None]
    return PhysicalCheck(power_check(ship, *states), power_check(ship, *box), power_check(prior, *states),
                         power_check(prior, *box), divs)
