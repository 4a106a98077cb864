"""Do the shared random and berthing records show a propeller walk?  Model-free figures, per record.

Mean yaw acceleration [deg/s^2] (the logged yaw rate, differentiated with a Savitzky-Golay filter)
over the samples with the rudder amidships (|delta| < 5 deg) and a small yaw rate (|r| < 0.03 rad/s),
split by the propeller: astern (n < -3 rps) or ahead (n > 3 rps), with the mean n^2 [rps^2] of each
set.  A single screw running astern walks its stern sideways (a right-handed screw to port: the bow
swings to starboard, r' > 0), by a force that grows as n^2: what ``propeller.Y_P_astern``
(:func:`mmg.model.propeller_lateral`) models.  No model is involved in these figures, so they say what
the records hold before any fit.

With ``--ship SHIP`` (e.g. ``mmg identify``'s DIR/ship.yaml) a last column gives the yaw acceleration
that ship's propeller walk alone gives at each record's mean astern n^2 (its lateral force and moment
through the model's own mass matrix, :func:`mmg.model.force_accelerations`), to set beside the
records' own figure.

    python bench/propwalk_check.py [--data DIR] [--ship SHIP]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "frt-ds-esso"
RUDDER_AMIDSHIPS = math.radians(5.0)
SMALL_R = 0.03          # rad/s
N_ACTIVE = 3.0          # rps
WINDOW = 31             # samples of the derivative filter (3.1 s at 10 Hz)


def record_figures(path: Path) -> dict:
    """{"astern": (samples, mean yaw acceleration [deg/s^2], mean n^2), "ahead": (...)} of one record."""
    import pandas as pd
    from scipy.signal import savgol_filter

    d = pd.read_csv(path).dropna()
    t = d["t [s]"].to_numpy()
    r, n, de = (d[c].to_numpy() for c in ("r_angvelo [rad/s]", "n_prop [rps]", "delta_rudder [rad]"))
    rdot = savgol_filter(r, WINDOW, 2, deriv=1, delta=float(np.median(np.diff(t))))
    calm = (np.abs(de) < RUDDER_AMIDSHIPS) & (np.abs(r) < SMALL_R)
    out = {}
    for side, m in (("astern", calm & (n < -N_ACTIVE)), ("ahead", calm & (n > N_ACTIVE))):
        k = int(m.sum())
        out[side] = (k, float(np.degrees(rdot[m].mean())) if k else math.nan, float(np.mean(n[m] ** 2)) if k else math.nan)
    return out


def walk_yaw_acceleration(ship, n2: float) -> float:
    """Yaw acceleration [deg/s^2] of ``ship``'s propeller walk alone at revolutions n = -sqrt(n2), at rest."""
    from mmg.model import force_accelerations, pack, propeller_lateral

    p = pack(ship).p
    Y, N = propeller_lateral(-math.sqrt(n2), p)
    return float(np.degrees(force_accelerations(0.0, Y, N, p)[2]))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=DATA)
    ap.add_argument("--ship", default=None, help="also the yaw acceleration this ship's propeller walk gives")
    a = ap.parse_args(argv)
    ship = None
    if a.ship is not None:
        from mmg.ship import load_ship

        ship = load_ship(a.ship)
    files = sorted((a.data / "random").glob("*.csv")) + sorted((a.data / "berthing").glob("*.csv"))
    if not files:
        print(f"{a.data}: no random/ or berthing/ records", file=sys.stderr)
        return 2
    extra = f" {ship.name}'s walk [deg/s^2] |" if ship else ""
    print("| record | astern: samples, r' [deg/s^2], n^2 [rps^2] | ahead: samples, r' [deg/s^2], n^2 [rps^2] | astern - ahead |"
          + extra)
    print("|---|---|---|---|" + ("---|" if ship else ""))
    for f in files:
        g = record_figures(f)
        (ka, ra, na), (kb, rb, nb) = g["astern"], g["ahead"]
        walk = f" {walk_yaw_acceleration(ship, na):+.4f} |" if ship and ka else (" - |" if ship else "")
        print(f"| {f.stem} | {ka}, {ra:+.4f}, {na:.0f} | {kb}, {rb:+.4f}, {nb:.0f} | {ra - rb:+.4f} |" + walk)
    return 0


if __name__ == "__main__":
    sys.exit(main())
