"""How closely the wind candidate's shape follows another wind-load curve over the angles one manoeuvre sees.

The diagnosis's wind candidate (:class:`mmg.effects.Wind`) is the Fujiwara regression of the config's wind
geometry with a scale and three shape terms (``sway_factor``, ``yaw_factor``, ``yaw_sin``).  A zigzag sees the
relative wind over a band of some tens of degrees.  For each band centre gamma_0 (the wind from gamma_0 off
the bow, 41 angles over gamma_0 +- ``--half-width``) the candidate's coefficients are fitted by least squares,
within its bounds, to those of a measured curve (the loaded VLCC of OCIMF 1994,
:data:`trials.measured.wind_curves.TANKER_LOADED`); each axis's load (X = q A_T C_X, Y = q A_L C_Y,
N = q A_L L C_N) is weighted by the band's mean |load| of that axis.  Printed per axis: the rms misfit over
that mean, with the candidate as it is and with one more shape term (``--extra``: ``x_cos2`` adds
e cos(2 gamma) to C_X, ``y_sin2`` e sin(2 gamma) to C_Y, e within +-0.5), and the fitted values.  What the
shape cannot follow is left to the other candidates (a surge misfit reads like a current along the course).

    python bench/wind_shape_band.py [--ship esso_osaka] [--half-width 20] [--extra x_cos2 y_sin2] [--json J]
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

EXTRAS = {"x_cos2": (0, np.cos, 2), "y_sin2": (1, np.sin, 2)}
"""Extra shape terms: (axis, function, harmonic) of e f(k gamma) added to that axis's coefficient."""
CENTRES_DEG = (30.0, 60.0, 90.0, 120.0, 150.0)


def candidate(gamma, particulars, theta, extra: str | None = None):
    """The candidate's (C_X, C_Y, C_N) at ``gamma`` [rad] for theta = (scale, sway_factor, yaw_factor, yaw_sin
    [, e of ``extra``])."""
    from mmg.wind import amplitude_vector, fujiwara_series

    scale, sway, yaw, ysin = theta[:4]
    c = list(fujiwara_series(np.cos(gamma), np.sin(gamma), amplitude_vector(particulars, sway, yaw, ysin)))
    if extra is not None:
        axis, f, k = EXTRAS[extra]
        c[axis] = c[axis] + theta[4] * f(k * gamma)
    return tuple(scale * ci for ci in c)


def band_fit(curve, particulars, centre_deg: float, half_width_deg: float = 20.0, extra: str | None = None) -> dict:
    """The candidate fitted to ``curve`` (``curve(gamma) -> (C_X, C_Y, C_N)``) over one band.

    Returns
    -------
    dict
        ``{"centre_deg", "extra", "misfit": {"X", "Y", "N"}, "theta": [...]}``: per axis the rms misfit of the
        load over the band's mean |load|.
    """
    from scipy.optimize import least_squares

    g = np.radians(np.linspace(centre_deg - half_width_deg, centre_deg + half_width_deg, 41))
    arm = np.array([particulars.A_T, particulars.A_L, particulars.A_L * particulars.L])
    target = [arm[k] * np.asarray(c, float) for k, c in enumerate(curve(g))]
    scale = [max(float(np.mean(np.abs(t))), 1e-12) for t in target]

    def res(th):
        c = candidate(g, particulars, th, extra)
        return np.concatenate([(arm[k] * c[k] - target[k]) / scale[k] for k in range(3)])

    from mmg.effects import Wind

    params = Wind.fit_parameters()                         # the candidate's own bounds and starts
    lo, hi = [q.lower for q in params], [q.upper for q in params]
    x0 = [q.default if q.start is None else q.start for q in params]
    if extra is not None:
        lo, hi, x0 = lo + [-0.5], hi + [0.5], x0 + [0.0]
    sol = least_squares(res, np.array(x0), bounds=(lo, hi))
    r = sol.fun.reshape(3, -1)
    return {"centre_deg": centre_deg, "extra": extra,
            "misfit": {ax: float(np.sqrt(np.mean(r[k] ** 2))) for k, ax in enumerate("XYN")},
            "theta": [float(v) for v in sol.x]}


def main(argv=None) -> int:
    import mmg
    from trials.measured.wind_curves import TANKER_LOADED

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ship", default="esso_osaka")
    ap.add_argument("--half-width", type=float, default=20.0, help="half the band of relative wind angles [deg]")
    ap.add_argument("--extra", nargs="*", default=list(EXTRAS), choices=list(EXTRAS))
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    ship = mmg.load_ship(mmg.ship_path(a.ship))
    if ship.wind is None:
        print(f"--ship {a.ship}: no wind section", file=sys.stderr)
        return 2
    p = ship.wind.particulars()
    rows = []
    print(f"OCIMF loaded VLCC against the candidate on {a.ship}'s wind geometry, bands of +-{a.half_width:g} deg: "
          "rms misfit over the band's mean |load|, X Y N (fitted scale, sway, yaw, yaw_sin[, extra])")
    for c0 in CENTRES_DEG:
        for extra in [None] + list(a.extra):
            r = band_fit(TANKER_LOADED.coefficients, p, c0, a.half_width, extra)
            rows.append(r)
            m = r["misfit"]
            print(f"  {c0:5.0f} deg  {extra or 'shape':7s}  X {m['X']:.2f}  Y {m['Y']:.2f}  N {m['N']:.2f}  "
                  f"({', '.join(f'{v:.2f}' for v in r['theta'])})")
    if a.json:
        Path(a.json).write_text(json.dumps({"ship": a.ship, "half_width_deg": a.half_width, "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
