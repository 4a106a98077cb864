"""The wind effect's shape factors (wind on every bundled ship): the effect stands for *a*
wind load, the published Fujiwara et al. (1998) curves times ``scale`` (X) and ``scale * sway_factor``
(Y), ``scale * yaw_factor`` (N).

The expected loads are written here from the published Fourier series (sin k gamma, cos k gamma
directly, not the package's polynomial form, the factors applied to the loads, not to the
amplitudes); only the regression's amplitudes (the geometry regression, :func:`mmg.wind.fujiwara_amplitudes`,
which the factors do not touch) are read from the package."""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

import mmg
import mmg.effects as E
from mmg.errors import InputError
from mmg.resources import ship_path
from mmg.wind import RHO_AIR, fujiwara_amplitudes

SHIP = "esso_osaka_3m"


def plain_loads(V, gamma, g, scale=1.0, sway=1.0, yaw=1.0):
    """X, Y [N], N [N m] about midship: Fujiwara's series written out; gamma: the apparent wind comes
    FROM, from the bow, + to starboard (the regression's own angle is -gamma)."""
    A = fujiwara_amplitudes(g)
    a = -np.asarray(gamma, float)
    cx = A["X0"] + A["X1"] * np.cos(a) + A["X3"] * np.cos(3 * a) + A["X5"] * np.cos(5 * a)
    cy = A["Y1"] * np.sin(a) + A["Y3"] * np.sin(3 * a) + A["Y5"] * np.sin(5 * a)
    cn = A["N1"] * np.sin(a) + A["N2"] * np.sin(2 * a) + A["N3"] * np.sin(3 * a)
    q = 0.5 * RHO_AIR * np.asarray(V, float) ** 2
    return (scale * q * g.A_T * cx, scale * sway * q * g.A_L * cy, scale * yaw * q * g.A_L * g.L * cn)


def _ctx(ship, t, V, gamma):
    return E.Context(t=t, delta=np.zeros_like(t), n=np.zeros_like(t),
                     channels={"wind_speed_rel": V, "wind_dir_rel": np.mod(gamma, 2 * np.pi)}, ship=ship)


@pytest.fixture(scope="module")
def ship():
    return mmg.load_ship(SHIP)


# ----------------------------------------------------------------------------- the loads

def test_measured_wind_loads_with_factors_are_the_published_ones_times_the_factors(ship):
    t = np.linspace(0.0, 10.0, 73)
    gamma = np.linspace(-math.pi, math.pi, 73)          # every direction
    V = np.full_like(t, 3.0)
    g = ship.wind.particulars()
    for scale, sway, yaw in ((1.0, 1.0, 1.0), (0.8, 0.6, 1.4), (2.0, 2.5, 0.3)):
        es = E.effect_set({"wind": {"scale": scale, "sway_factor": sway, "yaw_factor": yaw}})
        got = es.external(_ctx(ship, t, V, gamma))
        want = np.column_stack(plain_loads(V, gamma, g, scale, sway, yaw))
        assert np.allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())


def test_steady_wind_loads_of_the_simulator_take_the_same_factors(ship):
    """The simulator's steady true wind (mmg.model.wind_loads, the P_WIND_* slots Wind.pack writes) with
    the factors: the apparent wind worked out here from the true wind and the ship's velocity."""
    from mmg.model import pack, wind_loads

    g = ship.wind.particulars()
    for sway, yaw in ((1.0, 1.0), (0.6, 1.4)):
        es = E.effect_set({"wind": {"scale": 1.5, "sway_factor": sway, "yaw_factor": yaw,
                                    "true_speed_mps": 4.0, "true_from_deg": 60.0}})
        p = es.pack(pack(ship), ship).p
        for u, v, psi in ((0.4, 0.0, 0.0), (0.3, -0.05, 1.0), (0.45, 0.03, -2.5)):
            rel = math.radians(60.0) - psi                # the true wind's direction from the bow
            ax = -4.0 * math.cos(rel) - u                 # air velocity relative to the ship, ship axes
            ay = -4.0 * math.sin(rel) - v
            V, gam = math.hypot(ax, ay), math.atan2(-ay, -ax)
            want = plain_loads(V, gam, g, 1.5, sway, yaw)
            got = wind_loads(u, v, psi, p)
            assert np.allclose(got, [float(w) for w in want], rtol=1e-10), (sway, yaw, u, v, psi)


def test_yaw_sin_adds_its_sine_to_the_yaw_moment_alone(ship):
    """``yaw_sin`` c: N gains scale q A_L L c sin(gamma) at every angle (the same sign as the wind's side:
    positive turns the bow towards a wind from starboard), in the measured-wind loads and in the
    simulator's steady wind; X and Y are unchanged."""
    from mmg.model import pack, wind_loads

    t = np.linspace(0.0, 10.0, 73)
    gamma = np.linspace(-math.pi, math.pi, 73)
    V = np.full_like(t, 3.0)
    g = ship.wind.particulars()
    scale, c = 1.3, 0.07
    es = E.effect_set({"wind": {"scale": scale, "sway_factor": 0.9, "yaw_factor": 1.2, "yaw_sin": c}})
    got = es.external(_ctx(ship, t, V, gamma))
    X, Y, N = plain_loads(V, gamma, g, scale, 0.9, 1.2)
    N = N + scale * 0.5 * RHO_AIR * V ** 2 * g.A_L * g.L * c * np.sin(gamma)
    want = np.column_stack([X, Y, N])
    assert np.allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
    beam = es.external(_ctx(ship, t[:1], V[:1], np.array([math.pi / 2])))
    plain = E.effect_set({"wind": {"scale": scale, "sway_factor": 0.9, "yaw_factor": 1.2}}).external(
        _ctx(ship, t[:1], V[:1], np.array([math.pi / 2])))
    assert beam[0, 2] > plain[0, 2] and beam[0, 1] == plain[0, 1]
    steady = E.effect_set({"wind": {"scale": scale, "yaw_sin": c, "true_speed_mps": 4.0, "true_from_deg": 90.0}})
    p = steady.pack(pack(ship), ship).p
    V2 = 4.0 ** 2 + 0.4 ** 2                              # beam wind, u = 0.4 m/s, v = 0, heading 0
    gam = math.atan2(4.0, 0.4)
    want = plain_loads(math.sqrt(V2), gam, g, scale)
    want_n = float(want[2]) + scale * 0.5 * RHO_AIR * V2 * g.A_L * g.L * c * math.sin(gam)
    assert np.allclose(wind_loads(0.4, 0.0, 0.0, p), [float(want[0]), float(want[1]), want_n], rtol=1e-10)


# ----------------------------------------------------------------------------- configs

def _ship_yaml(tmp_path, name, edit):
    data = yaml.safe_load(ship_path(SHIP).read_text())
    edit(data)
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return p


def test_factors_in_the_ship_wind_section_reach_the_replay(tmp_path, ship):
    from trials.measured.predict import run_effects

    def with_factors(d):
        d["wind"].update(sway_factor=0.6, yaw_factor=1.4, scale=0.9)
    p = _ship_yaml(tmp_path, "s.yaml", with_factors)
    s = mmg.load_ship(p)
    assert (s.wind.sway_factor, s.wind.yaw_factor) == (0.6, 1.4)
    t = np.linspace(0.0, 5.0, 37)
    gamma = np.linspace(0.0, 2 * math.pi, 37)
    V = np.full_like(t, 2.0)
    want = np.column_stack(plain_loads(V, gamma, s.wind.particulars(), 0.9, 0.6, 1.4))
    for es in (s.effect_set(), run_effects(s, True)):          # as configured; --wind on
        assert es.get("wind")["sway_factor"] == 0.6 and es.get("wind")["yaw_factor"] == 1.4
        assert np.allclose(es.external(_ctx(s, t, V, gamma)), want, rtol=1e-12, atol=1e-9)

    def in_effects(d):                 # what mmg diagnose --out-ship writes: the effect's values in effects:
        d["wind"].pop("scale", None)
        d["effects"] = {"wind": {"scale": 0.9, "sway_factor": 0.6, "yaw_factor": 1.4}}
    s2 = mmg.load_ship(_ship_yaml(tmp_path, "s2.yaml", in_effects))
    assert np.allclose(s2.effect_set().external(_ctx(s2, t, V, gamma)), want, rtol=1e-12, atol=1e-9)
    assert (s2.wind.scale, s2.wind.sway_factor, s2.wind.yaw_factor) == (0.9, 0.6, 1.4)


@pytest.mark.parametrize("key", ["sway_factor", "yaw_factor"])
def test_a_shape_factor_given_twice_is_refused(tmp_path, key):
    def once(d):
        d["wind"][key] = 1.2
    assert getattr(mmg.load_ship(_ship_yaml(tmp_path, "once.yaml", once)).wind, key) == 1.2

    def both(d):
        d["wind"][key] = 1.2
        d["effects"] = {"wind": {key: 1.2}}
    p = _ship_yaml(tmp_path, "both.yaml", both)
    with pytest.raises(InputError) as e:
        mmg.load_ship(p)
    msg = str(e.value)
    assert "\n" not in msg and str(p) in msg and "given twice" in msg and f"wind.{key}" in msg

    def out_of_range(d):
        d["wind"][key] = 30.0
    p = _ship_yaml(tmp_path, "range.yaml", out_of_range)
    with pytest.raises(InputError, match=f"wind.{key}"):
        mmg.load_ship(p)


def test_a_trial_may_not_restate_the_ships_shape_factor(tmp_path):
    """The ship states wind.yaw_factor (its wind off); a trial's effects.wind.yaw_factor is refused."""
    def stated(d):
        d["wind"].update(enabled=False, yaw_factor=1.3)
    sp = _ship_yaml(tmp_path, "ship.yaml", stated)
    trial = {"name": "turn", "ship": str(sp), "approach": {"speed": "0.4 m/s"}, "duration": "10 s",
             "dt": "0.02 s", "manoeuvre": {"kind": "turning", "rudder": "35 deg", "execute": "2 s"},
             "log": {"interval": "0.1 s"}, "effects": {"wind": {"yaw_factor": 1.3}}}
    tp = tmp_path / "trial.yaml"
    tp.write_text(yaml.safe_dump(trial))
    with pytest.raises(InputError, match="twice"):
        mmg.load_trial(tp)


def test_every_bundled_ship_has_a_wind_section():
    for name in ("esso_osaka", "esso_osaka_3m", "esso_osaka_3m_crossflow", "kvlcc2_l7"):
        s = mmg.load_ship(ship_path(name))
        assert s.wind is not None, name
        g = s.wind.particulars()
        assert 0.0 < g.A_T < g.A_L and g.z_AL < g.H_BR, name


# ----------------------------------------------------------------------------- presence in mmg diagnose

def _report(effect, theta, std):
    from ekf.identify import effect_parameters
    from trials.measured.diagnose import _effect_report

    free = effect_parameters([effect])
    n = len(theta)
    fit = SimpleNamespace(theta=np.asarray(theta, float), std=np.asarray(std, float), corr=np.eye(n))
    return _effect_report(SimpleNamespace(free=free, fit=fit), effect, 1.0)


def test_presence_of_the_wind_needs_its_scale():
    """At scale 0 there is no wind whatever the shape factors say (z 0); a wind of 0.8 the published
    loads, each load known to about 0.1: present at more standard errors than the threshold (the test
    is on the three loads together, tests/test_effect_definitions.py checks its value)."""
    from trials.measured.diagnose import Z_THRESHOLD

    assert E.Wind.presence_parameters() == ("scale",)
    assert E.Current.presence_parameters() == tuple(q.name for q in E.Current.fit_parameters())
    _, _, z = _report(E.Wind, [0.0, 1.3, 1.3, 0.1], [0.1, 0.1, 0.1, 0.05])   # no wind, shape terms off neutral
    assert z == pytest.approx(0.0, abs=1e-9) and z < Z_THRESHOLD
    vals, _, z = _report(E.Wind, [0.8, 1.0, 1.0, 0.0], [0.1, 0.05, 0.05, 0.03])  # a wind of 0.8 the published
    assert z > 2 * Z_THRESHOLD and vals["scale"] == 0.8


# ----------------------------------------------------------------------------- the fit

def test_identify_fits_back_the_shape_of_a_wind_load_it_did_not_make(ship):
    """A record whose wind loads are the published ones times (sway 0.6, yaw 1.4), made here (the
    loads from the plain formula, replayed with mmg.replay), is fitted back by ekf.identify with the
    wind effect's three parameters (before: the scale alone)."""
    from ekf.identify import Scales, Segmented, effect_parameters, identify_segments, segment_resets
    from mmg.model import pack
    from mmg.replay import ReplayInputs, replay

    pk = pack(ship)
    t = np.arange(0.0, 240.0 + 1e-9, 0.2)
    delta = np.radians(15.0) * np.sign(np.sin(2 * np.pi * t / 40.0))
    delta = np.convolve(delta, np.ones(5) / 5, mode="same")
    n = np.full_like(t, 10.0)
    V = 3.0 + 0.5 * np.sin(2 * np.pi * t / 70.0)               # apparent wind, from every direction
    gamma = np.mod(2 * np.pi * t / 120.0, 2 * np.pi)
    X, Y, N = plain_loads(V, gamma, ship.wind.particulars(), 1.0, 0.6, 1.4)
    states = replay(pk, ReplayInputs(t=t, delta=delta, n=n, ext=np.column_stack([X, Y, N])),
                    [0.4, 0.0, 0.0, 0.0, 0.0, 0.0])
    rng = np.random.default_rng(3)
    meas = states + rng.normal(0.0, [0.002, 0.002, 0.0005, 0.01, 0.01, 0.002], states.shape)
    seg = Segmented("wind", meas, ReplayInputs(t=t, delta=delta, n=n), segment_resets(t, 40.0),
                    context=_ctx(ship, t, V, gamma))
    free = effect_parameters([E.Wind])
    fit = identify_segments(pk, [seg], free, Scales(0.005, 0.005, 0.001, np.radians(0.5)), n_jobs=1,
                            effects=[E.Wind], ship=ship, max_nfev=60)
    got = fit.values()
    assert got["wind.scale"] == pytest.approx(1.0, abs=0.08), got
    assert got["wind.sway_factor"] == pytest.approx(0.6, abs=0.08), got
    assert got["wind.yaw_factor"] == pytest.approx(1.4, abs=0.12), got
