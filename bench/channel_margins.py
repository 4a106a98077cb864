"""Margins of the record readers' channel-against-channel checks on the real records.

    python bench/channel_margins.py [DIR ...]

Reads every CSV under the folders given (default: ../shared/data/frt-ds-esso and
../shared/data/diagnose-dev/data beside the repository) with :func:`trials.files.logio.read_record`
and prints, per record, what the checks of :mod:`trials.files.logio` fit and the limits they are judged
against: the surge and sway factors against the track (``velocity_track_fit``, accepted within
``SCALE_OK`` = 0.8 to 1.25 where the standard error is below ``SCALE_SE``), the angle between the
track and the heading plus velocities (refused beyond 45 deg), the common wind-speed factor
(``wind_scale_fit``), and the heading-vs-yaw-rate slope (0.5 to 2); then the minimum and maximum of
each over the records.  Exit 1 when any record is refused.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEFAULT = [REPO.parent / "shared/data/frt-ds-esso", REPO.parent / "shared/data/diagnose-dev/data"]


def slope(rec) -> float:
    t, psi, r = rec.t, rec.psi, rec.r
    k = max(1, int(round(1.0 / float(np.median(np.diff(t))))))
    i = np.arange(0, len(t), k)
    rint = np.concatenate([[0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * np.diff(t))])
    a, b = np.diff(psi[i]), np.diff(rint[i])
    return float(np.dot(a, b) / np.dot(b, b)) if np.dot(b, b) > 0 else np.nan


def main() -> int:
    from mmg.errors import InputError
    from trials.files.logio import velocity_track_fit, wind_scale_fit, read_record

    dirs = [Path(a) for a in sys.argv[1:]] or DEFAULT
    files = sorted(f for d in dirs if d.is_dir() for f in d.rglob("*.csv"))
    rows, refused = [], 0
    print(f"{'record':42s} {'k_u':>6s} {'se_u':>7s} {'k_v':>6s} {'se_v':>7s} {'hdg miss':>8s} {'wind s':>7s} "
          f"{'se_s':>7s} {'psi/r':>6s}")
    for f in files:
        L = 325.0 if "diagnose-dev" in str(f) else None       # full-scale logs: the ship's length
        try:
            rec = read_record(f, length_m=L)
        except InputError as e:
            refused += 1
            print(f"REFUSED {e}")
            continue
        fit = velocity_track_fit(rec.t, rec.x, rec.y, rec.psi, rec.u, rec.v)
        s = se_s = np.nan
        if rec.wind_speed_rel is not None and np.any(rec.wind_speed_rel > 0):
            s, se_s, _ = wind_scale_fit(rec.t, rec.wind_speed_rel, rec.wind_dir_rel, rec.wind_speed_true,
                                        rec.wind_dir_true, rec.u, rec.v, rec.psi)
        row = (fit["k_u"], fit["se_u"], fit["k_v"], fit["se_v"], fit["heading_miss_deg"], s, se_s, slope(rec))
        rows.append(row)
        name = f"{f.parent.name}/{f.name}"[-42:]
        print(f"{name:42s} {row[0]:6.3f} {row[1]:7.4f} {row[2]:6.3f} {row[3]:7.4f} {row[4]:8.2f} {row[5]:7.4f} "
              f"{row[6]:7.1e} {row[7]:6.3f}")
    a = np.array(rows, dtype=float)
    print(f"\n{len(files)} records, {refused} refused")
    judged_v = a[:, 3] <= 0.05
    for j, what in ((0, "k_u (surge vs track)"), (4, "heading miss [deg]"), (5, "wind scale s"), (7, "psi vs r slope")):
        col = a[:, j][np.isfinite(a[:, j])]
        if col.size:
            print(f"{what:28s} min {col.min():.4f}  max {col.max():.4f}  ({col.size} records)")
    kv = a[judged_v, 2]
    if kv.size:
        print(f"{'k_v (sway vs track), judged':28s} min {kv.min():.4f}  max {kv.max():.4f}  ({kv.size} records with se <= 0.05)")
    print(f"{'largest se_u, se_v':28s} {np.nanmax(a[:, 1]):.4f}, {np.nanmax(a[:, 3]):.4f}")
    return 1 if refused else 0


if __name__ == "__main__":
    sys.exit(main())
