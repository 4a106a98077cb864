"""``mmg predict``: replay records against their own inputs (:func:`trials.measured.predict.predict`)."""
from __future__ import annotations

import sys
from pathlib import Path

from mmg.errors import InputError

from .common import _output_path, _whole, quantity, release_notes


def cmd_predict(args) -> int:
    from contextlib import nullcontext

    from mmg.ship import load_ship

    from ..files.output import StagedFile, StagedOutput, check_output_dir, check_output_file, dumps_json
    from ..measured.predict import predict
    from ..measured.window import with_windows

    check_output_file(args.json)
    if args.plots is not None:
        check_output_dir(args.plots, "--plots")
    for log in args.logs:                  # every record there before the first is replayed
        if not Path(log).is_file():
            raise InputError(log, "", "file not found" if not Path(log).exists() else "is not a regular file")
    ship = load_ship(args.ship)
    wind = None if args.wind is None else args.wind == "on"

    def progress(i, n, name):
        release_notes()                    # every record read and accepted: their notes, then progress
        print(f"replayed {i}/{n}: {name}", file=sys.stderr, flush=True)

    pred = predict(ship, args.logs, start=args.start, wind=wind, progress=progress)   # runs named after their files
    pred = with_windows(ship, pred, args.window, args.every)
    bands = _bands(args, ship, pred)
    text = dumps_json(_with_bands(pred.to_json(horizon_s=args.horizon), bands, args))
    names = [f"{r.run.name}.png" for r in pred.runs]
    with StagedFile(args.json) as tmp:     # the files first (renamed last, after the plots), then the console
        with StagedOutput(args.plots) if args.plots is not None else nullcontext() as stage:
            for k, (r, name) in enumerate(zip(pred.runs, names if args.plots is not None else ())):
                (bands[k] if bands and not bands[k].empty else r).plot(pyplot=False).savefig(stage.path(name))
        tmp.write_text(text)
    for r in pred.runs:
        s = r.scores()
        if r.diverged_at is not None:      # NaN scores (null in the JSON): say where and why
            print(f"{r.run.name}: the replay diverged at t = {r.diverged_at:.1f} s (the predicted state is not "
                  f"finite from there; scores null), wind {r.run.wind}")
            continue
        print(f"{r.run.name}: heading {s['heading_rms_deg']:.4g} deg RMS, yaw rate {s['yaw_rate_rms_degps']:.4g} deg/s RMS, "
              f"speed {s['speed_rms_mps']:.4g} m/s RMS, final position {s['final_position_error_m']:.4g} m "
              f"({s['final_position_error_L']:.4g} L), wind {r.run.wind}" + _first_text(r, args.horizon))
    print("\n".join(_window_lines(pred)))
    if len(pred.runs) > 1:                 # the figure a comparison of two configs quotes
        sc = [r.scores() for r in pred.runs if r.diverged_at is None]
        mean = lambda k: sum(x[k] for x in sc) / len(sc)  # noqa: E731
        left = len(pred.runs) - len(sc)
        if sc:
            first = ""
            if args.horizon is not None:
                f = [r.scores(until_s=args.horizon)["heading_rms_deg"] for r in pred.runs if r.diverged_at is None]
                first = f"; over the first {args.horizon:g} s: heading {sum(f) / len(f):.4g} deg RMS"
            print(f"mean over {len(sc)} runs{f' ({left} diverged, left out)' if left else ''}: heading "
                  f"{mean('heading_rms_deg'):.4g} deg RMS, final position {mean('final_position_error_L'):.4g} L{first}")
    _print_bands(bands)
    print(f"wrote {args.json}" + (f" and {len(names)} plot{'s' if len(names) != 1 else ''} to {args.plots}"
                                  if args.plots is not None else ""))
    return 0


# --samples: prediction bands (trials.measured.bands); every piece of it here, together
def _bands(args, ship, pred) -> list | None:
    """Each run's :func:`trials.measured.bands.prediction_bands` with ``--samples``, ``--seed`` (None without)."""
    if args.samples is None:
        return None
    from ..measured.bands import prediction_bands

    if args.model_form == "off":
        from dataclasses import replace

        ship = replace(ship, model_form=None)
    out = []
    for i, r in enumerate(pred.runs):
        out.append(prediction_bands(ship, r.run, args.samples, seed=args.seed, support=args.support))
        print(f"bands {i + 1}/{len(pred.runs)}: {r.run.name} ({args.samples} draws)", file=sys.stderr, flush=True)
    return out


def _with_bands(doc: dict, bands, args) -> dict:
    """The JSON with each run's band keys (:data:`trials.measured.bands.BAND_KEYS`) and what was drawn (``bands``)."""
    if bands is None:
        return doc
    for row, b in zip(doc["runs"], bands):
        row.update(b.to_json())
    notes = sorted({n for b in bands for n in b.notes})
    drawn = [b.notes for b in bands]
    form = ("off" if args.model_form == "off" else "on" if any(n.startswith("model-form heading error") for ns in drawn
                                                               for n in ns) else "none in the ship config")
    doc["bands"] = {"samples": int(args.samples), "seed": int(args.seed), "support": args.support,
                    "model_form": form, "notes": notes}
    return doc


def _print_bands(bands) -> None:
    """One console line per run's bands, then what was not drawn."""
    import numpy as np

    num = lambda x, unit: (f"{x:.3g} {unit}" if np.isfinite(x)                                     # noqa: E731
                           else "unbounded (diverged draws, or the model-form term unbounded)")
    for b in bands or ():
        if b.empty:
            print(f"{b.nominal.run.name}: no band: the {b.draws} draws all replay the nominal ship and start "
                  f"(nothing to draw them from: see the notes), so no width and no coverage")
            continue
        print(f"{b.nominal.run.name}: 90 % band from {b.draws} draws ({b.diverged} diverged"
              + (f"; {b.rejected} candidate ships rejected outside the support" if b.rejected else "") + "): heading coverage "
              f"{100 * b.coverage90:.0f} % of samples, median width {num(b.median_width_deg, 'deg')}; position "
              f"coverage {100 * b.position_coverage90:.0f} %, median radius {num(b.median_radius_m, 'm')}"
              + (f"; heading band unbounded on {100 * b.unbounded_share:.0f} % of samples (inside there; "
                 f"coverage {100 * b.coverage90_where_bounded:.0f} % over the others)" if b.unbounded_share else ""))
    for n in sorted({n for b in bands or () for n in b.notes}):
        print(f"note: {n}")


def _add_band_arguments(p) -> None:
    p.add_argument("--samples", type=_whole(1, "--samples"), default=None, metavar="N",
                   help="also a 90 %% band of heading and position per run from N replays, each with a ship drawn from "
                        "the YAML's covariance: and the start state offset by a draw from its run_spread: "
                        "(JSON keys heading_band_deg, coverage90, position_band_m, ...; bands drawn in the plots)")
    p.add_argument("--seed", type=_whole(0, "--seed"), default=0, metavar="S",
                   help="seed of the --samples draws (default 0)")
    p.add_argument("--support", choices=("none", "bounds", "physical"), default="physical",
                   help="where the --samples ship draws are kept: ships within the fit's hard bounds gaining no energy "
                        "unpowered over the training states (physical, default; the others rejected_draws, never "
                        "replayed), within the bounds alone, or anywhere (none: energy-gaining draws diverge and leave "
                        "the band unbounded); docs/prediction_bands.md")
    p.add_argument("--model-form", choices=("on", "off"), default="on",
                   help="add the YAML's model_form: term to each --samples draw's heading and position (on, default, "
                        "where the YAML has one: the error a replay gains with elapsed time, written by mmg identify) "
                        "or not")


def _first_text(r, horizon) -> str:
    """The console's short-horizon part of a run's line ("" without ``--horizon``)."""
    if horizon is None:
        return ""
    f = r.scores(until_s=horizon)
    return f"; first {horizon:g} s: heading {f['heading_rms_deg']:.4g} deg RMS, yaw rate {f['yaw_rate_rms_degps']:.4g} deg/s RMS"


def _window_lines(pred) -> list[str]:
    """The console's short-horizon lines: one per run (:meth:`trials.measured.window.WindowScores.text`), then
    with several runs the mean over them of the window means."""
    out = [w.text() for w in pred.windows]
    h = [w.mean("heading_rms_deg") for w in pred.windows]
    h = [x for x in h if x == x]
    if len(pred.windows) > 1 and h:
        w = pred.windows[0]
        out.append(f"windows of {w.window_s:g} s every {w.every_s:g} s, mean over {len(h)} runs of each run's mean: "
                   f"heading {sum(h) / len(h):.4g} deg RMS")
    return out


def _add_window_options(p) -> None:
    """--window and --every: the short-horizon windows restarted from the measured state."""
    from ..measured.window import EVERY_S, WINDOW_S

    p.add_argument("--window", type=quantity("time", "s", 0.0, lo_open=True), default=WINDOW_S, metavar="S",
                   help=f"length [s] of the windows each run is also predicted over from its measured state "
                        f"(JSON key 'window': mean heading RMS and final position error; default {WINDOW_S:g})")
    p.add_argument("--every", type=quantity("time", "s", 0.0, lo_open=True), default=EVERY_S, metavar="S",
                   help=f"interval [s] between the starts of those windows (default {EVERY_S:g})")


def add_parser(sub) -> None:
    """The predict subcommand of ``mmg`` (its options, help and function)."""
    p = sub.add_parser("predict", help="replay records open-loop against their own rudder and propeller history: "
                                       "heading, yaw-rate, speed RMS and final position error per run")
    p.add_argument("logs", nargs="+", metavar="LOG", help="FRT-DS-ESSO CSVs, project logs or truth files")
    p.add_argument("--ship", required=True, help="ship YAML or bundled name (esso_osaka_3m, esso_osaka, ...)")
    p.add_argument("--json", required=True, type=_output_path, help="write the scores of every run to this JSON file")
    p.add_argument("--plots", default=None, metavar="DIR", type=_output_path,
                   help="also one figure per run, DIR/<name>.png (<name>: the record's file name; two files of one "
                        "name told apart by their folders, DIR/<folder>/<name>.png)")
    p.add_argument("--start", type=quantity("time", "s"), default=None, metavar="S",
                   help="start time [s] of every replay, with its unit or a bare number in s (default: each "
                        "record's first sample)")
    p.add_argument("--wind", choices=("on", "off"), default=None,
                   help="wind loads from the measured relative wind (default: as the ship config says)")
    p.add_argument("--horizon", type=quantity("time", "s", 0.0, lo_open=True), default=None, metavar="S",
                   help="also the scores over the first S seconds of each replay (JSON key 'first'; the short-"
                        "horizon figure of docs/benchmark_frt.md, 60 s there)")
    _add_window_options(p)
    _add_band_arguments(p)
    p.set_defaults(func=cmd_predict)
