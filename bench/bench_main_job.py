"""The main job, ``mmg reproduce --out DIR`` on the default configs, in a fresh process.

    python bench/bench_main_job.py [--runs 2] [--baseline REV]

Runs the job once to warm numba's cache, then ``--runs`` times, and prints the wall and CPU times
(median) against the 60 s target.  With ``--baseline REV`` (a git revision) it also runs that
revision (checked out into a temporary worktree, its cache warmed by a first run) the same way,
interleaved, prints the ratio now/baseline and checks that the two ``report.md`` files hold the
same numbers: identical once the lines that report timings are masked.
"""
from __future__ import annotations

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET_S = 60.0
sys.path.insert(0, str(ROOT))
from trials.files.data import frt_folder  # noqa: E402

FRT = frt_folder()

_TIMING = re.compile(r"\(\d+(\.\d+)? s\)|\b\d+(\.\d+)? s\b|Total \d+(\.\d+)? s")


def run(src: Path, out: Path) -> tuple[float, float]:
    """Wall and CPU time [s] of ``mmg reproduce --out out`` with the package at ``src``."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    if "MMG_FRT_DATA" not in env and FRT is not None:       # a baseline worktree elsewhere finds the data too
        env["MMG_FRT_DATA"] = str(FRT)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "trials.cli", "reproduce", "--out", str(out)], cwd=src, env=env,
                   check=True, capture_output=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def masked(report: Path) -> list[str]:
    """The report's lines with every timing replaced by ``T``."""
    return [_TIMING.sub("T", ln) for ln in report.read_text().splitlines()]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--baseline", default=None, metavar="REV")
    ap.add_argument("--show", type=int, default=20, help="differing report lines to print")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        srcs = {"now": ROOT}
        if a.baseline:
            wt = tmp / "baseline"
            subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(wt), a.baseline], check=True,
                           capture_output=True)
            srcs["baseline"] = wt
        try:
            times = {k: [] for k in srcs}
            for k, src in srcs.items():
                print(f"warming {k} ...", flush=True)
                run(src, tmp / f"warm_{k}")
            for i in range(a.runs):
                for k, src in srcs.items():
                    w, c = run(src, tmp / f"{k}_{i}")
                    times[k].append((w, c))
                    print(f"  {k} run {i + 1}: {w:.1f} s wall, {c:.1f} s CPU", flush=True)
            med = {k: (statistics.median(w for w, _ in v), statistics.median(c for _, c in v)) for k, v in times.items()}
            w, c = med["now"]
            print(f"mmg reproduce (warm cache, fresh process): {w:.1f} s wall, {c:.1f} s CPU (median of {a.runs}); "
                  f"target <= {TARGET_S:g} s: {'met' if w <= TARGET_S else 'NOT met'}")
            if a.baseline:
                wb, cb = med["baseline"]
                print(f"baseline {a.baseline}: {wb:.1f} s wall, {cb:.1f} s CPU; ratio now/baseline wall {w / wb:.2f}, "
                      f"CPU {c / cb:.2f}")
                A, B = masked(tmp / "now_0" / "report.md"), masked(tmp / "baseline_0" / "report.md")
                diff = [(x, y) for x, y in zip(A, B) if x != y] + ([("<length>", "")] if len(A) != len(B) else [])
                print("report.md numbers: " + ("identical to the baseline's (timings masked)" if not diff else
                                                f"{len(diff)} lines differ:"))
                for x, y in diff[:a.show]:
                    print(f"  now:      {x[:160]}\n  baseline: {y[:160]}")
        finally:
            if a.baseline:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(srcs["baseline"])],
                               capture_output=True)


if __name__ == "__main__":
    main()
