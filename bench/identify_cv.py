"""Nested cross-validation of ``mmg identify`` on the shared FRT-DS-ESSO records (honest
evaluation): one command, every figure held out.

The records (default: all of ``turning/``, ``zigzag/``, ``random/`` and ``berthing/``; a record and its
cut copies count once and share a fold) are dealt into ``--folds`` outer folds, each kept out once.
Inside each outer training set an inner ``--inner-folds`` cross-validation on the training records only
chooses the hull form (``--hull auto``: Kijima ``esso_osaka_3m`` or cross-flow
``esso_osaka_3m_crossflow``, by the lower inner held-out mean heading RMS, fewer divergences first;
:func:`trials.measured.nested.nested_cross_validate`); the choice is fitted on the whole outer training
set and the kept-out records are replayed open loop with it and with the initial Froude-scaled
``esso_osaka_3m``.  The kept-out records never reach a fit or a choice of their fold.

Printed per kept-out record: the scaled and the identified model's heading RMS, yaw-rate RMS, speed RMS
and final position error in L, over the whole record and over its first minute (``--horizon``), and the
mean heading RMS over 60 s windows every 30 s restarted from the measured state
(:func:`trials.measured.window.window_scores`); a diverged replay (its time and last finite state); each
fold's choice with the inner figures behind it; the summary (mean heading RMS scaled / identified, better
on N of M, divergences); per kind of record, the whole-record and the window mean heading RMS
(:func:`kind_summary`).  ``--markdown`` prints the tables as Markdown (docs/benchmark_frt.md), ``--json
FILE`` writes :meth:`~trials.measured.nested.NestedCV.to_json` with the per-kind figures as ``by_kind``.

``--prior W1 W2 ...`` (several prior widths) makes each hull form at each width a candidate of the
inner choice, so the prior width too is chosen inside the training folds; ``--initial-state fit sample``
does the same for the start-state treatment of the fits.

Run: ``python bench/identify_cv.py [--hull auto|kijima|crossflow] [--prior 0.5 [0.25 ...]] [--folds 4] [--inner-folds 2]
[--records turning zigzag random berthing] [--jobs 2] [--markdown] [--json out.json]``.

``--offset-spread DEG`` also replays every kept-out record, with both models, under rudder offsets
from -DEG to +DEG (the ``rudder_offset`` effect) and prints the range of heading RMS each model spans;
``--offset-spread-of FILE`` does it for the fold models of an earlier run's ``--json`` (rebuilt from their
fitted values), without fitting.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(1, str(Path(__file__).resolve().parent))

from frt_gap import KINDS, kind_of  # noqa: E402  (the record kinds, defined once)

import mmg  # noqa: E402
from trials.measured.identify import load_runs  # noqa: E402
from trials.measured.nested import (HULL_FORMS, SCORE_NAMES, BandSpec, band_summary, hull_candidates,  # noqa: E402
                                    nested_cross_validate)
from trials.files.data import frt_folder  # noqa: E402

SHIP = "esso_osaka_3m"
"""The ship whose hull forms are candidates (:func:`trials.measured.nested.hull_candidates`)."""
INITIAL = "esso_osaka_3m"
"""The honest initial model every kept-out record is scored with: the Froude-scaled full-scale ship."""
SUBSETS = ("turning", "zigzag", "random", "berthing")
SHORT = {"heading_rms_deg": "heading [deg]", "yaw_rate_rms_degps": "yaw rate [deg/s]",
         "speed_rms_mps": "speed [m/s]", "final_position_error_L": "final pos. [L]"}
FMT = {"heading_rms_deg": "{:.1f}", "yaw_rate_rms_degps": "{:.2f}", "speed_rms_mps": "{:.3f}",
       "final_position_error_L": "{:.2f}"}


def _args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--hull", choices=("auto", *HULL_FORMS), default="auto",
                    help="the hull form: chosen in each fold by the inner CV (auto, default) or fixed")
    ap.add_argument("--hull-astern", choices=("as_ahead", "end_for_end"),
                    help="how the hull acts astern in every ship of the run, the scaled one included, over the "
                         "configs' hull.astern (mmg.model.astern_factor)")
    ap.add_argument("--folds", type=int, default=4, help="outer folds (default 4)")
    ap.add_argument("--inner-folds", type=int, default=2, help="inner folds of the choice (default 2)")
    ap.add_argument("--records", nargs="+", choices=SUBSETS, default=list(SUBSETS),
                    help="which shared record folders to use (default all four)")
    ap.add_argument("--wind", choices=["on", "off"], default="on")
    ap.add_argument("--free", nargs="+", default=None, help="free parameters (default: trials.measured.identify.DEFAULT_FREE)")
    ap.add_argument("--prior", type=float, nargs="+", default=[0.5],
                    help="prior std relative to the config value; several values: each is a candidate of the "
                         "inner choice beside the hull forms (hull form x prior width, chosen in each fold)")
    ap.add_argument("--weighting", choices=["samples", "equal", "relative"], default=None,
                    help="record weighting in the fit (default: trials.measured.identify.DEFAULT_WEIGHTING)")
    ap.add_argument("--folds-by", choices=["order", "revolutions", "manoeuvre"], default="order",
                    help="deal the records into folds (outer and inner) in file order, stratified by revolutions, "
                         "or by manoeuvre (trials.measured.identify.manoeuvre_class)")
    ap.add_argument("--max-nfev", type=int, default=None,
                    help="evaluation limit of each fit stage (default: trials.measured.identify.DEFAULT_MAX_NFEV)")
    ap.add_argument("--segment-s", type=float, nargs="+", default=None, metavar="S",
                    help="segment length [s] of each fit stage, inf for the whole record (identify(segment_s=); "
                         "default trials.measured.identify.DEFAULT_SEGMENTS_L: 52 sqrt(L/g), then the whole record)")
    ap.add_argument("--velocity-weight", type=float, default=1.0,
                    help="weight of the u, v, r residuals beside the heading's (identify(velocity_weight=))")
    ap.add_argument("--nuisance", nargs="+", default=(), metavar="EFFECT",
                    help="effects fitted once per training record as nuisances (e.g. current)")
    ap.add_argument("--initial-state", choices=("fit", "sample"), nargs="+", default=None,
                    help="each record's start state in the fits (mmg identify --initial-state; several: each a "
                         "candidate of the inner choice beside the hull forms; default its default, "
                         "'fit'; docs/benchmark_frt.md's figures: 'sample')")
    ap.add_argument("--horizon", type=float, default=60.0, help="the short-horizon window [s] (default 60)")
    ap.add_argument("--bands", type=int, default=0, metavar="N",
                    help="each kept-out record's 90 %% heading and position bands from N draws of its fold's model "
                         "(ship from the written covariance, start from the run-to-run spread, the model-form term); "
                         "pooled coverage, median width and radius")
    ap.add_argument("--band-support", choices=("none", "bounds", "physical"), default="physical",
                    help="where the bands' ship draws are kept (mmg predict --support; default physical)")
    ap.add_argument("--band-model-form", choices=("training", "kept-out", "none"), default="training",
                    help="the model-form term of the bands: from each fold's training replays (as mmg identify "
                         "writes it; default), from the kept-out replays of a cross-validation inside the fold (as "
                         "mmg identify --cv writes it: --inner-folds more fits per fold), or none")
    ap.add_argument("--backend", choices=("serial", "loky"), default="loky")
    ap.add_argument("--jobs", type=int, default=2, help="local workers of the loky backend (default 2)")
    ap.add_argument("--markdown", action="store_true", help="print the tables as Markdown")
    ap.add_argument("--json", default=None, metavar="FILE", help="also write the result as JSON")
    ap.add_argument("--offset-spread", type=float, default=0.0, metavar="DEG",
                    help="also score each kept-out record under rudder offsets within +-DEG (both models)")
    ap.add_argument("--offset-spread-of", type=Path, default=None, metavar="JSON",
                    help="with --offset-spread: scan the fold models of an earlier run's --json instead of fitting")
    return ap.parse_args(argv)


def _options(a) -> dict:
    extra = {"wind": a.wind == "on"}
    if len(a.prior) == 1:
        extra["prior_rel_std"] = a.prior[0]
    if a.free:
        extra["free"] = a.free
    if a.weighting:
        extra["record_weighting"] = a.weighting
    if a.nuisance:
        extra["record_nuisance"] = tuple(a.nuisance)
    if a.velocity_weight != 1.0:
        extra["velocity_weight"] = a.velocity_weight
    if a.max_nfev:
        extra["max_nfev"] = a.max_nfev
    if a.segment_s:
        extra["segment_s"] = tuple(a.segment_s)
    if a.initial_state and len(a.initial_state) == 1:
        extra["initial_state"] = a.initial_state[0]
    return extra


def candidates(forms, priors, starts=(None,)) -> dict:
    """The candidates of the inner choice: each hull form (:func:`trials.measured.nested.hull_candidates`),
    and with several prior widths (``priors``) or start-state treatments (``starts``: ``"fit"``, ``"sample"``)
    each form at each of them, named ``"<form>, prior <width>, start <start>"`` (a part only where there
    are several)."""
    from dataclasses import replace
    from itertools import product

    base = hull_candidates(SHIP, forms)
    priors, starts = list(dict.fromkeys(priors)), list(dict.fromkeys(starts))     # a value given twice counts once
    out = {}
    for (f, c), p, st in product(base.items(), priors, starts):
        name = f + (f", prior {p:g}" if len(priors) > 1 else "") + (f", start {st}" if len(starts) > 1 else "")
        opts = {**c.options, **({"prior_rel_std": float(p)} if len(priors) > 1 else {}),
                **({"initial_state": st} if len(starts) > 1 else {})}
        out[name] = replace(c, name=name, options=opts) if name != f else c
    return out


def _cell(s: dict, key: str) -> str:
    v = s[key]
    return "div." if v is None or not np.isfinite(v) else FMT[key.replace(_cell.tag, "")].format(v)


_cell.tag = "_60s"


def _window_cell(s: dict) -> str:
    """The mean heading RMS [deg] over a record's 60 s windows ("-" where no window stayed finite)."""
    v = s.get("window_heading_rms_deg")
    return "-" if v is None or not np.isfinite(v) else f"{v:.1f}"


def _divergence_text(d) -> str:
    if d is None:
        return ""
    st = d["last_state"]
    where = "at the start" if st is None else (
        f"last finite at {d['last_t_s']:.1f} s: u {st['u']:.3g} m/s, v {st['v']:.3g} m/s, r {np.degrees(st['r']):.3g} deg/s, "
        f"x {st['x']:.4g} m, y {st['y']:.4g} m, psi {np.degrees(st['psi']):.4g} deg")
    return f"non-finite at t = {d['t_s']:.1f} s ({where})"


def record_table(res, markdown: bool) -> list[str]:
    """Per kept-out record: scaled / identified scores over the whole record and over the first window."""
    tag = f"_{res.horizon_s:g}s"
    _cell.tag = tag
    keys = list(SCORE_NAMES) + [k + tag for k in SCORE_NAMES]
    head = (["record", "fold", "form"] + [f"{SHORT[k]} s / i" for k in SCORE_NAMES]
            + [f"first {res.horizon_s:g} s: {SHORT[k]} s / i" for k in SCORE_NAMES]
            + ["60 s windows: heading [deg] s / i", "diverged"])
    rows = []
    for r in res.records:
        a, b = r["scaled"], r["identified"]
        div = "; ".join(f"{who} at {s['divergence']['t_s']:.1f} s" for who, s in (("scaled", a), ("identified", b))
                        if s["divergence"] is not None) or "no"
        rows.append([r["name"], str(r["fold"]), r["choice"]] + [f"{_cell(a, k)} / {_cell(b, k)}" for k in keys]
                    + [f"{_window_cell(a)} / {_window_cell(b)}", div])
    return _table(head, rows, markdown)


KIND_KEYS = (("heading_rms_deg", "whole record"), ("window_heading_rms_deg", "60 s windows every 30 s"))
"""The per-kind figures (:func:`kind_summary`): the whole-record heading RMS and the mean over the windows
restarted from the measured state (:func:`trials.measured.window.window_scores`), both [deg]."""


def kind_summary(records, keys=tuple(k for k, _ in KIND_KEYS)) -> list[dict]:
    """Per kind of record (:data:`frt_gap.KINDS`, by the record's name) the mean of each of ``keys`` over its
    kept-out records, scaled and identified: ``{"kind", "n" (records), <key>: {"scaled", "identified", "n"}}``,
    each key's means over the records where both models' figures are finite (``n`` of them; None when
    none is).  ``records``: :attr:`trials.measured.nested.NestedCV.records` (``name``, ``scaled``,
    ``identified`` score dicts) or their JSON."""
    out = []
    for kind in KINDS:
        mine = [r for r in records if kind_of(r["name"]) == kind]
        if not mine:
            continue
        row = {"kind": kind, "n": len(mine)}
        for key in keys:
            pairs = [(r["scaled"].get(key), r["identified"].get(key)) for r in mine]
            pairs = np.array([p for p in pairs if None not in p and np.isfinite(p).all()], float).reshape(-1, 2)
            mean = [float(x) for x in pairs.mean(axis=0)] if len(pairs) else [None, None]
            row[key] = {"scaled": mean[0], "identified": mean[1], "n": len(pairs)}
        band = band_summary(mine)
        if band:
            row["band"] = {"coverage90": band["band_coverage90"], "median_width_deg": band["band_median_width_deg"],
                           "position_coverage90": band.get("band_position_coverage90"),
                           "median_radius_m": band.get("band_median_radius_m")}
        out.append(row)
    return out


def kind_table(summary: list[dict], markdown: bool) -> list[str]:
    """:func:`kind_summary` as a table: per kind, scaled / identified mean heading RMS [deg] over the whole
    record and over the 60 s windows (with the records each is over when fewer than the kind's)."""
    bands = any("band" in r for r in summary)
    head = (["kind", "records"] + [f"{words}: heading RMS s / i [deg]" for _, words in KIND_KEYS]
            + (["90 % heading band: coverage, median width", "90 % position band: coverage, median radius"]
               if bands else []))

    def cell(row, key):
        c = row[key]
        txt = f"{c['scaled']:.1f} / {c['identified']:.1f}" if c["n"] else "-"
        return txt + (f" ({c['n']} finite)" if c["n"] != row["n"] else "")

    def band(row):
        b = row.get("band")
        if not bands:
            return []
        if not b:
            return ["-", "-"]
        pos = (f"{100 * b['position_coverage90']:.1f} %, {b['median_radius_m']:.3g} m"
               if b.get("position_coverage90") is not None else "-")
        return [f"{100 * b['coverage90']:.1f} %, {b['median_width_deg']:.0f} deg", pos]

    return _table(head, [[r["kind"], str(r["n"])] + [cell(r, k) for k, _ in KIND_KEYS] + band(r) for r in summary],
                  markdown)


def _table(head, rows, markdown: bool) -> list[str]:
    if markdown:
        return ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)] + ["| " + " | ".join(r) + " |" for r in rows]
    w = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(head)] if rows else [len(h) for h in head]
    return ["  ".join(h.ljust(x) for h, x in zip(head, w))] + ["  ".join(c.ljust(x) for c, x in zip(r, w)) for r in rows]


def summary_lines(res) -> list[str]:
    """The summary: mean heading RMS over the whole record and the first window, better on N of M, divergences."""
    s = res.summary()
    tag = f"_{res.horizon_s:g}s"
    fin = [r for r in res.records if r["scaled"]["divergence"] is None and r["identified"]["divergence"] is None]
    out = [f"whole record: mean heading RMS scaled {s['mean_scaled']:.2f} deg, identified {s['mean_identified']:.2f} deg, "
           f"ratio scaled/identified {s['ratio']:.2f} (over the {s['n_both_finite']} records both replays kept finite); "
           f"identified better on {s['better']} of {s['n']}"]
    if "band_coverage90" in s:
        out.append(f"90 % heading bands of the kept-out records ({s['band_records']} records): "
                   f"{100 * s['band_coverage90']:.1f} % of their samples inside; unbounded (over 5 % of the draws "
                   f"diverged) on {100 * s['band_unbounded_share']:.1f} % of them, inside on "
                   f"{100 * s['band_coverage90_where_bounded']:.1f} % of the others; median width "
                   f"{s['band_median_width_deg']:.3g} deg (median over the records); "
                   f"{100 * s.get('band_rejected_share', 0.0):.1f} % of the candidate ships rejected outside the support")
        if "band_position_coverage90" in s:
            out.append(f"90 % position bands (a disc about the draws' median track, with the model-form term's "
                       "position part where the ship carries one): "
                       f"{100 * s['band_position_coverage90']:.1f} % of the samples inside, median radius "
                       f"{s['band_median_radius_m']:.3g} m (median over the records)")
    if s.get("band_refused_records"):
        out.append(f"bands refused on {s['band_refused_records']} kept-out records (their fold's covariance admits "
                   "no ship in the support, as mmg predict --samples would say) and left out of the band figures")
    for key, words in (("heading_rms_deg", "heading RMS [deg]"), ("yaw_rate_rms_degps", "yaw-rate RMS [deg/s]"),
                       ("speed_rms_mps", "speed RMS [m/s]"), ("final_position_error_L", "final position error [L]")):
        spans = ((key, "whole record"), (key + tag, f"first {res.horizon_s:g} s"), ("window_" + key, "60 s windows"))
        for k, span in spans:
            if not fin or k not in fin[0]["scaled"]:          # the window figures: where the run made them
                continue
            x = [r["scaled"][k] for r in fin if np.isfinite(r["scaled"][k]) and np.isfinite(r["identified"][k])]
            y = [r["identified"][k] for r in fin if np.isfinite(r["scaled"][k]) and np.isfinite(r["identified"][k])]
            nb = sum(q < p for p, q in zip(x, y))
            if x:
                out.append(f"{span}: mean {words} scaled {np.mean(x):.4g}, identified {np.mean(y):.4g}, ratio "
                           f"{np.mean(x) / np.mean(y):.2f}; identified lower on {nb} of {len(x)}")
    out.append(f"divergences: {len(s['diverged'])}" + ("" if not s["diverged"] else ": " + "; ".join(
        f"{n} ({who}) {_divergence_text(d)}" for n, who, d in s["diverged"])))
    return out


def choice_lines(res) -> list[str]:
    """Each outer fold's choice and the inner figures it was made on."""
    out = []
    for f in res.folds:
        inner = "; ".join(f"{c}: {t['mean_heading_rms_deg']:.2f} deg over {t['n'] - t['diverged']} inner kept-out "
                          f"records, {t['diverged']} diverged" for c, t in f["inner"].items()) or "fixed (no choice)"
        out.append(f"fold {f['fold']}: {f['choice']} ({len(f['train'])} training, {len(f['test'])} kept-out records; {inner})")
        for r in res.inner:
            if r["outer"] == f["fold"] and r["divergence"] is not None:
                out.append(f"  fold {f['fold']}, inner fold {r['inner']}, {r['candidate']}: {r['name']} diverged, "
                           f"{_divergence_text(r['divergence'])}")
    return out


def main(argv=None) -> None:
    a = _args(argv)
    d = frt_folder()
    if d is None:
        sys.exit("FRT-DS-ESSO data not found (set MMG_FRT_DATA)")
    files = [p for s in a.records for p in sorted((d / s).glob("*.csv"))]
    forms = tuple(HULL_FORMS) if a.hull == "auto" else (a.hull,)
    cands = candidates(forms, a.prior, a.initial_state or (None,))
    initial = mmg.load_ship(INITIAL)
    if a.hull_astern:
        from dataclasses import replace

        cands = {k: replace(c, ship=c.ship.with_hull_astern(a.hull_astern)) for k, c in cands.items()}
        initial = initial.with_hull_astern(a.hull_astern)
    opts = _options(a)
    runs = load_runs(initial, files, wind=opts["wind"])
    if a.offset_spread_of is not None:
        offset_spread(fold_models(json.loads(a.offset_spread_of.read_text())), runs, initial, a.offset_spread or 1.0)
        return
    print(f"nested cross-validation: {len(runs)} records ({', '.join(a.records)}), {a.folds} outer folds, "
          f"hull {a.hull} ({' / '.join(c.ship.name for c in cands.values())}), inner folds {a.inner_folds}, "
          f"scored against {initial.name}; hull astern {initial.hull.astern}; wind {a.wind}; free {a.free or 'default'}; "
          f"segments {a.segment_s or 'default'} s; prior {' / '.join(f'{p:g}' for p in a.prior)}; "
          f"weighting {a.weighting or 'default'}; folds by {a.folds_by}; backend {a.backend} ({a.jobs} jobs)", flush=True)
    t0 = time.perf_counter()
    res = nested_cross_validate(cands, runs, folds=a.folds, inner_folds=a.inner_folds, initial=initial,
                                folds_by=a.folds_by, backend=a.backend, n_jobs=a.jobs, horizon_s=a.horizon,
                                bands=BandSpec(a.bands, a.band_support, a.band_model_form), **opts)
    print(f"\n{time.perf_counter() - t0:.0f} s wall\n")
    print("Per kept-out record (s: scaled esso_osaka_3m, i: identified without it; 'div.': the replay diverged):\n")
    print("\n".join(record_table(res, a.markdown)))
    print("\nChoices of each fold (inner held-out mean heading RMS):\n")
    print("\n".join(("- " if a.markdown else "") + ln for ln in choice_lines(res)))
    print("\nSummary:\n")
    print("\n".join(("- " if a.markdown else "") + ln for ln in summary_lines(res)))
    by_kind = kind_summary(res.records)
    print("\nBy kind of record, held out (s: scaled, i: identified; the 60 s windows restart from the measured "
          "state):\n")
    print("\n".join(kind_table(by_kind, a.markdown)))
    if a.json:
        Path(a.json).write_text(json.dumps({**res.to_json(), "by_kind": by_kind}, indent=1) + "\n")
        print(f"\nwrote {a.json}")
    if a.offset_spread > 0:
        offset_spread(res.records, runs, initial, a.offset_spread)


def fold_models(nested: dict) -> list[dict]:
    """The kept-out records of a nested run's JSON (:meth:`~trials.measured.nested.NestedCV.to_json`) with
    each fold's identified ship rebuilt from its fitted values (the prior of the fold's hull form,
    :func:`trials.measured.identify.ship_with_values`): what :func:`offset_spread` needs, without refitting."""
    from trials.measured.identify import ship_with_values

    priors = {}
    out = []
    for r in nested["records"]:
        form = r["choice"].split(",")[0]
        if form not in priors:
            priors[form] = hull_candidates(SHIP, (form,))[form].ship
        out.append({**r, "ship": ship_with_values(priors[form], r["values"])})
    return out


def offset_spread(cv, runs, initial, spread_deg: float, n: int = 9) -> dict:
    """Per kept-out record: the heading RMS [deg] of the initial and the identified model under rudder
    offsets in [-spread_deg, +spread_deg] (``n`` values): the range each spans and the offset each
    prefers; then the comparison with each model at its own preferred offset (an oracle, both alike).
    Returns {"initial": each record's best heading RMS, "identified": the same, "not_as_scored": the records
    whose zero-offset replay differs from their score, or None where no offset is zero (an even ``n``):
    not checked}.

    The identified model is replayed as its scores were (:meth:`trials.measured.identify.Identification.replay`:
    the record's wind loads scaled by the fold's fitted wind factors); a record whose zero-offset replay
    does not give its scored heading RMS is named (a replay without the fitted wind factors would)."""
    from trials.measured.identify import ship_with_values, with_fitted_wind, with_ship_effects
    from trials.measured.predict import replay_record

    by_name = {r.name: r for r in runs}
    missing = [c["name"] for c in cv if c["name"] not in by_name]
    if missing:
        raise SystemExit(f"offset spread: no record loaded for {', '.join(missing)} (--records as in the run)")
    offs = np.linspace(-spread_deg, spread_deg, n)

    def scan(ship, run):
        return np.array([replay_record(s, with_ship_effects(run, s)).scores()["heading_rms_deg"]
                         for s in (ship_with_values(ship, {"rudder_offset": np.radians(o)}) for o in offs)])

    print(f"\nrudder offsets {offs[0]:+.2f} .. {offs[-1]:+.2f} deg ({n} values): heading RMS range [deg] and "
          f"preferred offset [deg] of each model")
    best_a, best_b, off_by, spans, edge = [], [], [], [], [0, 0]
    zero = int(np.argmin(np.abs(offs)))
    checked = bool(offs[zero] == 0.0)
    for c in cv:
        run = by_name[c["name"]]
        ra, rb = scan(initial, run), scan(c["ship"], with_fitted_wind(run, c["values"]))
        for who, r in (("scaled", ra), ("identified", rb)):
            want = c[who]["heading_rms_deg"]
            if checked and not np.isclose(r[zero], want, rtol=1e-6, equal_nan=True):
                off_by.append(f"{c['name']} ({who}: {r[zero]:.2f} against {want:.2f} scored)")
        ka, kb = int(np.nanargmin(ra)), int(np.nanargmin(rb))
        best_a.append(ra[ka])
        best_b.append(rb[kb])
        spans.append((np.nanmax(ra) - np.nanmin(ra), np.nanmax(rb) - np.nanmin(rb)))
        edge[0] += ka in (0, n - 1)
        edge[1] += kb in (0, n - 1)
        print(f"{c['name']:32s} {np.nanmin(ra):6.2f} - {np.nanmax(ra):6.2f} {offs[ka]:+6.2f} "
              f"{np.nanmin(rb):7.2f} - {np.nanmax(rb):7.2f} {offs[kb]:+6.2f}")
    best_a, best_b = np.array(best_a), np.array(best_b)
    print(f"each model at its own preferred offset: mean {best_a.mean():.2f} (initial) against {best_b.mean():.2f} "
          f"(identified), ratio {best_a.mean() / best_b.mean():.2f}, identified better on "
          f"{int(np.sum(best_b < best_a))} of {len(cv)}")
    sp = np.array(spans)
    print(f"range of heading RMS over the offsets [deg]: initial {sp[:, 0].min():.1f}-{sp[:, 0].max():.1f} (median "
          f"{np.median(sp[:, 0]):.1f}), identified {sp[:, 1].min():.1f}-{sp[:, 1].max():.1f} (median "
          f"{np.median(sp[:, 1]):.1f}); preferred offset at the edge of the scan on {edge[0]} (initial) and "
          f"{edge[1]} (identified) of {len(cv)}")
    if not checked:
        print("no zero offset among the values (an even number): the replays were not checked against the scores")
    elif off_by:
        print(f"zero offset not replayed as scored on {len(off_by)}: {'; '.join(off_by)}")
    return {"initial": best_a, "identified": best_b, "not_as_scored": off_by if checked else None}


if __name__ == "__main__":
    main()
