"""Does a learned correction of the identified MMG model's residual forces predict kept-out records better?

The nested protocol of ``bench/identify_cv.py --hull kijima --folds-by manoeuvre`` (4 outer folds, every
record kept out once, a record and its cut copies in one fold): in each outer fold the MMG model identified
on the fold's training records (``--folds-dir``: ``fold_K.pkl`` pickles of ``{"train", "test", "ident"}``,
read when present, else fitted here and written there) gets a correction of its residual forces
(:func:`trials.measured.hybrid.fit_correction`) fitted on the same training records only, with its penalty
chosen by a grouped cross-validation over those records.  The kept-out records are replayed open loop with
the Froude-scaled model, the identified one and the identified one plus each correction (``--variants``:
``ridge-D`` a ridge polynomial of degree D, ``mlp-H`` a network of H tanh units; :data:`VARIANTS`).  No
variant is chosen by its held-out figures: every one is reported.

Per kind of record (``frt_gap.kind_of``) and pooled: mean whole-record heading RMS [deg] and mean heading
RMS over 60 s windows every 30 s from the measured state [deg] (over the records every model kept finite),
the divergences, and the mean share of the kept-out records' samples outside the correction's training box.

Run: ``python bench/hybrid_cv.py --folds-dir DIR [--variants ridge-2/windows ridge-2 ...] [--jobs 2] [--json out.json]``.
"""
from __future__ import annotations

import argparse
import json
import pickle
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(1, str(Path(__file__).resolve().parent))

from frt_gap import KINDS, kind_of  # noqa: E402

VARIANTS = ("ridge-2/windows", "ridge-2", "ridge-3", "mlp-16", "ridge-2/output")
"""The corrections judged by default: ``FORM-SIZE[/windows]`` fitted to the residual forces, the penalty chosen
by the grouped held-out residual forces or, with ``/windows``, by the grouped held-out 60 s-window replays with
"no correction" a candidate (:attr:`trials.measured.hybrid.CorrectionSelection.select`); ``ridge-D/output``
fitted by output error on the training records' windows, its penalty (or none) chosen by the same grouped
window replays (:func:`trials.measured.hybrid.fit_output_correction`).  ``ridge-2/windows`` is the primary."""
SCALED, IDENT = "scaled", "identified"


def _args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--folds-dir", type=Path, required=True, help="fold_K.pkl of the identified folds (read or written)")
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS), help="corrections: ridge-D, mlp-H")
    ap.add_argument("--folds", type=int, default=4)
    ap.add_argument("--jobs", type=int, default=1, help="outer folds in parallel (default 1)")
    ap.add_argument("--json", type=Path, default=None)
    return ap.parse_args(argv)


def variant_options(label: str) -> dict:
    """``ridge-2`` -> {"kind": "ridge", "degree": 2, "select": "forces"}; ``mlp-16/windows`` -> {"kind": "mlp",
    "hidden": 16, "select": "windows"}."""
    form, _, select = label.partition("/")
    kind, _, size = form.partition("-")
    if kind not in ("ridge", "mlp") or not size.isdigit() or select not in ("", "windows", "forces", "output") or (
            select == "output" and kind != "ridge"):
        raise SystemExit(f"--variants: {label!r} is not ridge-D or mlp-H, optionally with /windows (or ridge-D/output)")
    return {"kind": kind, ("degree" if kind == "ridge" else "hidden"): int(size), "select": select or "forces"}


def _scores(rep, windows) -> dict:
    return {"heading_rms_deg": rep.scores()["heading_rms_deg"], "window_heading_rms_deg": windows.mean("heading_rms_deg"),
            "window_diverged": windows.n_diverged, "n_windows": windows.n_windows,
            "diverged_at_s": rep.diverged_at}


def _fold_ident(k: int, splits, folds_dir: Path, initial):
    f = folds_dir / f"fold_{k}.pkl"
    tr, te = splits[k]
    if f.exists():
        d = pickle.loads(f.read_bytes())
        if sorted(d["train"]) != sorted(r.name for r in tr) or sorted(d["test"]) != sorted(r.name for r in te):
            raise SystemExit(f"{f}: its records are not fold {k}'s of --folds-by manoeuvre")
        return d["ident"]
    from trials.measured.nested import fit_model

    ident = fit_model(initial, tr, initial=initial, wind=True, prior_rel_std=0.5)
    folds_dir.mkdir(parents=True, exist_ok=True)
    f.write_bytes(pickle.dumps({"train": [r.name for r in tr], "test": [r.name for r in te], "ident": ident}))
    return ident


def one_fold(task) -> dict:
    """Fit each correction on fold ``k``'s training records, replay its kept-out records with every model."""
    from mmg.model import pack
    from trials.measured.hybrid import (CorrectionForm, CorrectionSelection, fit_correction, fit_output_correction,
                                        hybrid_window_scores, replay_hybrid)
    from trials.measured.identify import fitted_run
    from trials.measured.predict import replay_record
    from trials.measured.window import window_scores

    k, splits, folds_dir, initial, variants = task
    ident = _fold_ident(k, splits, folds_dir, initial)
    tr, te = splits[k]
    ship, values = ident.ship, ident.fit.values()
    packed = pack(ship)
    prep = lambda r: fitted_run(ship, values, r)  # noqa: E731  (as ident.replay has it)
    corr, fits = {}, {}
    for v in variants:
        t0 = time.perf_counter()
        o = variant_options(v)
        if o["select"] == "output":
            corr[v] = fit_output_correction(packed, [prep(r) for r in tr], degree=o["degree"])
        else:
            form = CorrectionForm(**{key: x for key, x in o.items() if key != "select"})
            corr[v] = fit_correction(packed, [prep(r) for r in tr], form, CorrectionSelection(select=o["select"]))
        fits[v] = {**corr[v].to_json(), "fit_s": time.perf_counter() - t0}
    rows = []
    for r in te:
        run = prep(r)
        row = {"name": r.name, "kind": kind_of(r.name), "fold": k,
               SCALED: _scores(replay_record(initial, r), window_scores(initial, r)),
               IDENT: _scores(ident.replay(r), window_scores(ship, ident.replay(r).run))}
        for v, c in corr.items():
            row[v] = {**_scores(replay_hybrid(ship, run, c, packed), hybrid_window_scores(ship, run, c, packed=packed)),
                      "outside_share": c.outside_share(packed, run)}
        rows.append(row)
    return {"fold": k, "train": [r.name for r in tr], "test": [r.name for r in te], "fits": fits, "records": rows}


def summarise(records: list[dict], models: list[str]) -> list[dict]:
    """Per kind and pooled (``"all"``): per model the mean whole-record and 60 s-window heading RMS [deg] over
    the records every model kept finite (``n_finite``), its divergences (whole records, windows) and, for a
    correction, the mean out-of-training share."""
    out = []
    for kind in (*KINDS, "all"):
        mine = [r for r in records if kind == "all" or r["kind"] == kind]
        if not mine:
            continue
        fin = [r for r in mine if all(r[m]["diverged_at_s"] is None for m in models)]
        row = {"kind": kind, "n": len(mine), "n_finite": len(fin)}
        for m in models:
            w = [r[m]["window_heading_rms_deg"] for r in mine if np.isfinite(r[m]["window_heading_rms_deg"])]
            row[m] = {"heading_rms_deg": float(np.mean([r[m]["heading_rms_deg"] for r in fin])) if fin else None,
                      "window_heading_rms_deg": float(np.mean(w)) if w else None,
                      "diverged": sum(r[m]["diverged_at_s"] is not None for r in mine),
                      "window_diverged": sum(r[m]["window_diverged"] for r in mine)}
            if "outside_share" in mine[0][m]:
                row[m]["outside_share"] = float(np.mean([r[m]["outside_share"] for r in mine]))
        out.append(row)
    return out


def table(summary: list[dict], models: list[str]) -> list[str]:
    """Markdown: one row per kind and model."""
    f = lambda x, p=1: "-" if x is None else f"{x:.{p}f}"  # noqa: E731
    out = ["| kind (records) | model | whole record heading RMS [deg] | 60 s windows heading RMS [deg] | "
           "diverged records / windows | outside training box [% of samples] |", "|---|---|---|---|---|---|"]
    for row in summary:
        for m in models:
            c = row[m]
            share = f"{100 * c['outside_share']:.1f}" if "outside_share" in c else ""
            fin = "" if row["n_finite"] == row["n"] else f" ({row['n_finite']} finite)"
            out.append(f"| {row['kind']} ({row['n']}){fin} | {m} | {f(c['heading_rms_deg'])} | "
                       f"{f(c['window_heading_rms_deg'], 2)} | {c['diverged']} / {c['window_diverged']} | {share} |")
    return out


def main(argv=None) -> int:
    import mmg
    from identify_cv import INITIAL
    from trials.files.data import frt_folder
    from trials.files.sweep import run_sweep
    from trials.measured.identify import load_runs
    from trials.measured.nested import json_ready, split_folds

    a = _args(argv)
    variants = list(dict.fromkeys(a.variants))
    for v in variants:
        variant_options(v)
    d = frt_folder()
    if d is None:
        sys.exit("FRT-DS-ESSO data not found (set MMG_FRT_DATA)")
    files = [p for s in ("turning", "zigzag", "random", "berthing") for p in sorted((d / s).glob("*.csv"))]
    initial = mmg.load_ship(INITIAL)
    runs = load_runs(initial, files, wind=True)
    k, splits = split_folds(runs, a.folds, "manoeuvre")
    print(f"hybrid nested CV: {len(runs)} records, {k} outer folds by manoeuvre, variants {', '.join(variants)}", flush=True)
    t0 = time.perf_counter()
    parts = run_sweep(one_fold, [(j, splits, a.folds_dir, initial, variants) for j in range(k)],
                      backend="loky" if a.jobs > 1 else "serial", n_jobs=a.jobs,
                      labels=[f"fold {j + 1}/{k}" for j in range(k)])
    print(f"{time.perf_counter() - t0:.0f} s wall")
    records = [r for p in parts for r in p["records"]]
    models = [SCALED, IDENT, *variants]
    summary = summarise(records, models)
    for p in parts:
        print(f"fold {p['fold']}: " + "; ".join(f"{v} alpha {x['alpha']:g}, training R2 {x['r2_train']:.2f}, "
                                                 f"fit {x['fit_s']:.0f} s" for v, x in p["fits"].items()))
    print("\n".join(table(summary, models)))
    if a.json:
        a.json.write_text(json.dumps(json_ready({"variants": variants, "folds": parts, "summary": summary}), indent=1) + "\n")
        print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
