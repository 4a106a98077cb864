"""Cross-validation of ``mmg identify`` on the shared FRT-DS-ESSO turning and zigzag records
(issue 11, acceptance 1): four folds, each record kept out once, with and without wind; per
record the open-loop heading RMS of the initial (Froude-scaled) 3 m model and of the model
identified without it.  The fit starts from that ship (``esso_osaka_3m``, the Kijima hull form,
``--ship``; stop 19: it predicts the kept-out records better than the cross-flow form
``esso_osaka_3m_crossflow``, the default before) and is scored against it (``--initial``).
Run: ``python bench/identify_cv.py [--wind on|off|both] [--ship S] [--initial S] [--free ...]``.

``--offset-spread DEG`` also replays every kept-out record, with both models, under rudder offsets
from -DEG to +DEG (the ``rudder_offset`` effect: the blade DEG from what the indicator logs) and prints
the range of heading RMS each model spans and the offset each prefers: how much of a record's score a
small, record-specific asymmetry (a rudder zero, a steady gust, a pond current) decides."""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import mmg  # noqa: E402
from trials.measured.identify import cross_validate, load_runs  # noqa: E402
from trials.papers.reproduce import frt_data_dir  # noqa: E402


SHIP = "esso_osaka_3m"
"""The prior: the Froude-scaled 3 m ship in the Kijima hull form (``esso_osaka_3m_crossflow``: the same
ship in the low-speed cross-flow form, the default before stop 19; docs/identify_cv.md)."""
INITIAL = "esso_osaka_3m"
"""The honest initial model every kept-out record is scored with: the Froude-scaled full-scale ship."""


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--wind", choices=["on", "off", "both"], default="both")
    ap.add_argument("--folds", type=int, default=4)
    ap.add_argument("--free", nargs="+", default=None, help="free parameters (default: trials.measured.identify.DEFAULT_FREE)")
    ap.add_argument("--prior", type=float, default=0.5, help="prior std relative to the config value")
    ap.add_argument("--ship", default=SHIP, help=f"prior ship: the form identified and its starting values (default {SHIP})")
    ap.add_argument("--initial", default=INITIAL, help=f"the model the identified one is compared with (default {INITIAL})")
    ap.add_argument("--weighting", choices=["samples", "equal", "relative"], default=None,
                    help="record weighting in the fit (default: trials.measured.identify.DEFAULT_WEIGHTING)")
    ap.add_argument("--loss", default="linear", help="least_squares loss of the whole-record stage")
    ap.add_argument("--f-scale", type=float, default=1.0, help="the robust loss's residual scale")
    ap.add_argument("--nuisance", nargs="+", default=(), metavar="EFFECT",
                    help="effects fitted once per training record as nuisances (e.g. current)")
    ap.add_argument("--folds-by", choices=["order", "revolutions"], default="order",
                    help="deal the records into folds in file order or stratified by propeller revolutions")
    ap.add_argument("--max-nfev", type=int, default=None,
                    help="evaluation limit of each fit stage (default: trials.measured.identify.DEFAULT_MAX_NFEV)")
    ap.add_argument("--velocity-weight", type=float, default=1.0,
                    help="weight of the u, v, r residuals beside the heading's (identify(velocity_weight=))")
    ap.add_argument("--offset-spread", type=float, default=0.0, metavar="DEG",
                    help="also score each kept-out record under rudder offsets within +-DEG (both models)")
    a = ap.parse_args()
    d = frt_data_dir()
    if d is None:
        sys.exit("FRT-DS-ESSO data not found (set MMG_FRT_DATA)")
    files = sorted((d / "turning").glob("*.csv")) + sorted((d / "zigzag").glob("*.csv"))
    ship, initial = mmg.load_ship(a.ship), mmg.load_ship(a.initial)
    print(f"prior {ship.name}; initial {initial.name}; free {a.free or 'default'}; weighting "
          f"{a.weighting or 'default'}; loss {a.loss} (f_scale {a.f_scale:g}); folds by {a.folds_by}; "
          f"per-record nuisance {list(a.nuisance) or 'none'}; velocity weight {a.velocity_weight:g}", flush=True)
    for wind in ([True, False] if a.wind == "both" else [a.wind == "on"]):
        runs = load_runs(ship, files, wind=wind)
        t0 = time.perf_counter()
        extra = {"free": a.free} if a.free else {}
        if a.weighting:
            extra["record_weighting"] = a.weighting
        if a.nuisance:
            extra["record_nuisance"] = tuple(a.nuisance)
        if a.loss != "linear":
            extra.update(loss=a.loss, f_scale=a.f_scale)
        if a.velocity_weight != 1.0:
            extra["velocity_weight"] = a.velocity_weight
        if a.max_nfev:
            extra["max_nfev"] = a.max_nfev
        cv = cross_validate(ship, runs, folds=a.folds, wind=wind, prior_rel_std=a.prior, initial=initial,
                            folds_by=a.folds_by, **extra,
                            progress=lambda k, n: print(f"  fold {k}/{n} done, {time.perf_counter() - t0:.0f} s", flush=True))
        print(f"\nwind {'on' if wind else 'off'}: {len(runs)} records, {a.folds} folds, {time.perf_counter() - t0:.0f} s")
        print(f"{'record':32s} {'initial':>8s} {'identified':>10s} {'ratio':>6s}  (heading RMS, deg)")
        for c in cv:
            x, y = c["initial"]["heading_rms_deg"], c["identified"]["heading_rms_deg"]
            print(f"{c['name']:32s} {x:8.2f} {y:10.2f} {x / y:6.2f}")
        ok = [c for c in cv if np.isfinite(c["identified"]["heading_rms_deg"])]   # (a diverged replay: below)
        xa = np.mean([c["initial"]["heading_rms_deg"] for c in ok])
        xb = np.mean([c["identified"]["heading_rms_deg"] for c in ok])
        nb = sum(c["identified"]["heading_rms_deg"] < c["initial"]["heading_rms_deg"] for c in cv)
        print(f"{'mean':32s} {xa:8.2f} {xb:10.2f} {xa / xb:6.2f}   better on {nb} of {len(cv)} kept-out records")
        diverged = [c["name"] for c in cv if not np.isfinite(c["identified"]["heading_rms_deg"])]
        if diverged:
            print(f"the identified model's replay diverged on {', '.join(diverged)} (counted as not better; "
                  f"left out of both means)")
        if a.offset_spread > 0:
            offset_spread(cv, runs, initial, a.offset_spread)


def offset_spread(cv, runs, initial, spread_deg: float, n: int = 9) -> None:
    """Per kept-out record: the heading RMS [deg] of the initial and the identified model under rudder
    offsets in [-spread_deg, +spread_deg] (``n`` values): the range each spans and the offset each
    prefers; then the comparison with each model at its own preferred offset (an oracle, both alike)."""
    from trials.measured.identify import _ship_with, with_ship_effects
    from trials.measured.predict import replay_record

    by_name = {r.name: r for r in runs}
    offs = np.linspace(-spread_deg, spread_deg, n)

    def scan(ship, run):
        out = []
        for o in offs:
            s = _ship_with(ship, {"rudder_offset": np.radians(o)})
            out.append(replay_record(s, with_ship_effects(run, s)).scores()["heading_rms_deg"])
        return np.array(out)

    print(f"\nrudder offsets {offs[0]:+.2f} .. {offs[-1]:+.2f} deg ({n} values): heading RMS range [deg] and "
          f"preferred offset [deg] of each model")
    print(f"{'record':32s} {'initial range':>15s} {'at':>6s} {'identified range':>17s} {'at':>6s}")
    best_a, best_b = [], []
    for c in cv:
        run = by_name[c["name"]]
        ra, rb = scan(initial, run), scan(c["ship"], run)
        ka, kb = int(np.nanargmin(ra)), int(np.nanargmin(rb))
        best_a.append(ra[ka])
        best_b.append(rb[kb])
        print(f"{c['name']:32s} {np.nanmin(ra):6.2f} - {np.nanmax(ra):6.2f} {offs[ka]:+6.2f} "
              f"{np.nanmin(rb):7.2f} - {np.nanmax(rb):7.2f} {offs[kb]:+6.2f}")
    best_a, best_b = np.array(best_a), np.array(best_b)
    print(f"each model at its own preferred offset: mean {best_a.mean():.2f} (initial) against {best_b.mean():.2f} "
          f"(identified), ratio {best_a.mean() / best_b.mean():.2f}, identified better on "
          f"{int(np.sum(best_b < best_a))} of {len(cv)}")


if __name__ == "__main__":
    main()
