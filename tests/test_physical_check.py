"""The checks mmg identify makes of a fitted model (trials.measured.physical): a divergence is a
finding with its time and state; a fitted hull that gains energy where its prior does not is named."""
from __future__ import annotations

import numpy as np

import mmg
from mmg.replay import ReplayInputs
from trials.measured.physical import divergence_of, physical_check
from trials.measured.predict import MeasuredRun, Replayed


def _run(t, u, r):
    meas = np.column_stack([u, 0 * t, r, u * t, 0 * t, 0 * t])
    inputs = ReplayInputs(t=t, delta=np.radians(10.0) * np.ones_like(t), n=5.0 * np.ones_like(t))
    return MeasuredRun(name="rec", source="rec.csv", meas=meas, inputs=inputs)


def test_a_replay_that_runs_away_is_reported_with_its_time_and_state():
    t = np.arange(0.0, 100.0, 0.5)
    run = _run(t, 0.5 * np.ones_like(t), 0.01 * np.ones_like(t))
    pred = run.meas.copy()
    grow = t >= 40.0                                    # yaw rate grows e-fold every 2 s from 40 s ...
    pred[grow, 2] = 0.01 * np.exp((t[grow] - 40.0) / 2.0)
    pred[t >= 80.0] = np.nan                            # ... and is not finite from 80 s
    d = divergence_of(Replayed(run, pred, 3.0, 0.5))
    assert d is not None and d.time_s == 80.0
    # it left twice the logged range (0.02 rad/s) at 40 + 2 ln 2 = 41.39 s: the last sample within, 41.0 s
    assert d.state["t_s"] == 41.0
    assert abs(np.radians(d.state["r_degps"]) - 0.01 * np.exp(0.5)) < 1e-12
    assert d.inputs == {"rudder_deg": 10.0, "n_rps": 5.0}
    assert "80.0 s" in d.describe() and "rec" in d.describe()
    assert divergence_of(Replayed(run, run.meas.copy(), 3.0, 0.5)) is None


def test_a_fitted_hull_that_feeds_the_sway_is_named_as_the_fits():
    prior = mmg.load_ship("esso_osaka_3m_crossflow")
    y_v = dict(zip(prior.hull.names, prior.hull.values))["Y_v"]
    fitted = prior.with_hull({"Y_v": -3.0 * y_v})              # the sign of the sway damping lost
    t = np.arange(0.0, 60.0, 0.1)
    run = _run(t, 0.6 + 0.1 * np.sin(t / 7.0), 0.05 * np.sin(t / 5.0))
    run.meas[:, 1] = 0.25 * np.cos(t / 6.0)                  # drift both ways, up to 23 deg
    chk = physical_check(fitted, prior, [run])
    assert not chk.passes and chk.prior_logged.passes
    w = chk.warnings()[0]
    assert "Y_v" in w and "the fit's" in w, w
    assert physical_check(prior, prior, [run]).passes
