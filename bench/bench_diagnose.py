"""How good is mmg diagnose: false alarms on clean records, detection rate against effect size,
and the time of one diagnose of a 3500 s full-scale record at 1 s.

Records: turning + zigzag of the 3 m Esso Osaka model (0.5 s samples), simulated by a ship whose
added masses m_x', m_y' and wake w_P0 are perturbed by 5-10 % (random sign and size per seed) from
the config that diagnoses it, with white log noise, diagnosed jointly.  Writes
bench/out/diagnose_detection.png and prints a table.

    python bench/bench_diagnose.py [--clean 20] [--seeds 5] [--effects ...] [--quick] [--timing-only] [--no-timing]

bench/out/diagnose_bench.json keeps the figures as they come.

``--mismatch``: full-scale trials of the mismatch family (:mod:`trials.measured.mismatch`),
each record diagnosed alone with the bundled config; false alarms over ``--clean`` (default 40) clean
records, detection per effect and size split zigzag / turn (``bench/diagnose_mismatch.py``):

    python bench/bench_diagnose.py --mismatch [--ship esso_osaka] [--clean 40] [--seeds 5] [--seed0 0] [--jobs 2] [--effects ...]
        [--only ID ...] [--candidate-start config|current] [--max-nfev N] [--trials ...]
        [--quick] [--tag _cal] [--wide]

``--wide`` draws each record's hand, manoeuvre (turns 15-35 deg, zigzags 10/10-20/20, either hand
first) and approach speed (6-15 kn), with winds beside each other effect, and prints the figures per
class (hand, manoeuvre, speed band); ``--summarise`` prints that table for any run.

writes bench/out/diagnose_mismatch<tag>.json (every record's factors, truth, named effects and
candidate rounds) and bench/out/diagnose_detection_mismatch<tag>.png; the summary gives, per effect
and size, the records named, those reported ``not_identifiable`` and the silent ones.

    python bench/bench_diagnose.py --mismatch --summarise bench/out/diagnose_mismatch<tag>.json ...

summarises runs already made, pooled (their ``not_identifiable`` completed by the evidence rule of
the code as it is, :func:`trials.measured.diagnose.weak_evidence`).
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

SIZES = {
    "current": ("speed_mps", [0.0025, 0.005, 0.01], lambda s: {"current": {"speed_mps": s, "direction_deg": 60.0}}),
    "rudder_offset": ("offset_deg", [0.1, 0.25, 0.5], lambda s: {"rudder_offset": {"offset_deg": s}}),
    "heading_bias": ("bias_deg", [0.25, 0.5, 1.0], lambda s: {"heading_bias": {"bias_deg": s}}),
    "wind": ("scale", [0.25, 0.5, 1.0], lambda s: {"wind": {"scale": s}}),
}
"""Per effect: the parameter, the sizes tried (3 m model, 0.49 m/s approach; a current of 0.01 m/s
is 2 % of the speed, 0.1 m/s at full scale) and the effect spec."""


def perturbed(ship, rng):
    f = lambda: 1.0 + rng.choice([-1, 1]) * rng.uniform(0.05, 0.10)  # noqa: E731
    w = list(ship.propeller.w_P0)
    w[0] *= f()
    return replace(ship, mass=replace(ship.mass, m_x_prime=ship.mass.m_x_prime * f(), m_y_prime=ship.mass.m_y_prime * f()),
                   propeller=replace(ship.propeller, w_P0=tuple(w)))


def records(ship, truth, eff, seed, wind):
    from trials.measured.diagnose import RecordNoise, synthetic_record

    return [synthetic_record(ship, "turning", eff, truth_ship=truth, true_wind=wind, noise=RecordNoise(seed=2 * seed)),
            synthetic_record(ship, "zigzag", eff, truth_ship=truth, true_wind=wind,
                             noise=RecordNoise(seed=2 * seed + 1))]


def timing():
    import mmg
    from trials.measured.diagnose import Manoeuvre, RecordNoise, diagnose, synthetic_record

    ship = mmg.load_ship("esso_osaka")
    diagnose(ship, [synthetic_record(ship, Manoeuvre("turning", duration=300.0, dt=1.0), {})],
             candidates=["current"])  # compile
    worst = 0.0
    for kind, rudder in (("zigzag", 20.0), ("turning", 35.0)):       # a turn frees the rudder inflow as well
        rec = synthetic_record(ship, Manoeuvre(kind, rudder_deg=rudder, speed=10 * 0.5144, duration=3500.0, dt=1.0),
                               {"current": {"speed_mps": 0.3, "direction_deg": 120.0}}, noise=RecordNoise(seed=3))
        t0 = time.perf_counter()
        d = diagnose(ship, [rec])
        dt = time.perf_counter() - t0
        worst = max(worst, dt)
        print(f"timing: one diagnose of a {rec.t[-1]:.0f} s full-scale {kind} record at 1 s ({len(rec.t)} samples): "
              f"{dt:.1f} s wall (target <= 15 s); named {d.named} {d.parameters}", flush=True)
    return worst


def _refuse_bad_options(ap, a) -> None:
    """Options that would be ignored or do the wrong thing silently are refused (exit 2, one line)."""
    from trials.measured.diagnose import SCREEN_NFEV

    if a.ship is not None and not a.mismatch:
        ap.error("--ship: the config of --mismatch runs; give --mismatch with it")
    if a.summarise and not a.mismatch:
        ap.error("--summarise: summarises --mismatch runs; give --mismatch with it")
    missing = [f for f in a.summarise or () if not Path(f).is_file()]
    if missing:
        ap.error(f"--summarise: no such run file: {missing[0]}")
    if a.summarise and (a.only or a.max_nfev is not None or a.trials is not None):
        ap.error("--summarise: reads runs already made; --only, --max-nfev and --trials are not used with it")
    if a.wide and (not a.mismatch or a.trials is not None or a.summarise):
        ap.error("--wide: draws its own trials for a --mismatch run; not with --trials or --summarise")
    if a.wind_curve != "fujiwara" and not a.mismatch:
        ap.error("--wind-curve: the shape of the --mismatch family's wind loads; give --mismatch with it")
    if a.max_nfev is not None and a.max_nfev <= SCREEN_NFEV:
        ap.error(f"--max-nfev: {a.max_nfev} is not more than the screening budget of {SCREEN_NFEV} evaluations")


def main(argv=None):
    from trials.measured.wind_curves import WIND_CURVES

    ap = argparse.ArgumentParser()
    ap.add_argument("--clean", type=int, default=None,
                    help="clean record pairs (false alarms; default 20), with --mismatch clean records (default 40)")
    ap.add_argument("--clean-first", type=int, default=20,
                    help="first clean seed (seeds 0-19 calibrated the threshold; the default tests fresh ones)")
    ap.add_argument("--seeds", type=int, default=5, help="seeds per effect size")
    ap.add_argument("--effects", nargs="*", default=None)
    ap.add_argument("--sizes", type=float, nargs="*", help="effect sizes to try instead of SIZES (with one --effects)")
    ap.add_argument("--quick", action="store_true", help="4 clean pairs, 2 seeds")
    ap.add_argument("--timing-only", action="store_true")
    ap.add_argument("--no-timing", action="store_true")
    ap.add_argument("--tag", default="", help="suffix of the output names (bench/out/diagnose_bench<tag>.json, ...)")
    ap.add_argument("--mismatch", action="store_true",
                    help="full-scale trials of the mismatch family, one record per diagnose (bench/diagnose_mismatch.py)")
    ap.add_argument("--ship", default=None, metavar="SHIP",
                    help="--mismatch: the config diagnosed and drawn around (default esso_osaka; a model-scale one, "
                         "e.g. kvlcc2_l7, sails the full-scale trials Froude-scaled to it)")
    ap.add_argument("--seed0", type=int, default=0, help="--mismatch: the family's and the noise seeds' offset")
    ap.add_argument("--jobs", type=int, default=2, help="--mismatch: parallel processes")
    ap.add_argument("--only", nargs="+", default=None, metavar="ID",
                    help="--mismatch: only these records (ids as printed, e.g. wind_10_0 clean_20) of the full draw")
    ap.add_argument("--mirror", action="store_true",
                    help="--mismatch: each record's port <-> starboard twin instead (the other hand first, wind and "
                         "current directions mirrored about the approach course, offset and bias signs flipped; the "
                         "same member and noise): diagnose_mismatch.mirrored")
    ap.add_argument("--candidate-start", choices=("config", "current"), default="config",
                    help="--mismatch: where candidates' fits start the ship (DiagnoseOptions.candidate_start)")
    ap.add_argument("--max-nfev", type=int, default=None,
                    help="--mismatch: evaluations of each fit, the candidates' and the baseline's "
                         "(DiagnoseOptions.max_nfev; default 12; more than the screening budget of 6): "
                         "whether a candidate stopped by its budget or by its physics")
    ap.add_argument("--trials", nargs="*", default=None,
                    help="--mismatch: the trials to draw from (default all: turn35 turn35p zz10 zz15 zz20; "
                         "turn_pair: both 35 deg turns of one member diagnosed together)")
    ap.add_argument("--wide", action="store_true",
                    help="--mismatch: the wider draw: either hand first, turns 15-35 deg, zigzags 10/10-20/20, "
                         "approach 6-15 kn per record, winds 8-25 m/s alone and 15-25 m/s beside each other effect "
                         "(diagnose_mismatch.wide_jobs); prints the per-class table")
    ap.add_argument("--wind-curve", choices=WIND_CURVES, default="fujiwara",
                    help="--mismatch: the shape of the members' wind loads (MismatchSpec.wind_curve): the model's own "
                         "(fujiwara, default), a loaded tanker's measured curve drawn per member (harmonic), or half each")
    ap.add_argument("--summarise", nargs="+", default=None, metavar="JSON",
                    help="--mismatch: print the summary of runs already made (bench/out/diagnose_mismatch<tag>.json), "
                         "pooled, their not_identifiable lists completed by the evidence rule of the code as it is "
                         "(trials.measured.diagnose.weak_evidence over each record's stored rounds)")
    a = ap.parse_args(argv)
    _refuse_bad_options(ap, a)
    if a.mismatch and a.summarise:
        sys.path.insert(0, str(REPO / "bench"))
        from diagnose_mismatch import summarise_files

        summarise_files(a.summarise)
        return
    if a.mismatch:
        sys.path.insert(0, str(REPO / "bench"))
        from diagnose_mismatch import SHIP, main_mismatch

        a.ship = a.ship or SHIP

        main_mismatch(a)
        return
    a.clean = 20 if a.clean is None else a.clean
    a.effects = list(SIZES) if a.effects is None else a.effects
    if a.timing_only:
        timing()
        return
    import json

    import mmg
    from trials.measured.diagnose import diagnose

    ship = mmg.load_ship("esso_osaka_3m")
    seeds = 2 if a.quick else a.seeds
    nclean = 4 if a.quick else a.clean
    out = REPO / "bench" / "out"
    out.mkdir(exist_ok=True)
    t0 = time.perf_counter()
    results = {"clean": [], "detection": {}}

    def save():
        (out / f"diagnose_bench{a.tag}.json").write_text(json.dumps(results, indent=1))

    false = 0
    for s in range(a.clean_first, a.clean_first + nclean):
        t1 = time.perf_counter()
        truth = perturbed(ship, np.random.default_rng(100 + s))
        d = diagnose(ship, records(ship, truth, {}, 50 + s, (0.0, 0.0)))
        false += bool(d.named)
        best = max((c["delta_bic"] for r in d.rounds for c in r["candidates"]), default=float("nan"))
        results["clean"].append({"seed": s, "named": d.named, "max_delta_bic": best})
        save()
        print(f"clean seed {s} ({s - a.clean_first + 1}/{nclean}): named {d.named} (largest candidate dBIC {best:.1f}) "
              f"{time.perf_counter() - t1:.0f} s", flush=True)
    print(f"false alarms: {false}/{nclean} clean record pairs ({100 * false / max(nclean, 1):.0f} %)", flush=True)
    det = {}
    for eff in a.effects:
        par, sizes, spec = SIZES[eff]
        sizes = a.sizes or sizes
        sizes = sizes[1:] if a.quick else sizes
        det[eff] = []
        for size in sizes:
            hit, errs, wrong = 0, [], 0
            for s in range(seeds):
                t1 = time.perf_counter()
                truth = perturbed(ship, np.random.default_rng(200 + s))
                d = diagnose(ship, records(ship, truth, spec(size), s, (2.0, 1.0) if eff == "wind" else (0.0, 0.0)))
                ok = eff in d.named
                hit += ok
                wrong += bool(set(d.named) - {eff})
                if ok:
                    errs.append(d.parameters[eff][par] - size)
                r1 = {c["effect"]: c for c in d.rounds[0]["candidates"]} if d.rounds else {}
                print(f"  {eff} {par}={size:g} seed {s}: round-1 dBIC {r1.get(eff, {}).get('delta_bic', float('nan')):.1f}, "
                      f"named {d.named} "
                      f"{d.parameters.get(eff, {}).get(par, float('nan')):.4g} {time.perf_counter() - t1:.0f} s",
                      flush=True)
            det[eff].append((size, hit / seeds, float(np.mean(np.abs(errs))) if errs else math.nan, wrong))
            results["detection"][eff] = det[eff]
            save()
            print(f"{eff} {par}={size:g}: detected {hit}/{seeds}, mean |error| {det[eff][-1][2]:.3g}, "
                  f"others named {wrong}/{seeds}", flush=True)
    print(f"\nfalse alarms: {false}/{nclean} clean record pairs ({100 * false / max(nclean, 1):.0f} %)")
    print(f"{'effect':15s} {'size':>8s} {'detection':>10s} {'|error|':>9s} {'others':>7s}")
    for eff, rows in det.items():
        for size, rate, err, wrong in rows:
            print(f"{eff:15s} {size:8g} {rate:10.0%} {err:9.3g} {wrong:7d}")
        found = [s for s, r, _, _ in rows if r >= 0.8]
        print(f"  detection threshold ({SIZES[eff][0]}, smallest size found in >= 80 % of seeds): "
              f"{min(found) if found else 'above the sizes tried'}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if det:
        fig, axs = plt.subplots(1, len(det), figsize=(4 * len(det), 3.2), layout="constrained", squeeze=False)
        for ax, (eff, rows) in zip(axs[0], det.items()):
            ax.semilogx([r[0] for r in rows], [r[1] for r in rows], "o-")
            ax.set_ylim(-0.05, 1.05)
            ax.set_xlabel(f"{eff} {SIZES[eff][0]}")
            ax.set_ylabel("detection rate")
            ax.set_title(f"false alarms {false}/{nclean} clean, {seeds} seeds/size", fontsize=8)
        fig.savefig(out / f"diagnose_detection{a.tag}.png", dpi=110)
        print(f"wrote {out / f'diagnose_detection{a.tag}.png'}")
    print(f"{time.perf_counter() - t0:.0f} s")
    if not a.no_timing:
        timing()

if __name__ == "__main__":
    main()
