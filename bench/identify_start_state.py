"""Did fitting each record's start state make ``mmg identify`` worse on the real 3 m records?

Identifies ``esso_osaka_3m`` (``mmg identify``'s defaults) over the shared FRT-DS-ESSO turning and zigzag
records twice: ``initial_state="sample"`` (each record replayed from its raw first sample: the fit before
the start-state nuisances, bit for bit) and ``"fit"`` (the default since); prints each training record's
open-loop heading RMS [deg] of the identified model replayed from the record's first sample (the report's
training table, the same replay for both), the means, the fits' residual correlation time tau, their
evaluations and seconds, and each shared parameter's value with its std from the fit's own Gauss-Newton
covariance (:func:`trials.measured.identify.fit_covariance`) and from the covariance now written
(:func:`~trials.measured.identify.identification_covariance`).

Usage: ``python bench/identify_start_state.py [--data ../shared/data/frt-ds-esso] [--wind on|off]
[--out FILE.json]`` (minutes: two fits over 22 records).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))


def run(data: Path, wind: str | None, initial_state: str) -> dict:
    import mmg
    from trials.measured.identify import fit_covariance, identification_covariance, identify, load_runs

    ship = mmg.load_ship("esso_osaka_3m")
    paths = sorted((data / "turning").glob("*.csv")) + sorted((data / "zigzag").glob("*.csv"))
    runs = load_runs(ship, paths, wind=None if wind is None else wind == "on")
    t0 = time.perf_counter()
    ident = identify(ship, runs, initial_state=initial_state)
    secs = time.perf_counter() - t0
    sc = ident.scores()
    gn, wr = fit_covariance(ident.fit), identification_covariance(ident)
    std = lambda c: dict(zip(c["names"], np.sqrt(np.diag(np.asarray(c["matrix"]))).tolist())) if c else {}  # noqa: E731
    return {"initial_state": initial_state, "seconds": secs, "tau": ident.tau,
            "evaluations": [s["evaluations"] for s in ident.stages], "cost": [s["cost_final"] for s in ident.stages],
            "heading_rms_deg": {s["name"]: s["heading_rms_deg"] for s in sc},
            "mean_heading_rms_deg": float(np.nanmean([s["heading_rms_deg"] for s in sc])),
            "values": ident.fit.values(), "std_gauss_newton": std(gn), "std_written": std(wr)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", default=str(REPO.parent / "shared" / "data" / "frt-ds-esso"))
    ap.add_argument("--wind", choices=("on", "off"), default=None)
    ap.add_argument("--out", default=None)
    ap.add_argument("--sample-from", default=None, help="the 'sample' fit's figures from an earlier --out JSON "
                                                        "(that fit does not depend on the start-state options)")
    a = ap.parse_args(argv)
    res = [json.loads(Path(a.sample_from).read_text())[0]] if a.sample_from else []
    for st in ("sample", "fit")[len(res):]:
        r = run(Path(a.data), a.wind, st)
        res.append(r)
        print(f"initial_state={st}: {r['seconds']:.0f} s, evaluations {r['evaluations']}, tau {r['tau']:.2f}, "
              f"mean training heading RMS {r['mean_heading_rms_deg']:.3f} deg", flush=True)
    a0, a1 = res
    print(f"\n{'record':34s} {'sample':>8s} {'fit':>8s}  heading RMS [deg]")
    for k in a0["heading_rms_deg"]:
        print(f"{k:34s} {a0['heading_rms_deg'][k]:8.3f} {a1['heading_rms_deg'][k]:8.3f}")
    print(f"{'mean':34s} {a0['mean_heading_rms_deg']:8.3f} {a1['mean_heading_rms_deg']:8.3f}")
    print(f"\n{'parameter':14s} {'value sample':>12s} {'value fit':>10s} {'GN std (old)':>12s} {'written std':>11s}")
    for k in a1["values"]:
        print(f"{k:14s} {a0['values'].get(k, float('nan')):12.5g} {a1['values'][k]:10.5g} "
              f"{a1['std_gauss_newton'].get(k, float('nan')):12.3g} {a1['std_written'].get(k, float('nan')):11.3g}")
    if a.out:
        Path(a.out).write_text(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
