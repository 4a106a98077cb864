"""Estimators for any ship: the freed parameters come from the ship's own hull table."""
from __future__ import annotations

import json

import numpy as np
import pytest

from ekf.data import estimable_names, hull_slots
from ekf.estimate import P0_for, load_config
from mmg.errors import InputError
from mmg.ship import load_ship
from trials.cli import main

LINEAR_KVLCC2 = ("Y_v", "Y_r", "N_v", "N_r")


def test_names_come_from_the_hull_table():
    kv = load_ship("configs/ships/kvlcc2_l7.yaml")
    names = estimable_names(kv)
    # every Y/N coefficient of the file except the constant terms, in file order; no X terms
    expect = [n for n, a, t in zip(kv.hull.names, kv.hull.axes, kv.hull.terms) if a != "X" and t != "1"]
    assert list(names) == expect and "Y_v" in names and "Y_beta" not in names
    assert all(kv.hull.names[i] == n for i, n in zip(hull_slots(kv, names), names))
    eo = load_ship("configs/ships/esso_osaka.yaml")
    assert "Y_0" not in estimable_names(eo) and len(estimable_names(eo)) == 12
    with pytest.raises(KeyError, match="Y_beta"):
        hull_slots(kv, ["Y_beta"])


def test_P0_defaults_for_names_the_config_does_not_list():
    cfg = load_config()
    ref = {"Y_v": -0.315, "N_vvv": -0.030}
    P0 = P0_for(cfg, ("Y_v", "N_vvv"), ref)
    rel = cfg.get("P0_default_relative_std", 0.5)
    np.testing.assert_allclose(np.diag(P0)[4:], [(rel * 0.315) ** 2, (rel * 0.030) ** 2])
    # listed names keep the config's value (Table 7)
    assert P0_for(cfg, ("Y_beta",), {"Y_beta": 0.4})[4, 4] == cfg["P0"]["Y_beta"]
    with pytest.raises(InputError, match="P0.Y_x"):
        P0_for(cfg, ("Y_x",), {})


def test_unknown_config_keys_are_refused(tmp_path):
    with pytest.raises(InputError, match="initial.scal"):
        load_config(None, ["initial.scal=100"])
    with pytest.raises(InputError, match="foo"):
        load_config(None, ["foo.bar=1"])
    bad = tmp_path / "c.yaml"
    bad.write_text("dt: 0.1 s\nintial: {scale: 1.5}\n")
    with pytest.raises(InputError, match="intial"):
        load_config(bad)


def test_estimate_recovers_the_kvlcc2_linear_derivatives(tmp_path):
    """A simulated KVLCC2 L7 zigzag (Froude-scaled log noise): the linear derivatives within 3 %
    of the ship file's values, the ones the log was simulated with."""
    out = tmp_path / "kv"
    rc = main(["estimate", "configs/trials/kvlcc2_zz20.yaml", "--config", "configs/estimation/kvlcc2_l7.yaml",
               "--out", str(out), "--no-plots"])
    assert rc == 0
    js = json.loads((out / "estimates.json").read_text())
    kv = load_ship("configs/ships/kvlcc2_l7.yaml")
    assert set(js) == set(estimable_names(kv))
    for n in LINEAR_KVLCC2:
        true = kv.hull.value(n)
        assert js[n]["true"] == true
        assert abs(js[n]["estimate"] / true - 1) < 0.03, (n, js[n])
