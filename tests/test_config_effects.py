"""Effects switched on in ship and trial configs (``effects:`` sections) act in the simulator, its
logs, the replay and ``mmg diagnose`` as the one definition in mmg.effects says.

References the code did not produce: the apparent wind from vector arithmetic and the Fujiwara
series with explicit multiple angles written here; the equations of motion solved here from the
mass matrix; the config routes that existed before (``disturbances:``, ``log.bias``) for the same
physics; shallow water widening a turning circle (every published shallow-water trial)."""
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

import mmg
from mmg.errors import InputError

THREE_M = {"name": "turn", "ship": "esso_osaka_3m", "approach": {"speed": "0.4 m/s"}, "duration": "60 s",
           "dt": "0.02 s", "manoeuvre": {"kind": "turning", "rudder": "35 deg", "execute": "5 s"},
           "log": {"interval": "0.1 s"}}


def _trial(**extra):
    from trials.runs.trial import trial_from_dict

    return trial_from_dict({**THREE_M, **extra})


# ------------------------------------------------------------------ steady wind in the equations of motion

def _independent_wind_accel(p, ship, x, Vt, from_rad, scale, cur=(0.0, 0.0)):
    """du/dt, dv/dt, dr/dt a steady true wind adds, written out here without the code's helpers."""
    from mmg.wind import RHO_AIR, fujiwara_amplitudes

    u, v, r, psi = x[0], x[1], x[2], x[5]
    # velocities over ground, north/east
    cs, cd = cur
    sn = u * math.cos(psi) - v * math.sin(psi) + cs * math.cos(cd)
    se = u * math.sin(psi) + v * math.cos(psi) + cs * math.sin(cd)
    # the true wind moves air towards from + pi
    an, ae = -Vt * math.cos(from_rad), -Vt * math.sin(from_rad)
    rn, re = an - sn, ae - se                                       # air relative to the ship
    rx = rn * math.cos(psi) + re * math.sin(psi)                    # in ship axes
    ry = -rn * math.sin(psi) + re * math.cos(psi)
    V = math.hypot(rx, ry)
    g = math.atan2(-ry, -rx)                                        # comes FROM, from the bow, + starboard
    A = fujiwara_amplitudes(ship.wind.particulars())
    cx = A["X0"] + A["X1"] * math.cos(g) + A["X3"] * math.cos(3 * g) + A["X5"] * math.cos(5 * g)
    cy = -(A["Y1"] * math.sin(g) + A["Y3"] * math.sin(3 * g) + A["Y5"] * math.sin(5 * g))
    cn = -(A["N1"] * math.sin(g) + A["N2"] * math.sin(2 * g) + A["N3"] * math.sin(3 * g))
    q = 0.5 * RHO_AIR * V * V * scale
    w = ship.wind.particulars()
    F = np.array([q * w.A_T * cx, q * w.A_L * cy, q * w.A_L * w.L * cn])
    from mmg.model import P_IZ, P_JZ, P_M, P_MX, P_MY, P_XG

    m, mx, my, xG, Iz, Jz = (p[k] for k in (P_M, P_MX, P_MY, P_XG, P_IZ, P_JZ))
    M = np.array([[m + mx, 0, 0], [0, m + my, xG * m], [0, xG * m, Iz + xG * xG * m + Jz]])
    return np.linalg.solve(M, F)


@pytest.mark.parametrize("from_deg,psi_deg", [(0.0, 0.0), (90.0, 10.0), (225.0, -40.0), (300.0, 170.0)])
def test_steady_wind_in_rhs_is_the_fujiwara_load_of_the_apparent_wind(from_deg, psi_deg):
    import mmg.effects as E
    from mmg.model import pack, rhs

    ship = mmg.load_ship("esso_osaka_3m")
    cur = (0.05, math.radians(30.0))
    base = pack(ship, 0.0)
    base = E.effect_set({"current": {"speed_mps": cur[0], "direction_deg": 30.0}}).pack(base)
    es = E.effect_set({"wind": {"true_speed_mps": 2.5, "true_from_deg": from_deg, "scale": 1.3}})
    pk = es.pack(base, ship)
    x = np.array([0.35, -0.04, 0.03, 1.0, 2.0, math.radians(psi_deg), 0.1, 10.0])
    a0, a1 = np.zeros(8), np.zeros(8)
    rhs(x, 0.1, *base.args(), a0)
    rhs(x, 0.1, *pk.args(), a1)
    want = _independent_wind_accel(pk.p, ship, x, 2.5, math.radians(from_deg), 1.3, cur)
    np.testing.assert_allclose(a1[:3] - a0[:3], want, rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(a1[3:], a0[3:])                   # kinematics and steering untouched


def test_steady_wind_rhs_is_complex_step_analytic_in_heading():
    import mmg.effects as E
    from mmg.model import pack, rhs

    ship = mmg.load_ship("esso_osaka_3m")
    pk = E.effect_set({"wind": {"true_speed_mps": 3.0, "true_from_deg": 60.0}}).pack(pack(ship, 0.0), ship)
    x = np.array([0.35, -0.04, 0.03, 0.0, 0.0, 0.4, 0.1, 10.0])
    h = 1e-20
    xc = x.astype(complex)
    xc[5] += 1j * h
    out = np.zeros(8, complex)
    rhs(xc, 0.1, *pk.args(), out)
    d_cs = out.imag / h
    e = 1e-6
    ap, am = np.zeros(8), np.zeros(8)
    xp, xm = x.copy(), x.copy()
    xp[5] += e
    xm[5] -= e
    rhs(xp, 0.1, *pk.args(), ap)
    rhs(xm, 0.1, *pk.args(), am)
    np.testing.assert_allclose(d_cs, (ap - am) / (2 * e), rtol=1e-6, atol=1e-10)
    assert abs(d_cs[2]) > 1e-4                                      # the yaw acceleration depends on the heading


def test_head_wind_costs_rpm_following_wind_saves_it():
    calm = mmg.simulate(_trial())
    head = mmg.simulate(_trial(effects={"wind": {"true_speed_mps": 3.0, "true_from_deg": 0.0}}))
    foll = mmg.simulate(_trial(effects={"wind": {"true_speed_mps": 3.0, "true_from_deg": 180.0}}))
    assert head.equilibrium.n > calm.equilibrium.n > foll.equilibrium.n
    assert head.equilibrium.residual < 1e-10 and foll.equilibrium.residual < 1e-10
    # beam winds from either side need trim rudders on either side of the calm one, by about as much
    stb = mmg.simulate(_trial(effects={"wind": {"true_speed_mps": 2.0, "true_from_deg": 90.0}})).equilibrium
    prt = mmg.simulate(_trial(effects={"wind": {"true_speed_mps": 2.0, "true_from_deg": 270.0}})).equilibrium
    a, b = stb.delta - calm.equilibrium.delta, prt.delta - calm.equilibrium.delta
    assert a * b < 0 and 0.7 < abs(a / b) < 1.4


def test_logged_apparent_wind_gives_back_the_configured_true_wind(tmp_path):
    """mmg simulate writes the apparent wind; the true wind follows back from it, the ship's
    velocity over ground and its heading (the dataset's convention, mmg.wind)."""
    from mmg.wind import true_wind_from_relative
    from trials.files.logio import read_record

    eff = {"wind": {"true_speed_mps": 2.0, "true_from_deg": 45.0}, "current": {"speed_mps": 0.05, "direction_deg": 90.0}}
    r = subprocess.run([sys.executable, "-m", "trials.cli", "simulate", _write(tmp_path, {**THREE_M, "effects": eff}),
                        "--out", str(tmp_path / "o")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    truth = read_record(tmp_path / "o" / "truth.csv")
    log = read_record(tmp_path / "o" / "log.csv")
    assert truth.wind_speed_rel is not None and log.wind_speed_rel is not None
    # over ground = through the water + the current (0.05 m/s towards east) in ship axes
    cu = 0.05 * np.cos(math.radians(90.0) - truth.psi)
    cv = 0.05 * np.sin(math.radians(90.0) - truth.psi)
    V, d = true_wind_from_relative(truth.wind_speed_rel, truth.wind_dir_rel, truth.u + cu, truth.v + cv, truth.psi)
    np.testing.assert_allclose(V, 2.0, atol=1e-9)
    np.testing.assert_allclose(np.degrees(d), 45.0, atol=1e-7)
    # the log holds the same apparent wind (in knots and degrees) every log interval
    k = int(round(0.1 / 0.02))
    np.testing.assert_allclose(log.wind_speed_rel, truth.wind_speed_rel[::k], rtol=1e-9)
    np.testing.assert_allclose(log.wind_dir_rel, truth.wind_dir_rel[::k], atol=1e-9)


def _write(tmp_path, data, name="t.yaml"):
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data))
    return str(p)


# ------------------------------------------------------------------ the same physics through either config route

def test_effects_section_equals_the_disturbances_section():
    a = mmg.simulate(_trial(disturbances={"current": {"speed": "0.1 m/s", "direction": "30 deg"},
                                          "rudder_offset": "1.5 deg"}))
    b = mmg.simulate(_trial(effects={"current": {"speed_mps": 0.1, "direction_deg": 30.0},
                                     "rudder_offset": {"offset_deg": 1.5}}))
    np.testing.assert_allclose(b.states, a.states, rtol=0, atol=1e-9)
    np.testing.assert_allclose(b.sog, a.sog, rtol=0, atol=1e-9)


def test_disturbances_section_is_the_trials_current_and_rudder_offset_effects():
    """The ``disturbances:`` keys load as the ``current`` and ``rudder_offset`` effects of the trial
    (knots and degrees converted by hand here); a zero offset is no effect."""
    t = _trial(disturbances={"current": {"speed": "0.2 kn", "direction": "-30 deg"}, "rudder_offset": "-1.5 deg"})
    assert t.effects.names() == ["current", "rudder_offset"]
    assert t.effects.get("current") == pytest.approx({"speed_mps": 0.2 * 1852.0 / 3600.0, "direction_deg": -30.0},
                                                     rel=1e-12)
    assert t.effects.get("rudder_offset") == pytest.approx({"offset_deg": -1.5}, rel=1e-12)
    assert t.current() == pytest.approx((0.2 * 1852.0 / 3600.0, -math.pi / 6), rel=1e-12)
    none = _trial(disturbances={"rudder_offset": "0 deg"})
    assert none.effects is None or none.effects.get("rudder_offset") is None


def test_heading_bias_effect_equals_log_bias():
    a = mmg.simulate(_trial(log={"interval": "0.1 s", "bias": {"heading": "2 deg"}}))
    b = mmg.simulate(_trial(effects={"heading_bias": {"bias_deg": 2.0}}))
    pd_a, pd_b = a.log(), b.log()
    np.testing.assert_allclose(pd_b["heading_deg"].to_numpy(), pd_a["heading_deg"].to_numpy(), atol=1e-9)
    np.testing.assert_array_equal(b.states, a.states)             # a measurement effect: the motion is the same
    rec = b.record()
    np.testing.assert_allclose(np.degrees(rec.psi - b.psi[::5]), 2.0, atol=1e-9)


def _ship_with_effects(effects):
    from mmg.resources import config_path
    from mmg.ship import ship_from_dict

    data = yaml.safe_load(Path(config_path("ships", "esso_osaka_3m.yaml")).read_text())
    data["effects"] = effects
    return ship_from_dict(data)


def _on(ship, **extra):
    from trials.runs.trial import trial_from_dict

    return trial_from_dict({**{k: v for k, v in THREE_M.items() if k != "ship"}, **extra}, source="<t>", ship=ship)


def test_ship_config_effects_act_like_the_trial_ones():
    ship = _ship_with_effects({"rudder_offset": {"offset_deg": 2.0}})
    a = mmg.simulate(_on(ship))
    b = mmg.simulate(_trial(effects={"rudder_offset": {"offset_deg": 2.0}}))
    np.testing.assert_allclose(a.states, b.states, rtol=0, atol=1e-12)
    assert np.abs(a.states - mmg.simulate(_trial()).states).max() > 1e-3
    # a value the ship states is not given again by the trial (tests/test_config_twice.py)
    with pytest.raises(InputError, match="offset_deg"):
        _on(ship, effects={"rudder_offset": {"offset_deg": 0.0}})


def test_shallow_water_widens_the_turning_circle():
    deep = mmg.simulate(_trial(duration="120 s")).metrics()
    shallow = mmg.simulate(_trial(duration="120 s", effects={"shallow_water": {"depth_to_draft": 1.3}})).metrics()
    assert shallow["advance_L"] > deep["advance_L"]
    assert shallow["transfer_L"] > 1.2 * deep["transfer_L"]


def test_replay_applies_the_ship_configs_effects():
    """A record simulated with a current, a rudder offset and a compass bias in the ship config
    replays against that config to the integration error, and badly against the config without them."""
    from trials.measured.predict import replay_record

    eff = {"current": {"speed_mps": 0.06, "direction_deg": 120.0}, "rudder_offset": {"offset_deg": 1.0},
           "heading_bias": {"bias_deg": 1.5}}
    with_eff = _ship_with_effects(eff)
    rec = mmg.simulate(_on(with_eff)).record(interval=0.1)
    good = replay_record(with_eff, rec).scores()
    bad = replay_record(mmg.load_ship("esso_osaka_3m"), rec, wind=False).scores()
    assert good["heading_rms_deg"] < 0.05 and good["final_position_error_L"] < 0.01
    assert bad["heading_rms_deg"] > 1.0 and bad["final_position_error_L"] > 0.1


# ------------------------------------------------------------------ bad effects sections

@pytest.mark.parametrize("effects,field", [
    ({"tide": {}}, "effects.tide"),
    ({"current": {"speed": 0.5}}, "effects.current.speed"),
    ({"current": {"speed_mps": 25.0}}, "effects.current.speed_mps"),
    ({"current": {"speed_mps": "0.5 kn"}}, "effects.current.speed_mps"),
    ({"current": 0.5}, "effects.current"),
    ({"wind": {"scale": True}}, "effects.wind.scale"),
    ({"shallow_water": {"depth_to_draft": 0.8}}, "effects.shallow_water.depth_to_draft"),
    ({"wind": {"true_speed_mps": 90.0}}, "effects.wind.true_speed_mps"),
    ({"rudder_offset": {"offset_deg": float("nan")}}, "effects.rudder_offset.offset_deg"),
])
def test_bad_effects_refused_naming_file_and_field(tmp_path, effects, field):
    from trials.runs.trial import load_trial

    p = tmp_path / "t.yaml"
    p.write_text(yaml.safe_dump({**THREE_M, "effects": effects}))
    with pytest.raises(InputError) as e:
        load_trial(str(p))
    assert str(p) in str(e.value) and field in str(e.value) and "\n" not in str(e.value)


def test_effect_given_twice_refused(tmp_path):
    from trials.runs.trial import load_trial

    p = tmp_path / "t.yaml"
    p.write_text(yaml.safe_dump({**THREE_M, "disturbances": {"rudder_offset": "1 deg"},
                                 "effects": {"rudder_offset": {"offset_deg": 1.0}}}))
    with pytest.raises(InputError, match="effects.rudder_offset.*one place"):
        load_trial(str(p))


def test_wind_effect_needs_a_wind_section(tmp_path):
    from trials.runs.trial import load_trial

    from mmg.resources import config_path

    text = config_path("ships", "esso_osaka.yaml").read_text()
    assert "\nwind:" in text
    (tmp_path / "nowind.yaml").write_text(text[:text.index("\nwind:")])     # the ship without its wind section
    p = tmp_path / "t.yaml"
    p.write_text(yaml.safe_dump({"name": "st", "ship": "nowind.yaml", "approach": {"speed": "10 kn"},
                                 "duration": "100 s", "dt": "0.5 s",
                                 "manoeuvre": {"kind": "turning", "rudder": "35 deg", "execute": "10 s"},
                                 "effects": {"wind": {"true_speed_mps": 10.0}}}))
    with pytest.raises(InputError, match="effects.wind"):
        load_trial(str(p))


def test_ship_config_bad_effects_refused(tmp_path):
    from mmg.resources import config_path
    from mmg.ship import load_ship

    data = yaml.safe_load(Path(config_path("ships", "esso_osaka_3m.yaml")).read_text())
    data["effects"] = {"heading_bias": {"bias_deg": 45.0}}
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(data))
    with pytest.raises(InputError) as e:
        load_ship(str(p))
    assert str(p) in str(e.value) and "effects.heading_bias.bias_deg" in str(e.value)


def test_cli_bad_effects_exit_2_nothing_written(tmp_path):
    p = _write(tmp_path, {**THREE_M, "effects": {"current": {"speed_mps": -1}}})
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "trials.cli", "simulate", p, "--out", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1 and "effects.current.speed_mps" in r.stderr
    assert not out.exists()


# ------------------------------------------------------------------ hidden in a trial config, named by mmg diagnose

def _hidden_records(effects):
    """A turning and a zigzag of the 3 m model, closed loop (the zigzag's rudder answers the
    effects), by a ship whose added masses and wake differ by 7-8 % from the config that diagnoses
    them, with ``effects`` in the trial configs, logged as the FRT-DS-ESSO files log (TrialRun.record)."""
    from mmg.resources import config_path
    from mmg.ship import ship_from_dict
    from trials.runs.trial import trial_from_dict

    data = yaml.safe_load(Path(config_path("ships", "esso_osaka_3m.yaml")).read_text())
    data["mass"]["m_x_prime"] *= 1.08
    data["mass"]["m_y_prime"] *= 0.93
    data["propeller"]["w_P0"][0] *= 1.07
    truth = ship_from_dict(data)
    base = {"approach": {"speed": "0.45 m/s"}, "dt": "0.02 s", "log": {"interval": "0.5 s", "seed": 3}, "effects": effects}
    turn = trial_from_dict({**base, "name": "turn", "duration": "70 s",
                            "manoeuvre": {"kind": "turning", "rudder": "35 deg", "execute": "3 s"}}, ship=truth)
    zz = trial_from_dict({**base, "name": "zz", "duration": "90 s",
                          "manoeuvre": {"kind": "zigzag", "rudder": "20 deg", "heading": "20 deg"}}, ship=truth)
    L, U0 = 3.0, 0.45
    noise = [0.002 * U0, 0.002 * U0, 1.2e-4 * math.sqrt(9.80665 / L), 0.002 * L, 0.002 * L, math.radians(0.05)]
    return [mmg.simulate(t).record(noise=noise, seed=k) for k, t in enumerate((turn, zz))]


def test_diagnose_names_current_and_offset_hidden_in_trial_configs():
    from trials.measured.diagnose import diagnose

    d = diagnose(mmg.load_ship("esso_osaka_3m"), _hidden_records(
        {"current": {"speed_mps": 0.03, "direction_deg": 200.0}, "rudder_offset": {"offset_deg": 1.0}}))
    j = d.to_json()
    assert sorted(j["named_effects"]) == ["current", "rudder_offset"]
    assert abs(j["parameters"]["current"]["speed_mps"] - 0.03) < 0.003
    assert abs((j["parameters"]["current"]["direction_deg"] - 200.0 + 180) % 360 - 180) < 10.0
    assert abs(j["parameters"]["rudder_offset"]["offset_deg"] - 1.0) < 0.3
    for c in ("u", "v", "heading", "position"):
        assert j["rms_after"][c] <= 0.5 * j["rms_before"][c]


@pytest.mark.slow
def test_diagnose_names_a_steady_wind_of_a_trial_config_from_the_logged_apparent_wind():
    from trials.measured.diagnose import diagnose

    d = diagnose(mmg.load_ship("esso_osaka_3m"), _hidden_records(
        {"wind": {"true_speed_mps": 2.0, "true_from_deg": 60.0}}))       # the scale: the ship's wind.scale, 1
    j = d.to_json()
    assert j["named_effects"] == ["wind"]
    assert abs(j["parameters"]["wind"]["scale"] - 1.0) < 0.2
    assert j["rms_after"]["heading"] <= 0.5 * j["rms_before"]["heading"]


# ------------------------------------------------------------------ any effects section: a result or one line

from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402

_NAMES = ["current", "wind", "rudder_offset", "heading_bias", "shallow_water", "tide", "Current", ""]
_PARAMS = ["speed_mps", "direction_deg", "scale", "true_speed_mps", "true_from_deg", "offset_deg", "bias_deg",
           "depth_to_draft", "speed", "offset", "bias"]
_VALUES = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**6, 10**6),
                    st.sampled_from(["0.5 kn", "1", "", "deg", None, True]), st.lists(st.floats(), max_size=2))


@settings(max_examples=150, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.dictionaries(st.sampled_from(_NAMES),
                       st.one_of(st.none(), _VALUES, st.dictionaries(st.sampled_from(_PARAMS), _VALUES, max_size=3)),
                       max_size=4))
def test_any_effects_section_gives_an_effect_set_or_one_line(spec):
    import mmg.effects as E

    try:
        es = E.effect_set(spec, "effects", "t.yaml")
    except InputError as e:
        msg = str(e)
        assert msg.startswith("t.yaml: effects") and "\n" not in msg
        return
    # accepted: every effect registered, every value a finite number within its bounds
    for cls, vals in es.items:
        assert cls.name in E.REGISTRY
        for p in cls.parameters:
            v = vals[p.name]
            assert type(v) is float and p.lower <= v <= p.upper
            assert math.isfinite(v) or (p.name == "depth_to_draft" and v == math.inf)


def test_a_ship_with_effects_stays_hashable_and_comparable():
    a, b = _ship_with_effects({"current": {"speed_mps": 0.1}}), _ship_with_effects({"current": {"speed_mps": 0.1}})
    assert a == b and hash(a) == hash(b)
    assert a != _ship_with_effects({"current": {"speed_mps": 0.2}})
