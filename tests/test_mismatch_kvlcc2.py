"""The mismatch family around a config of another hull form and scale: the KVLCC2 L7 model (MMG
standard method: resistance ``X_0`` on the constant term, cubic terms in v'), its trials the
full-scale development set's Froude-scaled.  Expected values come from the config YAML, the
development set's README and Froude's law worked by hand, not from the module."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import mmg
from trials.measured.mismatch import froude_scaled, mismatch_family, trial_records

REPO = Path(__file__).resolve().parents[1]
YAML = yaml.safe_load((REPO / "configs" / "ships" / "kvlcc2_l7.yaml").read_text())
COEF = {n: c for n, c in YAML["hull"]["coefficients"].items()}
LAM = 320.0 / 7.0                       # the YAML's full_scale L over its L
LINEAR = {"X_0", "Y_v", "Y_r", "N_v", "N_r"}                   # resistance and the terms in v', r'
CUBIC = {"Y_vvv", "Y_vvr", "Y_vrr", "Y_rrr", "N_vvv", "N_vvr", "N_vrr", "N_rrr"}


@pytest.fixture(scope="module")
def kvlcc2():
    return mmg.load_ship("kvlcc2_l7")


@pytest.fixture(scope="module")
def family(kvlcc2):
    return mismatch_family(kvlcc2, 16, seed=5)


def test_the_resistance_and_linear_terms_take_the_linear_width(family):
    """X_0 (a constant term, but the resistance) is drawn within +-10 % like Y_v, Y_r, N_v, N_r; the
    nonlinear terms within +-25 %, and some of them beyond 10 %."""
    lin, nonlin = [], []
    for ship, f in family:
        assert "X_0" in f["hull"]
        for name, x in f["hull"].items():
            (lin if name in LINEAR else nonlin).append(x - 1.0)
        if f["hull_form"] == "config":
            for name, c in COEF.items():
                assert ship.hull.value(name) == pytest.approx(c["value"] * f["hull"][name], rel=1e-12), name
    lin, nonlin = np.array(lin), np.array(nonlin)
    assert np.all(np.abs(lin) <= 0.10) and np.abs(lin).max() > 0.05
    assert np.all(np.abs(nonlin) <= 0.25) and np.abs(nonlin).max() > 0.15


def test_crossflow_member_has_no_cubic_terms_and_keeps_the_cubic_sway_force_roughly(family):
    """A cross-flow member's hull: the cubic sway and yaw terms gone, the cross-flow drags in, its
    nonlinear sway force within the fit's misfit and its own +-25 % of the config's cubic one at a
    drift of 15 deg in a turn r' = 0.4 (v' = -sin beta)."""
    from mmg.terms import crossflow_Y

    forms = [f["hull_form"] for _, f in family]
    assert forms.count("crossflow") == 4 and forms.count("config") == 12
    b, r = math.radians(15.0), 0.4
    v = -math.sin(b)
    c = {n: COEF[n]["value"] for n in CUBIC}
    cubic = c["Y_vvv"] * v ** 3 + c["Y_vvr"] * v * v * r + c["Y_vrr"] * v * r * r + c["Y_rrr"] * r ** 3
    for ship, f in family:
        if f["hull_form"] != "crossflow":
            continue
        h = dict(zip(ship.hull.names, zip(ship.hull.axes, ship.hull.terms, ship.hull.values)))
        assert not CUBIC & set(h)
        assert {"Y_v", "Y_r", "N_v", "N_r", "X_0", "X_vvvv"} <= set(h)
        val = {"int(|v+x*r|*(v+x*r))": crossflow_Y(v, r), "r|r|": r * abs(r)}
        cf = sum(x * val[t] for ax, t, x in h.values() if ax == "Y" and t in val)
        assert cf == pytest.approx(cubic, rel=0.5)


def test_froude_scaling_by_hand():
    """Speeds over sqrt(lambda), r times it, x and y over lambda; angles kept."""
    k = math.sqrt(LAM)
    eff, wind, noise = froude_scaled({"current": {"speed_mps": 0.15, "direction_deg": 60.0},
                                      "heading_bias": {"bias_deg": 1.0}}, (10.0, 0.7),
                                     (0.02, 0.02, 0.0002, 0.5, 0.5, 0.001), LAM)
    assert eff["current"] == {"speed_mps": pytest.approx(0.15 / k), "direction_deg": 60.0}
    assert eff["heading_bias"] == {"bias_deg": 1.0}
    assert wind == (pytest.approx(10.0 / k), 0.7)
    assert noise == pytest.approx((0.02 / k, 0.02 / k, 0.0002 * k, 0.5 / LAM, 0.5 / LAM, 0.001))


def test_trial_is_the_full_scale_one_froude_scaled(kvlcc2, family):
    """A 35 deg turn of the L7 model: 1 s full-scale samples over 1510 s at a 10 kn approach, as
    model times and speeds; its noise the development set's half-widths at model scale; a current
    given at full scale sets the model-scale current in the record's effects."""
    member = family[0][0]
    k = math.sqrt(LAM)
    noisy = trial_records(kvlcc2, member, "turn35", {}, seed=3)
    clean = trial_records(kvlcc2, member, "turn35", {}, seed=3, noise=(0.0,) * 6)
    assert noisy.t[1] - noisy.t[0] == pytest.approx(1.0 / k) and noisy.t[-1] == pytest.approx(1510.0 / k)
    assert np.mean(clean.u[noisy.t < 9.0 / k]) == pytest.approx(10 * 1852 / 3600 / k, rel=0.01)
    half = {"u": 0.02 / k, "v": 0.02 / k, "r": 0.0002 * k, "x": 0.5 / LAM, "y": 0.5 / LAM, "psi": math.radians(0.05)}
    for ch, h in half.items():
        e = getattr(noisy, ch) - getattr(clean, ch)
        if ch == "psi":
            e = np.angle(np.exp(1j * e))
        assert np.abs(e).max() <= h * (1 + 1e-9), ch
        assert np.std(e) == pytest.approx(h / math.sqrt(3.0), rel=0.08), ch
    cur = trial_records(kvlcc2, member, "zz10", {"current": {"speed_mps": 0.15, "direction_deg": 30.0}}, seed=1,
                        noise=(0.0,) * 6)
    assert cur.meta["effects"]["current"]["speed_mps"] == pytest.approx(0.15 / k)


def test_the_baseline_frees_the_kvlcc2_resistance_and_pure_yaw_terms(kvlcc2):
    """The diagnosis's baseline frees the straight-ahead resistance whatever its term (the KVLCC2's
    X_0 on ``1``, at the resistance's 10 % prior width of the YAML value) and the pure-yaw
    nonlinearity of the cubic form (``r^3``, as ``r|r|`` of Kijima's), beside Y_v, Y_r, N_v, N_r;
    never the sway and yaw constants of a ship that has them (the Esso Osaka's Y_0, N_0)."""
    from mmg.model import pack
    from trials.measured.diagnose import _ship_free

    for kind in ("zigzag", "turn"):
        free = {f.name: f for f in _ship_free(kvlcc2, pack(kvlcc2), kind=kind)}
        assert {"X_0", "Y_v", "Y_r", "N_v", "N_r", "Y_rrr", "N_rrr"} <= set(free), kind
        assert free["X_0"].sigma == pytest.approx(0.10 * abs(COEF["X_0"]["value"]))
        assert free["X_0"].upper <= 0.0                 # the resistance keeps its sign
    esso = mmg.load_ship("esso_osaka")
    names = {f.name for f in _ship_free(esso, pack(esso), kind="zigzag")}
    assert "X_uu" in names and not {"Y_0", "N_0"} & names
