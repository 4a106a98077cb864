"""Short-horizon prediction (``trials.measured.window``): windows restarted from the measured state.

* the windows' sample ranges, start times and count for given record lengths, by hand;
* the simulator's own record (no noise) replays with ~0 error in every window;
* a heading offset stepped into the record: the windows across the step see it as c sqrt(fraction of
  their samples after it) [deg], the windows after it restart from the measured (offset) heading and see
  no heading error but a track turned by c about their start, so a final position error of
  2 sin(c/2) |displacement| [m] (hand formulas, the replay's own numbers nowhere);
* a wrong yaw-damping coefficient: the window figure is below half the whole-record one (replayed apart),
  and one window equals the replay of the record cut to it by the record's own slicing;
* windows every window length equal the one-call multiple shooting of :func:`mmg.replay.replay_states`
  with ``reset`` at the window starts.
"""
from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture(scope="module")
def zz20(tmp_path_factory):
    """The full-scale ship's ZZ20 truth file (3000 s at 0.1 s, no noise), written and read back."""
    import mmg
    from trials.files.logio import read_record, write_csv

    res = mmg.simulate(mmg.load_trial("zz20"))
    p = tmp_path_factory.mktemp("window") / "zz20_truth.csv"
    write_csv(p, res.truth(), res.log_meta())
    ship = res.trial.ship
    return ship, read_record(p, length_m=ship.particulars.L)


# --------------------------------------------------------------------------- windows by hand


@pytest.mark.parametrize("length, starts", [
    (200.0, [0, 30, 60, 90, 120]),              # floor((200 - 60) / 30) + 1 = 5; 150 + 60 > 200
    (210.0, [0, 30, 60, 90, 120, 150]),         # the last window ends on the last sample: kept
    (60.0, [0]),                                # exactly one window
])
def test_window_starts_and_count_by_hand(length, starts):
    from trials.measured.window import window_bounds

    t0 = 12.3                                   # not zero: windows count from the record's first sample
    t = t0 + np.arange(round(length / 0.1) + 1) * 0.1
    bounds, short = window_bounds(t, 60.0, 30.0)
    assert not short and len(bounds) == len(starts)
    for (i0, i1), s in zip(bounds, starts):
        assert t[i0] == pytest.approx(t0 + s, abs=1e-9)
        assert t[i1] == pytest.approx(t0 + s + 60.0, abs=1e-9)
        assert i1 - i0 == 600                   # 60 s at 10 Hz: 601 samples


def test_a_record_shorter_than_a_window_is_one_window_of_its_length():
    from trials.measured.window import window_bounds

    t = np.arange(451) * 0.1                    # 45 s
    assert window_bounds(t, 60.0, 30.0) == ([(0, 450)], True)


def test_window_bounds_refuse_a_non_positive_length():
    from trials.measured.window import window_bounds

    with pytest.raises(ValueError):
        window_bounds(np.arange(10.0), 0.0, 30.0)
    with pytest.raises(ValueError):
        window_bounds(np.arange(10.0), 60.0, float("nan"))


def test_window_scores_start_times_and_short_flag(zz20):
    from trials.measured.window import window_scores

    ship, rec = zz20
    w = window_scores(ship, rec.slice_time(0.0, 1000.0 + 1e-6), 300.0, 200.0)
    # floor((1000 - 300) / 200) + 1 = 4 windows: 0, 200, 400, 600 s (800 + 300 > 1000)
    assert w.n_windows == 4 and not w.short
    assert np.allclose(w.start_s, [0, 200, 400, 600], atol=1e-9)
    assert np.allclose(w.end_s - w.start_s, 300.0, atol=1e-9)
    s = window_scores(ship, rec.slice_time(0.0, 100.0 + 1e-6), 300.0, 200.0)
    assert s.short and s.n_windows == 1 and s.to_json()["window_s"] == pytest.approx(100.0, abs=1e-9)
    assert "shorter than 300 s" in s.text()


# --------------------------------------------------------------------------- the model's own record


def test_the_simulators_own_record_has_no_window_error(zz20):
    from trials.measured.window import window_scores

    ship, rec = zz20
    w = window_scores(ship, rec)
    assert w.n_windows == int(np.floor((3000 - 60) / 30)) + 1 == 99
    assert w.n_diverged == 0
    assert np.max(w.heading_rms_deg) < 1e-3                 # deg (the whole record: < 0.05 deg)
    assert np.max(w.position_error_m) < 1e-2                # m, of a ship making 5 m/s for 60 s
    j = w.to_json()
    assert list(j)[:6] == ["window_s", "every_s", "n_windows", "heading_rms_deg", "position_error_m", "position_error_L"]
    assert j["position_error_L"] == pytest.approx(j["position_error_m"] / 325.0, rel=1e-12)


def test_a_heading_step_is_seen_only_by_the_windows_across_it(zz20):
    """A constant offset c added to the measured heading from t_off on (the replay knows nothing of it).

    Across the step: the prediction keeps the true heading, the record jumps by c: heading RMS
    c sqrt(k / n) [deg] with k of the window's n samples at or after t_off; position unchanged.
    After the step: the restart takes the offset heading, and the yaw dynamics do not depend on the
    heading (no wind, no current), so the prediction is the true motion turned by c about the window's
    start: heading error 0, final position error 2 sin(c / 2) |x(t1) - x(t0)| [m]."""
    from dataclasses import replace

    from trials.measured.window import window_scores

    ship, rec = zz20
    rec = rec.slice_time(0.0, 600.0 + 1e-6)
    c, t_off = 5.0, 215.0                                   # deg; inside the windows starting 180 and 210 s
    bad = replace(rec, psi=rec.psi + np.radians(c) * (rec.t >= t_off - 1e-9))
    w = window_scores(ship, bad)
    seen = 0
    for a, b, h, e in zip(w.start_s, w.end_s, w.heading_rms_deg, w.position_error_m):
        inside = (rec.t >= a - 1e-6) & (rec.t <= b + 1e-6)
        if b < t_off:                                       # before the step: as clean as the record
            assert h < 1e-3 and e < 1e-2
        elif a < t_off:                                     # across it
            frac = np.mean(rec.t[inside] >= t_off - 1e-9)
            assert h == pytest.approx(c * np.sqrt(frac), rel=1e-3)
            assert e < 1e-2
            seen += 1
        else:                                               # after it: restarted from the offset heading
            i0, i1 = np.flatnonzero(inside)[[0, -1]]
            d = np.hypot(rec.x[i1] - rec.x[i0], rec.y[i1] - rec.y[i0])
            assert h < 1e-3
            assert e == pytest.approx(2 * np.sin(np.radians(c) / 2) * d, rel=1e-3, abs=1e-2)
    assert seen == 2
    # the whole-record replay carries the step to the end: c sqrt(fraction of the record after it)
    from trials.measured.predict import replay_record

    whole = replay_record(ship, bad).scores()["heading_rms_deg"]
    assert whole == pytest.approx(c * np.sqrt(np.mean(rec.t >= t_off - 1e-9)), rel=1e-3)


# --------------------------------------------------------------------------- a wrong model


def test_a_wrong_yaw_damping_grows_in_open_loop_but_stays_bounded_per_window(zz20):
    """N_r at 60 % of the true value: the open-loop heading error is carried over the 3000 s, each
    60 s window restarts from the record; the window figure is well below the whole-record one, and
    one window equals the replay (:func:`replay_record`) of the record cut to that window."""
    from trials.measured.predict import replay_record
    from trials.measured.window import window_scores

    ship, rec = zz20
    wrong = ship.with_hull({"N_r": 0.6 * ship.hull.value("N_r")})
    whole = replay_record(wrong, rec).scores()["heading_rms_deg"]
    w = window_scores(wrong, rec)
    assert w.n_windows == 99
    assert whole > 1.0                                       # deg: the coefficient is wrong enough to see
    assert w.mean("heading_rms_deg") < 0.5 * whole
    assert np.max(w.heading_rms_deg) < whole
    for k in (7, 60):
        a = w.start_s[k]
        cut = replay_record(wrong, rec.slice_time(a - 1e-6, a + 60.0 + 1e-6)).scores()
        assert w.heading_rms_deg[k] == pytest.approx(cut["heading_rms_deg"], rel=1e-9)
        assert w.position_error_m[k] == pytest.approx(cut["final_position_error_m"], rel=1e-9)


def test_adjacent_windows_equal_the_one_call_multiple_shooting(zz20):
    """``every_s == window_s``: the windows tile the record, and one :func:`mmg.replay.replay_states` call
    with ``reset`` at their starts gives the same predictions (its sample at a window's start holds the
    previous window's end, so the window starts from the measured state there)."""
    from mmg.model import pack
    from mmg.replay import replay_states
    from trials.measured.predict import measured_run
    from trials.measured.window import window_bounds, window_scores

    ship, rec = zz20
    wrong = ship.with_hull({"N_r": 0.6 * ship.hull.value("N_r")})
    run = measured_run(wrong, rec.slice_time(0.0, 900.0 + 1e-6))
    bounds, _ = window_bounds(run.t, 300.0, 300.0)
    reset = np.zeros(len(run.t), bool)
    reset[[i0 for i0, _ in bounds]] = True
    pred = replay_states(pack(wrong), run.inputs, run.meas[0], meas=run.meas, reset=reset)
    w = window_scores(wrong, run, 300.0, 300.0)
    assert w.n_windows == 3
    for k, (i0, i1) in enumerate(bounds):
        p = pred[i0:i1 + 1].copy()
        p[0] = run.meas[i0]
        m = run.meas[i0:i1 + 1]
        h = np.sqrt(np.mean(np.degrees(p[:, 5] - m[:, 5]) ** 2))
        e = np.hypot(p[-1, 3] - m[-1, 3], p[-1, 4] - m[-1, 4])
        assert w.heading_rms_deg[k] == pytest.approx(h, rel=1e-9)
        assert w.position_error_m[k] == pytest.approx(e, rel=1e-9)
        assert w.position_error_L[k] == pytest.approx(e / 325.0, rel=1e-9)


def test_a_diverged_window_spoils_only_itself(zz20):
    """A window whose replay goes non-finite is NaN and counted; the means are over the others."""
    from trials.measured.window import WindowScores

    w = WindowScores("x", 60.0, 30.0, np.array([0.0, 30.0, 60.0]), np.array([60.0, 90.0, 120.0]),
                     np.array([1.0, np.nan, 3.0]), np.array([2.0, np.nan, 4.0]), np.array([0.5, np.nan, 1.0]))
    j = w.to_json()
    assert j["n_windows"] == 3 and j["n_diverged"] == 1
    assert j["heading_rms_deg"] == 2.0 and j["position_error_m"] == 3.0 and j["position_error_L"] == 0.75
    assert "1 diverged (left out)" in w.text() and "2 deg RMS" in w.text()
