"""`mmg diagnose` on the real 3 m Esso Osaka records of FRT-DS-ESSO.

Diagnoses every record of ``../shared/data/frt-ds-esso/`` (folders ``turning``, ``zigzag``,
``random``, ``berthing``) ALONE with the bundled 3 m ship (``esso_osaka_3m``), as a user would
(``mmg diagnose --ship esso_osaka_3m LOG --json OUT``: wind off in the model, so wind is a
candidate), and writes per record what is named (values with 95 % intervals), what is reported
not identifiable, the fitted wind and current, and beside them the record's own measured wind:
the mean true wind speed and the circular mean of the direction it comes FROM (clockwise from
north), from the logged true-wind channels, or, where those are absent or all zero, computed
from the relative wind and the ship's motion over ground (:func:`mmg.wind.true_wind_from_relative`).

A record the diagnosis refuses or fails on gets a one-line row saying why; nothing is hidden.

    python bench/diagnose_frt.py [--jobs 2] [--folders turning zigzag] [--only turn_cut zigzag_31-Jul-2020_13_04_24]
                                 [--json bench/out/diagnose_frt.json] [--md docs/diagnose.md]

Where ``--md`` has the ``diagnose_frt`` markers (docs/diagnose.md) the summary goes between them and
the per-record table beside the JSON (``bench/out/diagnose_frt.md``); else the table with the summary.
``--only`` keeps the records whose file stem contains any of the strings given.  The data are read
from the shared folder and never copied; the script stops with a message where it is absent.
"""
from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
FRT = REPO.parent / "shared" / "data" / "frt-ds-esso"
FOLDERS = ("turning", "zigzag", "random", "berthing")
SLOW_S = 120.0
"""A record whose diagnosis takes longer than this [s] is noted."""
LIST_MAX = 10
"""The summary names the records with nothing named when there are at most this many (else counts them)."""
KIND = {"turning": "turn", "zigzag": "zigzag", "random": "random", "berthing": "berthing"}


# --------------------------------------------------------------------------- the record's own data


def circular_mean_deg(angles_rad) -> tuple[float, float]:
    """(circular mean [deg, 0-360), mean resultant length 0-1) of angles [rad]."""
    a = np.asarray(angles_rad, float)
    a = a[np.isfinite(a)]
    if a.size == 0:
        return math.nan, math.nan
    c, s = float(np.mean(np.cos(a))), float(np.mean(np.sin(a)))
    return math.degrees(math.atan2(s, c)) % 360.0, math.hypot(c, s)


def measured_wind(rec) -> dict:
    """The record's true wind: mean speed [m/s], circular mean of the FROM direction [deg] and its
    steadiness (mean resultant length), and where it came from (logged true channels or computed
    from the relative wind and the ship's u, v, heading); also the mean relative wind speed."""
    from mmg.wind import true_wind_from_relative

    out = {"source": "none"}
    if rec.wind_speed_rel is not None:
        out["rel_speed_mean_mps"] = float(np.nanmean(rec.wind_speed_rel))
    vt, dt = rec.wind_speed_true, rec.wind_dir_true
    if vt is not None and dt is not None and np.any(np.asarray(vt) > 0):
        out["source"] = "logged true wind"
    elif rec.wind_speed_rel is not None and rec.wind_dir_rel is not None and np.any(np.asarray(rec.wind_speed_rel) > 0) \
            and rec.u is not None and rec.v is not None and rec.psi is not None:
        vt, dt = true_wind_from_relative(rec.wind_speed_rel, rec.wind_dir_rel, rec.u, rec.v, rec.psi)
        out["source"] = "computed from relative wind"
    else:
        return out
    out["true_speed_mean_mps"] = float(np.nanmean(vt))
    out["true_from_deg"], out["steadiness"] = circular_mean_deg(dt)
    return out


def trial_info(folder: str, rec) -> dict:
    """What the manoeuvre was, from the record itself: duration, revolutions, largest rudder, time astern."""
    t = np.asarray(rec.t, float)
    n = np.asarray(rec.n, float) if rec.n is not None else np.full_like(t, np.nan)
    d = np.degrees(np.asarray(rec.delta, float)) if rec.delta is not None else np.full_like(t, np.nan)
    info = {"kind": KIND.get(folder, folder), "duration_s": float(t[-1] - t[0]),
            "n_median_rps": float(np.nanmedian(n[len(n) // 2:])), "rudder_max_abs_deg": float(np.nanmax(np.abs(d))),
            "astern_prop_fraction": float(np.mean(n < 0)),
            "rudder_median_2nd_half_deg": float(np.nanmedian(d[len(d) // 2:]))}
    if rec.u is not None:
        info["u_negative_fraction"] = float(np.mean(np.asarray(rec.u) < 0))
    return info


def kind_text(info: dict) -> str:
    k = info["kind"]
    if k == "turn":
        return f"turn, n {info['n_median_rps']:.3g} rps, rudder {info['rudder_median_2nd_half_deg']:+.0f} deg"
    if k == "zigzag":
        return f"{k}, n {info['n_median_rps']:.3g} rps, rudder {info['rudder_max_abs_deg']:.0f} deg"
    return (f"{k}, prop astern {100 * info['astern_prop_fraction']:.0f} %, moving astern "
            f"{100 * info.get('u_negative_fraction', math.nan):.0f} %")


# --------------------------------------------------------------------------- one record


def _one_line(e: BaseException) -> str:
    return f"{type(e).__name__}: " + " ".join(str(e).split())[:300]


def _one(path: str, folder: str, ship: str) -> dict:
    """Diagnose one record alone (as ``mmg diagnose --ship SHIP LOG``): the JSON of the diagnosis, the
    record's own wind and trial facts, or the one-line reason it failed."""
    from mmg.resources import ship_path
    from mmg.ship import load_ship
    from trials.files.logio import read_record
    from trials.measured.diagnose import diagnose

    out = {"file": f"{folder}/{Path(path).name}", "folder": folder}
    t0 = time.perf_counter()
    try:
        s = load_ship(ship_path(ship))
        rec = read_record(path, length_m=s.particulars.L)
        out["trial"] = trial_info(folder, rec)
        out["measured_wind"] = measured_wind(rec)
    except Exception as e:  # noqa: BLE001 - the row says why
        out["error"] = "read: " + _one_line(e)
        out["seconds"] = time.perf_counter() - t0
        return out
    try:
        d = diagnose(s, [path], wind=False)
        j = d.to_json()
        out["diagnosis"] = {k: j.get(k) for k in ("named_effects", "parameters", "standard_errors", "intervals_95",
                                                    "evidence", "not_identifiable", "model_form_mismatch", "rms_config",
                                                    "rms_before", "rms_after", "unexplained", "unexplained_description",
                                                    "candidates", "rounds", "ship_coefficients", "threshold",
                                                    "model_form_effects", "effect_status")}
    except Exception as e:  # noqa: BLE001 - the row says why
        out["error"] = "diagnose: " + _one_line(e)
    out["seconds"] = time.perf_counter() - t0
    return out


# --------------------------------------------------------------------------- table


def _f(x) -> str:
    from trials.measured.diagnose_report import fmt3

    return fmt3(x)


def _iv(iv, unit: str = "") -> str:
    if iv == "any":
        return "any"
    if not iv or iv[0] is None:
        return "n/a"
    sep = " to " if iv[0] < 0 or iv[1] < 0 else "-"
    return f"{_f(iv[0])}{sep}{_f(iv[1])}{unit}"


UNITS = {"speed_mps": " m/s", "direction_deg": " deg", "offset_deg": " deg", "bias_deg": " deg",
         "scale": "", "sway_factor": "", "yaw_factor": "", "depth_to_draft": ""}
SHORT = {"speed_mps": "", "direction_deg": "to", "offset_deg": "", "bias_deg": "", "scale": "scale",
         "sway_factor": "sway", "yaw_factor": "yaw", "depth_to_draft": "H/T"}


def effect_text(eff: str, d: dict) -> str:
    """``current 0.0312 m/s (0.02-0.04 m/s), to 241 deg (200-280 deg)``: named values with 95 % intervals."""
    vals, ivs = d["parameters"].get(eff, {}), (d.get("intervals_95") or {}).get(eff, {})
    parts = []
    for k, v in vals.items():
        u = UNITS.get(k, "")
        lab = SHORT.get(k, k)
        parts.append(f"{lab + ' ' if lab else ''}{_f(v)}{u} ({_iv(ivs.get(k), u)})")
    return f"{eff} " + ", ".join(parts)


def _last_candidate(d: dict, eff: str):
    """The effect's entry in the last search round that tried it (its fitted values when not named)."""
    hit = None
    for rd in d.get("rounds") or []:
        for c in rd.get("candidates", []):
            if c.get("effect") == eff:
                hit = c
    return hit


def fitted_text(d: dict, eff: str) -> str:
    if eff in d["named_effects"]:
        vals = d["parameters"][eff]
        if eff == "current":
            return f"**{_f(vals['speed_mps'])} m/s to {_f(vals['direction_deg'])} deg**"
        return "**" + ", ".join(f"{SHORT.get(k, k)} {_f(v)}" for k, v in vals.items()) + "**"
    form = next((x for x in d.get("model_form_effects") or [] if x["effect"] == eff), None)
    if form is not None:
        return "model_form_mismatch (" + ", ".join(f"{SHORT.get(k, k)} {_f(v)}" for k, v in form["parameters"].items()) + ")"
    skipped = next((c.get("skipped") for c in d.get("candidates") or [] if c.get("effect") == eff and "skipped" in c), None)
    if skipped:
        return f"skipped ({skipped})"
    c = _last_candidate(d, eff)
    if c is None:
        return "-"
    v = c.get("parameters") or {}
    if eff == "current" and "speed_mps" in v:
        val = f"{_f(v['speed_mps'])} m/s to {_f(v['direction_deg'])}"
    else:
        val = f"scale {_f(v.get('scale'))}" if "scale" in v else ", ".join(f"{k} {_f(x)}" for k, x in v.items())
    return f"not named ({val}; dBIC {_f(c.get('delta_bic'))}, z {_f(c.get('z'))})"


def notes_text(r: dict) -> str:
    d = r["diagnosis"]
    notes = []
    if d.get("unexplained"):
        notes.append("unexplained")
    mm = d.get("model_form_mismatch") or {}
    if mm:
        notes.append("model-form mismatch: " + ", ".join(mm))
    if r["seconds"] > SLOW_S:
        notes.append(f"slow (> {SLOW_S:.0f} s)")
    return "; ".join(notes) or "-"


def row(i: int, r: dict) -> str:
    t = r.get("trial") or {}
    w = r.get("measured_wind") or {}
    wtxt = "n/a" if "true_speed_mean_mps" not in w else \
        f"{_f(w['true_speed_mean_mps'])} from {_f(w['true_from_deg'])}" + ("" if w["source"] == "logged true wind" else " (computed)")
    head = f"| {i} | {r['file']} | {kind_text(t) if t else '?'} | {_f(t.get('duration_s'))} |"
    if "error" in r:
        return head + f" **failed**: {r['error'].replace('|', '/')} | | | | {wtxt} | | {r['seconds']:.0f} | - |"
    d = r["diagnosis"]
    named = "; ".join(effect_text(e, d) for e in d["named_effects"]) or "nothing"
    ni = "; ".join(f"{x.get('effect')} (with {', '.join(map(str, x.get('confused_with') or []))}, "
                   f"corr {_f(x.get('correlation'))})" for x in d.get("not_identifiable") or []) or "-"
    hd = f"{_f(d['rms_config']['heading'])} / {_f(d['rms_before']['heading'])} / {_f(d['rms_after']['heading'])}"
    return (head + f" {named} | {ni} | {fitted_text(d, 'wind')} | {fitted_text(d, 'current')} | {wtxt} | {hd} | "
            f"{r['seconds']:.0f}{' (slow)' if r['seconds'] > SLOW_S else ''} | {notes_text(r)} |")


def summary(results: list) -> list[str]:
    """Prose: how often each effect was named, per folder; failures; not identifiable; slow records."""
    ok = [r for r in results if "error" not in r]
    bad = [r for r in results if "error" in r]
    lines = [f"**Summary.** {len(results)} records; diagnosed {len(ok)}, failed {len(bad)}."]
    counts = {}
    for r in ok:
        for e in r["diagnosis"]["named_effects"]:
            counts.setdefault(e, []).append(r)
    none = [r for r in ok if not r["diagnosis"]["named_effects"]]
    lines.append(f"Nothing named on {len(none)} of {len(ok)}" +
                 (" (" + ", ".join(Path(r['file']).stem for r in none) + ")." if 0 < len(none) <= LIST_MAX else "."))
    for e, rs in sorted(counts.items(), key=lambda kv: -len(kv[1])):
        per = ", ".join(f"{f} {sum(r['folder'] == f for r in rs)} of {sum(r['folder'] == f for r in ok)}"
                        for f in FOLDERS if any(r["folder"] == f for r in ok))
        warn = " — on most records: read as a model-form gap or a false-alarm pattern unless the physics agrees" \
            if len(rs) > 2 * len(ok) / 3 else ""
        lines.append(f"{e} named on {len(rs)} of {len(ok)} ({per}){warn}.")
    cur = [r for r in counts.get("current", []) if "true_from_deg" in (r.get("measured_wind") or {})]
    if cur:
        diffs = []
        for r in cur:
            downwind = (r["measured_wind"]["true_from_deg"] + 180.0) % 360.0
            diffs.append(abs((r["diagnosis"]["parameters"]["current"]["direction_deg"] - downwind + 180.0) % 360.0 - 180.0))
        lines.append(f"Named currents against the measured wind: the angle between the set and downwind is "
                     f"{', '.join(f'{x:.0f}' for x in diffs)} deg (0: the current sets where the wind blows).")
    ni = {}
    for r in ok:
        for x in r["diagnosis"].get("not_identifiable") or []:
            ni[x.get("effect")] = ni.get(x.get("effect"), 0) + 1
    if ni:
        lines.append("Not identifiable: " + ", ".join(f"{k} on {v} record{'s' if v > 1 else ''}" for k, v in ni.items()) + ".")
    st = [(Path(r["file"]).stem, x) for r in ok for x in r["diagnosis"].get("straight_runs") or []]
    lines.append(f"A leading straight run (the fit's straight-run residual) on {len(st)} of {len(ok)}" +
                 (": " + ", ".join(f"{nm} {x['samples']} samples, drift over ground {_f(x['logged_drift_deg'])} deg "
                                   f"(sd {_f(x['sd_deg'])}), {_f(abs(x['z_before']))} -> {_f(abs(x['z_after']))} sd"
                                   for nm, x in st) + "." if st else
                  " (none opens steady, straight and with a relative wind under half the ship's speed)."))
    lines.append(form_summary(ok))
    un = [r for r in ok if r["diagnosis"].get("unexplained")]
    lines.append(f"`unexplained` on {len(un)} of {len(ok)}.")
    for r in bad:
        lines.append(f"Failed: {r['file']}: {r['error']}")
    slow = [r for r in results if r["seconds"] > SLOW_S]
    if slow:
        lines.append(f"Slower than {SLOW_S:.0f} s: " + ", ".join(f"{Path(r['file']).stem} {r['seconds']:.0f} s" for r in slow) + ".")
    lines.append(f"Diagnosis time: median {np.median([r['seconds'] for r in results]):.0f} s, "
                 f"total {sum(r['seconds'] for r in results):.0f} s (CPU-seconds of the workers).")
    return lines


def form_summary(ok: list) -> str:
    """How many named effects became ``model_form_mismatch`` (:mod:`trials.measured.diagnose.model_form`), record by
    record (those with none left out), and what put them there: a shape on its bound, a value outside
    its plausible range."""
    per, why = {}, {"shape on its bound": 0, "value outside its plausible range": 0}
    for r in ok:
        mf = r["diagnosis"].get("model_form_effects") or []
        if mf:
            stem = Path(r["file"]).stem.split("_", 1)[-1]               # the folder says the kind
            per.setdefault(r["folder"], []).append(f"{stem} {len(mf)} ({', '.join(x['effect'] for x in mf)})")
        for x in mf:
            why["shape on its bound"] += bool(x.get("shapes"))
            why["value outside its plausible range"] += bool(x.get("coefficients"))
    n = sum(len(r["diagnosis"].get("model_form_effects") or []) for r in ok)
    total = n + sum(len(r["diagnosis"]["named_effects"]) for r in ok)
    return (f"Named effects reported `model_form_mismatch` instead: {n} of the {total} the search named, on "
            f"{sum(map(len, per.values()))} of {len(ok)} records" +
            (" (" + ", ".join(f"{k} {v}" for k, v in why.items()) + "); per record: "
             + "; ".join(f"{f}: " + ", ".join(v) for f, v in per.items()) + "." if per else "."))


def markdown(results: list, cmd: str, ship: str, wall: float) -> str:
    try:
        rev = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True, timeout=10).stdout.strip() or "?"
    except Exception:  # noqa: BLE001
        rev = "?"
    now = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    out = [f"<!-- generated file: do not edit; made by `{cmd}` on {now} at commit {rev} ({wall:.0f} s wall) -->",
           f"# `mmg diagnose` on the real 3 m records (FRT-DS-ESSO), each alone, ship `{ship}`", "",
           f"Generated by `{cmd}` on {now} (commit {rev}). Each record diagnosed alone as "
           f"`mmg diagnose --ship {ship} LOG --json OUT` (wind off in the model: a candidate). "
           "Named values with their 95 % intervals in brackets (3 s.f.); current: speed and the direction it sets "
           "*towards*; wind: scale and the sway and yaw shape factors of the Fujiwara loads. Where an effect was "
           "tried but not named, its fitted value in the last round that tried it, with dBIC and z (named above "
           "the thresholds). Measured wind: mean true wind speed [m/s] and the circular mean of the direction it comes "
           "*from* [deg, clockwise from north], from the record's `wind_velo_true`, `wind_dir_true` columns. "
           "Heading RMS [deg] of the segment replays: config as given / ship coefficients fitted / with the named effects.",
           "",
           "| # | record | trial (from the record) | duration [s] | named (95 % interval) | not identifiable | "
           "wind fitted | current fitted | measured true wind [m/s, from deg] | heading RMS [deg] config / fitted / + named | "
           "time [s] | notes |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    out += [row(i + 1, r) for i, r in enumerate(results)]
    out += ["", summary_md(results), ""]
    return "\n".join(out)


# --------------------------------------------------------------------------- main


def records(folders, only) -> list[tuple[str, str]]:
    out = []
    for f in folders:
        for p in sorted((FRT / f).glob("*.csv")):
            if not only or any(s in p.stem for s in only):
                out.append((f, str(p)))
    return out


BEGIN, END = "<!-- diagnose_frt: begin -->", "<!-- diagnose_frt: end -->"


def summary_md(results: list) -> str:
    """The summary as markdown: its first line, then one bullet per line."""
    s = summary(results)
    return "\n".join([s[0], ""] + [f"- {ln}" for ln in s[1:]])


def write_outputs(md: Path, table: Path, results: list, cmd: str, ship: str, wall: float) -> Path:
    """Write the per-record table (:func:`markdown`) to ``md``, or, where ``md`` has the markers
    :data:`BEGIN` and :data:`END` (docs/diagnose.md keeps its prose around them), the summary alone
    between them and the table to ``table``; returns where the table went."""
    old = md.read_text() if md.is_file() else ""
    full = markdown(results, cmd, ship, wall)
    if BEGIN in old and END in old:
        write_md(md, summary_md(results))
        write_md(table, full)
        return table
    write_md(md, full)
    return md


def write_md(path: Path, text: str) -> None:
    """Write ``text`` to ``path``: between the markers :data:`BEGIN` and :data:`END` where the file
    has them, else the whole file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    old = path.read_text() if path.is_file() else ""
    if BEGIN in old and END in old:
        head, rest = old.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        text = f"{head}{BEGIN}\n{text.rstrip()}\n{END}{tail}"
    path.write_text(text)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ship", default="esso_osaka_3m")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--folders", nargs="*", default=list(FOLDERS), choices=FOLDERS)
    ap.add_argument("--only", nargs="*", help="keep records whose file stem contains one of these strings")
    ap.add_argument("--json", default=str(REPO / "bench" / "out" / "diagnose_frt.json"))
    ap.add_argument("--md", default=str(REPO / "docs" / "diagnose.md"),
                    help="where the table goes (where the file has the diagnose_frt markers: the summary between them, "
                         "the table beside --json)")
    ap.add_argument("--from-json", action="store_true", help="only rewrite the table from --json (no diagnosis)")
    a = ap.parse_args(argv)
    if a.from_json:
        data = json.loads(Path(a.json).read_text())
        where = write_outputs(Path(a.md), Path(a.json).with_suffix(".md"), data["records"], data["command"].strip(),
                              data["ship"], data["wall_s"])
        print("\n".join(summary(data["records"])) + f"\nwrote {a.md}" + (f" and {where}" if where != Path(a.md) else ""))
        return 0
    if not FRT.is_dir():
        print(f"FRT-DS-ESSO folder absent: {FRT}", file=sys.stderr)
        return 2
    todo = records(a.folders, a.only)
    if not todo:
        print("no record selected", file=sys.stderr)
        return 2
    cmd = "python bench/diagnose_frt.py " + " ".join(sys.argv[1:] if argv is None else argv)
    t0 = time.perf_counter()
    results = [None] * len(todo)
    with ProcessPoolExecutor(max_workers=max(1, a.jobs)) as ex:
        # longest records first (both workers busy to the end); the table keeps the folder order
        order = sorted(range(len(todo)), key=lambda i: -Path(todo[i][1]).stat().st_size)
        futs = {ex.submit(_one, todo[i][1], todo[i][0], a.ship): i for i in order}
        for k, fu in enumerate(as_completed(futs)):
            i = futs[fu]
            f, p = todo[i]
            try:
                r = fu.result()
            except Exception as e:  # noqa: BLE001 - a worker that died: the row says so
                r = {"file": f"{f}/{Path(p).name}", "folder": f, "error": "worker: " + _one_line(e), "seconds": math.nan}
            results[i] = r
            what = r["error"] if "error" in r else \
                ("named " + ("+".join(r["diagnosis"]["named_effects"]) or "nothing") + "; not_identifiable "
                 + (",".join(x.get("effect", "?") for x in r["diagnosis"].get("not_identifiable") or []) or "-")
                 + "; model_form_mismatch " + (",".join(x["effect"] for x in r["diagnosis"].get("model_form_effects") or [])
                                               or "-"))
            print(f"[{k + 1:2d}/{len(todo)}] {r['file']:45s} {what}  {r['seconds']:.1f} s  "
                  f"(wall {time.perf_counter() - t0:.0f} s)", flush=True)
    wall = time.perf_counter() - t0
    for r in results:
        if not math.isfinite(r.get("seconds", math.nan)):
            r["seconds"] = 0.0
    out = Path(a.json)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"ship": a.ship, "command": cmd, "wall_s": wall, "records": results}, indent=1,
                              default=float))
    md = Path(a.md)
    where = write_outputs(md, out.with_suffix(".md"), results, cmd.strip(), a.ship, wall)
    for ln in summary(results):
        print(ln)
    print(f"wrote {out} and {md}" + (f" (summary; the per-record table: {where})" if where != md else "")
          + f" ({wall:.0f} s wall)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
