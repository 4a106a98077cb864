"""``mmg diagnose --ship SHIP`` on logs of the mismatch family with hidden effects, as a user runs it.

Draws members of :func:`trials.measured.mismatch.mismatch_family` around SHIP (default
``kvlcc2_l7``; a model-scale config sails the full-scale trials Froude-scaled), makes one trial of
each with one known effect (or none), writes it as an FRT-DS-ESSO CSV
(:func:`trials.measured.diagnose_records.write_frt_csv`), runs the command line on it alone and
prints the truth beside what the command named.  Effect sizes are full scale.

    python bench/diagnose_cli_family.py [--ship kvlcc2_l7] [--seed0 63000] [--out bench/out/cli_family] [--reuse]

``--reuse`` reads the JSON an earlier run of the same options wrote beside a log instead of running
the command again.
"""
from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

CASES = (
    ("clean", "zz20", {}, (0.0, 0.0)),
    ("current", "zz15", {"current": {"speed_mps": 0.2, "direction_deg": 135.0}}, (0.0, 0.0)),
    ("current", "turn35p", {"current": {"speed_mps": 0.25, "direction_deg": 300.0}}, (0.0, 0.0)),
    ("wind", "turn35", {"wind": {}}, (15.0, math.radians(45.0))),
    ("heading_bias", "zz10", {"heading_bias": {"bias_deg": -1.5}}, (0.0, 0.0)),
    ("rudder_offset", "zz20", {"rudder_offset": {"offset_deg": 1.5}}, (0.0, 0.0)),
)
"""(true effect, trial, effects at full scale, true wind [m/s full scale, rad from]) of each log."""


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ship", default="kvlcc2_l7")
    ap.add_argument("--seed0", type=int, default=63000, help="family and noise seed")
    ap.add_argument("--out", type=Path, default=REPO / "bench" / "out" / "cli_family")
    ap.add_argument("--reuse", action="store_true", help="read the JSONs of an earlier run instead of diagnosing again")
    a = ap.parse_args(argv)
    import mmg
    from trials.measured.diagnose_records import write_frt_csv
    from trials.measured.mismatch import TrialConditions, mismatch_family, trial_records

    config = mmg.load_ship(mmg.ship_path(a.ship))
    fam = mismatch_family(config, len(CASES), a.seed0)
    a.out.mkdir(parents=True, exist_ok=True)
    right = 0
    for i, (truth, trial, eff, wind) in enumerate(CASES):
        member, factors = fam[i]
        rec = trial_records(config, member, trial, TrialConditions(eff, wind), seed=a.seed0 + i,
                            name=f"{truth}_{trial}")
        log, js = a.out / f"{i}_{truth}_{trial}.csv", a.out / f"{i}_{truth}_{trial}.json"
        write_frt_csv(rec, log)
        t0 = time.perf_counter()
        cmd = [sys.executable, "-m", "trials.cli", "diagnose", "--ship", a.ship, "--json", str(js), "--backend", "serial",
               str(log)]
        if a.reuse and js.is_file():
            p = subprocess.CompletedProcess(cmd, 0, "", "")
        else:
            p = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
        d = json.loads(js.read_text()) if p.returncode == 0 else {}
        named = list(d.get("named_effects", []))
        ok = set(named) == ({truth} if truth != "clean" else set())
        right += ok
        full = eff or "none"
        print(f"{log.name}: member {i} ({factors['hull_form']}), true {full}"
              f"{f' wind {wind[0]:g} m/s from {math.degrees(wind[1]):g} deg' if wind[0] else ''} (full scale); "
              f"exit {p.returncode}; named {named or 'nothing'} {d.get('parameters', {})}; not identifiable "
              f"{[n.get('effect') for n in d.get('not_identifiable', [])]}; {'right' if ok else 'WRONG'}; "
              f"{time.perf_counter() - t0:.0f} s", flush=True)
        if p.returncode:
            print(p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "", flush=True)
    print(f"named exactly the hidden effect (nothing on the clean log): {right}/{len(CASES)}")


if __name__ == "__main__":
    main()
