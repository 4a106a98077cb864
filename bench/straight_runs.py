"""The leading straight runs of the development set's logs, as `mmg diagnose` finds them, against the
manifest's hidden effects: what the straight run reads (docs/diagnose.md).

    python bench/straight_runs.py [--ship esso_osaka]

Per log: the straight run's samples, the drift angle over ground it logs (atan2(-v, u) in the logged
heading's axes, the mean over the run) with its standard error, and what the manifest says it should
read: the heading bias plus a current's part across the heading over the speed (a wind's drift is
not predicted: such logs have no straight run when the relative wind exceeds half the speed).  Also
the config's own straight-run drift (:func:`mmg.equilibrium.straight_run`), which the hull-drift
allowance is ten times.  No diagnosis is run: a few seconds.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEV = REPO.parent / "shared" / "data" / "diagnose-dev"


def expected_drift_deg(entry: dict, U: float) -> float:
    """The drift over ground [deg] a straight run at true heading 0 logs under the manifest's effects."""
    p = entry.get("parameters", {})
    b = p.get("heading_bias", {}).get("bias_deg", 0.0)
    cur = p.get("current")
    cross = cur["speed_m_s"] * math.sin(math.radians(cur["set_towards_deg"])) if cur else 0.0
    return b - math.degrees(math.atan2(cross, U))


def main(argv=None) -> int:
    import mmg
    from mmg.equilibrium import straight_run
    from trials.measured.diagnose_records import prepare

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ship", default="esso_osaka")
    a = ap.parse_args(argv)
    if not (DEV / "manifest.json").is_file():
        print(f"no development set at {DEV}", file=sys.stderr)
        return 2
    ship = mmg.load_ship(mmg.ship_path(a.ship))
    eq = straight_run(ship, 10.0 * 0.5144444)
    print(f"config {a.ship}: straight-run drift at 10 kn {math.degrees(math.atan2(-eq.v, eq.u)):.4f} deg "
          f"(v {eq.v:.5f} m/s, trim rudder {math.degrees(eq.delta):.3f} deg)")
    files = json.loads((DEV / "manifest.json").read_text())["files"]
    prep = prepare(ship, [DEV / f["file"] for f in files])
    print(f"{'log':8} {'trial':8} {'effects':28} {'samples':>7} {'drift [deg]':>11} {'sd':>6} {'expected':>9}")
    for f, p in zip(files, prep):
        st = p.seg.straight
        eff = "+".join(f["effects"]) or "none"
        if st is None:
            print(f"{p.name:8} {f['trial']:8} {eff:28} {'-':>7}  (no straight run: wind or not steady)")
            continue
        m = p.seg.meas[:st.n]
        U = float(np.mean(np.hypot(m[:, 0], m[:, 1])))
        drift = math.degrees(float(np.mean(np.arctan2(-m[:, 1], m[:, 0]))))
        exp = "wind" if "wind" in f["effects"] else f"{expected_drift_deg(f, U):.3f}"
        print(f"{p.name:8} {f['trial']:8} {eff:28} {st.n:7d} {drift:11.3f} {math.degrees(st.sigma / U):6.3f} {exp:>9}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
