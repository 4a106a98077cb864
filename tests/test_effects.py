"""Effects as model components (mmg.effects): registry, parameters, state maps, slots, the
disturbance adapters and the estimator's effect parameters."""
import math

import numpy as np
import pytest

import mmg.effects as E
from mmg.errors import InputError


def test_registry_names_and_parameters():
    assert E.names() == ["current", "wind", "rudder_offset", "heading_bias", "shallow_water"]
    assert [p.name for p in E.Current.parameters] == ["speed_mps", "direction_deg"]
    assert [p.name for p in E.Wind.parameters] == ["scale", "sway_factor", "yaw_factor", "yaw_sin", "true_speed_mps",
                                                   "true_from_deg"]
    # the steady wind is given, not fitted; the scale and the shape factors are
    assert [p.name for p in E.Wind.fit_parameters()] == ["scale", "sway_factor", "yaw_factor", "yaw_sin"]
    assert [p.name for p in E.RudderOffset.parameters] == ["offset_deg"]
    assert [p.name for p in E.HeadingBias.parameters] == ["bias_deg"]
    assert [p.name for p in E.ShallowWater.parameters] == ["depth_to_draft"]
    for cls in E.REGISTRY.values():
        for p in cls.parameters:
            assert p.unit and p.lower <= p.default <= p.upper


def test_values_checked():
    with pytest.raises(InputError, match="speed_mps"):
        E.effect_set({"current": {"speed_mps": -1.0}})
    with pytest.raises(InputError, match="unknown effect"):
        E.effect_set({"tide": {}})
    with pytest.raises(InputError, match="unknown parameter"):
        E.effect_set({"rudder_offset": {"offset": 1.0}})


def test_state_maps_round_trip_and_conventions():
    es = E.effect_set({"current": {"speed_mps": 0.2, "direction_deg": 90.0}, "heading_bias": {"bias_deg": 2.0}})
    rng = np.random.default_rng(0)
    s = rng.standard_normal((20, 6))
    assert np.allclose(es.to_model(es.to_logged(s)), s, atol=1e-14)
    # heading north, current towards east: logged v over ground = water v + 0.2
    cur = E.effect_set({"current": {"speed_mps": 0.2, "direction_deg": 90.0}})
    st = np.array([[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]])
    assert np.allclose(cur.to_logged(st)[0, :2], [1.0, 0.2])
    # heading bias: the earth-frame velocity is the same from true and logged heading
    hb = E.effect_set({"heading_bias": {"bias_deg": 3.0}})
    st = np.array([[2.0, 0.3, 0.0, 0.0, 0.0, 0.7]])
    lg = hb.to_logged(st)
    assert math.isclose(lg[0, 5], 0.7 + math.radians(3.0))
    def earth(x):
        c, s_ = math.cos(x[5]), math.sin(x[5])
        return np.array([x[0] * c - x[1] * s_, x[0] * s_ + x[1] * c])
    assert np.allclose(earth(st[0]), earth(lg[0]))


def test_current_and_rudder_offset_slots_in_si():
    """The effects write SI into the parameter vector: m/s, and radians from their degrees."""
    from mmg import model as M

    cur = E.Current.slots({"speed_mps": 0.5, "direction_deg": 30.0})
    assert np.allclose([cur[M.P_CUR_SPEED], cur[M.P_CUR_DIR]], [0.5, math.pi / 6])
    assert math.isclose(E.RudderOffset.slots({"offset_deg": 1.5})[M.P_RUDDER_OFFSET], 1.5 * math.pi / 180)


def test_current_over_ground_track_in_model(esso):
    """The model's track adds the current the effect writes: a ship at rest drifts with it."""
    from mmg.model import pack
    from mmg.replay import ReplayInputs, replay_states

    pk = E.effect_set({"current": {"speed_mps": 0.5, "direction_deg": 45.0}}).pack(pack(esso))
    t = np.linspace(0, 100, 11)
    s = replay_states(pk, ReplayInputs(t, np.zeros(11), np.zeros(11)), np.zeros(6))
    assert np.allclose(s[-1, 3:5], 50.0 * np.array([math.cos(math.pi / 4), math.sin(math.pi / 4)]), rtol=1e-9)


def test_shallow_water_factors(esso):
    from mmg.effects.shallow_water import factors
    from mmg.model import pack

    assert factors(esso, 0.0) == {}
    f = factors(esso, 1 / 1.5)
    assert f["Y_beta"] > 1.2 and f["m_y"] > 1.5 and f["J_z"] > 1.0
    pk0 = pack(esso)
    deep = E.ShallowWater.pack(pk0, {"depth_to_draft": math.inf}, esso)
    assert deep is pk0
    sh = E.ShallowWater.pack(pk0, {"depth_to_draft": 1.5}, esso)
    i = list(esso.hull.names).index("Y_beta")
    assert sh.hull_coef[i] > pk0.hull_coef[i]


def test_wind_availability():
    from mmg.ship import load_ship

    ship = load_ship("esso_osaka_3m")
    z = np.zeros(5)
    ctx = E.Context(t=np.arange(5.0), delta=z, n=z, channels={"wind_speed_rel": None, "wind_dir_rel": None}, ship=ship)
    assert "no wind_speed_rel" in E.Wind.unavailable(ctx)
    ctx = E.Context(t=np.arange(5.0), delta=z, n=z, channels={"wind_speed_rel": z, "wind_dir_rel": z}, ship=ship)
    assert "all zero" in E.Wind.unavailable(ctx)
    ctx = E.Context(t=np.arange(5.0), delta=z, n=z, channels={"wind_speed_rel": z + 2, "wind_dir_rel": z + 1}, ship=ship)
    assert E.Wind.unavailable(ctx) is None
    f = E.Wind.external({"scale": 2.0}, ctx)
    f1 = E.Wind.external({"scale": 1.0}, ctx)
    assert np.allclose(f, 2 * f1) and f.shape == (5, 3)


def test_current_report_delta_method():
    v, s = E.Current.report([0.0, 0.1], np.diag([1e-4, 1e-4]))
    assert math.isclose(v["speed_mps"], 0.1) and math.isclose(v["direction_deg"], 90.0)
    assert math.isclose(s["speed_mps"], 0.01, rel_tol=1e-3) and math.isclose(s["direction_deg"], math.degrees(0.1), rel_tol=1e-2)


def test_identify_without_effects_unchanged():
    from ekf.identify import FreeParameter, Scales, effect_parameters

    assert Scales(1, 1, 1, 1).array().tolist() == [1, 1, 1, 1]
    fp = effect_parameters([E.Current, E.RudderOffset])
    assert [f.name for f in fp] == ["current.north_mps", "current.east_mps", "rudder_offset.offset_deg"]
    assert [f.index for f in fp] == [0, 0, 1] and [f.sub for f in fp] == [0, 1, 0]
    assert FreeParameter("Y_r", "hull", 0, 1.0, 0.1).sub == 0


@pytest.mark.parametrize("ship_name, resistance", [("esso_osaka", "X_uu"), ("kvlcc2_l7", "X_0")])
def test_shallow_water_scales_every_hulls_resistance(ship_name, resistance):
    """The resistance correction reaches the hull's own resistance coefficient whatever its name (X_uu of the
    Kijima form, X_0 of the MMG standard method): at H/T = 1.5 it is multiplied by Furukawa et al.'s (2016)
    1 + 0.388 (T/H)^2, computed here by hand; no other X coefficient moves."""
    from mmg.model import pack
    from mmg.ship import load_ship

    ship = load_ship(ship_name)
    pk0 = pack(ship)
    sh = E.ShallowWater.pack(pk0, {"depth_to_draft": 1.5}, ship)
    ratio = {n: sh.hull_coef[i] / pk0.hull_coef[i] for i, n in enumerate(ship.hull.names)
             if ship.hull.axes[i] == "X" and pk0.hull_coef[i] != 0}
    assert ratio[resistance] == pytest.approx(1 + 0.388 * (1 / 1.5) ** 2, rel=1e-12)
    assert all(r == 1.0 for n, r in ratio.items() if n != resistance)
    assert resistance in E.ShallowWater.changed_coefficients(ship)
    assert ship.hull.resistance_names() == (resistance,)
