"""Peak memory (maximum resident set size) of ``mmg estimate`` on a 3000 s log, of the CLI
refusing pathological logs (bad input refused in one line), and of ``mmg metrics`` / ``mmg nomoto`` on
large records, each command measured by ``/usr/bin/time -v``.

    python bench/bench_memory.py [--keep DIR] [--no-large]

Large records: a 110 000 s ZZ20 simulated with its log at 0.1 s (an 85 MB project log and a
159 MB truth file) and, where ../shared/data/frt-ds-esso is present, a 162 MB FRT-DS-ESSO record
made of 620 copies of a real zigzag laid end to end; each row prints the peak over the file's size
(fails above LARGE_RATIO).  ``mmg nomoto`` refuses both as a zigzag (the copies are many zigzags; the
long ZZ20's analysis finds no counter-rudder) after reading and analysing them: its peak is that
of the reading and the analysis up to the refusal.

Runs ``mmg simulate configs/trials/zz20.yaml`` (a 3000 s ZZ20 at 0.1 s; its 5 s log), then
``mmg estimate`` on that log, then ``mmg metrics`` / ``mmg estimate`` / ``mmg nomoto`` on logs
made from it that once made the tools run away (a 12-row log whose samples are 1e6 s apart made
``mmg estimate`` grow to 11 GB and ``mmg nomoto`` to 8.8 GB) or give wrong numbers (time in
milliseconds, heading in radians, ...).  Prints one row per command: exit status, wall time,
peak RSS and the first line of stderr; fails (exit 1) when the estimate needs more than 1 GB or
a pathological log is not refused with exit status 2 in one stderr line.

Needs GNU time (``apt-get install -y time``).
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TIME = "/usr/bin/time"
LIMIT_MB = 1024.0
LARGE_RATIO = 5.0
"""Largest peak RSS over file size of mmg metrics / nomoto on a large record."""
FRT_ZIGZAG = REPO.parent / "shared/data/frt-ds-esso/zigzag/zigzag_31-Jul-2020_13_22_52.csv"


def run(argv: list[str], cwd: Path) -> dict:
    """Run ``argv`` under ``/usr/bin/time -v``: exit status, wall time [s], peak RSS [MB], stderr lines."""
    report = cwd / ".time.txt"
    env = {**os.environ, "MPLBACKEND": "Agg"}
    p = subprocess.run([TIME, "-v", "-o", str(report)] + argv, cwd=cwd, env=env, capture_output=True, text=True)
    txt = report.read_text()
    rss = float(re.search(r"Maximum resident set size \(kbytes\): (\d+)", txt).group(1)) / 1024.0
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", txt).group(1)
    secs = 0.0
    for part in wall.split(":"):
        secs = secs * 60 + float(part)
    err = [ln for ln in p.stderr.splitlines() if ln.strip()]
    return {"code": p.returncode, "wall_s": secs, "rss_mb": rss, "stderr": err}


def rewrite(src: Path, dst: Path, col: str | None = None, fn=None, keep_rows: int | None = None,
            drop_header: tuple = ()) -> Path:
    lines = src.read_text().splitlines()
    head = [ln for ln in lines if ln.startswith("#") and not any(ln.startswith(f"# {k}:") for k in drop_header)]
    body = [ln for ln in lines if not ln.startswith("#")]
    names = body[0].split(",")
    rows = [ln.split(",") for ln in body[1:]]
    if keep_rows is not None:
        rows = rows[:keep_rows]
    if col is not None:
        k = names.index(col)
        for r in rows:
            r[k] = repr(float(fn(float(r[k]))))
    dst.write_text("\n".join(head + [",".join(names)] + [",".join(r) for r in rows]) + "\n")
    return dst


def tiled_frt(src: Path, dst: Path, copies: int) -> Path:
    """``copies`` of the FRT-DS-ESSO record ``src`` end to end: time and positions continued, so that
    the result is one record at 10 Hz (its samples are the real ones)."""
    import pandas as pd

    df = pd.read_csv(src).dropna(how="all")
    t, x, y = (df[c].to_numpy() for c in ("t [s]", "x_position_mid [m]", "y_position_mid [m]"))
    span, dx, dy = t[-1] - t[0] + 0.1, x[-1] - x[0], y[-1] - y[0]
    with open(dst, "w") as fh:
        fh.write(",".join(df.columns) + "\n")
        for k in range(copies):
            part = df.copy()
            part["t [s]"] = t - t[0] + k * span
            part["x_position_mid [m]"] = x + k * dx
            part["y_position_mid [m]"] = y + k * dy
            part.to_csv(fh, header=False, index=False, float_format="%.10g")
    return dst


def large(record, work: Path) -> bool:
    """mmg metrics and mmg nomoto on large records; True when every peak is within LARGE_RATIO of the file."""
    ok = True
    trial = work / "zz_long.yaml"
    text = (REPO / "configs/trials/zz20.yaml").read_text()
    trial.write_text(text.replace("duration: 3000 s", "duration: 110000 s").replace("interval: 5 s", "interval: 0.1 s"))
    out = work / "zz_long"
    shutil.rmtree(out, ignore_errors=True)
    record("mmg simulate ZZ20, 110000 s, log at 0.1 s", ["simulate", str(trial), "--out", str(out)], expect=0)
    files = [(out / "log.csv", "project log"), (out / "truth.csv", "project truth")]
    if FRT_ZIGZAG.exists():
        files.append((tiled_frt(FRT_ZIGZAG, work / "frt_long.csv", 620), "FRT-DS-ESSO"))
    else:
        print(f"(no {FRT_ZIGZAG}: no large FRT-DS-ESSO record)")
    for path, what in files:
        mb = path.stat().st_size / 1e6
        for argv in (["metrics", str(path)], ["nomoto", str(path), "--length", "325" if "project" in what else "3"]):
            r = record(f"mmg {argv[0]:7s} [{what}, {mb:.0f} MB]", argv)
            ratio = r["rss_mb"] / mb
            bad = ratio > LARGE_RATIO
            ok &= not bad
            print(f"{'':58s} peak / file size = {ratio:.2f}{'  FAIL' if bad else ''}")
    return ok


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--keep", help="work in this folder and keep it (default: a temporary folder)")
    ap.add_argument("--no-large", action="store_true", help="skip the large records")
    args = ap.parse_args()
    if not Path(TIME).exists():
        print(f"{TIME} not found: apt-get update && apt-get install -y time", file=sys.stderr)
        return 2
    mmg = shutil.which("mmg")
    cmd = [mmg] if mmg else [sys.executable, "-m", "trials.cli"]
    work = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="bench-memory-"))
    work.mkdir(parents=True, exist_ok=True)
    rows, ok = [], True

    def record(label, argv, expect=None):
        nonlocal ok
        r = run(cmd + argv, work)
        bad = False
        if expect == 2:
            bad = r["code"] != 2 or len(r["stderr"]) != 1
        elif expect == 0:
            bad = r["code"] != 0
        ok &= not bad
        rows.append((label, r, bad))
        print(f"{label:58s} exit {r['code']:>3}  {r['wall_s']:7.1f} s  {r['rss_mb']:8.1f} MB  "
              f"{'FAIL ' if bad else ''}{r['stderr'][0][:110] if r['stderr'] else ''}", flush=True)
        return r

    print(f"working in {work}\n{'command':58s} {'status':>8}  {'wall':>9}  {'peak RSS':>11}  first stderr line")
    sim = work / "zz20"
    if sim.exists():
        shutil.rmtree(sim)
    record("mmg simulate configs/trials/zz20.yaml (3000 s)", ["simulate", str(REPO / "configs/trials/zz20.yaml"),
                                                              "--out", str(sim)], expect=0)
    log = sim / "log.csv"
    est_out = work / "est"
    shutil.rmtree(est_out, ignore_errors=True)
    est = record("mmg estimate zz20/log.csv (3000 s log, EKF)", ["estimate", str(log), "--out", str(est_out),
                                                                  "--no-plots"], expect=0)
    if est["rss_mb"] > LIMIT_MB:
        ok = False
        print(f"FAIL: the estimate peaked at {est['rss_mb']:.0f} MB > {LIMIT_MB:.0f} MB")

    bad = {
        "12 rows 1e6 s apart": rewrite(log, work / "far.csv", "time_s", lambda v: v / 5 * 1e6, keep_rows=12),
        "12 rows 1e6 s apart, no interval_s header": rewrite(log, work / "far_bare.csv", "time_s", lambda v: v / 5 * 1e6,
                                                             keep_rows=12, drop_header=("interval_s",)),
        "time in milliseconds": rewrite(log, work / "ms.csv", "time_s", lambda v: v * 1000),
        "speed in m/s": rewrite(log, work / "mps.csv", "speed_kn", lambda v: v * 0.514444),
        "heading x100": rewrite(log, work / "hdg.csv", "heading_deg", lambda v: v * 100),
    }
    for what, path in bad.items():
        record(f"mmg metrics  [{what}]", ["metrics", str(path)], expect=2)
        record(f"mmg estimate [{what}]", ["estimate", str(path), "--out", str(work / "est_bad"), "--no-plots"], expect=2)
        record(f"mmg nomoto   [{what}]", ["nomoto", str(path), "--length", "325", "--json", str(work / "nm.json")],
               expect=2)
    peak = max(r["rss_mb"] for label, r, _ in rows if "[" in label)
    if not args.no_large:
        ok &= large(record, work)
    print(f"\nestimate of the 3000 s log: {est['rss_mb']:.0f} MB peak (limit {LIMIT_MB:.0f} MB); "
          f"largest refusal: {peak:.0f} MB")
    if not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    print("OK" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
