"""A sea-trial log (positions, heading, speed over ground; no u, v) replayed with a known cross
current: the replay must start with no sway through the water (the ship was on a straight
approach), not with the stand-in zero of the logged sway turned into a sway of minus the current's
cross part (the 1 kn current on ZZ20)."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import yaml


def test_speed_only_log_with_a_cross_current_replays_its_track(tmp_path):
    import mmg
    from ekf.identify import effect_parameters, predict_logged
    from mmg.effects import get
    from mmg.model import pack
    from mmg.resources import config_path
    from trials.measured.diagnose_records import prepare

    spec = yaml.safe_load(open(config_path("trials", "zz20.yaml")))
    spec["duration"] = "600 s"
    spec["log"]["noise"] = {"lat": "0 deg", "lon": "0 deg", "heading": "0 deg", "rpm": "0 rpm", "speed": "0 kn"}
    speed, towards = 0.5, 90.0                     # across the approach (north): east at 0.5 m/s
    spec["effects"] = {"current": {"speed_mps": speed, "direction_deg": towards}}
    (tmp_path / "t.yaml").write_text(yaml.safe_dump(spec))
    subprocess.run([sys.executable, "-m", "trials.cli", "simulate", str(tmp_path / "t.yaml"), "--out",
                    str(tmp_path / "o")], check=True, capture_output=True)
    ship = mmg.load_ship("esso_osaka")
    seg = prepare(ship, [tmp_path / "o" / "log.csv"])[0].seg
    assert seg.speed_only
    cur = get("current")
    theta = np.array([speed * np.cos(np.radians(towards)), speed * np.sin(np.radians(towards))])
    pred = predict_logged(pack(ship), seg, [cur], effect_parameters([cur]), theta, ship)
    end = float(np.hypot(*(pred[-1, 3:5] - seg.meas[-1, 3:5])))
    drift = speed * (seg.inputs.t[-1] - seg.inputs.t[0])          # 300 m across the track
    # the one error left: u starts as the speed over ground, high by about c^2 / 2U (0.016 m/s): ~10 m
    assert end < 0.08 * drift, (end, drift)
    assert np.degrees(np.max(np.abs(pred[:, 5] - seg.meas[:, 5]))) < 1.0
