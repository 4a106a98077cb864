"""Benchmark: ``mmg.imo`` with 1000 parameter samples of the full-scale Esso Osaka on this machine's cores.

Every sample runs all the standard manoeuvres (35 deg turning circles, 10/10 and 20/20 zigzags, each to
starboard and port: six simulations at 0.1 s steps) and reads the criteria.  The full-scale ship has no
identification, so the covariance is an illustrative one stated here: 10 % standard deviation on the
linear hull derivatives and 20 % on the non-linear yaw ones, with correlations of the kind a fit gives
(Y_beta / N_beta, Y_r / N_r).  Prints the wall time, the cost per sample (wall and core seconds), a
serial run's cost per sample beside it (the pool's efficiency) and the criteria with their intervals.
Timings are never asserted in the test suite.  Run::

    PYTHONPATH=. python bench/bench_imo.py [--samples 1000] [--jobs 2] [--serial-samples 20] [--dask]

With ``--dask`` the same samples run again on a Dask ``LocalCluster`` of ``--jobs`` worker processes
(what ``mmg imo --backend dask`` starts), its start-up timed apart, and the two results are compared
criterion by criterion (they must be equal: the same tasks, the same compiled code).
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

PARAMETERS = {"Y_beta": 0.10, "Y_r": 0.10, "N_beta": 0.10, "N_r": 0.10, "N_rr": 0.20, "N_brr": 0.20}
"""Relative standard deviation of each sampled hull derivative (illustrative)."""
CORRELATIONS = {("Y_beta", "N_beta"): 0.6, ("Y_r", "N_r"): 0.5, ("N_r", "N_rr"): -0.3}


def covariance(ship) -> dict:
    """The illustrative covariance of :data:`PARAMETERS` about the ship's own values."""
    names = list(PARAMETERS)
    vals = np.array([ship.hull.value(n) for n in names])
    sd = np.abs(vals) * np.array([PARAMETERS[n] for n in names])
    corr = np.eye(len(names))
    for (a, b), c in CORRELATIONS.items():
        i, j = names.index(a), names.index(b)
        corr[i, j] = corr[j, i] = c
    return {"names": names, "values": vals.tolist(), "matrix": (corr * np.outer(sd, sd)).tolist()}


def _dask(ship, cov, a, wall_local: float, res_local) -> None:
    """The same samples on a LocalCluster: its start-up, the run, the overhead against the local pool."""
    import mmg
    from distributed import Client, LocalCluster
    from trials.imo.sampling import local_executor

    t0 = time.perf_counter()
    with LocalCluster(n_workers=a.jobs, processes=True, threads_per_worker=1, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        client.run(lambda: None)
        start = time.perf_counter() - t0
        t0 = time.perf_counter()
        res = mmg.imo(ship, samples=a.samples, cov=cov, seed=a.seed,
                      executor=local_executor(a.jobs, backend="dask", client=client))
        wall = time.perf_counter() - t0
    same = res.as_dict() == res_local.as_dict()
    print(f"  dask LocalCluster     {wall:8.1f} s   ({a.jobs} workers; start-up {start:.1f} s apart; "
          f"{wall / wall_local:.2f} x the local pool; {1e3 * wall / a.samples:.1f} ms per sample)")
    print(f"  same criteria, intervals and probabilities as the local pool: {same}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--serial-samples", type=int, default=20, help="samples of the serial reference run")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--dask", action="store_true", help="also through a dask LocalCluster, with its overhead")
    a = ap.parse_args()

    import mmg
    from trials.imo.sampling import local_executor

    ship = mmg.load_ship("esso_osaka")
    cov = covariance(ship)
    mmg.imo(ship)                                           # numba's cache loaded, imports done

    def serial(func, tasks):
        return [func(t) for t in tasks]

    t0 = time.perf_counter()
    mmg.imo(ship, samples=a.serial_samples, cov=cov, seed=a.seed, executor=serial)
    per_serial = (time.perf_counter() - t0) / a.serial_samples

    t0 = time.perf_counter()
    res = mmg.imo(ship, samples=a.samples, cov=cov, seed=a.seed, executor=local_executor(a.jobs))
    wall = time.perf_counter() - t0
    print(f"Esso Osaka, full scale, 10 kn: {a.samples} samples x 6 manoeuvres on {a.jobs} processes")
    print(f"  wall time            {wall:8.1f} s")
    print(f"  per sample (wall)    {1e3 * wall / a.samples:8.1f} ms")
    print(f"  per sample (core)    {1e3 * wall * a.jobs / a.samples:8.1f} ms   (wall x processes)")
    print(f"  per sample (serial)  {1e3 * per_serial:8.1f} ms   ({a.serial_samples} samples in this process)")
    print(f"  parallel efficiency  {per_serial / (wall * a.jobs / a.samples):8.2f}")
    load = os.getloadavg()
    print(f"  load average         {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} on {os.cpu_count()} cores "
          f"(other processes share them)")
    if a.dask:
        _dask(ship, cov, a, wall, res)
    print()
    print(res.to_pandas()[["value", "interval_low", "interval_high", "limit", "probability", "verdict"]].to_string())


if __name__ == "__main__":
    main()
