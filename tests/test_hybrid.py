"""The learned correction of the MMG model's residual forces (trials.measured.hybrid)."""
import numpy as np
import pytest

from tests.conftest import load_bench

pytest.importorskip("sklearn")

from mmg.model import P_D, P_L, P_RHO, P_T, P_ULOW, pack  # noqa: E402
from mmg.replay import ReplayInputs, replay_states  # noqa: E402
from trials.measured.hybrid import (Correction, CorrectionForm, CorrectionSelection, fit_correction,  # noqa: E402
                                    hybrid_states, replay_hybrid, residual_samples)
from trials.measured.predict import MeasuredRun  # noqa: E402

DY_R, DN_R = 0.03, -0.01
"""The hull's Y_r', N_r' of the records' ship minus the model's: the residual sway force and yaw moment
the correction must learn."""


def _constant(b2, lo=-1.0, hi=1.0) -> Correction:
    """A correction of constant value ``b2`` (X', Y', N') inside the box [lo, hi]^5 (unit scales, mean 0)."""
    return Correction(kind="ridge", mu=np.zeros(5), sd=np.ones(5), lo=np.full(5, lo), hi=np.full(5, hi),
                      A=np.zeros((1, 5)), b1=np.zeros(1), W2=np.zeros((1, 3)), b2=np.asarray(b2, float), alpha=0.0)


def _inputs(k: int) -> ReplayInputs:
    """A 150 s zigzag-like rudder history (amplitude and period differ with k), 10 rps, at 10 Hz."""
    t = np.arange(0.0, 150.0, 0.1)
    delta = np.radians(10.0 + 5.0 * k) * np.sin(2 * np.pi * t / (30.0 + 8.0 * k))
    return ReplayInputs(t=t, delta=delta, n=np.full_like(t, 10.0))


def _records(ship, k_list):
    """Records of ``ship`` (the standard replay from 0.5 m/s ahead), each of its own run (other start x)."""
    out = []
    for k in k_list:
        inp = _inputs(k)
        meas = replay_states(pack(ship), inp, [0.5, 0.0, 0.0, float(k), 0.0, 0.0])
        out.append(MeasuredRun(name=f"rec{k}", source="", meas=meas, inputs=inp))
    return out


@pytest.fixture(scope="module")
def truth(esso3m_ship):
    ship = esso3m_ship
    h = dict(zip(ship.hull.names, ship.hull.values))
    return ship, ship.with_hull({"Y_r": h["Y_r"] + DY_R, "N_r": h["N_r"] + DN_R})


@pytest.fixture(scope="module")
def esso3m_ship():
    from mmg.ship import load_ship

    return load_ship("esso_osaka_3m")


def test_zero_correction_is_the_replay(esso3m_ship):
    """With a correction that is zero everywhere the corrected replay is mmg.replay's, bit for bit."""
    p = pack(esso3m_ship)
    inp = _inputs(1)
    s0 = [0.5, 0.01, 0.0, 0.0, 0.0, 0.1]
    assert np.array_equal(hybrid_states(p, inp, s0, _constant([0.0, 0.0, 0.0])), replay_states(p, inp, s0))


def test_constant_correction_is_an_external_force(esso3m_ship):
    """A constant Y' inside the box acts as the external force Y' 1/2 rho L T V^2 would in the standard replay
    (V^2 = u^2 + v^2 + (n D)^2 + U_low^2, computed here): with the force from the replayed states the two agree."""
    p = pack(esso3m_ship)
    inp = _inputs(0)
    s0 = [0.5, 0.0, 0.0, 0.0, 0.0, 0.0]
    yp = 0.002
    hy = hybrid_states(p, inp, s0, _constant([0.0, yp, 0.0], lo=-10.0, hi=10.0))
    u, v = hy[:, 0], hy[:, 1]
    V2 = u ** 2 + v ** 2 + (inp.n * p.p[P_D]) ** 2 + p.p[P_ULOW] ** 2
    Y = yp * 0.5 * p.p[P_RHO] * p.p[P_L] * p.p[P_T] * V2
    ext = np.column_stack([np.zeros_like(Y), Y, np.zeros_like(Y)])
    ref = replay_states(p, ReplayInputs(t=inp.t, delta=inp.delta, n=inp.n, ext=ext), s0)
    plain = replay_states(p, inp, s0)
    assert np.degrees(np.abs(hy[:, 5] - plain[:, 5])).max() > 5.0          # the force matters
    assert np.degrees(np.abs(hy[:, 5] - ref[:, 5])).max() < 0.05          # and is that force


def test_outside_flag_and_damping():
    """A state outside the training box is flagged; the correction there is the box edge's, damped by
    exp(-(d / 0.25)^2) with d the distance outside in training standard deviations."""
    c = _constant([0.1, 0.2, 0.3])
    f = np.array([[0.0, 0.5, -0.5, 0.9, 0.0], [0.0, 0.0, 1.1, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, -2.0]])
    assert c.outside(f).tolist() == [False, True, True]
    got = c.predict(f)
    assert np.allclose(got[0], [0.1, 0.2, 0.3])
    assert np.allclose(got[1], np.array([0.1, 0.2, 0.3]) * np.exp(-(0.1 / 0.25) ** 2))
    assert np.allclose(got[2], 0.0, atol=1e-6)


def test_residual_of_a_known_hull_term_is_recovered(truth):
    """Records of a ship whose Y_r', N_r' are the model's + 0.03, - 0.01: the residual sway force is
    0.03 r' 1/2 rho L T U^2, i.e. Y' = 0.03 (r L / V)(U / V) in the correction's units (an independent
    formula), the yaw moment N' = -0.01 (r L / V)(U / V); X' is zero."""
    model, rec_ship = truth
    runs = _records(rec_ship, [0, 1, 2, 3])
    p = pack(model)
    s = residual_samples(p, runs)
    u, v, r = (np.concatenate([x.meas[::1, j] for x in runs]) for j in range(3))
    n = np.concatenate([x.inputs.n for x in runs])
    V = np.sqrt(u ** 2 + v ** 2 + (n * p.p[P_D]) ** 2 + p.p[P_ULOW] ** 2)
    shape = (r * p.p[P_L] / V) * (np.hypot(u, v) / V)
    inner = np.abs(np.arange(len(u)) % 1500 - 750) < 700                   # away from each record's ends
    c = fit_correction(p, runs, CorrectionForm("ridge", degree=2), CorrectionSelection(stride=3))
    for axis, d in ((1, DY_R), (2, DN_R)):
        want = d * shape
        err = s.target[inner, axis] - want[inner]
        assert np.sqrt(np.mean(err ** 2)) < 0.05 * np.sqrt(np.mean(want[inner] ** 2))
        pred = c.predict(s.features)[:, axis]
        assert np.sqrt(np.mean((pred - want) ** 2)) < 0.2 * np.sqrt(np.mean(want ** 2))
    assert np.abs(s.target[inner, 0]).max() < 0.05 * np.abs(DY_R * shape[inner]).max()
    assert c.records == ["rec0", "rec1", "rec2", "rec3"]


def test_corrected_replay_of_a_kept_out_record(truth):
    """Fitted on three records, the corrected model replays a fourth (not in its fit) closer to the truth
    than the model alone does."""
    model, rec_ship = truth
    train, (test,) = _records(rec_ship, [0, 1, 3]), _records(rec_ship, [2])
    p = pack(model)
    c = fit_correction(p, train, CorrectionForm("ridge", degree=2), CorrectionSelection(stride=3))
    assert "rec2" not in c.records
    rms = lambda a: float(np.sqrt(np.mean(np.degrees(a[:, 5] - test.meas[:, 5]) ** 2)))  # noqa: E731
    plain = rms(replay_states(p, test.inputs, test.meas[0]))
    hyb = replay_hybrid(model, test, c, p)
    assert hyb.diverged_at is None
    assert plain > 2.0
    assert rms(hyb.pred) < 0.25 * plain
    assert c.outside_share(p, test) < 0.2


def test_refuses_runs_with_other_effects(esso3m_ship):
    import mmg.effects as E

    run = _records(esso3m_ship, [0])[0]
    from dataclasses import replace

    bad = replace(run, effects=E.effect_set({"rudder_offset": {"offset_deg": 1.0}}))
    with pytest.raises(ValueError, match="rec0"):
        residual_samples(pack(esso3m_ship), [bad])


def test_bench_summary_by_kind():
    """The bench's per-kind means are over the records every model kept finite; divergences counted."""
    b = load_bench("hybrid_cv")

    def rec(name, s, i, c, c_div=None):
        w = lambda x: {"heading_rms_deg": x, "window_heading_rms_deg": x / 2, "window_diverged": 0, "n_windows": 3}  # noqa: E731
        return {"name": name, "kind": name.split("_")[0], "scaled": {**w(s), "diverged_at_s": None},
                "identified": {**w(i), "diverged_at_s": None},
                "ridge-2": {**w(c), "diverged_at_s": c_div, "outside_share": 0.1}}

    recs = [rec("turn_a", 40.0, 20.0, 10.0), rec("turn_b", 60.0, 30.0, 50.0, c_div=12.0), rec("zigzag_a", 10, 8, 6)]
    out = {r["kind"]: r for r in b.summarise(recs, ["scaled", "identified", "ridge-2"])}
    assert out["turn"]["n"] == 2 and out["turn"]["n_finite"] == 1
    assert out["turn"]["identified"]["heading_rms_deg"] == 20.0
    assert out["turn"]["ridge-2"]["diverged"] == 1
    assert out["turn"]["ridge-2"]["window_heading_rms_deg"] == pytest.approx(15.0)
    assert out["all"]["scaled"]["heading_rms_deg"] == pytest.approx(25.0)
    assert out["all"]["ridge-2"]["outside_share"] == pytest.approx(0.1)


def test_output_error_correction_of_a_known_hull_term(truth):
    """The output-error fit on three records of the altered ship replays a fourth closer than the model alone,
    and its cross-validation over the training records prefers a correction to none."""
    from trials.measured.hybrid import fit_output_correction

    model, rec_ship = truth
    train, (test,) = _records(rec_ship, [0, 1, 3]), _records(rec_ship, [2])
    p = pack(model)
    c = fit_output_correction(p, train, degree=1)
    assert np.isfinite(c.alpha)
    assert c.cv[c.alpha]["mean_window_heading_rms_deg"] < c.cv[float("inf")]["mean_window_heading_rms_deg"]
    rms = lambda a: float(np.sqrt(np.mean(np.degrees(a[:, 5] - test.meas[:, 5]) ** 2)))  # noqa: E731
    assert rms(replay_hybrid(model, test, c, p).pred) < 0.5 * rms(replay_states(p, test.inputs, test.meas[0]))


def test_window_choice_turns_on_a_correction_that_helps(truth):
    """Chosen by the grouped held-out window replays, the correction of a real residual is on (a finite
    penalty whose windows beat no correction's), and a bad select name or form kind is refused."""
    model, rec_ship = truth
    c = fit_correction(pack(model), _records(rec_ship, [0, 1, 2, 3]), CorrectionForm("ridge", degree=2),
                       CorrectionSelection(stride=3, select="windows"))
    assert np.isfinite(c.alpha)
    assert c.cv[c.alpha]["mean_window_heading_rms_deg"] < 0.5 * c.cv[float("inf")]["mean_window_heading_rms_deg"]
    with pytest.raises(ValueError, match="select"):
        CorrectionSelection(select="best")
    with pytest.raises(ValueError, match="kind"):
        CorrectionForm(kind="forest")


def test_bench_variant_names():
    b = load_bench("hybrid_cv")
    assert b.variant_options("ridge-3") == {"kind": "ridge", "degree": 3, "select": "forces"}
    assert b.variant_options("mlp-16/windows") == {"kind": "mlp", "hidden": 16, "select": "windows"}
    with pytest.raises(SystemExit):
        b.variant_options("mlp-16/output")


def test_a_subset_of_the_samples_indexes_its_own_records():
    """``ResidualSamples.of`` keeps the chosen records' samples, and ``record`` then indexes the subset's
    ``names``: the first kept record is 0, the next 1, whatever their indices before."""
    from trials.measured.hybrid import ResidualSamples

    rec = np.array([0, 0, 1, 1, 1, 2])
    s = ResidualSamples(features=np.arange(12.0).reshape(6, 2), target=np.zeros((6, 3)), weight=np.ones(6),
                        group=rec.copy(), record=rec, names=["a", "b", "c"])
    sub = s.of([2, 0])
    assert sub.names == ["a", "c"]
    np.testing.assert_array_equal(sub.record, [0, 0, 1])
    np.testing.assert_array_equal(sub.features[:, 0], [0.0, 2.0, 10.0])
    assert all(sub.names[i] in ("a", "c") for i in sub.record)
