"""mmg identify: the fit recovers coefficients it did not start from, writes a usable ship config,
and skips unusable records with one line."""
from __future__ import annotations

import numpy as np
import pytest

import mmg
from ekf.identify import Scales, Segmented, free_parameters, identify_segments, segment_resets
from mmg.model import pack
from mmg.replay import ReplayInputs, replay
from trials.measured.identify import identify, ship_yaml, write_identification
from trials.measured.predict import MeasuredRun

SHIP = "esso_osaka_3m"


def _zigzag_inputs(t, amp_deg=20.0, period=40.0, n=10.0):
    delta = np.radians(amp_deg) * np.sign(np.sin(2 * np.pi * t / period))
    delta = np.convolve(delta, np.ones(5) / 5, mode="same")             # a finite rudder rate
    return ReplayInputs(t=t, delta=delta, n=np.full_like(t, n))


def _synthetic_runs(ship_true, seeds=(0, 1), duration=120.0):
    """Records made by replaying the *true* ship (coefficients the fit does not know) from a
    moving start with zigzag-like rudders; measurement noise added."""
    pk = pack(ship_true)
    runs = []
    for k in seeds:
        rng = np.random.default_rng(k)
        t = np.arange(0.0, duration + 1e-9, 0.1)
        inp = _zigzag_inputs(t, amp_deg=15.0 + 10 * k, period=30.0 + 10 * k)
        s = replay(pk, inp, [0.35, 0.0, 0.0, 0.0, 0.0, 0.0])
        meas = s + rng.normal(0.0, [0.002, 0.002, 0.0005, 0.01, 0.01, 0.002], s.shape)
        runs.append(MeasuredRun(name=f"syn{k}", source=f"syn{k}", meas=meas, inputs=inp))
    return runs


def test_fit_recovers_the_coefficients_that_made_the_records():
    ship = mmg.load_ship(SHIP)
    true = {"N_r": ship.hull.value("N_r") * 1.3, "N_beta": ship.hull.value("N_beta") * 0.8,
            "Y_beta": ship.hull.value("Y_beta") * 1.2}
    runs = _synthetic_runs(ship.with_hull(true))
    pk = pack(ship)
    free = free_parameters(pk, ship.hull.names, list(true))
    segs = [Segmented(r.name, r.meas, r.inputs, segment_resets(r.t, 30.0)) for r in runs]
    fit = identify_segments(pk, segs, free, Scales(0.005, 0.005, 0.001, np.radians(0.5)), n_jobs=2)
    got = fit.values()
    for k, v in true.items():                    # from 20-30 % off to within 3 %
        assert got[k] == pytest.approx(v, rel=0.03), (k, got[k], v)
    assert fit.cost_final < 0.1 * fit.cost_initial
    assert np.all(np.isfinite(fit.std)) and np.all(fit.std > 0)


def test_identify_improves_the_open_loop_replay_and_writes_a_usable_ship(tmp_path):
    ship = mmg.load_ship(SHIP)
    true = {"N_r": ship.hull.value("N_r") * 1.3, "N_beta": ship.hull.value("N_beta") * 0.8}
    runs = _synthetic_runs(ship.with_hull(true), seeds=(0,), duration=90.0)
    ident = identify(ship, runs, free=list(true), segment_s=(30.0, np.inf), say=lambda m: None)
    a = ident.scores(model="initial")[0]["heading_rms_deg"]
    b = ident.scores()[0]["heading_rms_deg"]
    assert b < 0.2 * a
    out = write_identification(ident, mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path)
    back = mmg.load_ship(out["ship"])                      # a complete, valid ship config
    for k, v in ident.fit.values().items():
        assert back.hull.value(k) == pytest.approx(v, rel=1e-5)
    assert back.wind is not None and back.particulars == ship.particulars
    rep = out["report"].read_text()
    assert "| N_r |" in rep and "Training fits" in rep


def test_each_record_is_replayed_once_per_model(monkeypatch):
    """The scores, the physical check and the report read the same replays: one per record and model
    (the identified and the initial), and the identified replay is not the initial one."""
    import trials.measured.identify.fit as I

    ship = mmg.load_ship(SHIP)
    runs = _synthetic_runs(ship.with_hull({"N_r": ship.hull.value("N_r") * 1.3}), seeds=(0,), duration=40.0)
    ident = identify(ship, runs, free=["N_r"], segment_s=(20.0,), say=lambda m: None)
    calls = []
    real = I.replay_record
    monkeypatch.setattr(I, "replay_record", lambda s, r: calls.append(s) or real(s, r))
    for _ in range(2):
        ident.scores(model="initial"), ident.scores()
    ident.physical_check()
    assert len(calls) == 2 and calls[0] is ident.initial and calls[1] is ident.ship
    assert ident.replay(runs[0]) is not ident.replay(runs[0], "initial")
    assert ident.scores()[0] != ident.scores(model="initial")[0]


def test_ship_yaml_changes_only_the_fitted_values(tmp_path):
    src = mmg.config_path("ships", f"{SHIP}.yaml")
    text = ship_yaml(src, {"N_r": -0.04, "w_P0": 0.5, "epsilon": 1.2}, "test")
    p = tmp_path / "s.yaml"
    p.write_text(text)
    a, b = mmg.load_ship(src), mmg.load_ship(p)
    assert b.hull.value("N_r") == -0.04 and b.propeller.w_P0[0] == 0.5 and b.rudder.epsilon == 1.2
    assert b.hull.value("Y_beta") == a.hull.value("Y_beta") and b.mass == a.mass


def test_unusable_record_is_skipped_with_one_line(tmp_path, capsys):
    ship = mmg.load_ship(SHIP)
    runs = _synthetic_runs(ship, seeds=(0,), duration=40.0)
    bad = tmp_path / "bad.csv"
    bad.write_text("t [s],x_position_mid [m],y_position_mid [m],psi_hat [rad]\n0,0,0,0\n0.1,nan,0,0\n0.2,0,0,0\n")
    said = []
    ident = identify(ship, runs + [bad], free=["N_r"], segment_s=(20.0,), say=said.append)
    assert len(said) == 1 and "bad.csv" in said[0] and "\n" not in said[0]
    assert len(ident.runs) == 1


def test_identify_in_another_form_scores_against_the_initial_model(tmp_path):
    """--ship the cross-flow form, --initial the Kijima ship: the fit starts from the cross-flow prior,
    the 'initial' scores and report are the Kijima ship's replay."""
    kij, cf = mmg.load_ship(SHIP), mmg.load_ship("esso_osaka_3m_crossflow")
    runs = _synthetic_runs(kij, seeds=(0,), duration=40.0)
    ident = identify(cf, runs, free=["N_r"], segment_s=(20.0,), say=lambda m: None, initial=kij)
    assert ident.initial is kij and ident.prior is cf and "N_CD" in ident.ship.hull.names
    assert ident.scores(model="initial")[0]["heading_rms_deg"] < 1.0      # the Kijima ship made the record
    rep = write_identification(ident, mmg.config_path("ships", "esso_osaka_3m_crossflow.yaml"), tmp_path)["report"]
    assert "Fitted in the form of" in rep.read_text()


def _doubled(run: MeasuredRun, reset: np.ndarray):
    """``run`` twice in a row (the second copy restarted from its own first state) and its resets."""
    dt = run.inputs.t[1] - run.inputs.t[0]
    t = np.concatenate([run.inputs.t, run.inputs.t + run.inputs.t[-1] + dt])
    inp = ReplayInputs(t=t, delta=np.tile(run.inputs.delta, 2), n=np.tile(run.inputs.n, 2))
    return Segmented(run.name + "x2", np.vstack([run.meas, run.meas]), inp, np.concatenate([reset, reset]))


def test_equal_record_weighting_makes_a_doubled_record_count_as_the_single_one():
    """Two records made by two different ships pull N_r apart.  Doubling one record (the same samples
    twice) moves the samples-weighted fit towards that record's ship; with ``weights=record_weights(...,
    "equal")`` the fit is the one of the two single records (computed independently: both of one length,
    unit weights).  The prior is made negligible so that only the records' relative weight matters."""
    from ekf.identify import record_weights

    ship = mmg.load_ship(SHIP)
    nr = ship.hull.value("N_r")
    a = _synthetic_runs(ship.with_hull({"N_r": nr * 1.3}), seeds=(0,), duration=59.9)[0]
    b = _synthetic_runs(ship.with_hull({"N_r": nr * 0.8}), seeds=(1,), duration=59.9)[0]
    assert len(a.t) % 2 == 0                                      # stride 2 keeps both copies' samples alike
    pk = pack(ship)
    free = free_parameters(pk, ship.hull.names, ["N_r"], prior_rel_std=1e4)
    sc = Scales(0.005, 0.005, 0.001, np.radians(0.5))
    ra, rb = segment_resets(a.t, 30.0), segment_resets(b.t, 30.0)
    sa, sb = Segmented(a.name, a.meas, a.inputs, ra), Segmented(b.name, b.meas, b.inputs, rb)
    bb = _doubled(b, rb)
    fit = lambda recs, w=None: identify_segments(pk, recs, free, sc, n_jobs=2, weights=w).values()["N_r"]  # noqa: E731
    ref = fit([sa, sb])
    samples = fit([sa, bb], record_weights([sa, bb], "samples"))
    equal = fit([sa, bb], record_weights([sa, bb], "equal"))
    assert nr * 0.8 < ref < nr * 1.3 or nr * 1.3 < ref < nr * 0.8
    assert abs(samples - nr * 0.8) < abs(ref - nr * 0.8) - 0.05 * abs(ref - samples) - 1e-6   # doubled b pulls
    assert abs(samples - ref) > 0.02 * abs(nr)
    assert equal == pytest.approx(ref, rel=2e-3)


def test_relative_record_weighting_divides_by_each_records_misfit():
    from ekf.identify import record_weights

    runs = _synthetic_runs(mmg.load_ship(SHIP), seeds=(0, 1), duration=40.0)
    segs = [Segmented(r.name, r.meas, r.inputs, segment_resets(r.t, 20.0)) for r in runs]
    w = record_weights(segs, "relative", rms=[1.0, 4.0])
    assert w[0] / w[1] == pytest.approx(4.0)                       # same length: only the misfit differs
    assert np.all(record_weights(segs, "samples") == 1.0)
    with pytest.raises(ValueError):
        record_weights(segs, "relative")


def test_rudder_constants_and_added_masses_can_be_freed_and_are_written_back(tmp_path):
    ship = mmg.load_ship(SHIP)
    runs = _synthetic_runs(ship.with_hull({}), seeds=(0,), duration=40.0)
    ident = identify(ship, runs, free=["gamma_R_pos", "l_R_prime", "m_y", "J_z"], segment_s=(20.0,), say=lambda m: None,
                     max_nfev=3)
    v = ident.fit.values()
    assert ident.ship.rudder.gamma_R_pos == v["gamma_R_pos"] and ident.ship.rudder.l_R_prime == v["l_R_prime"]
    from mmg.model import P_JZ, P_MY
    assert pack(ident.ship).p[P_MY] == pytest.approx(v["m_y"], rel=1e-12)      # the config's prime, rescaled
    assert pack(ident.ship).p[P_JZ] == pytest.approx(v["J_z"], rel=1e-12)
    back = mmg.load_ship(write_identification(ident, mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path)["ship"])
    assert back.rudder.gamma_R_pos == pytest.approx(v["gamma_R_pos"], rel=1e-5)
    assert pack(back).p[P_MY] == pytest.approx(v["m_y"], rel=1e-5) and back.mass.m_x_prime == ship.mass.m_x_prime
    assert back.rudder.gamma_R_neg == ship.rudder.gamma_R_neg


def _fake_run(name, rps, n_rows=50, seed=0, meas=None):
    from mmg.replay import ReplayInputs
    from trials.measured.predict import MeasuredRun

    rng = np.random.default_rng(seed)
    t = np.arange(n_rows) * 0.1
    m = rng.normal(size=(n_rows, 6)) if meas is None else meas
    return MeasuredRun(name, name, m, ReplayInputs(t, np.zeros(n_rows), np.full(n_rows, float(rps))))


def test_a_cut_copy_of_a_record_stays_in_its_records_fold():
    """The FRT set's turn_cut_* files are the first minutes of another file: kept out, a record's copy
    must not be in its training set (the CV would then score partly in-sample)."""
    from trials.measured.identify import fold_of, same_run_groups

    runs = [_fake_run(f"r{i}", 10, seed=i) for i in range(7)]
    runs.append(_fake_run("r3_cut", 10, n_rows=20, meas=runs[3].meas[:20].copy()))
    runs.append(_fake_run("r5_late", 10, n_rows=20, meas=runs[5].meas[10:30].copy()))   # a cut from later on
    assert same_run_groups(runs) == [0, 1, 2, 3, 4, 5, 6, 3, 5]
    for by in ("order", "revolutions"):
        f = fold_of(runs, 4, by)
        assert f[7] == f[3] and f[8] == f[5]
        assert sorted(np.bincount(f, minlength=4)) == [2, 2, 2, 3]      # 7 runs in 4 folds, one of them doubled


def test_folds_by_revolutions_spread_every_revolution_band_over_the_folds():
    from trials.measured.identify import fold_of

    rps = [8, 8, 8, 8, 10, 10, 10, 10, 12, 12, 15, 16.7, 16.7, 10, 10, 10]
    runs = [_fake_run(f"r{i}", n, seed=i) for i, n in enumerate(rps)]
    f = fold_of(runs, 4, "revolutions")
    fast = [f[i] for i, n in enumerate(rps) if n >= 15]
    assert len(set(fast)) == 3                           # the three fastest records in three folds
    for k in range(4):                                   # every training set holds a record above 12 rps
        assert any(n > 12 and f[i] != k for i, n in enumerate(rps))
        assert any(n == 8 and f[i] != k for i, n in enumerate(rps))
    assert list(fold_of(runs, 4, "order")) == [i % 4 for i in range(16)]
    with pytest.raises(ValueError):
        fold_of(runs, 4, "alphabet")


def _manoeuvre_run(name, delta_deg, rps, seed):
    from mmg.replay import ReplayInputs
    from trials.measured.predict import MeasuredRun

    d = np.radians(np.asarray(delta_deg, float))
    t = np.arange(len(d)) * 1.0
    n = np.broadcast_to(np.asarray(rps, float), d.shape).copy()
    return MeasuredRun(name, name, np.random.default_rng(seed).normal(size=(len(d), 6)), ReplayInputs(t, d, n))


def test_folds_by_manoeuvre_put_records_of_one_class_in_different_folds():
    """Stratified by manoeuvre: the classes are told from the rudder and revolutions as a trial engineer
    would (a turn holds one side, a zigzag changes side, astern revolutions make a record astern, small
    rudder angles count for nothing), and two port turns that the file order puts in one fold go to two."""
    from trials.measured.identify import fold_of, manoeuvre_class

    hold = np.r_[np.zeros(10), np.full(90, 35.0)]
    zig = np.r_[np.zeros(10), np.tile(np.r_[np.full(20, 20.0), np.full(20, -20.0)], 2), np.zeros(10)]
    assert manoeuvre_class(_manoeuvre_run("s", hold, 10, 0)) == (0, 1, 10.0)
    assert manoeuvre_class(_manoeuvre_run("p", -hold + 1.5 * (hold == 0), 8, 0)) == (0, -1, 8.0)  # 1.5 deg is not a side
    assert manoeuvre_class(_manoeuvre_run("z", zig, 12, 0))[:2] == (1, 0)
    astern = np.where(np.arange(100) > 60, -6.0, 10.0)
    assert manoeuvre_class(_manoeuvre_run("a", hold, astern, 0))[:2] == (2, 0)
    one_glitch = np.where(np.arange(100) == 50, -0.1, 10.0)        # one noisy sample is not an astern phase
    assert manoeuvre_class(_manoeuvre_run("g", hold, one_glitch, 0))[:2] == (0, 1)
    assert manoeuvre_class(_manoeuvre_run("c", np.full(100, 1.0), 10, 0))[:2] == (3, 0)   # straight: no side
    # file order: stbd, port, stbd, stbd, port, zig, zig, zig -> with 4 folds the two port turns (1, 5 in
    # the order below) share fold 1
    kinds = [hold, -hold, hold, hold, zig, -hold, zig, zig]
    runs = [_manoeuvre_run(f"r{i}", k, 10, i) for i, k in enumerate(kinds)]
    assert fold_of(runs, 4, "order")[1] == fold_of(runs, 4, "order")[5]
    f = fold_of(runs, 4, "manoeuvre")
    port = [f[i] for i, k in enumerate(kinds) if k is not hold and k is not zig]
    stbd = [f[i] for i, k in enumerate(kinds) if k is hold]
    zz = [f[i] for i, k in enumerate(kinds) if k is zig]
    assert len(set(port)) == 2 and len(set(stbd)) == 3 and len(set(zz)) == 3
    assert sorted(np.bincount(f, minlength=4)) == [2, 2, 2, 2]


def test_a_rudder_offset_is_recovered_and_written_back_as_the_effect(tmp_path):
    """Records made with the blade 2 deg to starboard of the indicator: the freed ``rudder_offset``
    finds it, ship.yaml carries it as the ``rudder_offset`` effect, and that config replays the
    records as the identification scored them (what ``mmg predict --ship DIR/ship.yaml`` does)."""
    from mmg.model import P_RUDDER_OFFSET
    from trials.measured.predict import replay_record

    ship = mmg.load_ship(SHIP)
    pk = pack(ship)
    pk.p[P_RUDDER_OFFSET] = np.radians(2.0)
    runs = []
    for k in (0, 1):
        t = np.arange(0.0, 90.0 + 1e-9, 0.1)
        inp = _zigzag_inputs(t, amp_deg=15.0 + 10 * k, period=30.0 + 10 * k)
        runs.append(MeasuredRun(name=f"off{k}", source=f"off{k}", meas=replay(pk, inp, [0.35, 0, 0, 0, 0, 0]),
                                inputs=inp))
    ident = identify(ship, runs, free=["rudder_offset"], segment_s=(30.0, np.inf), say=lambda m: None)
    assert np.degrees(ident.fit.values()["rudder_offset"]) == pytest.approx(2.0, abs=0.02)
    assert ident.ship.effect_set().get("rudder_offset")["offset_deg"] == pytest.approx(2.0, abs=0.02)
    before = [x["heading_rms_deg"] for x in ident.scores(model="initial")]
    after = [x["heading_rms_deg"] for x in ident.scores()]
    assert max(after) < 0.02 * min(before)
    back = mmg.load_ship(write_identification(ident, mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path)["ship"])
    assert back.effect_set().get("rudder_offset")["offset_deg"] == pytest.approx(2.0, abs=0.02)
    from dataclasses import replace

    for r, a in zip(runs, after):                           # the written config replays as scored
        run = replace(r, effects=back.effect_set().without("wind"))
        assert replay_record(back, run).scores()["heading_rms_deg"] == pytest.approx(a, abs=1e-3)   # 6 digits in YAML


def test_per_record_currents_are_nuisances_that_keep_the_shared_fit_unbiased():
    """Two records made in two different currents (a pond's wind drift differs run to run): with a
    current per record as a nuisance the fit recovers each record's current and the hull coefficient
    that made them; the currents stay out of the identified ship."""
    from mmg.effects import effect_set

    ship = mmg.load_ship(SHIP)
    true = {"N_r": ship.hull.value("N_r") * 1.3}
    truth = ship.with_hull(true)
    currents = [(0.04, 0.0), (0.0, -0.03)]                     # north, east [m/s]
    runs = []
    for k, (cn, ce) in enumerate(currents):
        es = effect_set({"current": {"speed_mps": float(np.hypot(cn, ce)),
                                     "direction_deg": float(np.degrees(np.arctan2(ce, cn)))}})
        t = np.arange(0.0, 90.0 + 1e-9, 0.1)
        inp = _zigzag_inputs(t, amp_deg=15.0 + 10 * k, period=30.0 + 10 * k)
        s0 = es.to_model(np.array([[0.35, 0, 0, 0, 0, 0]], float))[0]
        logged = es.to_logged(replay(es.pack(pack(truth), truth), inp, s0))   # u, v over ground, as logged
        runs.append(MeasuredRun(name=f"c{k}", source=f"c{k}", meas=logged, inputs=inp))
    ident = identify(ship, runs, free=["N_r"], segment_s=(30.0, np.inf), say=lambda m: None,
                     record_nuisance=("current",))
    v = ident.fit.values()
    assert v["N_r"] == pytest.approx(true["N_r"], rel=0.02)
    for k, (cn, ce) in enumerate(currents):
        assert v[f"current.north_mps[c{k}]"] == pytest.approx(cn, abs=2e-3)
        assert v[f"current.east_mps[c{k}]"] == pytest.approx(ce, abs=2e-3)
    assert ident.ship.effect_set().get("current") is None         # not part of the identified ship
    own = [d[:, :2] for d in ident.fit_residuals()]          # u, v over ground: the fit's own replays keep each current
    pred = [ident.replay(r).pred[:, :2] - r.meas[:, :2] for r in runs]   # a prediction has none
    for k, c in enumerate(currents):
        speed = float(np.hypot(*c))
        assert np.sqrt(np.mean(np.sum(own[k] ** 2, axis=1))) < 0.1 * speed
        assert np.sqrt(np.mean(np.sum(pred[k] ** 2, axis=1))) > 0.5 * speed
    plain = identify(ship, runs, free=["N_r"], segment_s=(30.0, np.inf), say=lambda m: None)
    assert abs(plain.fit.values()["N_r"] / true["N_r"] - 1) > abs(v["N_r"] / true["N_r"] - 1)


def test_a_diverged_kept_out_replay_is_named_not_counted_better_and_left_out_of_both_means(tmp_path):
    ship = mmg.load_ship(SHIP)
    true = {"N_r": ship.hull.value("N_r") * 1.3}
    runs = _synthetic_runs(ship.with_hull(true), seeds=(0,), duration=60.0)
    ident = identify(ship, runs, free=list(true), segment_s=(30.0, np.inf), say=lambda m: None)
    h = lambda x: {"heading_rms_deg": x}                       # noqa: E731 (the one score the summary reads)
    cv = [{"name": "a", "fold": 0, "initial": h(10.0), "identified": h(2.0)},
          {"name": "b", "fold": 1, "initial": h(6.0), "identified": h(3.0)},
          {"name": "gone", "fold": 1, "initial": h(50.0), "identified": h(float("nan"))}]
    rep = write_identification(ident, mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path, cv)["report"].read_text()
    # means over a and b only: (10 + 6) / 2 = 8 against (2 + 3) / 2 = 2.5, ratio 3.2; "gone" is not better
    assert "| **mean** | | 8.00 | 2.50 | 3.20 |" in rep
    assert "better on 2 of 3" in rep
    assert "diverged on 1 kept-out record(s) (gone)" in rep


def test_fit_warnings_name_bounds_sign_changes_and_no_convergence():
    """IdentifyResult.warnings(): a value on a finite bound, a value of the opposite sign to a nonzero
    prior, and status 0 (evaluation limit) each give one sentence naming the parameter; values inside
    their bounds with their prior's sign, a zero prior and a converged fit give none."""
    from ekf.identify import FreeParameter, IdentifyResult

    free = [FreeParameter("Y_bb", "hull", 0, 0.6732, 0.3),                       # sign flips
            FreeParameter("w_P0", "const", 0, 0.3946, 0.2, lower=0.0, upper=0.9),  # on the lower bound
            FreeParameter("N_r", "hull", 1, -0.054, 0.03),                       # same sign, changed
            FreeParameter("N_0", "hull", 2, 0.0, 0.01),                           # zero prior: no sign to keep
            FreeParameter("epsilon", "const", 0, 1.0, 0.5, lower=0.1, upper=3.0)]  # inside its bounds
    theta = np.array([-1.131, 0.0, -0.0071, -0.002, 2.999])

    def result(status):
        return IdentifyResult(free=free, theta=theta, std=np.ones(5), corr=np.eye(5), cost_initial=2.0,
                              cost_final=1.0, n_residuals=100, iterations=30, message="limit", status=status)

    w = result(0).warnings()
    assert len(w) == 3
    assert w[0].startswith("Y_bb changed sign") and "0.6732" in w[0] and "-1.131" in w[0]
    assert w[1].startswith("w_P0 is at its lower bound 0")
    assert w[2].startswith("the fit stopped at its evaluation limit after 30 evaluations")
    assert result(1).warnings() == w[:2]
    assert IdentifyResult(free=free[2:], theta=theta[2:], std=np.ones(3), corr=np.eye(3), cost_initial=2.0,
                          cost_final=1.0, n_residuals=100, iterations=9, message="ok", status=2).warnings() == []


def test_velocity_weight_sets_whether_the_fit_follows_the_heading_or_a_biased_rate_gyro(tmp_path):
    """A rate gyro reading 30 % high (the heading clean, the start state true): a fit that counts the
    velocities a hundred times as much as the heading follows the gyro and makes the yaw damping N_r
    too weak (the replayed yaw rate larger); counting them a hundredth as much, it follows the heading
    and recovers the N_r that made the record.  Inverting or ignoring the weight fails one side."""
    ship = mmg.load_ship(SHIP)
    true = {"N_r": ship.hull.value("N_r") * 1.3}
    runs = []
    for r in _synthetic_runs(ship.with_hull(true), seeds=(0,), duration=90.0):
        meas = r.meas.copy()
        meas[1:, 2] *= 1.3
        runs.append(MeasuredRun(name=r.name, source=r.source, meas=meas, inputs=r.inputs))
    idents = {w: identify(ship, runs, free=list(true), segment_s=(np.inf,), say=lambda m: None, velocity_weight=w)
              for w in (100.0, 0.01)}
    ratio = {w: i.fit.values()["N_r"] / true["N_r"] for w, i in idents.items()}
    assert ratio[100.0] < 0.85, ratio                   # pulled by the gyro: weaker damping
    assert ratio[0.01] == pytest.approx(1.0, abs=0.03), ratio
    write_identification(idents[0.01], mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path)   # the report says how it was fitted
    assert "velocity residuals weighted 0.01 beside the heading's" in (tmp_path / "report.md").read_text()
    for bad in (0.0, -1.0, float("nan"), "ten", None):
        with pytest.raises(ValueError, match="velocity_weight"):
            identify(ship, runs, free=list(true), say=lambda m: None, velocity_weight=bad)


def test_propeller_walk_astern_is_recovered_written_back_and_sampled(tmp_path):
    """Records with the screw going astern, made with a lateral force Y_P = -0.02 rho n^2 D^4 the
    config does not have: the freed ``Y_P_astern`` finds it, ship.yaml carries it, and the IMO
    sampling reads it from the written covariance (a round trip of the parameter's plumbing; the
    force itself is checked against the written-out formula in tests/test_four_quadrant.py)."""
    from dataclasses import replace

    from trials.imo.sampling import _ship_values, covariance_of

    ship = mmg.load_ship(SHIP)
    true = replace(ship, propeller=replace(ship.propeller, Y_P_astern=-0.02))
    runs = []
    for k in (0, 1):
        t = np.arange(0.0, 80.0 + 1e-9, 0.1)
        n = np.where(np.sin(2 * np.pi * t / (40.0 + 10 * k)) > 0, 10.0, -12.0)    # ahead, then full astern
        inp = ReplayInputs(t=t, delta=np.radians(5.0 * k) * np.ones_like(t), n=n)
        runs.append(MeasuredRun(name=f"ast{k}", source=f"ast{k}",
                                meas=replay(pack(true), inp, [0.3, 0, 0, 0, 0, 0]), inputs=inp))
    ident = identify(ship, runs, free=["Y_P_astern"], segment_s=(20.0, np.inf), say=lambda m: None)
    assert ident.fit.values()["Y_P_astern"] == pytest.approx(-0.02, abs=0.001)
    out = write_identification(ident, mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path)
    back = mmg.load_ship(out["ship"])
    assert back.propeller.Y_P_astern == pytest.approx(-0.02, abs=0.001)
    names, mean, cov, _ = covariance_of(back)
    assert "Y_P_astern" in names and mean[names.index("Y_P_astern")] == pytest.approx(back.propeller.Y_P_astern, rel=1e-5)
    assert _ship_values(back, ["Y_P_astern"])[0] == back.propeller.Y_P_astern       # a covariance without values


def test_wind_shape_factors_are_recovered_scale_the_loads_and_are_written_back(tmp_path):
    """Records whose wind yaw moment is 1.8x and sway force 0.6x the loads the config computes from the
    measured wind (given here as prescribed loads, Fujiwara's from a steady 4 m/s relative wind on the
    bow quarter): the freed ``wind_sway_factor`` and ``wind_yaw_factor`` find them, ``with_fitted_wind``
    scales a record's loads as the fit did (X unchanged), and ship.yaml's ``wind:`` section carries
    the factors times the config's."""
    from dataclasses import replace

    import yaml

    from mmg.wind import wind_forces
    from trials.measured.identify import with_fitted_wind

    ship = mmg.load_ship(SHIP)
    runs = []
    for k in (0, 1):
        t = np.arange(0.0, 90.0 + 1e-9, 0.1)
        inp = _zigzag_inputs(t, amp_deg=15.0 + 10 * k, period=30.0 + 10 * k, n=6.0)
        X, Y, N = wind_forces(np.full_like(t, 4.0), np.full_like(t, np.radians(60.0 - 120.0 * k)), ship.wind.geometry)
        ext = np.column_stack([X, Y, N])
        truth = replace(inp, ext=ext * np.array([1.0, 0.6, 1.8]))
        runs.append(MeasuredRun(name=f"w{k}", source=f"w{k}", meas=replay(pack(ship), truth, [0.2, 0, 0, 0, 0, 0]),
                                inputs=replace(inp, ext=ext)))
    ident = identify(ship, runs, free=["wind_sway_factor", "wind_yaw_factor"], segment_s=(30.0, np.inf),
                     say=lambda m: None)
    v = ident.fit.values()
    assert v["wind_sway_factor"] == pytest.approx(0.6, abs=0.03) and v["wind_yaw_factor"] == pytest.approx(1.8, abs=0.03)
    scaled = with_fitted_wind(runs[0], v).inputs.ext
    assert np.allclose(scaled, runs[0].inputs.ext * [1.0, v["wind_sway_factor"], v["wind_yaw_factor"]])
    out = write_identification(ident, mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path)
    w = yaml.safe_load(open(out["ship"]))["wind"]
    assert w["sway_factor"] == pytest.approx(ship.wind.sway_factor * v["wind_sway_factor"], rel=1e-5)
    assert w["yaw_factor"] == pytest.approx(ship.wind.yaw_factor * v["wind_yaw_factor"], rel=1e-5)
    back = mmg.load_ship(out["ship"])
    assert back.wind.yaw_factor == pytest.approx(ident.ship.wind.yaw_factor, rel=1e-5)


def test_propeller_walk_is_not_fitted_on_records_that_never_go_astern():
    """With no record astern the term has no information: it is left out of the fit (and so out of the
    covariance the IMO sampling draws from), and the run says so."""
    ship = mmg.load_ship(SHIP)
    runs = _synthetic_runs(ship, seeds=(0,), duration=30.0)
    said = []
    ident = identify(ship, runs, free=["Y_P_astern", "w_P0"], segment_s=(15.0,), say=said.append, max_nfev=2)
    assert [f.name for f in ident.fit.free if f.kind != "start"] == ["w_P0"]
    assert any("Y_P_astern not fitted" in m for m in said)


def test_fitted_wind_factors_multiply_the_configs_and_stay_within_its_range(tmp_path):
    """A config whose wind yaw factor is 1.4: a fitted factor f is a factor on the loads it computes, so
    ship.yaml writes 1.4 f, and the fit's bound is 3 / 1.4 so that what is written loads."""
    import yaml

    from ekf.identify import free_parameters
    from trials.measured.identify import _bounded_wind

    data = yaml.safe_load(open(mmg.config_path("ships", f"{SHIP}.yaml")))
    data["wind"]["yaw_factor"] = 1.4
    path = tmp_path / "ship.yaml"
    path.write_text(yaml.safe_dump(data))
    ship = mmg.load_ship(path)
    (f,) = _bounded_wind(ship, free_parameters(pack(ship), ship.hull.names, ["wind_yaw_factor"]))
    assert f.upper == pytest.approx(3.0 / 1.4) and f.lower == pytest.approx(0.2 / 1.4)
    out = tmp_path / "out.yaml"
    out.write_text(ship_yaml(path, {"wind_yaw_factor": f.upper}, "test"))
    assert mmg.load_ship(out).wind.yaw_factor == pytest.approx(3.0, rel=1e-5)


def test_pooled_residuals_are_in_record_order_whatever_order_the_pool_runs_them():
    """The pool takes the records longest first; the residual vector must still hold each record's block in
    the records' order: equal, bit for bit, to the serial evaluation, with records given shortest first."""
    from concurrent.futures import ThreadPoolExecutor

    from ekf.identify import FitOptions, _SegmentFit

    ship = mmg.load_ship(SHIP)
    runs = [_synthetic_runs(ship, seeds=(k,), duration=d)[0] for k, d in ((0, 30.0), (1, 90.0), (2, 60.0))]
    pk = pack(ship)
    free = free_parameters(pk, ship.hull.names, ["N_r", "Y_beta"])
    segs = [Segmented(r.name, r.meas, r.inputs, segment_resets(r.t, 20.0)) for r in runs]
    with ThreadPoolExecutor(max_workers=2) as pool:
        fit = _SegmentFit(pk, segs, free, Scales(0.005, 0.005, 0.001, np.radians(0.5)), FitOptions(), pool)
        assert fit.longest_first == [1, 2, 0]
        theta = fit.theta0 * 1.1
        pooled, serial = fit.resid(theta), fit.resid(theta, parallel=False)
    assert np.array_equal(pooled, serial)
    assert len(pooled) == fit.start[-1] + len(free)                  # the blocks, then the prior's rows
    first = fit.block(theta, 0)                                      # the shortest record's block comes first
    assert np.array_equal(pooled[: len(first)], first)


def test_fit_residuals_are_the_replay_errors_of_the_fitted_model_in_si_units():
    """From the first sample, no nuisance: the fit's own residuals are the identified model's open-loop
    replay (trials.measured.predict.replay_record, another code path) minus the record, u, v [m/s],
    r [rad/s], heading [rad]; a record whose replay fails gives NaN, not the fit's finite stand-in."""
    ship = mmg.load_ship(SHIP)
    runs = _synthetic_runs(ship.with_hull({"N_r": ship.hull.value("N_r") * 1.2}), duration=60.0)
    kw = dict(free=["N_r"], segment_s=(np.inf,), say=lambda m: None, initial_state="sample", max_nfev=3)
    other = identify(mmg.load_ship(f"{SHIP}_crossflow"), runs, initial=ship, **kw)    # fitted in another form
    assert other.prior is not None
    ident = identify(ship, runs, **kw)
    for fitted in (ident, other):
        for r, d in zip(runs, fitted.fit_residuals()):
            err = fitted.replay(r).pred - r.meas
            assert d.shape == (len(r.t), 4)
            for j, c in enumerate((0, 1, 2, 5)):
                np.testing.assert_allclose(d[:, j], err[:, c], atol=1e-6 * np.abs(err[:, c]).max())
    assert np.abs(ident.fit_residuals(stride=3)[0] - ident.fit_residuals()[0][::3]).max() == 0.0
    bad = MeasuredRun(name="bad", source="bad", meas=runs[0].meas.copy(), inputs=runs[0].inputs)
    from dataclasses import replace
    broken = replace(ident, runs=[bad], fit=replace(ident.fit, theta=np.array([np.nan])))
    assert np.isnan(broken.fit_residuals()[0][1:]).all()             # after the start sample, which is the record's


def test_cv_report_sets_the_written_std_against_the_folds_jackknife(tmp_path):
    """--cv's report: per parameter, the std written into ship.yaml beside the delete-a-group jackknife of
    the folds' fits, sqrt((K-1)/K sum (theta_i - mean)^2), and their ratio; folds of another free set than
    the written fit's are not compared."""
    import re

    from trials.measured.identify import cross_validate

    ship = mmg.load_ship(SHIP)
    runs = _synthetic_runs(ship.with_hull({"N_r": ship.hull.value("N_r") * 1.2}), seeds=(0, 1, 2), duration=40.0)
    kw = dict(free=["N_r", "N_beta"], segment_s=(np.inf,), say=lambda m: None, max_nfev=4)
    ident = identify(ship, runs, **kw)
    cv = cross_validate(ship, runs, folds=3, **kw)
    rep = write_identification(ident, mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path, cv)["report"].read_text()
    assert "## The written standard errors against the folds' spread" in rep
    written = mmg.load_ship(tmp_path / "ship.yaml").covariance
    for name in ("N_r", "N_beta"):
        th = np.array([next(c["values"][name] for c in cv if c["fold"] == k) for k in range(3)])
        jk = np.sqrt(2 / 3 * np.sum((th - th.mean()) ** 2))
        std = written.std()[written.names.index(name)]
        row = re.search(rf"^\| {name} \| \S+ \| (\S+) \| (\S+) \| (\S+) \|", rep, flags=re.M)
        assert float(row[1]) == pytest.approx(std, rel=0.05) and float(row[2]) == pytest.approx(jk, rel=0.05)
        assert float(row[3]) == pytest.approx(jk / std, abs=0.06)
    other = cross_validate(ship, runs, folds=3, **{**kw, "free": ["N_r"]})
    rep2 = write_identification(ident, mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path, other)["report"].read_text()
    assert "no fold spread" in rep2 and "## The written standard errors" not in rep2


def test_jacobian_reuses_the_residuals_just_evaluated_and_not_a_stale_copy(monkeypatch):
    # every Jacobian starts at a point the solver has just evaluated: counted replays show one saved per
    # Jacobian, and the fit is the same as when every residual vector is made afresh
    import ekf.identify as I

    ship = mmg.load_ship(SHIP)
    true = {"N_r": ship.hull.value("N_r") * 1.3, "N_beta": ship.hull.value("N_beta") * 0.8}
    runs = _synthetic_runs(ship.with_hull(true), seeds=(0,), duration=60.0)
    pk = pack(ship)
    free = free_parameters(pk, ship.hull.names, list(true))
    segs = [Segmented(r.name, r.meas, r.inputs, segment_resets(r.t, 30.0)) for r in runs]
    sc = Scales(0.005, 0.005, 0.001, np.radians(0.5))
    calls = []
    one = I._residual_one
    monkeypatch.setattr(I, "_residual_one", lambda *a, **k: calls.append(1) or one(*a, **k))
    cached = identify_segments(pk, segs, free, sc, n_jobs=1, max_nfev=6)
    n_cached = len(calls)
    monkeypatch.setattr(I._SegmentFit, "resid", lambda self, theta, parallel=True: self._resid(theta, parallel))
    calls.clear()
    fresh = identify_segments(pk, segs, free, sc, n_jobs=1, max_nfev=6)
    assert np.array_equal(cached.theta, fresh.theta) and cached.cost_final == fresh.cost_final
    assert np.array_equal(cached.std, fresh.std)
    # fresh: 1 initial + nfev evaluations + (1 + n columns) per Jacobian; cached: one fewer per Jacobian,
    # and the solver's first evaluation at the start (the priors) is the initial one
    n_jac = (len(calls) - 1 - fresh.iterations) // (1 + len(free))
    assert n_jac >= 2
    assert n_cached <= len(calls) - n_jac
