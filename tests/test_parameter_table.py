"""The parameter table (mmg.parameters): every freeable parameter round-trips through a ship, its YAML and the
packed ship an estimator fits; a parameter added to the table alone is freed, applied, written and sampled by
the identification, the config writer and the IMO sampler without another line."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import yaml

import mmg
from ekf.identify import apply_parameters, free_parameters
from mmg.model import P_FALPHA, pack
from mmg.parameters import CONSTANTS, ShipParameter, is_resistance, parameter, ship_value, unit_of, with_value
from trials.imo.sampling import _ship_values
from trials.measured.identify import ship_with_values, ship_yaml

SHIPS = ("esso_osaka_3m", "kvlcc2_l7", "esso_osaka_3m_crossflow")


def _names(ship):
    return list(ship.hull.names) + [n for n in CONSTANTS if not n.startswith("wind_") or ship.wind is not None]


@pytest.mark.parametrize("name", SHIPS)
def test_every_parameter_round_trips_through_the_yaml_the_ship_and_the_packed_ship(name, tmp_path):
    """For each entry: a new value written into the ship's YAML reads back (loaded) as that value, the ship
    with the value written in reads it too, and the packed ship of that ship carries it where the fit looks."""
    ship = mmg.load_ship(name)
    path = mmg.config_path("ships", f"{name}.yaml")
    for nm in _names(ship):
        old = ship_value(ship, nm)
        new = 1.25 * old if old else 0.0123
        if nm.startswith("wind_"):                     # a factor on the ship's: read back as the product
            new = 1.25
        loaded_path = tmp_path / f"{nm}.yaml"
        loaded_path.write_text(ship_yaml(path, {nm: new}, "round trip"))
        loaded = mmg.load_ship(loaded_path)
        written = with_value(ship, nm, new)
        spec = parameter(nm, ship.hull.names, ship.hull.terms)
        if nm.startswith("wind_"):
            key = spec.yaml.split(".")[1]
            assert getattr(loaded.wind, key) == pytest.approx(1.25 * getattr(ship.wind, key), rel=1e-5), nm
            assert getattr(written.wind, key) == pytest.approx(1.25 * getattr(ship.wind, key), rel=1e-12), nm
            continue
        assert ship_value(loaded, nm) == pytest.approx(new, rel=1e-5, abs=1e-9), nm
        assert ship_value(written, nm) == pytest.approx(new, rel=1e-12, abs=1e-15), nm
        if nm != "rudder_offset":         # an effect: the packed ship carries it through the effect set's slots
            assert spec.config_value(pack(written)) == pytest.approx(new, rel=1e-9, abs=1e-15), nm


def test_the_fit_reads_a_parameter_where_it_writes_it():
    """free_parameters' prior is the packed ship's value; apply_parameters puts a new value where the table
    reads it back, for every constant the packed ship carries."""
    ship = mmg.load_ship("esso_osaka_3m")
    pk = pack(ship)
    names = [n for n in CONSTANTS if not n.startswith("wind_")] + ["N_r", "X_uu"]
    free = free_parameters(pk, ship.hull.names, names, hull_terms=ship.hull.terms)
    for f in free:
        assert f.prior == pytest.approx(ship_value(ship, f.name), rel=1e-12, abs=1e-15), f.name
    theta = np.array([f.prior + 0.01 for f in free])
    pk2 = apply_parameters(pk, free, theta)
    for f, v in zip(free, theta):
        if f.name == "rudder_offset":       # an effect's slot, set by the effect: not the packed ship's
            continue
        assert parameter(f.name, ship.hull.names).config_value(pk2) == pytest.approx(v, rel=1e-12), f.name


def test_the_straight_ahead_resistance_stays_negative_on_either_hull_model():
    """X_uu (Kijima form, cos(beta)^2) and X_0 (the KVLCC2's polynomial, term 1) are the resistance: bounded
    above by 0 in a fit; no other surge coefficient is."""
    for name, res in (("esso_osaka_3m", "X_uu"), ("kvlcc2_l7", "X_0")):
        ship = mmg.load_ship(name)
        free = free_parameters(pack(ship), ship.hull.names, list(ship.hull.names), hull_terms=ship.hull.terms)
        bounded = [f.name for f in free if f.upper == 0.0]
        assert bounded == [res], (name, bounded)
        assert is_resistance(res, dict(zip(ship.hull.names, ship.hull.terms))[res])


def test_a_parameter_added_to_the_table_alone_is_fitted_written_and_sampled(monkeypatch, tmp_path):
    """A made-up entry (the rudder's lift-slope coefficient f_alpha, not in the table) registered in the table
    and nowhere else: the fit frees it with its family's prior, applies it to the packed ship, the ship and its
    YAML take the fitted value, the IMO sampler reads the ship's own value, and its unit is the entry's."""
    spec = ShipParameter("f_alpha", "1", "rudder", "rudder", P_FALPHA, "rudder.f_alpha",
                         read=lambda s: s.rudder.f_alpha,
                         write=lambda s, v: replace(s, rudder=replace(s.rudder, f_alpha=float(v))),
                         write_yaml=lambda d, v, path: d["rudder"].__setitem__("f_alpha", float(f"{v:.6g}")),
                         packed=lambda p: p.p[P_FALPHA], floor=0.05, bounds=lambda v: (0.5, 10.0))
    ship = mmg.load_ship("esso_osaka_3m")
    with pytest.raises(KeyError):
        free_parameters(pack(ship), ship.hull.names, ["f_alpha"])
    monkeypatch.setitem(CONSTANTS, "f_alpha", spec)
    (f,) = free_parameters(pack(ship), ship.hull.names, ["f_alpha"])
    v0 = ship.rudder.f_alpha
    assert (f.prior, f.sigma, f.lower, f.upper) == (pytest.approx(v0), pytest.approx(max(0.5 * v0, 0.05)), 0.5, 10.0)
    assert apply_parameters(pack(ship), [f], [2.5]).p[P_FALPHA] == 2.5
    assert ship_with_values(ship, {"f_alpha": 2.5}).rudder.f_alpha == 2.5
    text = ship_yaml(mmg.config_path("ships", "esso_osaka_3m.yaml"), {"f_alpha": 2.5}, "made-up entry")
    assert yaml.safe_load(text)["rudder"]["f_alpha"] == 2.5
    (tmp_path / "s.yaml").write_text(text)
    assert mmg.load_ship(tmp_path / "s.yaml").rudder.f_alpha == 2.5
    assert _ship_values(ship, ["f_alpha"]).tolist() == [v0]
    assert unit_of("f_alpha") == "1"


def _with_t_P0(s, v):
    t = list(s.propeller.t_P)
    t[0] = float(v)
    return replace(s, propeller=replace(s.propeller, t_P=tuple(t)))


def test_a_parameter_with_its_own_apply_rule_needs_the_table_alone(monkeypatch, tmp_path):
    """A made-up entry that goes where no entry goes (the thrust deduction's constant term t_P0, the first
    coefficient of the t_P polynomial row of the packed ship), its rule on the entry and nothing else: the
    fit frees it, applies it there (a copy: the caller's packed ship untouched, nothing else moved), a
    FreeParameter made by hand with its kind takes the same rule, and the ship and its YAML take the value."""
    from ekf.identify import FreeParameter
    from mmg.model import POLY_TP

    def to_t_P0(packed, index, value):
        packed.poly[POLY_TP][0] = value

    spec = ShipParameter("t_P0", "1", "", "thrust_deduction", 0, "propeller.t_P[0]",
                         read=lambda s: s.propeller.t_P[0], write=_with_t_P0,
                         write_yaml=lambda d, v, path: d["propeller"]["t_P"].__setitem__(0, float(f"{v:.6g}")),
                         packed=lambda p: p.poly[POLY_TP][0], abs_std=0.05, bounds=lambda v: (0.0, 0.6),
                         apply=to_t_P0)
    ship = mmg.load_ship("esso_osaka_3m")
    pk = pack(ship)
    monkeypatch.setitem(CONSTANTS, "t_P0", spec)
    (f,) = free_parameters(pk, ship.hull.names, ["t_P0"])
    assert (f.prior, f.sigma, f.lower, f.upper) == (ship.propeller.t_P[0], 0.05, 0.0, 0.6)
    for free in ([f], [FreeParameter("t_P0", "thrust_deduction", 0, 0.1, 0.05)]):
        pk2 = apply_parameters(pk, free, [0.2345])
        want = pk.poly.copy()
        want[POLY_TP, 0] = 0.2345
        np.testing.assert_array_equal(pk2.poly, want)
        np.testing.assert_array_equal(pk2.p, pk.p)
        np.testing.assert_array_equal(pk2.hull_coef, pk.hull_coef)
    assert pk.poly[POLY_TP, 0] == ship.propeller.t_P[0]                 # the caller's packed ship as it was
    assert ship_with_values(ship, {"t_P0": 0.2345}).propeller.t_P[0] == 0.2345
    text = ship_yaml(mmg.config_path("ships", "esso_osaka_3m.yaml"), {"t_P0": 0.2345}, "made-up rule")
    (tmp_path / "s.yaml").write_text(text)
    assert mmg.load_ship(tmp_path / "s.yaml").propeller.t_P[0] == 0.2345


def test_the_fitted_wind_factors_act_through_the_wind_effect(monkeypatch):
    """``--free wind_scale wind_sway_factor wind_yaw_factor`` scale a record's loads by the wind effect's
    own factors (mmg.effects.Wind.load_factors, no second copy: a changed definition changes the fit's
    loads), and those factors are what the effect's loads do: the loads at (s, a, b) are the loads at
    (1, 1, 1) times s, s a, s b (mmg.wind.wind_forces computed at both, compared to round-off)."""
    import mmg.effects as E
    from ekf.identify import Segmented, _wind_scaled
    from mmg.effects.base import Context
    from mmg.replay import ReplayInputs

    ship = mmg.load_ship("esso_osaka_3m")
    t = np.arange(0.0, 5.0, 0.1)
    ctx = Context(t=t, delta=0 * t, n=10 + 0 * t, ship=ship,
                  channels={"wind_speed_rel": 1.0 + 0.5 * np.sin(t), "wind_dir_rel": np.mod(0.9 * t, 2 * np.pi)})
    ext = E.Wind.external(E.Wind.values({}), ctx)
    rec = Segmented("r", np.zeros((len(t), 6)), ReplayInputs(t=t, delta=0 * t, n=10 + 0 * t, ext=ext),
                    np.ones(len(t), bool))
    free = free_parameters(pack(ship), ship.hull.names, ["wind_scale", "wind_sway_factor", "wind_yaw_factor"])
    theta = [0.83, 1.21, 0.64]
    got = _wind_scaled(rec, free, theta).inputs.ext
    other = E.Wind.external(E.Wind.values({"scale": 0.83, "sway_factor": 1.21, "yaw_factor": 0.64}), ctx)
    np.testing.assert_allclose(got, other, rtol=1e-12, atol=1e-12 * np.abs(other).max())
    monkeypatch.setattr(E.Wind, "load_factors", classmethod(lambda cls, s, a=1.0, b=1.0: np.array([2.0, 3.0, 5.0])))
    np.testing.assert_array_equal(_wind_scaled(rec, free, theta).inputs.ext, ext * [2.0, 3.0, 5.0])


def test_the_identifications_rudder_offset_is_the_effects_slot_to_round_off():
    """``--free rudder_offset`` (radians, written into the slot) and the rudder_offset effect (degrees,
    its slots) put the same blade offset into the packed ship, to the last bit or one: the one
    conversion between them, degrees to radians and back, is exact only to round-off."""
    import mmg.effects as E
    from mmg.model import P_RUDDER_OFFSET

    ship = mmg.load_ship("esso_osaka_3m")
    pk = pack(ship)
    (f,) = free_parameters(pk, ship.hull.names, ["rudder_offset"])
    for deg in (-4.0, -0.3, 0.77, 2.5):
        mine = apply_parameters(pk, [f], [np.radians(deg)]).p[P_RUDDER_OFFSET]
        effect = E.RudderOffset.pack(pk, {"offset_deg": deg}).p[P_RUDDER_OFFSET]
        assert mine == pytest.approx(effect, rel=4e-16) and mine == pytest.approx(deg * np.pi / 180.0, rel=1e-15)


def test_the_identifications_rudder_offset_goes_through_the_effect(monkeypatch):
    """One path for the offset: ``--free rudder_offset`` enters the packed ship by the effect's own
    :meth:`~mmg.effects.RudderOffset.slots` (a changed effect changes the fit's model too), not by a
    write of its own into the slot."""
    import mmg.effects as E
    from mmg.model import P_RUDDER_OFFSET

    ship = mmg.load_ship("esso_osaka_3m")
    pk = pack(ship)
    (f,) = free_parameters(pk, ship.hull.names, ["rudder_offset"])
    monkeypatch.setattr(E.RudderOffset, "slots",
                        classmethod(lambda cls, v: {P_RUDDER_OFFSET: 3.0 * np.radians(v["offset_deg"])}))
    assert apply_parameters(pk, [f], [np.radians(1.5)]).p[P_RUDDER_OFFSET] == pytest.approx(np.radians(4.5), rel=1e-12)


def test_an_unknown_name_is_refused_by_the_fit_and_the_sampler_and_left_out_by_the_writers():
    ship = mmg.load_ship("esso_osaka_3m")
    with pytest.raises(KeyError, match="unknown parameter"):
        free_parameters(pack(ship), ship.hull.names, ["N_q"])
    with pytest.raises(mmg.errors.InputError):
        _ship_values(ship, ["N_q"])
    assert with_value(ship, "start.u[rec0]", 1.0) is ship
    assert unit_of("m_x") == "kg" and unit_of("J_z") == "kg m^2" and unit_of("rudder_offset") == "rad"


def test_an_effect_registered_alone_carries_its_magnitude_unit_and_detection_size(monkeypatch):
    """A made-up effect, registered and nothing else: the diagnosis's magnitude and detection size are its
    own; a bundled effect's magnitude against its definition computed here (a current's speed over sqrt(g L))."""
    import math

    import mmg.effects as E
    from mmg.effects.base import Effect, Parameter
    from trials.measured.decision import magnitude
    from trials.measured.identifiability import detection_size

    class Trim(Effect):
        name = "made_up_trim"
        kind = "coefficients"
        description = "a made-up trim"
        parameters = (Parameter("trim_deg", "deg", 0.0, -5.0, 5.0, 1.0),)
        magnitude_unit = "deg"
        detection_size = (0.25, "deg")

        @classmethod
        def magnitude(cls, values, L):
            return abs(float(values["trim_deg"]))

    monkeypatch.setitem(E.REGISTRY, Trim.name, Trim)
    assert magnitude("made_up_trim", {"trim_deg": -0.7}, 3.0) == 0.7
    assert detection_size("made_up_trim", 3.0) == 0.25
    assert magnitude("current", {"speed_mps": 0.15}, 325.0) == pytest.approx(0.15 / math.sqrt(9.80665 * 325.0), rel=1e-14)
    assert detection_size("current", 325.0) == pytest.approx(0.0027 * math.sqrt(9.80665 * 325.0), rel=1e-14)
    assert math.isnan(magnitude("no_such_effect", {}, 3.0))


def test_fitted_values_under_the_configs_keys_prime_the_added_masses():
    """An added mass [kg] goes to the config as m_x' = m_x / (rho L^2 T / 2), the moment of inertia as
    J_z' = J_z / (rho L^4 T / 2) (the primes of mmg.nondim, written out here); others keep name and value."""
    from mmg.parameters import config_values

    ship = mmg.load_ship("esso_osaka_3m")
    pa = ship.particulars
    got = config_values(ship, {"m_x": 20.0, "J_z": 90.0, "N_r": -0.05, "start.u[a]": 0.1})
    assert got["m_x_prime"] == pytest.approx(20.0 / (0.5 * pa.rho * pa.L ** 2 * pa.T), rel=1e-12)
    assert got["J_z_prime"] == pytest.approx(90.0 / (0.5 * pa.rho * pa.L ** 4 * pa.T), rel=1e-12)
    assert got["N_r"] == -0.05 and got["start.u[a]"] == 0.1 and "m_x" not in got


def test_without_hull_terms_the_packed_ship_tells_the_resistance():
    """free_parameters called without ``hull_terms`` bounds the resistance the packed ship's own terms name
    (X_uu of the Kijima form, X_0 of the KVLCC2's), not a coefficient picked by its name."""
    for name, res in (("esso_osaka_3m", "X_uu"), ("kvlcc2_l7", "X_0")):
        ship = mmg.load_ship(name)
        free = free_parameters(pack(ship), ship.hull.names, list(ship.hull.names))
        assert [f.name for f in free if f.upper == 0.0] == [res], name
