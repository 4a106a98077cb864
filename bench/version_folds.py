"""Held-out heading RMS of any version's ``mmg identify`` on the outer folds of ``bench/identify_cv.py``.

The shared FRT-DS-ESSO records are dealt into the outer folds the nested bench uses
(:func:`trials.measured.identify.cv_folds` and :func:`~trials.measured.identify.fold_of` over the records
loaded in its order: turning, zigzag, random, berthing, each sorted; a record and its cut copies share a
fold).  For each fold, ``mmg identify --ship SHIP --train <the fold's training records>`` of the code
under ``--version ROOT`` (run as ``PYTHONPATH=ROOT python -c 'from trials.cli import main; main()'`` from
the run folder, so that the package imported is that version's; the module file imported is recorded)
writes a ``ship.yaml``; the fold's kept-out records are then scored with *this* version's code exactly as
``bench/identify_cv.py`` scores them: :func:`trials.measured.predict.predict` (``mmg predict``) of the
kept-out records with the written ``ship.yaml`` and with the Froude-scaled ``esso_osaka_3m``, wind on,
each replay scored by :func:`trials.measured.nested.replay_scores` (whole-record heading RMS, first
60 s, the 60 s windows every 30 s restarted from the measured state).

Printed: per kept-out record the scaled and the version's identified heading RMS [deg]; per kind the
means, beside those of earlier ``bench/identify_cv.py --json`` runs given with ``--today NAME=FILE``
(their records are checked to fall into the same folds).  Each fold's fit and scores are saved to
``--json`` as soon as they are made, and a fold already there is not refitted, so a crash loses at most
the fold in progress.  A fit that does not end within ``--timeout`` minutes is stopped and reported.

Run::

    python bench/version_folds.py --version /work/wt-old --out RUNDIR \\
        [--today "default=nested.json" "Kijima fixed=kijima.json"] [--folds 4] [--folds-by manoeuvre]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(1, str(Path(__file__).resolve().parent))

from frt_gap import KINDS, kind_of  # noqa: E402  (the record kinds, defined once)
from identify_cv import INITIAL, SUBSETS, kind_summary  # noqa: E402  (the nested bench's records and summary)

__all__ = ["outer_folds", "fit_fold", "version_predict", "score_fold", "fold_check", "kind_rows", "main"]

CLI = "import sys; from trials.cli import main; sys.exit(main())"
"""The command-line entry of a version's code, run with ``python -c`` (works for every version)."""


def outer_folds(files, folds: int = 4, folds_by: str = "manoeuvre") -> list[tuple[list[str], list[str]]]:
    """The nested bench's outer folds of ``files``: [(training files, kept-out files)] per fold, as
    :func:`trials.measured.nested.nested_cross_validate` deals the records loaded from them.

    Raises ValueError when a file cannot be loaded (the folds would then differ from the bench's)."""
    import mmg
    from trials.measured.identify import cv_folds, fold_of, load_runs

    files = [str(p) for p in files]
    runs = load_runs(mmg.load_ship(INITIAL), files, wind=True)
    if len(runs) != len(files):
        raise ValueError(f"{len(files) - len(runs)} of {len(files)} records could not be loaded")
    k = cv_folds(runs, folds)
    f = fold_of(runs, k, folds_by)
    return [([p for p, g in zip(files, f) if g != j], [p for p, g in zip(files, f) if g == j]) for j in range(k)]


def fit_fold(root: Path, train, out: Path, ship: str = "esso_osaka_3m", timeout_min: float = 25.0) -> dict:
    """``mmg identify --ship ship --train train --out out/ident`` of the code under ``root``, niced, from
    ``out``.  Returns {"status": "done" | "timeout" | "failed (exit N)", "wall_s", "trials_file" (the
    package the run imported), "ship_yaml" (None unless done)}; the output in ``out/identify.log``."""
    out.mkdir(parents=True, exist_ok=True)
    env = {**os.environ, "PYTHONPATH": str(root)}
    which = subprocess.run([sys.executable, "-c", "import trials; print(trials.__file__)"], cwd=out, env=env,
                           capture_output=True, text=True, check=True).stdout.strip()
    cmd = ["nice", "-n", "5", sys.executable, "-c", CLI, "identify", "--ship", ship, "--train", *map(str, train),
           "--out", str(out / "ident")]
    t0 = time.perf_counter()
    with open(out / "identify.log", "w") as log:
        proc = subprocess.Popen(cmd, cwd=out, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            rc = proc.wait(timeout=60 * timeout_min)
            status = "done" if rc == 0 else f"failed (exit {rc})"
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGTERM)      # the fit and any workers it started, nothing else
            proc.wait()
            status = "timeout"
    yaml = out / "ident" / "ship.yaml"
    return {"status": status, "wall_s": time.perf_counter() - t0, "trials_file": which,
            "ship_yaml": str(yaml) if status == "done" and yaml.is_file() else None}


def version_predict(root: Path, ship_yaml, tests, out: Path) -> dict:
    """``mmg predict --ship ship_yaml tests --wind on`` of the code under ``root`` (its own physics replaying
    its own fit): {record name: whole-record heading RMS [deg], None where it is not finite}."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    js = out / "pred_version.json"
    subprocess.run(["nice", "-n", "5", sys.executable, "-c", CLI, "predict", "--ship", str(ship_yaml), "--wind", "on",
                    *map(str, tests), "--json", str(js)], cwd=out, env=env, capture_output=True, check=True)
    runs = json.loads(js.read_text())["runs"]
    val = (lambda v: None if v is None or not math.isfinite(v) else float(v))  # noqa: E731
    return {Path(r["file"]).stem: val(r.get("heading_rms_deg")) for r in runs}


def _clean(score: dict) -> dict:
    """A :func:`~trials.measured.nested.replay_scores` dict for JSON: NaN as None, the divergence as its time."""
    d = score.get("divergence")
    out = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in score.items()
           if k != "divergence"}
    out["diverged_at_s"] = None if d is None else float(d["t_s"])
    return out


def score_fold(ship_yaml, tests, horizon_s: float = 60.0) -> list[dict]:
    """The kept-out records ``tests`` replayed (``mmg predict``, wind on) with the ship of ``ship_yaml``
    (read by this version's code) and with the scaled :data:`identify_cv.INITIAL`: per record
    {"name", "scaled", "identified"}, each :func:`trials.measured.nested.replay_scores` (JSON-clean)."""
    import mmg
    from trials.measured.nested import replay_scores
    from trials.measured.predict import predict

    ship, initial = mmg.load_ship(str(ship_yaml)), mmg.load_ship(INITIAL)
    ident, scaled = predict(ship, tests, wind=True), predict(initial, tests, wind=True)
    return [{"name": a.run.name, "scaled": _clean(replay_scores(a, horizon_s, initial)),
             "identified": _clean(replay_scores(b, horizon_s, ship))} for a, b in zip(scaled.runs, ident.runs)]


def fold_check(folds, nested: dict) -> list[str]:
    """The records of a ``bench/identify_cv.py --json`` run (``nested``) whose fold differs from ``folds``
    (:func:`outer_folds`), or that ``folds`` does not keep out: empty when the folds are the same."""
    mine = {Path(p).stem: j for j, (_, tests) in enumerate(folds) for p in tests}
    theirs = {r["name"]: r["fold"] for r in nested["records"]}
    return sorted(n for n in set(mine) | set(theirs) if mine.get(n) != theirs.get(n))


def kind_rows(records, today: dict) -> list[list[str]]:
    """Per kind: records, then the mean whole-record heading RMS [deg] of the scaled model, of the version's
    identified models (``records``), and of each ``today`` run's identified models ({name: its JSON}); the
    60 s window means after a slash.  A mean is over the records where both models stayed finite."""
    def cell(summary, kind, who):
        row = next((r for r in summary if r["kind"] == kind), None)
        if row is None:
            return "-"
        w, v = row["heading_rms_deg"][who], row["window_heading_rms_deg"][who]
        txt = "-" if w is None else f"{w:.1f}"
        return txt + ("" if v is None else f" / {v:.1f}") + (
            "" if row["heading_rms_deg"]["n"] == row["n"] else f" ({row['heading_rms_deg']['n']} finite)")

    mine = kind_summary(records)
    names = {r["name"] for r in records}                  # the folds scored here, when some are missing
    others = {n: kind_summary([r for r in d["records"] if r["name"] in names]) for n, d in today.items()}
    out = []
    for kind in KINDS:
        n = sum(kind_of(r["name"]) == kind for r in records)
        if n:
            out.append([kind, str(n), cell(mine, kind, "scaled"), cell(mine, kind, "identified")]
                       + [cell(s, kind, "identified") for s in others.values()])
    return out


def _args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--version", type=Path, required=True, help="root of the version whose mmg identify fits")
    ap.add_argument("--out", type=Path, required=True, help="run folder: <out>/fold<k>/ and the JSON")
    ap.add_argument("--json", type=Path, default=None, help="results, saved after each fold (default OUT/folds.json)")
    ap.add_argument("--label", default=None, help="the version's column heading (default: its git commit)")
    ap.add_argument("--ship", default="esso_osaka_3m", help="the version's --ship (default esso_osaka_3m)")
    ap.add_argument("--folds", type=int, default=4)
    ap.add_argument("--folds-by", choices=("order", "revolutions", "manoeuvre"), default="manoeuvre")
    ap.add_argument("--only", type=int, nargs="+", default=None, help="fit only these folds (0-based)")
    ap.add_argument("--timeout", type=float, default=25.0, help="minutes a fold's fit may take (default 25)")
    ap.add_argument("--today", nargs="+", default=[], metavar="NAME=FILE",
                    help="bench/identify_cv.py --json runs to tabulate beside (same folds, checked)")
    ap.add_argument("--version-predict", action="store_true",
                    help="also replay each fold's fit with the version's own mmg predict (its physics)")
    return ap.parse_args(argv)


def _label(root: Path) -> str:
    r = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    return r.stdout.strip() or root.name


def main(argv=None) -> int:
    a = _args(argv)
    from trials.files.data import frt_folder

    d = frt_folder()
    if d is None:
        print("FRT-DS-ESSO data not found (set MMG_FRT_DATA)", file=sys.stderr)
        return 2
    if not (a.version / "trials" / "cli").exists() and not (a.version / "trials" / "cli.py").is_file():
        print(f"{a.version}: no trials/cli in it (--version must be a root of the project's code)", file=sys.stderr)
        return 2
    today = {}
    for item in a.today:
        name, _, path = item.partition("=")
        if not path or not Path(path).is_file():
            print(f"{item}: --today takes NAME=FILE with FILE an identify_cv.py --json output", file=sys.stderr)
            return 2
        today[name] = json.loads(Path(path).read_text())
    files = [p for s in SUBSETS for p in sorted((d / s).glob("*.csv"))]
    folds = outer_folds(files, a.folds, a.folds_by)
    for name, doc in today.items():
        bad = fold_check(folds, doc)
        if bad:
            print(f"--today {name}: {len(bad)} records in other folds ({', '.join(bad[:3])} ...)", file=sys.stderr)
            return 2
    label = a.label or _label(a.version)
    path = a.json or a.out / "folds.json"
    state = json.loads(path.read_text()) if path.is_file() else {"version": str(a.version), "label": label, "folds": {}}
    for j, (train, tests) in enumerate(folds):
        done = state["folds"].get(str(j))
        if done and a.version_predict and done["ship_yaml"] and "version_predict" not in done:
            done["version_predict"] = version_predict(a.version, done["ship_yaml"], tests, a.out / f"fold{j}")
            path.write_text(json.dumps(state, indent=1) + "\n")
        if done or (a.only is not None and j not in a.only):
            continue
        print(f"fold {j}: fitting on {len(train)} records with {label} ...", flush=True)
        fit = fit_fold(a.version, train, a.out / f"fold{j}", a.ship, a.timeout)
        rec = score_fold(fit["ship_yaml"], tests) if fit["ship_yaml"] else []
        state["folds"][str(j)] = {**fit, "train": [Path(p).stem for p in train], "records": rec}
        if a.version_predict and fit["ship_yaml"]:
            state["folds"][str(j)]["version_predict"] = version_predict(a.version, fit["ship_yaml"], tests,
                                                                        a.out / f"fold{j}")
        a.out.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(state, indent=1) + "\n")
        print(f"fold {j}: {fit['status']} in {fit['wall_s']:.0f} s ({fit['trials_file']}); saved {path}", flush=True)
    print_tables(state, today, folds)
    return 0


def print_tables(state: dict, today: dict, folds) -> None:
    """Per kept-out record and per kind (Markdown), from the saved ``state``."""
    records = [dict(r, fold=int(j), own=f.get("version_predict", {}).get(r["name"], "-"))
               for j, f in sorted(state["folds"].items()) for r in f["records"]]
    for j, f in sorted(state["folds"].items()):
        print(f"fold {j}: {f['status']}, {f['wall_s']:.0f} s, {len(f['train'])} training, "
              f"{len(folds[int(j)][1])} kept out, {len(f['records'])} scored")
    fmt = (lambda v: v if isinstance(v, str) else "div." if v is None else f"{v:.1f}")  # noqa: E731
    print(f"\n| record | fold | scaled [deg] | {state['label']} procedure [deg] | the same fit, "
          f"{state['label']}'s own predict [deg] |\n|---|---|---|---|---|")
    for r in records:
        print(f"| {r['name']} | {r['fold']} | {fmt(r['scaled']['heading_rms_deg'])} "
              f"| {fmt(r['identified']['heading_rms_deg'])} | {fmt(r['own'])} |")
    own = {}
    for r in records:
        if isinstance(r["own"], float):
            own.setdefault(kind_of(r["name"]), []).append(r["own"])
    if own:
        print(f"\n{state['label']}'s own predict of the same fits, mean whole-record heading RMS over the finite "
              "replays [deg]: " + ", ".join(f"{k} {sum(v) / len(v):.1f} ({len(v)})" for k, v in own.items()))
    head = ["kind", "records", "scaled", f"{state['label']} procedure"] + list(today)
    print("\nMean heading RMS of the kept-out records [deg], whole record / 60 s windows every 30 s:\n")
    print("| " + " | ".join(head) + " |\n|" + "---|" * len(head))
    for row in kind_rows(records, today):
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    sys.exit(main())
