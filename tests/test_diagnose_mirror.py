"""``mmg diagnose`` reads port and starboard alike: a record and its port <-> starboard mirror image get
mirrored diagnoses.

The records are made by the independent writer (``tests/independent_writer.py``: the clean ship simulated
by :func:`mmg.simulation.simulate`, each effect applied afterwards by plain formulas, not by
:mod:`mmg.effects`), for a ship with no hand of its own (:func:`~tests.independent_writer.without_hand`:
Y_0 = N_0 = 0, no propeller walk, the rudder's flow straightening equal for both signs of its inflow
angle), both the config the diagnosis is given and the ship that makes the records (its hull 5 % off the
config's in odd terms, so still without a hand).  Each record is mirrored about the approach heading
(:func:`~tests.independent_writer.mirror`: rudder, yaw rate, sway, heading change, cross-track position,
the wind's directions negated; a current's direction, a heading bias's and a rudder offset's sign follow).
:func:`mirror_mismatch` compares the two diagnoses: the same named effects, each value the mirror of the
other within its standard error, the same effects reported ``not_identifiable``.  That the mirror image is
the other hand's record is checked against the simulator itself (:func:`test_mirror_is_the_other_hands_record`),
and that the comparison catches a decision that treats the two hands differently on two such rules
(:func:`test_mirror_check_catches_a_one_handed_rule`).  Records are short (turn 80, zigzag 100 sqrt(L/g))
and fitted at every third sample, to keep this file quick.
"""
import math

import numpy as np
import pytest

from . import independent_writer as W

TURN_S, ZIGZAG_S = 80.0, 100.0        # record lengths [sqrt(L/g)]
STRIDE = 3                            # fit every third sample (0.6 s of the 3 m model)
APPROACH_DEG = 0.0                    # the writer's approach heading (north)
LAM = 325.0 / 3.0                     # Froude scale of the 3 m model (wind speeds from full scale)

EFFECTS = {
    "clean": {},
    "current": {"current": (0.012 * math.sqrt(W.G * 3.0), 120.0)},   # 0.065 m/s (0.65 m/s at 325 m) towards 120 deg
    "heading_bias": {"bias_deg": 2.0},
    "rudder_offset": {"offset_deg": 1.5},
    "wind": {"wind": (15.0 / math.sqrt(LAM), 45.0)},                   # 15 m/s at full scale, from the starboard bow
}
"""The writer's effects of each case (its :func:`~tests.independent_writer.log` keywords)."""

MIRROR = {
    "current": {"speed_mps": "same", "direction_deg": "angle"},
    "heading_bias": {"bias_deg": "negated"},
    "rudder_offset": {"offset_deg": "negated"},
    "wind": {"scale": "same", "sway_factor": "same", "yaw_factor": "same", "yaw_sin": "same", "true_speed_mps": "same",
             "true_from_deg": "angle"},
    "shallow_water": {"depth_to_draft": "same", "draft_to_depth": "same"},
}
"""How each effect's reported parameters change in the mirror image: ``same``, ``negated``, or ``angle``
(a direction clockwise from north, reflected about the approach heading: 2 approach - value)."""


def mirrored_value(how: str, value: float, about_deg: float = APPROACH_DEG) -> float:
    """``value`` as the mirror image reports it (:data:`MIRROR`)."""
    return {"same": value, "negated": -value, "angle": 2.0 * about_deg - value}[how]


def mirror_mismatch(d, dm, about_deg: float = APPROACH_DEG) -> list:
    """How diagnosis ``dm`` of the mirror image fails to be the mirror of ``d`` (empty: mirrored): the named
    effects (in order), each named effect's values against the mirrored ones (a difference over the larger of
    the two standard errors, angles wrapped), the effects reported ``not_identifiable``."""
    out = []
    if list(d.named) != list(dm.named):
        out.append(f"named {d.named} but mirrored {dm.named}")
    for eff in set(d.named) & set(dm.named):
        for p, v in d.parameters[eff].items():
            want = mirrored_value(MIRROR[eff][p], v, about_deg)
            diff = dm.parameters[eff][p] - want
            if MIRROR[eff][p] == "angle":
                diff = W.angdiff(diff, 0.0)
            tol = max(d.standard_errors[eff][p], dm.standard_errors[eff][p])
            if not abs(diff) <= tol:
                out.append(f"{eff}.{p} {v:.4g} but mirrored {dm.parameters[eff][p]:.4g} (want {want:.4g} +- {tol:.2g})")
    ni = sorted(e["effect"] for e in d.not_identifiable)
    nim = sorted(e["effect"] for e in dm.not_identifiable)
    if ni != nim:
        out.append(f"not identifiable {ni} but mirrored {nim}")
    return out


# --------------------------------------------------------------------------- the ship and the records


@pytest.fixture(scope="module")
def config():
    return W.without_hand(W.load_config())


@pytest.fixture(scope="module")
def truth(config):
    return W.truth_ship(config)


def _sim(ship, kind, effects, first=1.0):
    s = math.sqrt(ship.particulars.L / W.G)
    if kind == "turn":
        return W.turn(ship, first * 35.0, TURN_S * s, wind=effects.get("wind"))
    return W.zigzag(ship, 20.0, 20.0, effects.get("offset_deg", 0.0), ZIGZAG_S * s, first=first,
                    wind=effects.get("wind"))


def _pair(tmp_path, config, truth, case, kind):
    """The diagnoses of a record with the effects of ``case`` and of its mirror image."""
    from trials.measured.diagnose import diagnose

    effects = EFFECTS[case]
    frame = W.log(truth, _sim(truth, kind, effects), seed=7, **effects)
    paths = (tmp_path / f"{kind}.csv", tmp_path / f"{kind}_mirror.csv")
    frame.to_csv(paths[0], index=False)
    W.mirror(frame, APPROACH_DEG).to_csv(paths[1], index=False)
    return tuple(diagnose(config, [p], stride=STRIDE) for p in paths)


# --------------------------------------------------------------------------- the mirror image itself


def test_mirror_table_covers_every_effect():
    """Every registered effect's parameters have a mirror rule (a new effect must say how it mirrors)."""
    import mmg.effects as E

    for name, cls in E.REGISTRY.items():
        assert name in MIRROR, name
        assert {p.name for p in cls.parameters} <= set(MIRROR[name]), (name, MIRROR[name])


def test_without_hand(config):
    """The hand-free config: no side force or moment straight ahead, no walk, one flow straightening."""
    h = config.hull
    assert h.value("Y_0") == 0.0 and h.value("N_0") == 0.0
    assert config.propeller.Y_P_astern == 0.0
    assert config.rudder.gamma_R_pos == config.rudder.gamma_R_neg
    assert W.load_config().hull.value("Y_0") != 0.0             # the config itself has a hand


def test_writer_wind_channels(truth):
    """The writer's wind, checked on its output: a wind from the east on a ship heading north at U is
    logged at the start from atan(V / U) off the starboard bow at sqrt(U^2 + V^2), its true wind as
    given throughout, and :func:`mmg.wind.true_wind_from_relative` gets the true wind back from the
    logged channels at every sample; the wind pushes the ship to port (west)."""
    from mmg.wind import true_wind_from_relative

    s = math.sqrt(truth.particulars.L / W.G)
    V = 1.4
    f = W.log(truth, W.turn(truth, 0.0, 20.0 * s, wind=(V, 90.0)), noise=False, wind=(V, 90.0))
    U = W.speed(truth)
    assert abs(f["wind_dir_relative_mid [rad]"].iloc[0] - math.atan2(V, U)) < 1e-9
    assert abs(f["wind_velo_relative_mid [m/s]"].iloc[0] - math.hypot(U, V)) < 1e-9
    assert np.allclose(f["wind_velo_true [m/s]"], V) and np.allclose(f["wind_dir_true [rad]"], math.pi / 2)
    Vt, dt = true_wind_from_relative(f["wind_velo_relative_mid [m/s]"], f["wind_dir_relative_mid [rad]"],
                                     f["u_velo [m/s]"], f["vm_velo [m/s]"], f["psi_hat [rad]"])
    assert np.allclose(Vt, V, atol=1e-9) and np.allclose(dt, math.pi / 2, atol=1e-9)
    assert f["y_position_mid [m]"].iloc[-1] < 0.0


@pytest.mark.parametrize("kind", ["turn", "zigzag"])
def test_mirror_is_the_other_hands_record(truth, kind):
    """The mirror image of a starboard (first) record with current, bias, offset and wind is what the
    simulator makes of the port (first) manoeuvre with the mirrored effects, noise aside: the mirror is
    the physics' own, not only the test's convention."""
    eff = {"current": (0.05, 120.0), "bias_deg": 2.0, "offset_deg": 1.5, "wind": (1.4, 45.0)}
    mir = {"current": (0.05, -120.0), "bias_deg": -2.0, "offset_deg": -1.5, "wind": (1.4, -45.0)}
    stbd = W.log(truth, _sim(truth, kind, eff), noise=False, **eff)
    port = W.log(truth, _sim(truth, kind, mir, first=-1.0), noise=False, **mir)
    m = W.mirror(stbd, APPROACH_DEG)
    assert len(m) == len(port)
    assert np.ptp(np.degrees(m["psi_hat [rad]"])) > 30.0             # it turned
    for c in m.columns:
        a, b = m[c].to_numpy(), port[c].to_numpy()
        if "dir" in c or "psi" in c:
            err = np.abs(W.angdiff(np.degrees(a), np.degrees(b)))
            assert np.max(err) < 1e-4, (c, np.max(err))
        else:
            assert np.allclose(a, b, rtol=1e-6, atol=1e-6 * max(1.0, np.max(np.abs(b)))), (c, np.max(np.abs(a - b)))


# --------------------------------------------------------------------------- the diagnoses


@pytest.mark.parametrize("kind", ["turn", "zigzag"])
@pytest.mark.parametrize("case", list(EFFECTS))
def test_mirrored_record_gets_the_mirrored_diagnosis(config, truth, tmp_path, case, kind):
    """Every candidate tried on a record and on its mirror image: the same effects named, values mirrored
    within their standard errors, the same ones not identifiable.  On a zigzag each effect is named (a
    mirror of two empty diagnoses would prove little); on a single turn a bias or an offset need not be."""
    d, dm = _pair(tmp_path, config, truth, case, kind)
    assert mirror_mismatch(d, dm) == [], (d.named, d.parameters, dm.named, dm.parameters)
    if case == "clean":
        assert d.named == []
    elif kind == "zigzag" or case in ("current", "wind"):
        assert case in d.named, d.rounds


def _floor_on_starboard_offsets(real):
    """A one-handed rule: a rudder offset to starboard must also exceed 3 deg to be named."""
    def rule(effect, values, L, kind, heading=None, speed=None):
        if effect == "rudder_offset" and values["offset_deg"] > 0 and values["offset_deg"] < 3.0:
            return False
        return real(effect, values, L, kind, heading, speed)
    return rule


def _signed_parts(real):
    """A one-handed rule: a current's parts against their floors with their signs (a current setting
    astern or to port never clears), the absolute value dropped."""
    def rule(size, fl, parts=None):
        if parts:
            return any(x > f for x, f in parts.values())
        return real(size, fl, parts)
    return rule


@pytest.mark.parametrize("case, module, name, mutate", [
    ("rudder_offset", "trials.measured.diagnose.search", "clears_floor", _floor_on_starboard_offsets),
    ("current", "trials.measured.decision", "over_floor", _signed_parts),
])
def test_mirror_check_catches_a_one_handed_rule(config, truth, tmp_path, monkeypatch, case, module, name, mutate):
    """The comparison fails on a decision that treats the two hands differently: with the rule mutated the
    zigzag and its mirror image are diagnosed differently, and :func:`mirror_mismatch` says so."""
    import importlib

    mod = importlib.import_module(module)
    monkeypatch.setattr(mod, name, mutate(getattr(mod, name)))
    d, dm = _pair(tmp_path, config, truth, case, "zigzag")
    bad = mirror_mismatch(d, dm)
    assert bad and bad[0].startswith("named"), bad
    assert (case in d.named) != (case in dm.named), (d.named, dm.named)


def test_diagnose_reports_a_wind_outside_the_plausible_range_as_model_form_mismatch(config, truth, tmp_path,
                                                                                     monkeypatch):
    """The model-form rule acts inside :func:`~trials.measured.diagnose.diagnose`: the same wind record
    names the wind with the packaged rule, and with a plausible scale range that excludes the fitted scale
    (here 5-10, the writer's loads being the config's, scale about 1) the wind leaves the named effects
    for ``model_form_mismatch``, its values kept in its entry and said in one console line."""
    from trials.measured.diagnose import diagnose, model_form

    frame = W.log(truth, _sim(truth, "zigzag", EFFECTS["wind"]), seed=7, **EFFECTS["wind"])
    path = tmp_path / "wind.csv"
    frame.to_csv(path, index=False)
    plain = diagnose(config, [path], stride=STRIDE)
    assert "wind" in plain.named and plain.model_form_effects == []
    monkeypatch.setattr(model_form, "rules", lambda cal=None: {"bound_tolerance": None,
                                                               "plausible": {"wind": {"scale": (5.0, 10.0)}}})
    said = []
    d = diagnose(config, [path], stride=STRIDE, say=said.append)
    assert "wind" not in d.named and "wind" not in d.parameters
    (ent,) = d.model_form_effects
    assert ent["effect"] == "wind" and ent["parameters"]["scale"] == pytest.approx(plain.parameters["wind"]["scale"])
    assert d.to_json()["effect_status"]["wind"] == "model_form_mismatch"
    assert sum("model_form_mismatch, not named" in m for m in said) == 1
    assert sum("model_form_mismatch, not named" in ln for ln in d.summary_lines()) == 1
