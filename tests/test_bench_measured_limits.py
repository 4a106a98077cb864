"""The helpers of the identification limit benches: bench/identify_cv.py's candidate grid (hull form x prior width,
chosen inside the folds), bench/yaw_residual_check.py's heading bound and model yaw acceleration,
bench/identify_ceiling.py's heading RMS windows, bench/fold_values.py's jackknife and fold table, and
bench/frt_gap.py's figures by record kind."""
from __future__ import annotations

import math

import numpy as np
import pytest

from .conftest import load_bench


def _load(name: str):
    return load_bench(name)


def test_several_prior_widths_make_each_hull_form_at_each_width_a_candidate():
    cv = _load("identify_cv")
    one = cv.candidates(("kijima", "crossflow"), [0.5])
    assert set(one) == {"kijima", "crossflow"} and all("prior_rel_std" not in c.options for c in one.values())
    grid = cv.candidates(("kijima", "crossflow"), [0.5, 0.25])
    assert set(grid) == {"kijima, prior 0.5", "kijima, prior 0.25", "crossflow, prior 0.5", "crossflow, prior 0.25"}
    for name, c in grid.items():
        assert c.name == name
        assert c.options["prior_rel_std"] == float(name.rsplit(" ", 1)[1])
        assert c.ship.name == one[name.split(",")[0]].ship.name          # the form's own config, unchanged
    both = cv.candidates(("kijima",), [0.5, 0.25, 0.5], ["fit", "sample"])
    assert {n: c.options for n, c in both.items()} == {
        "kijima, prior 0.5, start fit": {"prior_rel_std": 0.5, "initial_state": "fit"},
        "kijima, prior 0.5, start sample": {"prior_rel_std": 0.5, "initial_state": "sample"},
        "kijima, prior 0.25, start fit": {"prior_rel_std": 0.25, "initial_state": "fit"},
        "kijima, prior 0.25, start sample": {"prior_rel_std": 0.25, "initial_state": "sample"}}
    assert set(cv.candidates(("kijima",), [0.5, 0.5])) == {"kijima"}          # a width given twice counts once
    starts = cv.candidates(("kijima", "crossflow"), [0.5], ["fit", "sample"])
    assert {n: c.options for n, c in starts.items()} == {
        "kijima, start fit": {"initial_state": "fit"}, "kijima, start sample": {"initial_state": "sample"},
        "crossflow, start fit": {"initial_state": "fit"}, "crossflow, start sample": {"initial_state": "sample"}}
    assert cv._options(cv._args(["--initial-state", "fit", "sample"])).get("initial_state") is None
    assert cv._options(cv._args(["--initial-state", "sample"]))["initial_state"] == "sample"
    # the common options carry the width only when there is one (else each candidate's own applies)
    a = cv._args(["--prior", "0.5", "0.25"])
    assert "prior_rel_std" not in cv._options(a)
    assert cv._options(cv._args(["--prior", "0.3"]))["prior_rel_std"] == 0.3


def test_heading_bound_of_a_constant_yaw_acceleration_is_the_rms_of_a_t2_over_2():
    yc = _load("yaw_residual_check")
    a, T = 0.0062, 60.0
    t = (np.arange(600000) + 0.5) * (T / 600000)                      # midpoints of a fine grid
    rms = math.sqrt(np.mean((0.5 * a * t ** 2) ** 2))                 # numerically, independent of the closed form
    assert yc.heading_rms_of(a, T) == pytest.approx(rms, rel=1e-6)
    assert yc.heading_rms_of(a, T) == pytest.approx(5.0, rel=0.01)    # the 5 deg target over 60 s
    assert yc.heading_rms_of(-a, T) == yc.heading_rms_of(a, T)


def test_model_yaw_acceleration_is_the_equations_of_motion_at_the_logged_state():
    """At rest with the rudder amidships and no wind the hull, rudder and propeller walk give no yaw; an
    added yaw moment N gives N over the yaw inertia of the equations of motion (independent 2x2 solve)."""
    import mmg
    from mmg.model import P_IZ, P_JZ, P_M, P_MY, P_XG, pack
    from mmg.replay import ReplayInputs

    yc = _load("yaw_residual_check")
    ship = mmg.load_ship("esso_osaka_3m")
    p = pack(ship).p

    class Run:
        meas = np.zeros((4, 6))
        inputs = ReplayInputs(t=np.arange(4.0), delta=np.zeros(4), n=np.zeros(4),
                              ext=np.array([[0, 0, 0], [0, 0, 2.0], [0, 1.0, 0], [3.0, 0, 0]]))

    acc = yc.model_yaw_acceleration(ship, Run())
    m, xg = p[P_M], p[P_XG]
    M = np.array([[m + p[P_MY], xg * m], [xg * m, p[P_IZ] + xg * xg * m + p[P_JZ]]])
    assert acc[0] == pytest.approx(0.0, abs=1e-15)
    assert acc[1] == pytest.approx(np.linalg.solve(M, [0.0, 2.0])[1], rel=1e-12)
    assert acc[2] == pytest.approx(np.linalg.solve(M, [1.0, 0.0])[1], rel=1e-12)
    assert acc[3] == pytest.approx(0.0, abs=1e-15)                    # a surge force alone gives no yaw


def test_ceiling_heading_windows():
    ce = _load("identify_ceiling")
    t = np.arange(100.0, 220.0, 0.1)                                 # the window counts from the first sample
    e = np.radians(np.where(t - 100.0 <= 60.0, 3.0, 9.0))
    whole, first = ce._rms_deg(e, t, 60.0)
    assert first == pytest.approx(3.0)
    n1 = int(np.sum(t - 100.0 <= 60.0))
    assert whole == pytest.approx(math.sqrt((n1 * 9.0 + (len(t) - n1) * 81.0) / len(t)))
    assert all(math.isnan(x) for x in ce._rms_deg(np.r_[e[:-1], np.nan], t, 60.0))


def test_damped_heading_bound_is_the_first_order_response():
    """With yaw damping the heading error of a constant yaw acceleration a is a T_r (t - T_r (1 - e^-t/T_r)):
    checked against a step-by-step integration of r' = a - r / T_r, psi' = r; no damping gives the undamped
    bound; more damping a smaller heading error."""
    yc = _load("yaw_residual_check")
    a, t_r, T, dt = 0.03, 8.0, 60.0, 1e-3
    r = psi = 0.0
    acc = []
    for k in range(int(T / dt)):                                     # semi-implicit Euler, fine steps
        r += dt * (a - r / t_r)
        psi += dt * r
        acc.append(psi)
    rms = math.sqrt(np.mean(np.square(acc)))
    assert yc.heading_rms_damped(a, t_r, T) == pytest.approx(rms, rel=2e-3)
    assert yc.heading_rms_damped(a, float("inf"), T) == yc.heading_rms_of(a, T)
    assert yc.heading_rms_damped(a, 4.0, T) < yc.heading_rms_damped(a, 8.0, T) < yc.heading_rms_of(a, T)


def test_jackknife_se_of_leave_one_group_out_means_is_the_standard_error_of_the_group_means():
    """Independent formula: for K equal groups and theta_i the mean of all but group i, the delete-a-group
    jackknife SE equals the standard error of the mean of the K group means, sd(group means) / sqrt(K)."""
    from trials.measured.foldspread import jackknife_se

    rng = np.random.default_rng(7)
    groups = rng.normal(3.0, 2.0, (4, 25))
    theta = [np.delete(groups, i, axis=0).mean() for i in range(4)]
    gm = groups.mean(axis=1)
    assert jackknife_se(theta) == pytest.approx(np.std(gm, ddof=1) / math.sqrt(4), rel=1e-12)
    assert jackknife_se([1.5, 1.5, 1.5]) == 0.0


def test_fold_table_flags_sign_changes_spread_and_ratio_to_the_fits_own_se():
    """Three folds of a fixed Kijima fit: N_r of both signs, spread counted in its prior std
    (max(0.5 |value|, 0.01)), the jackknife SE set against a stated covariance's SE; a record's own
    nuisance value is left out."""
    from types import SimpleNamespace

    import mmg

    fv = _load("fold_values")
    nr = mmg.load_ship("esso_osaka_3m").hull.value("N_r")
    vals = [{"N_r": nr, "N_0": 0.0, "current.north_mps[a]": 9.0}, {"N_r": -nr, "N_0": 0.001}, {"N_r": nr, "N_0": 0.002}]
    nested = {"records": [{"fold": k, "choice": "kijima", "values": v} for k, v in enumerate(vals)]}
    cov = SimpleNamespace(names=("N_r", "N_0"), std=lambda: (0.01, 0.0))
    rows, s = fv.table(nested, 0.5, cov)
    row = {r.split(" | ")[0].lstrip("| "): r for r in rows[3:]}
    assert set(row) == {"N_r", "N_0"}
    sigma = 0.5 * abs(nr)
    spread = float(row["N_r"].split(" | ")[7])
    assert spread == pytest.approx(2 * abs(nr) / sigma, abs=0.05)          # from -|N_r| to +|N_r|: 4 prior stds
    assert s["sign"] == 1 and s["spread_over_2"] == 1
    jk = math.sqrt(2 / 3 * sum((x - nr / 3) ** 2 for x in (nr, -nr, nr)))
    assert s["ratios"] == {"N_r": pytest.approx(jk / 0.01, rel=1e-3)}       # N_0's SE is 0: no ratio
    mixed = {"records": [{"fold": 0, "choice": "kijima", "values": vals[0]},
                         {"fold": 1, "choice": "crossflow", "values": {"N_r": 0.1, "N_0": 0.0}}]}
    assert fv.table(mixed)[0][3].split(" | ")[7] == "nan"                  # no jackknife across forms


def test_gap_by_kind_needed_mean_and_replacement_by_hand():
    """Four records, scaled 30/30/90/90 deg (mean 60), identified 10/20/60/40: 3x asks for a mean of 20, a sum
    of 80; the turns give 30, so the two random runs may sum to 50: a mean of 25.  With the random runs at
    in-sample 5 and 15 the mean is (10 + 20 + 5 + 15) / 4 = 12.5: 4.8x."""
    gap = _load("frt_gap")
    rows = {"turn_a": (30.0, 10.0), "turn_cut_b": (30.0, 20.0), "random_c": (90.0, 60.0), "random_d": (90.0, 40.0)}
    assert gap.kind_of("turn_cut_b") == "turn"
    assert gap.needed_mean(rows, "random") == pytest.approx(25.0)
    assert gap.ratio_with(rows, {"random_c": 5.0, "random_d": 15.0, "turn_a": 0.0}, ("random",)) == pytest.approx(60 / 12.5)
    kinds = {r["kind"]: r for r in gap.kind_table(rows)}
    assert set(kinds) == {"turn", "random"}
    assert kinds["random"]["identified"] == pytest.approx(50.0) and kinds["random"]["share"] == pytest.approx(100 / 130)
    assert kinds["turn"]["n"] == 2 and kinds["turn"]["scaled"] == pytest.approx(30.0)
    recs = [{"name": n, "fold": k % 2, "choice": "kijima", "identified": {"heading_rms_deg": x[1]}}
            for k, (n, x) in enumerate(rows.items())]
    assert gap.fold_means({"records": recs}) == {0: ("kijima", pytest.approx(35.0)), 1: ("kijima", pytest.approx(30.0))}


def _windy_run(ship, k: int = 0):
    """A 90 s zigzag record replayed by ``ship`` under steady prescribed wind loads (Fujiwara's, 4 m/s)."""
    from dataclasses import replace

    from mmg.model import pack
    from mmg.replay import ReplayInputs, replay
    from mmg.wind import wind_forces
    from trials.measured.predict import MeasuredRun

    t = np.arange(0.0, 90.0 + 1e-9, 0.1)
    delta = np.convolve(np.radians(20.0) * np.sign(np.sin(2 * np.pi * t / 40.0)), np.ones(5) / 5, mode="same")
    inp = ReplayInputs(t=t, delta=delta, n=np.full_like(t, 6.0))
    X, Y, N = wind_forces(np.full_like(t, 4.0), np.full_like(t, np.radians(60.0 - 120.0 * k)), ship.wind.geometry)
    inp = replace(inp, ext=np.column_stack([X, Y, N]))
    return MeasuredRun(name=f"w{k}", source=f"w{k}", meas=replay(pack(ship), inp, [0.2, 0, 0, 0, 0, 0]), inputs=inp)


def test_offset_scan_replays_the_fold_model_as_its_scores_were_wind_scale_included():
    """A fold model rebuilt from its JSON values (fold_models), its fitted wind scale 0.3: the offset scan's
    zero-offset replay gives the heading RMS that Identification.replay scored, for both models; scanning
    without the fitted values replays another model and is named."""
    from types import SimpleNamespace

    import mmg
    from trials.measured.identify import Identification
    from trials.measured.nested import replay_scores
    from trials.measured.predict import replay_record

    cv = _load("identify_cv")
    ship = mmg.load_ship("esso_osaka_3m")
    run = _windy_run(ship)
    values = {"N_r": 0.6 * ship.hull.value("N_r"), "wind_scale": 0.3}
    rec = cv.fold_models({"records": [{"name": run.name, "choice": "kijima", "values": values}]})[0]
    assert rec["ship"].hull.value("N_r") == pytest.approx(values["N_r"])          # the fold's values written in
    assert rec["ship"].wind.scale == pytest.approx(0.3 * ship.wind.scale)
    ident = Identification(ship=rec["ship"], initial=ship, fit=SimpleNamespace(values=lambda: values), runs=[run],
                           segment_s=np.inf)
    rec["scaled"] = replay_scores(replay_record(ship, run))
    rec["identified"] = replay_scores(ident.replay(run))
    assert rec["identified"]["heading_rms_deg"] > 1.0                # the model differs from the one that made it
    out = cv.offset_spread([rec], [run], ship, 1.0, n=3)
    assert out["not_as_scored"] == []
    old = cv.offset_spread([{**rec, "values": {}}], [run], ship, 1.0, n=3)
    assert [s.split(" ")[0] for s in old["not_as_scored"]] == [run.name]
    assert cv.offset_spread([rec], [run], ship, 1.0, n=4)["not_as_scored"] is None     # no zero offset: unchecked


def test_kind_summary_whole_record_and_window_means_by_hand():
    """Four kept-out records of two kinds.  Turns: whole record scaled 30, 20 / identified 10, 20 -> 25 / 15;
    windows scaled 6, 4 / identified 2, NaN -> the pair with the NaN left out: 6 / 2 over 1 record.
    Random runs: the scaled whole-record replay of random_d diverged (None) -> 90 / 60 over 1; windows
    12, 10 / 8, 6 -> 11 / 7 over 2.  No zigzag or berthing record: no row."""
    cv = _load("identify_cv")
    s = lambda h, w: {"heading_rms_deg": h, "window_heading_rms_deg": w}    # noqa: E731
    recs = [{"name": "turn_a", "scaled": s(30.0, 6.0), "identified": s(10.0, 2.0)},
            {"name": "turn_cut_b", "scaled": s(20.0, 4.0), "identified": s(20.0, float("nan"))},
            {"name": "random_c", "scaled": s(90.0, 12.0), "identified": s(60.0, 8.0)},
            {"name": "random_d", "scaled": s(None, 10.0), "identified": s(40.0, 6.0)}]
    rows = cv.kind_summary(recs)
    assert [r["kind"] for r in rows] == ["turn", "random"] and [r["n"] for r in rows] == [2, 2]
    turn, rnd = rows
    assert turn["heading_rms_deg"] == {"scaled": 25.0, "identified": 15.0, "n": 2}
    assert turn["window_heading_rms_deg"] == {"scaled": 6.0, "identified": 2.0, "n": 1}
    assert rnd["heading_rms_deg"] == {"scaled": 90.0, "identified": 60.0, "n": 1}
    assert rnd["window_heading_rms_deg"] == {"scaled": 11.0, "identified": 7.0, "n": 2}
    md = cv.kind_table(rows, markdown=True)
    assert md[2] == "| turn | 2 | 25.0 / 15.0 | 6.0 / 2.0 (1 finite) |"
    assert md[3] == "| random | 2 | 90.0 / 60.0 (1 finite) | 11.0 / 7.0 |"
    none = cv.kind_summary([{"name": "zigzag_x", "scaled": s(None, None), "identified": s(1.0, 1.0)}])
    assert none[0]["heading_rms_deg"] == {"scaled": None, "identified": None, "n": 0}
    assert cv.kind_table(none, markdown=True)[2] == "| zigzag | 1 | - (0 finite) | - (0 finite) |"
    # bands pooled per kind: turns 90 of 100 and 30 of 50 samples inside (120 of 150: 80 %), median width
    # of the records' medians 40 and 60 deg: 50 deg; positions 80 and 45 inside (125 of 150: 83.3 %), median
    # radius of 3 and 5 m: 4 m; the random runs carry none
    band = lambda n, k, w, p, r: {"samples": n, "inside": k, "median_width_deg": w,     # noqa: E731
                                  "position_inside": p, "median_radius_m": r}
    recs[0]["band"], recs[1]["band"] = band(100, 90, 40.0, 80, 3.0), band(50, 30, 60.0, 45, 5.0)
    rows = cv.kind_summary(recs)
    assert rows[0]["band"] == {"coverage90": pytest.approx(0.8), "median_width_deg": 50.0,
                               "position_coverage90": pytest.approx(125 / 150), "median_radius_m": 4.0}
    assert "band" not in rows[1]
    md = cv.kind_table(rows, markdown=True)
    assert md[2].endswith("| 80.0 %, 50 deg | 83.3 %, 4 m |") and md[3].endswith("| - | - |")


def test_the_identified_models_window_scores_carry_its_fitted_wind_scale():
    """replay_scores with the identified ship scores the windows of the run as Identification.replay made it:
    the record's wind loads times the fitted wind_scale 0.3 (built here by hand), not the unscaled ones."""
    from dataclasses import replace
    from types import SimpleNamespace

    import mmg
    from trials.measured.identify import Identification
    from trials.measured.nested import replay_scores
    from trials.measured.window import window_scores

    ship = mmg.load_ship("esso_osaka_3m")
    run = _windy_run(ship)
    values = {"wind_scale": 0.3}
    ident = Identification(ship=ship, initial=ship, fit=SimpleNamespace(values=lambda: values), runs=[run],
                           segment_s=np.inf)
    got = replay_scores(ident.replay(run), ship=ship)["window_heading_rms_deg"]
    by_hand = window_scores(ship, replace(run, inputs=replace(run.inputs, ext=0.3 * run.inputs.ext)))
    unscaled = window_scores(ship, run)
    assert got == pytest.approx(by_hand.mean("heading_rms_deg"), rel=1e-12)
    assert unscaled.mean("heading_rms_deg") < 1e-6 < got            # the record is the unscaled model's own


def test_window_kinds_of_a_predict_json_by_hand():
    """Three runs of mmg predict's JSON: two turns (whole 10 and null: diverged; windows 4 and 2 deg over 3 and
    5 windows, 1.0 and 3.0 m) -> whole 10 over 1 finite, windows 3 deg, 2 m, 8 windows; one zigzag."""
    wk = _load("window_kinds")
    w = lambda h, m, n: {"window_s": 60.0, "every_s": 30.0, "n_windows": n, "heading_rms_deg": h,   # noqa: E731
                         "position_error_m": m, "position_error_L": m / 3.0}
    doc = {"runs": [{"name": "turn_a", "heading_rms_deg": 10.0, "window": w(4.0, 1.0, 3)},
                    {"name": "turn_cut_b", "heading_rms_deg": None, "window": w(2.0, 3.0, 5)},
                    {"name": "zigzag_c", "heading_rms_deg": 7.0, "window": w(5.0, 0.5, 2)}]}
    turn, zz = wk.kind_rows(doc)
    assert (turn["kind"], turn["n"], turn["windows"], turn["n_whole"]) == ("turn", 2, 8, 1)
    assert turn["heading_rms_deg"] == 10.0 and turn["window_heading_rms_deg"] == 3.0
    assert turn["window_position_error_m"] == 2.0 and turn["window_position_error_L"] == pytest.approx(2.0 / 3.0)
    assert zz["kind"] == "zigzag" and zz["window_heading_rms_deg"] == 5.0
    assert wk.table([turn], 60.0, 30.0)[2] == "| turn | 2 | 8 | 10.0 (1 finite) | 3.0 | 2.00 | 0.67 |"
