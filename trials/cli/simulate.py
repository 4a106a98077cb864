"""``mmg simulate``: a trial from its YAML (:func:`trials.runs.run.run_trial`), its log, truth, metrics and figures."""
from __future__ import annotations

import sys

from .common import _output_path, print_metrics


def cmd_simulate(args) -> int:
    from ..files.output import StagedOutput, check_output_dir, write_trial_outputs
    from ..runs.run import run_trial
    from ..runs.trial import load_trial

    check_output_dir(args.out)
    trial = load_trial(args.config)
    with StagedOutput(args.out) as stage:
        run = run_trial(trial)
        m = write_trial_outputs(run, stage, show=args.show)
    print(f"{trial.name}: wrote log.csv, truth.csv, metrics.json, track.png, histories.png to {args.out}")
    print_metrics(m)
    if trial.kind == "stopping" and not m.get("stopped"):
        print(f"warning: {trial.name}: the ship has not stopped within {trial.duration:g} s", file=sys.stderr)
    elif not run.result.completed and trial.kind != "stopping":     # a stopping run ends when the ship stops
        print(f"warning: {trial.name} stopped early at t = {run.result.t[-1]:g} s (speed collapsed)", file=sys.stderr)
    return 0


def add_parser(sub) -> None:
    """The simulate subcommand of ``mmg`` (its options, help and function)."""
    p = sub.add_parser("simulate", help="simulate a trial from its YAML config")
    p.add_argument("config", help="trial YAML (configs/trials/*.yaml) or a bundled trial name (st35, zz20, ...)")
    p.add_argument("--out", required=True, type=_output_path,
                   help="output folder (log.csv, truth.csv, metrics.json, PNGs)")
    p.add_argument("--show", action="store_true", help="also show the figures on screen")
    p.set_defaults(func=cmd_simulate)
