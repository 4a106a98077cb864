"""How much of another effect's signature on a zigzag a wind-curve departure within real ships' scatter takes up.

A zigzag is simulated with a steady true wind (the ship's published wind loads) and a second effect (``--target``:
a rudder offset, a heading bias or a current), and again with the same wind alone; both are logged as an
on-board system logs them (:meth:`trials.runs.run.TrialRun.record`: the heading bias is in the logged heading,
the current in the track over ground).  The wind's shape terms (``sway_factor``, ``yaw_factor``, ``yaw_sin``:
:mod:`mmg.effects.wind`) are then fitted, without the second effect, to the record with it: a
maximum-a-posteriori fit (from the best of a grid of starts within two prior standard deviations) with the
effect's own prior (how far real ships' curves stray from the regression),
the residuals of the logged heading, position, velocities over ground and yaw rate over the noise of the
independent development set's logs (uniform half-widths 0.05 deg, 0.5 m, 0.02 m/s, 0.0002 rad/s:
``../shared/data/diagnose-dev/README.md``).  A
current sets downwind (towards the direction the wind blows to), where a wind's leeway drifts the track too.

Per case the table gives the effect's signature (logged-heading and position RMS between the records with
and without it), what the best wind-curve departure leaves of it, the share of the signature taken up (one
minus the ratio of the noise-weighted norms over every channel, left over signature), and that departure in
prior standard deviations.  Where the share is large with departures of a
standard deviation or two, one zigzag cannot tell the effect from the wind curve of a ship that is not the
config's: a diagnosis can only report it ``not_identifiable`` there.

    python bench/wind_alias.py [--target rudder_offset|heading_bias|current] [--size S] [--ship esso_osaka]
        [--zigzags 10 20] [--speed-kn 10] [--wind 20] [--directions 0 45 90 135 180 225 270 315] [--jobs 2]
        [--json J] [--markdown]
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
NOISE_STD = np.array([0.05, 0.5, 0.5, 0.02, 0.02, np.degrees(0.0002)]) / np.sqrt(3)
"""The development set's uniform noise as standard deviations (half-width / sqrt 3) of the columns of
:func:`_record`: heading [deg], x, y [m], u, v [m/s], r [deg/s]."""
DURATION_S = 1200.0
SAMPLE_S = 1.0
TARGETS = {"rudder_offset": ("offset_deg", 1.0, "deg"), "heading_bias": ("bias_deg", 1.0, "deg"),
           "current": ("speed_mps", 0.15, "m/s")}
"""The second effect: its size parameter, default size (the issue's smallest size to detect) and unit."""


def target_effect(target: str, size: float, wind_from_deg: float) -> dict:
    """The ``effects:`` entry of the second effect at ``size`` (a current setting downwind)."""
    key = TARGETS[target][0]
    if target == "current":
        return {"current": {key: size, "direction_deg": float(np.mod(wind_from_deg + 180.0, 360.0))}}
    return {target: {key: size}}


def _record(ship, zz: float, kn: float, wind: dict, other: dict | None) -> np.ndarray:
    """(N, 6) every SAMPLE_S of the zigzag, as logged: heading unwrapped [deg], x, y [m], u, v over ground in the
    logged heading's axes [m/s], r [deg/s]."""
    trial = mmg.zigzag(ship, rudder=f"{zz} deg", heading=f"{zz} deg", speed=f"{kn} kn", duration=f"{DURATION_S} s",
                       effects={"wind": wind, **(other or {})})
    rec = mmg.simulate(trial).record(interval=SAMPLE_S)
    return np.column_stack([np.degrees(np.unwrap(rec.psi)), rec.x, rec.y, rec.u, rec.v, np.degrees(rec.r)])


def _scaled(d: np.ndarray) -> np.ndarray:
    return (d / NOISE_STD).ravel()


def _rms(a) -> float:
    return float(np.sqrt(np.mean(np.square(a))))


GRID_SD = (-2.0, -1.0, 0.0, 1.0, 2.0)
"""The starts of the fit: every combination of these prior standard deviations from the published curve, per
shape term, within its bounds (the record's residual jumps where a change of the zigzag's timing moves a
rudder reversal, so a local fit from one start stays where it starts)."""


def _grid(mu, sd, lo, hi) -> list:
    import itertools

    return [np.clip(mu + sd * np.array(k), lo, hi) for k in itertools.product(GRID_SD, repeat=len(mu))]


def alias_case(ship_name: str, zz: float, kn: float, wind_mps: float, from_deg: float, size: float,
               target: str = "rudder_offset") -> dict:
    """One case: the ``target`` effect's signature, what the best wind-curve departure leaves, and that departure."""
    from scipy.optimize import least_squares

    ship = mmg.load_ship(ship_name)
    pars = {p.name: p for p in Wind.fit_parameters()}
    mu = np.array([pars[n].default for n in SHAPES])
    sd = np.array([pars[n].sigma for n in SHAPES])
    lo, hi = np.array([pars[n].lower for n in SHAPES]), np.array([pars[n].upper for n in SHAPES])
    base = {"true_speed_mps": wind_mps, "true_from_deg": from_deg}
    goal = _record(ship, zz, kn, base, target_effect(target, size, from_deg))
    plain = _record(ship, zz, kn, base, None)

    def resid(th):
        return np.concatenate([_scaled(goal - _record(ship, zz, kn, dict(base, **dict(zip(SHAPES, th))), None)),
                               (th - mu) / sd])

    start = min(_grid(mu, sd, lo, hi), key=lambda th: float(np.sum(resid(th) ** 2)))     # the residual is rough
    fit = least_squares(resid, start, bounds=(lo, hi), diff_step=1e-3, max_nfev=60)
    best = _record(ship, zz, kn, dict(base, **dict(zip(SHAPES, fit.x))), None)
    sig, left = _rms(goal[:, 0] - plain[:, 0]), _rms(goal[:, 0] - best[:, 0])
    whole, rest = np.linalg.norm(_scaled(goal - plain)), np.linalg.norm(_scaled(goal - best))
    return {"target": target, "size": size, "unit": TARGETS[target][2], "zigzag": zz, "speed_kn": kn,
            "wind_mps": wind_mps, "from_deg": from_deg, "signature_heading_rms_deg": sig, "left_heading_rms_deg": left,
            "signature_position_rms_m": _rms(np.hypot(*(goal[:, 1:3] - plain[:, 1:3]).T)),
            "left_position_rms_m": _rms(np.hypot(*(goal[:, 1:3] - best[:, 1:3]).T)),
            "taken_up": 1.0 - rest / whole if whole > 0 else float("nan"),
            "shape": dict(zip(SHAPES, map(float, fit.x))),
            "shape_prior_sd": dict(zip(SHAPES, map(float, (fit.x - mu) / sd)))}


def table(rows: list, markdown: bool) -> list:
    head = ["zigzag", "wind from [deg]", "signature, logged heading RMS [deg]", "left [deg]", "taken up",
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
    ap.add_argument("--target", choices=tuple(TARGETS), default="rudder_offset", help="the second effect")
    ap.add_argument("--size", type=float, default=None,
                    help="its size (offset, bias [deg], current [m/s]); default the smallest the diagnosis should show")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", default=None)
    ap.add_argument("--markdown", action="store_true")
    a = ap.parse_args(argv)
    from joblib import Parallel, delayed

    t0 = time.time()
    size = TARGETS[a.target][1] if a.size is None else a.size
    cases = [(a.ship, zz, a.speed_kn, a.wind, d, size, a.target) for zz in a.zigzags for d in a.directions]
    rows = Parallel(n_jobs=a.jobs)(delayed(alias_case)(*c) for c in cases)
    print(f"{a.ship}: {a.target} {size:g} {TARGETS[a.target][2]} on zigzags at {a.speed_kn:g} kn in a {a.wind:g} m/s "
          f"true wind; the wind's shape terms fitted (with their prior) to the record with it, without it")
    print("\n".join(table(rows, a.markdown)))
    beam = [r for r in rows if 30 <= np.mod(r["from_deg"], 180) <= 150]
    if beam:
        share = [r["taken_up"] for r in beam]
        far = [max(abs(v) for v in r["shape_prior_sd"].values()) for r in beam]
        print(f"wind from 30-150 deg off the bow, either side: median share taken up {100 * np.median(share):.0f} % "
              f"({len(beam)} cases, {100 * min(share):.0f}-{100 * max(share):.0f} %), the largest departure of a shape "
              f"term {min(far):.1f}-{max(far):.1f} prior sd (the starts reach {max(GRID_SD):g})")
    print(f"{time.time() - t0:.0f} s wall")
    if a.json:
        Path(a.json).write_text(json.dumps({"args": vars(a), "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
