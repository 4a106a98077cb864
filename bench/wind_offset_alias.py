"""How much of a rudder offset's signature on a zigzag a wind-curve departure within real ships' scatter takes up.

A zigzag is simulated with a steady true wind (the ship's published wind loads) and a rudder offset, and again
with the same wind and no offset.  The wind's shape terms (``sway_factor``, ``yaw_factor``, ``yaw_sin``:
:mod:`mmg.effects.wind`) are then fitted, without any offset, to the record with the offset: a
maximum-a-posteriori fit with the effect's own prior (how far real ships' curves stray from the regression),
the residuals of heading, position and speed over the noise of the independent development set's logs
(uniform half-widths 0.05 deg, 0.5 m, 0.02 m/s: ``../shared/data/diagnose-dev/README.md``).

Per case the table gives the offset's signature (heading RMS between the records with and without it), what
the best wind-curve departure leaves of it, the share taken up, and that departure in prior standard
deviations.  Where the share is large with departures of a standard deviation or two, one zigzag cannot
tell the offset from the wind curve of a ship that is not the config's: a diagnosis can only report it
``not_identifiable`` there.

    python bench/wind_offset_alias.py [--ship esso_osaka] [--zigzags 10 20] [--speed-kn 10] [--wind 20]
        [--directions 0 45 90 135 180 225 270 315] [--offset 1] [--jobs 2] [--json J] [--markdown]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

import mmg  # noqa: E402
from mmg.effects import Wind  # noqa: E402

SHAPES = ("sway_factor", "yaw_factor", "yaw_sin")
NOISE_STD = {"heading_deg": 0.05 / np.sqrt(3), "position_m": 0.5 / np.sqrt(3), "speed_mps": 0.02 / np.sqrt(3)}
"""The development set's uniform noise as standard deviations (half-width / sqrt 3)."""
DURATION_S = 1200.0
SAMPLE_S = 1.0


def _record(ship, zz: float, kn: float, wind: dict, offset_deg: float) -> np.ndarray:
    """(N, 4): heading unwrapped [deg], x, y [m], speed [m/s] every SAMPLE_S of the zigzag."""
    eff = {"wind": wind}
    if offset_deg:
        eff["rudder_offset"] = {"offset_deg": offset_deg}
    trial = mmg.zigzag(ship, rudder=f"{zz} deg", heading=f"{zz} deg", speed=f"{kn} kn", duration=f"{DURATION_S} s",
                       effects=eff)
    df = mmg.simulate(trial).to_pandas()
    df = df[np.isclose(np.mod(df.index.to_numpy(), SAMPLE_S), 0.0, atol=1e-6)]
    return np.column_stack([np.degrees(np.unwrap(df["psi"].to_numpy())), df["x"].to_numpy(), df["y"].to_numpy(),
                            df["U"].to_numpy()])


def _scaled(d: np.ndarray) -> np.ndarray:
    return np.concatenate([d[:, 0] / NOISE_STD["heading_deg"], d[:, 1] / NOISE_STD["position_m"],
                           d[:, 2] / NOISE_STD["position_m"], d[:, 3] / NOISE_STD["speed_mps"]])


def _rms(a) -> float:
    return float(np.sqrt(np.mean(np.square(a))))


def alias_case(ship_name: str, zz: float, kn: float, wind_mps: float, from_deg: float, offset_deg: float) -> dict:
    """One case: the offset's heading signature, what the best wind-curve departure leaves, and that departure."""
    from scipy.optimize import least_squares

    ship = mmg.load_ship(ship_name)
    pars = {p.name: p for p in Wind.fit_parameters()}
    mu = np.array([pars[n].default for n in SHAPES])
    sd = np.array([pars[n].sigma for n in SHAPES])
    lo, hi = np.array([pars[n].lower for n in SHAPES]), np.array([pars[n].upper for n in SHAPES])
    base = {"true_speed_mps": wind_mps, "true_from_deg": from_deg}
    target = _record(ship, zz, kn, base, offset_deg)
    plain = _record(ship, zz, kn, base, 0.0)

    def resid(th):
        return np.concatenate([_scaled(target - _record(ship, zz, kn, dict(base, **dict(zip(SHAPES, th))), 0.0)),
                               (th - mu) / sd])

    fit = least_squares(resid, mu, bounds=(lo, hi), diff_step=1e-3, max_nfev=60)
    best = _record(ship, zz, kn, dict(base, **dict(zip(SHAPES, fit.x))), 0.0)
    sig, left = _rms(target[:, 0] - plain[:, 0]), _rms(target[:, 0] - best[:, 0])
    return {"zigzag": zz, "speed_kn": kn, "wind_mps": wind_mps, "from_deg": from_deg, "offset_deg": offset_deg,
            "signature_heading_rms_deg": sig, "left_heading_rms_deg": left,
            "signature_position_rms_m": _rms(np.hypot(*(target[:, 1:3] - plain[:, 1:3]).T)),
            "left_position_rms_m": _rms(np.hypot(*(target[:, 1:3] - best[:, 1:3]).T)),
            "taken_up": 1.0 - left / sig if sig > 0 else float("nan"),
            "shape": dict(zip(SHAPES, map(float, fit.x))),
            "shape_prior_sd": dict(zip(SHAPES, map(float, (fit.x - mu) / sd)))}


def table(rows: list, markdown: bool) -> list:
    head = ["zigzag", "wind from [deg]", "offset signature, heading RMS [deg]", "left [deg]", "taken up",
            "position RMS [m]: signature / left", "wind shape (prior sd): sway, yaw, yaw_sin"]
    body = [[f"{r['zigzag']:g}/{r['zigzag']:g}", f"{r['from_deg']:g}", f"{r['signature_heading_rms_deg']:.2f}",
             f"{r['left_heading_rms_deg']:.2f}", f"{100 * r['taken_up']:.0f} %",
             f"{r['signature_position_rms_m']:.0f} / {r['left_position_rms_m']:.0f}",
             ", ".join(f"{v:+.1f}" for v in r["shape_prior_sd"].values())] for r in rows]
    if markdown:
        return ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)] + ["| " + " | ".join(b) + " |" for b in body]
    w = [max(len(h), *(len(b[i]) for b in body)) for i, h in enumerate(head)]
    return ["  ".join(h.ljust(x) for h, x in zip(head, w))] + ["  ".join(c.ljust(x) for c, x in zip(b, w)) for b in body]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ship", default="esso_osaka")
    ap.add_argument("--zigzags", type=float, nargs="+", default=[10.0, 20.0])
    ap.add_argument("--speed-kn", type=float, default=10.0)
    ap.add_argument("--wind", type=float, default=20.0, help="true wind speed [m/s]")
    ap.add_argument("--directions", type=float, nargs="+", default=[0, 45, 90, 135, 180, 225, 270, 315],
                    help="directions the wind comes from [deg], the zigzag's approach course being 0")
    ap.add_argument("--offset", type=float, default=1.0, help="rudder offset [deg]")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", default=None)
    ap.add_argument("--markdown", action="store_true")
    a = ap.parse_args(argv)
    from joblib import Parallel, delayed

    t0 = time.time()
    cases = [(a.ship, zz, a.speed_kn, a.wind, d, a.offset) for zz in a.zigzags for d in a.directions]
    rows = Parallel(n_jobs=a.jobs)(delayed(alias_case)(*c) for c in cases)
    print(f"{a.ship}: {a.offset:g} deg rudder offset on zigzags at {a.speed_kn:g} kn in a {a.wind:g} m/s true wind; "
          "the wind's shape terms fitted (with their prior) to the record with the offset, without it")
    print("\n".join(table(rows, a.markdown)))
    beam = [r["taken_up"] for r in rows if 30 <= np.mod(r["from_deg"], 180) <= 150]
    if beam:
        print(f"wind from 30-150 deg off the bow, either side: median share taken up {100 * np.median(beam):.0f} % "
              f"({len(beam)} cases, {100 * min(beam):.0f}-{100 * max(beam):.0f} %)")
    print(f"{time.time() - t0:.0f} s wall")
    if a.json:
        Path(a.json).write_text(json.dumps({"args": vars(a), "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
