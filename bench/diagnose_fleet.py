"""A fleet's records diagnosed one by one, locally and on a Dask cluster: the same named effects and
values either way, and what each costs.

The records: the development set's 32 full-scale logs (``../shared/data/diagnose-dev/``, read in
place), then trials of the mismatch family (:func:`trials.measured.mismatch.trial_records`, one
effect or none each, written as FRT-layout CSVs to a temporary folder) up to ``--records``.  Each is
diagnosed alone (:func:`trials.measured.diagnose.diagnose_each`, as ``mmg diagnose`` does for its
JSON ``runs``) with the bundled ``esso_osaka``: first on this machine's cores (``loky``), then on
Dask (``--scheduler ADDRESS``, or a ``LocalCluster`` of ``--jobs`` worker processes), and the two
compared record by record: named effects, every fitted value, every round's dBIC and z.

    python bench/diagnose_fleet.py [--records 50] [--jobs 2] [--scheduler tcp://host:8786]
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
DEV = REPO.parent / "shared" / "data" / "diagnose-dev"
EFFECTS = [None, {"current": {"speed_mps": 0.2, "direction_deg": 120.0}},
           {"rudder_offset": {"offset_deg": 1.0}}, {"heading_bias": {"bias_deg": -1.0}}]
"""What the family's extra records hide, in turn."""


def family_records(n: int, folder: Path, seed: int = 5000) -> list:
    """``n`` family trials (zigzags and turns in turn) with the effects of :data:`EFFECTS` in turn, as CSVs."""
    import mmg
    from trials.measured.diagnose import write_frt_csv
    from trials.measured.mismatch import mismatch_family, trial_records

    ship = mmg.load_ship("esso_osaka")
    fam = mismatch_family(ship, max(n, 1), seed)
    kinds = ["zz10", "turn35", "zz20", "turn35p", "zz15"]
    out = []
    for i in range(n):
        rec = trial_records(ship, fam[i][0], kinds[i % len(kinds)], EFFECTS[i % len(EFFECTS)], seed=seed + i)
        p = folder / f"family_{i:02d}_{kinds[i % len(kinds)]}.csv"
        write_frt_csv(rec, p)
        out.append(str(p))
    return out


def summary(d) -> dict:
    """What must not depend on the backend: named effects, values, every round's dBIC and z."""
    return {"named": d.named, "parameters": d.parameters,
            "rounds": [[(c["effect"], c["delta_bic"], c["z"]) for c in rd["candidates"]] for rd in d.rounds]}


def run(paths, backend: str, jobs: int, client=None) -> tuple[list, float]:
    import mmg
    from trials.measured.diagnose import DiagnoseOptions, diagnose_each

    t0 = time.perf_counter()
    res = diagnose_each(mmg.load_ship("esso_osaka"), paths, DiagnoseOptions(backend=backend, n_jobs=jobs, client=client),
                        progress=True)
    return res, time.perf_counter() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=50)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--scheduler", default=None, help="a running dask scheduler (default: a LocalCluster)")
    ap.add_argument("--json", default=str(REPO / "bench" / "out" / "diagnose_fleet.json"))
    a = ap.parse_args(argv)
    from distributed import Client, LocalCluster

    dev = sorted(str(p) for p in (DEV / "data").glob("dev_*.csv"))[:a.records] if DEV.is_dir() else []
    with tempfile.TemporaryDirectory() as tmp:
        paths = dev + family_records(a.records - len(dev), Path(tmp))
        print(f"{len(paths)} records ({len(dev)} of the development set), esso_osaka, {a.jobs} local workers",
              flush=True)
        local, t_local = run(paths, "loky", a.jobs)
        t0 = time.perf_counter()
        if a.scheduler:
            cluster, client = None, Client(a.scheduler)
        else:
            cluster = LocalCluster(n_workers=a.jobs, processes=True, threads_per_worker=1, dashboard_address=":0")
            client = Client(cluster)
        try:
            client.run(lambda: None)                    # the workers up before the clock of the run starts
            t_start = time.perf_counter() - t0
            dask, t_dask = run(paths, "dask", a.jobs, client)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    same = [summary(x) == summary(y) for x, y in zip(local, dask)]
    named = sum(bool(x.named) for x in local)
    print(f"same named effects, values, dBIC and z on {sum(same)} of {len(same)} records "
          f"({named} with an effect named); loky {t_local:.0f} s, dask {t_dask:.0f} s "
          f"({t_dask / t_local:.2f} x; the cluster's start {t_start:.1f} s apart), "
          f"{t_local / len(paths):.1f} s per record locally")
    Path(a.json).parent.mkdir(parents=True, exist_ok=True)
    Path(a.json).write_text(json.dumps({"records": [Path(p).name for p in paths], "same": same,
                                        "named": [x.named for x in local], "seconds_loky": t_local,
                                        "seconds_dask": t_dask, "jobs": a.jobs}, indent=1))
    return 0 if all(same) else 1


if __name__ == "__main__":
    raise SystemExit(main())
