"""One value given in two places: refused, one line naming the file and both places,
whatever the two values are (equal ones too), through load_ship / load_trial and ``mmg simulate``
(exit 2, nothing written).

Every pair a ship or trial config can state twice:

* ship: ``wind.scale`` / ``effects.wind.scale``; ``wind.enabled: false`` / ``effects.wind``;
* trial: ``disturbances.current`` / ``effects.current``; ``disturbances.rudder_offset`` /
  ``effects.rudder_offset``; ``log.bias.heading`` / ``effects.heading_bias``;
* trial and its ship: any ``effects.<effect>.<parameter>`` (or ``wind.scale``) the ship file states
  and the trial's ``effects:`` states again; an older trial key for an effect the ship has.

Values each config states once are taken together (the ship's wind scale with the trial's steady
wind), checked against the simulator's own packed parameters."""
import copy
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

import mmg
from mmg.errors import InputError
from tests.conftest import CONFIGS

SHIP = yaml.safe_load((CONFIGS / "ships" / "esso_osaka_3m.yaml").read_text())
TRIAL = {"name": "turn", "approach": {"speed": "0.4 m/s"}, "duration": "10 s", "dt": "0.02 s",
         "manoeuvre": {"kind": "turning", "rudder": "35 deg", "execute": "2 s"}, "log": {"interval": "0.1 s"}}


def _ship_file(tmp_path, wind=None, effects=None, drop=()):
    data = copy.deepcopy(SHIP)
    data["wind"].update(wind or {})
    for k in drop:
        data["wind"].pop(k)
    if effects is not None:
        data["effects"] = effects
    p = tmp_path / "ship.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


def _trial_file(tmp_path, ship="esso_osaka_3m", **extra):
    p = tmp_path / "t.yaml"
    p.write_text(yaml.safe_dump({**TRIAL, "ship": str(ship), **extra}))
    return p


def _one_line(e, path, *places):
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"{path}: "), msg
    for p in places:
        assert p in msg, (p, msg)


# ------------------------------------------------------------------ in a ship file

@pytest.mark.parametrize("wind_scale,effect_scale", [(1.0, 2.0), (2.0, 2.0), (0.5, 1.0)])
def test_ship_wind_scale_in_both_places_refused(tmp_path, wind_scale, effect_scale):
    p = _ship_file(tmp_path, wind={"scale": wind_scale}, effects={"wind": {"scale": effect_scale}})
    with pytest.raises(InputError) as e:
        mmg.load_ship(p)
    _one_line(e, p, "wind.scale", "effects.wind.scale")


def test_ship_wind_switched_off_and_on_refused(tmp_path):
    p = _ship_file(tmp_path, wind={"enabled": False}, effects={"wind": {"true_speed_mps": 2.0}})
    with pytest.raises(InputError) as e:
        mmg.load_ship(p)
    _one_line(e, p, "effects.wind", "wind.enabled")


@pytest.mark.parametrize("wind,effects,scale", [
    ({"scale": 2.0}, {"wind": {"true_speed_mps": 2.0}}, 2.0),         # the wind section's scale, stated once
    ({}, {"wind": {"scale": 2.0}}, 2.0),                              # only in effects (wind.scale dropped)
    ({}, {"wind": None}, 1.0),
])
def test_ship_wind_scale_stated_once_is_the_one_used(tmp_path, wind, effects, scale):
    p = _ship_file(tmp_path, wind=wind, effects=effects, drop=() if "scale" in wind else ("scale",))
    s = mmg.load_ship(p)
    assert s.effects.get("wind")["scale"] == scale and s.wind.scale == scale


# ------------------------------------------------------------------ in a trial file

@pytest.mark.parametrize("extra,places", [
    ({"disturbances": {"current": {"speed": "0.1 m/s", "direction": "30 deg"}},
      "effects": {"current": {"speed_mps": 0.1}}}, ("effects.current", "disturbances.current")),
    ({"disturbances": {"current": {"speed": "0 m/s", "direction": "0 deg"}}, "effects": {"current": {}}},
     ("effects.current", "disturbances.current")),
    ({"disturbances": {"rudder_offset": "0 deg"}, "effects": {"rudder_offset": {"offset_deg": 1.0}}},
     ("effects.rudder_offset", "disturbances.rudder_offset")),
    ({"log": {"interval": "0.1 s", "bias": {"heading": "0 deg"}}, "effects": {"heading_bias": {"bias_deg": 2.0}}},
     ("effects.heading_bias", "log.bias.heading")),
])
def test_trial_older_key_and_its_effect_refused(tmp_path, extra, places):
    p = _trial_file(tmp_path, **extra)
    with pytest.raises(InputError) as e:
        mmg.load_trial(p)
    _one_line(e, p, *places)


# ------------------------------------------------------------------ a trial and its ship

@pytest.mark.parametrize("ship_kw,trial_extra,places", [
    ({}, {"effects": {"wind": {"scale": 1.0}}}, ("effects.wind.scale", "wind.scale of ")),       # equal: refused too
    ({"effects": {"rudder_offset": {"offset_deg": 2.0}}}, {"effects": {"rudder_offset": {"offset_deg": 0.0}}},
     ("effects.rudder_offset.offset_deg", "effects.rudder_offset.offset_deg of ")),
    ({"effects": {"current": {"speed_mps": 0.1, "direction_deg": 10.0}}},
     {"effects": {"current": {"direction_deg": 10.0}}}, ("effects.current.direction_deg", "of ")),
    ({"effects": {"shallow_water": {"depth_to_draft": 2.0}}}, {"effects": {"shallow_water": {"depth_to_draft": 1.5}}},
     ("effects.shallow_water.depth_to_draft", "of ")),
    ({"effects": {"current": {"speed_mps": 0.1}}},
     {"disturbances": {"current": {"speed": "0.1 m/s", "direction": "0 deg"}}}, ("disturbances.current", "effects.current")),
    ({"effects": {"rudder_offset": {}}}, {"disturbances": {"rudder_offset": "1 deg"}},
     ("disturbances.rudder_offset", "effects.rudder_offset")),
    ({"effects": {"heading_bias": {"bias_deg": 1.0}}}, {"log": {"interval": "0.1 s", "bias": {"heading": "1 deg"}}},
     ("log.bias.heading", "effects.heading_bias")),
])
def test_trial_and_ship_giving_one_value_refused(tmp_path, ship_kw, trial_extra, places):
    sp = _ship_file(tmp_path, **ship_kw)
    p = _trial_file(tmp_path, ship=sp, **trial_extra)
    with pytest.raises(InputError) as e:
        mmg.load_trial(p)
    _one_line(e, p, *places)
    if "of " in places[-1]:
        assert str(sp) in str(e.value)                      # the other place: in the ship file, named


def test_values_stated_once_in_each_config_act_together(tmp_path):
    """The ship's wind scale (2) with the trial's steady wind: the packed parameters are those of
    the wind effect with all three values (before, the trial's wind dropped the ship's scale to 1)."""
    from mmg.effects import effect_set
    from mmg.model import P_WIND_Q, P_WIND_V, pack
    from mmg.simulation import prepare

    sp = _ship_file(tmp_path, wind={"scale": 2.0})
    t = mmg.load_trial(_trial_file(tmp_path, ship=sp, effects={"wind": {"true_speed_mps": 2.0, "true_from_deg": 45.0}}))
    assert t.effect_set().get("wind") == {"scale": 2.0, "sway_factor": 1.0, "yaw_factor": 1.0, "yaw_sin": 0.0,
                                          "true_speed_mps": 2.0, "true_from_deg": 45.0}
    pk, _ = prepare(t.ship, t.u0, t.n0, t.trim, t.effects)
    ship = mmg.load_ship(sp)
    want = effect_set({"wind": {"scale": 2.0, "true_speed_mps": 2.0, "true_from_deg": 45.0}}).pack(pack(ship, 0.0), ship)
    assert pk.p[P_WIND_Q] == want.p[P_WIND_Q] and pk.p[P_WIND_V] == 2.0
    # and a current the ship states with its direction given by the trial
    sp2 = _ship_file(tmp_path, effects={"current": {"speed_mps": 0.1}})
    t2 = mmg.load_trial(_trial_file(tmp_path, ship=sp2, effects={"current": {"direction_deg": 90.0}}))
    assert t2.effect_set().get("current") == {"speed_mps": 0.1, "direction_deg": 90.0}
    assert t2.current() == pytest.approx((0.1, np.pi / 2))


# ------------------------------------------------------------------ through mmg simulate

def _simulate(trial, out):
    return subprocess.run([sys.executable, "-m", "trials.cli", "simulate", str(trial), "--out", str(out)],
                          capture_output=True, text=True)


@pytest.mark.parametrize("case", ["ship", "trial", "both"])
def test_cli_value_given_twice_exit_2_nothing_written(tmp_path, case):
    if case == "ship":
        sp = _ship_file(tmp_path, wind={"scale": 1.0}, effects={"wind": {"scale": 2.0}})
        p, places = _trial_file(tmp_path, ship=sp), (str(sp), "wind.scale", "effects.wind.scale")
    elif case == "trial":
        p = _trial_file(tmp_path, disturbances={"rudder_offset": "1 deg"}, effects={"rudder_offset": {"offset_deg": 1.0}})
        places = (str(p), "effects.rudder_offset", "disturbances.rudder_offset")
    else:
        p = _trial_file(tmp_path, effects={"wind": {"scale": 2.0}})
        places = (str(p), "effects.wind.scale", "wind.scale of ", "esso_osaka_3m.yaml")
    out = tmp_path / "out"
    r = _simulate(p, out)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and all(x in lines[0] for x in places), r.stderr
    assert not out.exists()
