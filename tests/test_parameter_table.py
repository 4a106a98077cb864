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


def test_an_unknown_name_is_refused_by_the_fit_and_the_sampler_and_left_out_by_the_writers():
    ship = mmg.load_ship("esso_osaka_3m")
    with pytest.raises(KeyError, match="unknown parameter"):
        free_parameters(pack(ship), ship.hull.names, ["N_q"])
    with pytest.raises(mmg.errors.InputError):
        _ship_values(ship, ["N_q"])
    assert with_value(ship, "start.u[rec0]", 1.0) is ship
    assert unit_of("m_x") == "kg" and unit_of("J_z") == "kg m^2" and unit_of("rudder_offset") == "rad"
