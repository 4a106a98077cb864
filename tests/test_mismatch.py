"""The mismatch family (trials.measured.mismatch): factors within the spec, members built from them,
records logged as the development set's (noise, port turn, zigzag length).  Expected values come from
the config YAML and the development set's README, not from the module."""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

import mmg
from trials.measured.mismatch import MismatchSpec, TrialConditions, mismatch_family, trial_records

REPO = Path(__file__).resolve().parents[1]
YAML = yaml.safe_load((REPO / "configs" / "ships" / "esso_osaka.yaml").read_text())

# the development set's README: uniform noise half-widths
HALF = {"x": 0.5, "y": 0.5, "u": 0.02, "v": 0.02, "psi": math.radians(0.05), "r": 0.0002}


@pytest.fixture(scope="module")
def family():
    return mismatch_family(mmg.load_ship("esso_osaka"), 12, seed=7)


def test_factors_within_the_spec_with_both_signs(family):
    sp = MismatchSpec()
    linear = {n for n, c in YAML["hull"]["coefficients"].items() if c["term"] in ("beta", "r", "cos(beta)^2")}
    groups = {"hull_linear": [], "hull_nonlinear": [], "rudder": [], "propeller": [], "mass": [], "wind": []}
    for _, f in family:
        for name, x in f["hull"].items():
            groups["hull_linear" if name in linear else "hull_nonlinear"].append(x - 1.0)
        for key in ("rudder", "propeller", "mass", "wind"):
            groups[key] += [x - 1.0 for x in f[key].values()]
    half = {"hull_linear": 0.10, "hull_nonlinear": 0.25, "rudder": 0.15, "propeller": 0.15, "mass": 0.10, "wind": 0.30}
    assert sp.hull_linear == half["hull_linear"] and sp.hull_nonlinear == half["hull_nonlinear"]
    for key, d in groups.items():
        d = np.array(d)
        assert np.all(np.abs(d) <= half[key]), key
        assert (d > 0).any() and (d < 0).any(), key
        assert np.abs(d).max() > 0.5 * half[key], key          # the draws fill the range, not a sliver of it
    forms = [f["hull_form"] for _, f in family]
    assert forms.count("crossflow") == 3 and forms.count("kijima") == 9          # a quarter of 12


def test_members_are_the_config_times_their_factors(family):
    coef = YAML["hull"]["coefficients"]
    for ship, f in family:
        if f["hull_form"] == "kijima":
            for name, c in coef.items():
                want = c["value"] * f["hull"].get(name, 1.0)
                assert ship.hull.value(name) == pytest.approx(want, rel=1e-12), name
            assert set(f["hull"]) == {n for n, c in coef.items() if c["term"] != "1"}
        else:
            # the Kijima nonlinear sway and yaw terms are gone, cross-flow drag terms are in
            terms = dict(zip(ship.hull.names, ship.hull.terms))
            assert "int(|v+x*r|*(v+x*r))" in terms.values() and "int(x*|v+x*r|*(v+x*r))" in terms.values()
            assert "beta^2*r" not in terms.values()
            for name in ("Y_beta", "Y_r", "N_beta", "N_r", "X_uu", "X_br"):
                assert ship.hull.value(name) == pytest.approx(coef[name]["value"] * f["hull"][name], rel=1e-12)
        for k, x in f["rudder"].items():
            assert getattr(ship.rudder, k) == pytest.approx(YAML["rudder"][k] * x, rel=1e-12), k
        for k, x in f["mass"].items():
            assert getattr(ship.mass, k) == pytest.approx(YAML["mass"][k] * x, rel=1e-12), k
        p = YAML["propeller"]
        assert ship.propeller.w_P0[0] == pytest.approx(p["w_P0"][0] * f["propeller"]["w_P0"], rel=1e-12)
        assert ship.propeller.w_P0[1:] == pytest.approx(p["w_P0"][1:], rel=1e-12)
        assert ship.propeller.t_P[0] == pytest.approx(p["t_P"][0] * f["propeller"]["t_P"], rel=1e-12)
        assert ship.propeller.K_T == pytest.approx([c * f["propeller"]["K_T"] for c in p["K_T"]], rel=1e-12)
        w = f["wind"]                                   # surge, sway, yaw loads on their own factors
        assert ship.wind.scale == pytest.approx(w["surge"])
        assert ship.wind.scale * ship.wind.sway_factor == pytest.approx(w["sway"])
        assert ship.wind.scale * ship.wind.yaw_factor == pytest.approx(w["yaw"])


def test_crossflow_member_keeps_the_kijima_nonlinear_forces_roughly(family):
    """The cross-flow hull's nonlinear sway force tracks the Kijima one it was fitted to (within its
    own +-25 % perturbation and the form's misfit) at a drift of 15 deg in a turn r' = 0.4."""
    from mmg.terms import crossflow_N, crossflow_Y

    c = {n: v["value"] for n, v in YAML["hull"]["coefficients"].items()}
    b, r = math.radians(15.0), 0.4
    kij = c["Y_bb"] * b * abs(b) + c["Y_rr"] * r * abs(r) + c["Y_bbr"] * b * b * r + c["Y_brr"] * b * r * r
    ship, _ = next(m for m in family if m[1]["hull_form"] == "crossflow")
    h = dict(zip(ship.hull.names, zip(ship.hull.terms, ship.hull.values)))
    val = {"int(|v+x*r|*(v+x*r))": crossflow_Y(-math.sin(b), r), "int(x*|v+x*r|*(v+x*r))": crossflow_N(-math.sin(b), r),
           "r|r|": r * abs(r)}
    ax = dict(zip(ship.hull.names, ship.hull.axes))
    cf = sum(v * val[t] for n, (t, v) in h.items() if ax[n] == "Y" and t in val)
    assert cf == pytest.approx(kij, rel=0.5)


@pytest.fixture(scope="module")
def config():
    return mmg.load_ship("esso_osaka")


def test_records_have_the_dev_sets_uniform_noise(config, family):
    member = family[0][0]
    noisy = trial_records(config, member, "turn35", {}, seed=3)
    clean = trial_records(config, member, "turn35", {}, seed=3, noise=(0.0,) * 6)
    assert noisy.t[1] - noisy.t[0] == 1.0 and noisy.t[-1] == pytest.approx(1510.0)
    for ch, h in HALF.items():
        e = getattr(noisy, ch) - getattr(clean, ch)
        if ch == "psi":
            e = np.angle(np.exp(1j * e))
        assert np.abs(e).max() <= h * (1 + 1e-9), ch
        assert np.std(e) == pytest.approx(h / math.sqrt(3.0), rel=0.08), ch      # std of a uniform on [-h, h]


def test_port_turn_turns_to_port_and_starboard_to_starboard(config, family):
    member = family[1][0]
    port = trial_records(config, member, "turn35p", {}, seed=1)
    stbd = trial_records(config, member, "turn35", {}, seed=1)
    dpsi = lambda rec: math.degrees(np.unwrap(rec.psi)[-1] - rec.psi[0])  # noqa: E731
    assert dpsi(port) < -270.0 and dpsi(stbd) > 270.0
    assert port.delta[-1] == pytest.approx(-math.radians(35.0), abs=1e-6)
    assert np.all(np.abs(port.delta[port.t < 9.5]) < math.radians(1.0))          # 10 s straight approach
    assert np.mean(port.u[:10]) == pytest.approx(10 * 1852 / 3600, abs=0.03)       # 10 kn


def test_zigzag_ends_sixty_seconds_after_its_ninth_reversal(config, family):
    rec = trial_records(config, replace(family[2][0]), "zz20", {}, seed=2)
    d = np.asarray(rec.delta)
    flips = np.flatnonzero(np.sign(d[1:]) != np.sign(d[:-1])) + 1
    flips = flips[rec.t[flips] > 11.0]
    assert len(flips) == 9
    assert rec.t[-1] == pytest.approx(rec.t[flips[-1]] + 60.0, abs=1.0)
    assert np.max(np.abs(d)) == pytest.approx(math.radians(20.0), abs=1e-6)


def test_port_first_zigzag_puts_port_rudder_first_and_swings_to_port_first(config, family):
    rec = trial_records(config, family[3][0], "zz15p", TrialConditions(speed_kn=7.0), seed=4, noise=(0.0,) * 6)
    d = np.asarray(rec.delta)
    big = d[np.abs(d) > math.radians(5.0)]
    assert big[0] < 0.0                                                      # port rudder first
    assert np.max(np.abs(d)) == pytest.approx(math.radians(15.0), abs=1e-6)
    psi = np.degrees(np.unwrap(rec.psi))
    first = psi[np.argmax(np.abs(psi) > 15.0)]                             # first +-15 deg heading crossing
    assert first < -15.0
    assert np.mean(rec.u[:10]) == pytest.approx(7 * 1852 / 3600, abs=0.03)   # 7 kn approach
    flips = np.flatnonzero(np.sign(d[1:]) != np.sign(d[:-1])) + 1
    assert len(flips[rec.t[flips] > 11.0]) == 9


def test_trial_names_say_their_hand_and_size():
    from trials.measured.mismatch import DEV_TRIALS, TRIALS, WIDE_TRIALS, trial_hand

    assert set(DEV_TRIALS) < set(WIDE_TRIALS) == set(TRIALS)
    for name, tr in TRIALS.items():
        size = float(name.removeprefix("turn").removeprefix("zz").removesuffix("p"))
        assert abs(tr["rudder_deg"]) == size
        assert trial_hand(name) == ("port" if name.endswith("p") else "starboard")
        assert (tr["kind"] == "zigzag") == name.startswith("zz")
    assert {abs(t["rudder_deg"]) for t in TRIALS.values() if t["kind"] == "turning"} == {15, 20, 25, 30, 35}


def test_wide_draw_spans_hands_manoeuvres_speeds_and_winds_beside_each_effect():
    import sys

    sys.path.insert(0, str(REPO / "bench"))
    import diagnose_mismatch as dm
    from trials.measured.mismatch import TRIALS, trial_hand

    effects = ["current", "wind", "heading_bias", "rudder_offset"]
    jobs = dm.wide_jobs(40, 3, effects, 1)
    assert len({j["id"] for j in jobs}) == len(jobs) and len({j["seed"] for j in jobs}) == len(jobs)
    clean = [j for j in jobs if j["effect"] is None]
    assert len(clean) == 40
    classes = {(trial_hand(j["trial"]), TRIALS[j["trial"]]["kind"]) for j in clean}
    assert classes == {(h, k) for h in ("starboard", "port") for k in ("turning", "zigzag")}
    assert all(6.0 <= j["speed_kn"] <= 15.0 for j in jobs)
    assert max(j["speed_kn"] for j in jobs) - min(j["speed_kn"] for j in jobs) > 6.0
    for e in ("current", "heading_bias", "rudder_offset"):
        both = [j for j in jobs if j["effect"] == f"wind+{e}"]
        assert len(both) == 3 * len(dm.WIDE_BESIDE_WIND)
        assert all(set(j["spec"]) == {"wind", e} and j["true_wind"][0] >= 15.0 for j in both)
    assert all(TRIALS[j["trial"]]["kind"] == "zigzag" for j in jobs if "rudder_offset" in (j["effect"] or ""))
    wind = [j["true_wind"][0] for j in jobs if j["effect"] == "wind"]
    assert min(wind) == 8.0 and max(wind) == 25.0
    assert dm.jobs(5, 1, ["current"], 0) == dm.jobs(5, 1, ["current"], 0)          # the old draw is untouched
    assert {j["trial"] for j in dm.jobs(5, 0, [], 0)} == set(dm.KINDS)


def test_class_figures_count_by_the_records_truth():
    import sys

    sys.path.insert(0, str(REPO / "bench"))
    import diagnose_mismatch as dm

    def row(trial, effect, truth, named, v=10.0):
        return {"trial": trial, "effect": effect, "truth": truth, "named": named, "speed_kn": v}

    rows = [row("zz20p", None, {}, ["current"], 6.5), row("zz20p", None, {}, []),
            row("zz10p", "wind+rudder_offset", {"wind": {"speed_mps": 20.0}, "rudder_offset": {"offset_deg": -1.0}},
                ["wind", "heading_bias"]),
            row("turn20", "rudder_offset", {"rudder_offset": {"offset_deg": 1.5}}, []),
            row("turn25p", "current", {"current": {"speed_mps": 0.1, "direction_deg": 3.0}}, [])]
    f = dm.class_figures(rows)
    assert f["false_alarms"] == [1, 2]
    assert f["rudder_offset"] == [0, 1]              # the turn's offset is not counted; the zigzag's missed
    assert f["current"] == [0, 0]                    # 0.1 m/s is under the 0.15 m/s counted
    assert f["wind"] == [1, 1] and f["wind_no_spurious"] == [0, 1]
    assert dm.record_class(rows[0]) == ("port", "zigzag", "6-9 kn")
    assert dm.record_class(rows[3]) == ("starboard", "turn", "9-12 kn")
    assert dm.record_class(row("zz10", None, {}, [], 15.0))[2] == "12-15 kn"


def test_class_figures_read_a_model_scale_truth_at_full_scale():
    """A Froude-scaled record (lambda = 45.7) holds its current at model scale: 0.03 m/s there is
    0.03 sqrt(45.7) = 0.203 m/s at full scale, above the 0.15 m/s counted; 0.02 (0.135 full) is under it;
    an angle (a bias) is the same at either scale."""
    import sys

    sys.path.insert(0, str(REPO / "bench"))
    import diagnose_mismatch as dm

    lam = 45.7
    rows = [{"trial": "zz20", "effect": "current", "truth": {"current": {"speed_mps": c}}, "named": ["current"],
             "speed_kn": 10.0, "froude_scale": lam} for c in (0.03, 0.02)]
    rows.append({"trial": "zz20", "effect": "heading_bias", "truth": {"heading_bias": {"bias_deg": 1.2}},
                 "named": [], "speed_kn": 10.0, "froude_scale": lam})
    assert dm.true_sizes(rows[0])["current"] == pytest.approx(0.03 * lam ** 0.5)
    f = dm.class_figures(rows)
    assert f["current"] == [1, 1] and f["heading_bias"] == [0, 1]


def test_mirrored_job_is_the_other_hand_in_the_mirrored_sea():
    import sys

    sys.path.insert(0, str(REPO / "bench"))
    import diagnose_mismatch as dm

    job = {"id": "wind+current_20_1", "trial": "zz10", "member": 3, "speed_kn": 9.0, "seed": 11,
           "spec": {"wind": {}, "current": {"speed_mps": 0.15, "direction_deg": 30.0},
                    "heading_bias": {"bias_deg": 1.0}, "rudder_offset": {"offset_deg": -1.5}},
           "true_wind": (20.0, math.radians(100.0))}
    m = dm.mirrored(job)
    assert m["trial"] == "zz10p" and m["id"] == "wind+current_20_1_mirror"
    assert m["member"] == 3 and m["seed"] == 11 and m["speed_kn"] == 9.0
    assert math.isclose(m["spec"]["current"]["direction_deg"], 330.0)
    assert m["spec"]["heading_bias"]["bias_deg"] == -1.0 and m["spec"]["rudder_offset"]["offset_deg"] == 1.5
    assert math.isclose(m["true_wind"][0], 20.0) and math.isclose(math.degrees(m["true_wind"][1]), 260.0)
    assert job["spec"]["current"]["direction_deg"] == 30.0                      # the job itself untouched
    back = dm.mirrored(m)
    assert back["trial"] == "zz10" and back["spec"] == job["spec"]
    assert math.isclose(back["true_wind"][1], job["true_wind"][1])
    assert dm.mirrored({**job, "trial": "turn_pair"})["trial"] == "turn_pair"   # a pair holds both hands


def test_mirrored_record_swings_the_other_way_by_as_much(config):
    # the config as its own truth, a current setting 30 deg off the course: the twin's heading is the
    # original's mirror image, up to the config's own asymmetry and the noise (the same draw, unmirrored)
    import sys

    sys.path.insert(0, str(REPO / "bench"))
    import diagnose_mismatch as dm

    job = {"id": "current_0.25_0", "trial": "zz20", "spec": {"current": {"speed_mps": 0.25, "direction_deg": 30.0}},
           "true_wind": (0.0, 0.0)}
    recs = []
    for j in (job, dm.mirrored(job)):
        sea = TrialConditions(j["spec"], j["true_wind"], 10.0)
        recs.append(trial_records(config, config, j["trial"], sea, seed=5))
    a, b = recs
    n = min(len(a.psi), len(b.psi))
    swing = float(np.max(np.abs(np.degrees(a.psi[:n]))))
    assert swing > 20.0
    assert float(np.max(np.abs(np.degrees(a.psi[:n] + b.psi[:n])))) < 0.1 * swing
    ya, yb = a.y[:n], b.y[:n]
    assert float(np.max(np.abs(ya + yb))) < 0.2 * float(np.max(np.abs(ya)))   # the asymmetry adds up over the run


def test_exact_by_hand_counts_each_record_once_per_class():
    import sys

    sys.path.insert(0, str(REPO / "bench"))
    import diagnose_mismatch as dm

    rows = [{"trial": "zz10p", "effect": "wind+current", "named": ["wind", "current"]},
            {"trial": "zz10p", "effect": "current", "named": ["current", "heading_bias"]},
            {"trial": "turn25", "effect": "wind+heading_bias", "named": ["wind"]},
            {"trial": "zz20", "effect": None, "named": []},
            {"trial": "zz20", "effect": None, "named": ["current"]},
            {"trial": "turn35p", "effect": None, "named": []}]
    got = dm.exact_by_hand(rows)
    assert got["port"] == {"effect": (1, 2), "wind_beside": (1, 1), "clean": (1, 1)}
    assert got["starboard"] == {"effect": (0, 1), "wind_beside": (0, 1), "clean": (1, 2)}
