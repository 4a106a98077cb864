"""Open-loop replay speed: one 600 s record at 10 Hz, after compilation; target <= 0.5 s.

A real FRT-DS-ESSO record when the data folder is there ($MMG_FRT_DATA, else ../shared/data/frt-ds-esso
beside the repository): the longest one, cut to its first 600 s, replayed with the 3 m model and the wind
loads on, through trials.measured.predict (the record's inputs and wind loads made once, the replay timed).
Without the data, a simulated 600 s record (rudder steps, constant revolutions) of the same model.
Prints the median of ``--repeat`` replays (7), the best, and the ratio to the target.

    python bench/bench_replay.py [--repeat N]
"""
from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
TARGET_S = 0.5
SPAN_S = 600.0


def _record(ship):
    from trials.files.records import TrialRecord

    from trials.files.data import frt_folder

    data = frt_folder()
    files = sorted(data.glob("*/*.csv")) if data is not None else []
    if files:
        from trials.files.logio import read_record

        recs = [read_record(f, length_m=ship.particulars.L) for f in files]
        rec = max(recs, key=lambda r: r.t[-1] - r.t[0])
        rec = rec.slice_time(rec.t[0], rec.t[0] + SPAN_S - 1e-6)
        return rec, f"real record {Path(rec.source).name} (first {rec.t[-1] - rec.t[0]:.1f} s)"
    from mmg.model import pack
    from mmg.replay import ReplayInputs, replay_states

    t = np.round(np.arange(0.0, SPAN_S, 0.1), 10)
    delta = np.radians(20.0) * np.sign(np.sin(2 * np.pi * t / 60.0))
    n = np.full_like(t, 10.0)
    s = replay_states(pack(ship), ReplayInputs(t=t, delta=delta, n=n), [0.01, 0, 0, 0, 0, 0])
    rec = TrialRecord(t=t, name="simulated", source="simulated", u=s[:, 0], v=s[:, 1], r=s[:, 2], x=s[:, 3],
                      y=s[:, 4], psi=s[:, 5], delta=delta, n=n,
                      wind_speed_rel=np.full_like(t, 1.8), wind_dir_rel=np.full_like(t, 0.7))
    return rec, f"simulated record ({SPAN_S:g} s; the data folder {data} is absent)"


def main(argv=None) -> int:
    import argparse

    import mmg
    from mmg.model import pack
    from trials.measured.predict import measured_run, replay_record

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7, help="replays timed (median and best printed)")
    repeat = ap.parse_args(argv).repeat
    ship = mmg.load_ship("esso_osaka_3m")
    rec, what = _record(ship)
    run = measured_run(ship, rec, wind=True)
    packed = pack(ship)
    t0 = time.perf_counter()
    replay_record(ship, run, packed=packed)            # compiles (or loads the numba cache)
    first = time.perf_counter() - t0
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        rep = replay_record(ship, run, packed=packed)
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    print(f"{what}: {len(run.t)} samples at {np.median(np.diff(run.t)):g} s, wind {run.wind}")
    print(f"first call (compilation or cache load) {first:.3f} s")
    print(f"replay: median {med * 1e3:.1f} ms, best {min(times) * 1e3:.1f} ms of {repeat}; target {TARGET_S:g} s; "
          f"ratio to target {med / TARGET_S:.3f} ({'meets' if med <= TARGET_S else 'MISSES'} it)")
    print(f"heading RMS of that replay {rep.scores()['heading_rms_deg']:.3g} deg")
    return 0


if __name__ == "__main__":
    sys.exit(main())
