"""The ``mmg`` command.

Subcommands: ``simulate``, ``metrics``, ``reproduce`` (the main job) and those
registered by other modules (``nomoto``, ``estimate``, ...).  Bad input gives one
line naming the file and field on stderr and exit status 2, with nothing
written to ``--out``.
"""
from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

import numpy as np

from mmg.errors import InputError

from .output import StagedOutput, dump_json  # noqa: F401  (re-exported for the CLI modules)

REPO = Path(__file__).resolve().parents[1]
CONFIGS = REPO / "configs"


def fmt(v, nd=4):
    if v is None:
        return "-"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(f"{x:.{min(nd, 2)}f}" for x in v) + "]"
    if isinstance(v, (float, np.floating)):
        return f"{v:.{nd}g}"
    return str(v)


# --------------------------------------------------------------------------- simulate

def write_trial_outputs(run, stage: StagedOutput, show: bool = False) -> dict:
    """log.csv, truth.csv, metrics.json, track.png, histories.png for one simulated trial."""
    from .logio import write_csv
    from .plots import plot_histories, plot_track

    meta = run.log_meta()
    write_csv(stage.path("log.csv"), run.log(), meta)
    write_csv(stage.path("truth.csv"), run.truth(), meta)
    m = run.metrics()
    dump_json(m, stage.path("metrics.json"))
    r, sh = run.result, run.trial.ship.particulars
    plot_track(r.t, r.x, r.y, r.psi, sh.L, sh.B, f"{run.trial.name} ({run.trial.ship.name})", stage.path("track.png"), show=show)
    plot_histories(r.t, r.psi, r.delta, r.r, r.U, r.n, f"{run.trial.name} ({run.trial.ship.name})",
                   stage.path("histories.png"), delta_order=r.orders, show=show)
    return m


def print_metrics(m: dict, out=None) -> None:
    out = out or sys.stdout
    keys = ["trial", "kind", "approach_speed_kn", "approach_rpm", "trim_rudder_deg", "advance_L", "transfer_L",
            "tactical_diameter_L", "steady_diameter_L", "speed_loss", "overshoots_deg", "initial_turning_time_s",
            "period_s", "final_heading_change_deg"]
    for k in keys:
        if k in m:
            print(f"  {k:26s} {fmt(m[k])}", file=out)


def cmd_simulate(args) -> int:
    from .run import run_trial
    from .trial import load_trial

    trial = load_trial(args.config)
    run = run_trial(trial)
    with StagedOutput(args.out) as stage:
        m = write_trial_outputs(run, stage, show=args.show)
    print(f"{trial.name}: wrote log.csv, truth.csv, metrics.json, track.png, histories.png to {args.out}")
    print_metrics(m)
    if not run.result.completed:
        print(f"warning: {trial.name} stopped early at t = {run.result.t[-1]:g} s (speed collapsed)", file=sys.stderr)
    return 0


# --------------------------------------------------------------------------- metrics

def record_metrics(rec, kind=None, length=None, angle=None) -> dict:
    """Metrics of a read record (kind guessed from the heading history when not given)."""
    from . import metrics as MET

    L = length or rec.meta.get("length_m")
    if L is None:
        raise InputError(rec.source, "--length", "the log does not give the ship length; pass --length")
    L = float(L)
    kind = kind or rec.meta.get("kind")
    if kind not in ("turning", "zigzag", "stype"):
        kind = "turning" if abs(rec.psi[-1] - rec.psi[0]) > np.pi else "zigzag"
    out = {"record": rec.name, "source": rec.source, "kind": kind, "length_m": L}
    U = rec.speed()
    if kind == "turning":
        if rec.x is None:
            raise InputError(rec.source, "lat_deg", "turning metrics need the track (positions)")
        out.update(MET.turning_metrics(rec.t, rec.x, rec.y, rec.psi, U, L,
                                       t_execute=rec.meta.get("execute_s"), delta=rec.delta,
                                       order=rec.meta.get("delta_order")))
    else:
        order = rec.meta.get("delta_order", rec.delta)
        ang = angle
        if order is None and ang is None:
            key = "heading_deg" if kind == "zigzag" else "switch_heading_deg"
            if key not in rec.meta:
                raise InputError(rec.source, "heading_deg", "a zigzag log without rudder needs --zigzag-angle")
            ang = float(rec.meta[key]) * np.pi / 180
        first = None
        if rec.meta.get("first") in ("starboard", "port"):
            first = 1 if rec.meta["first"] == "starboard" else -1
        if kind == "stype" and order is None:
            raise InputError(rec.source, "rudder", "S-type metrics from a log need the rudder channel")
        out.update(MET.zigzag_metrics(rec.t, rec.psi, order=order, angle=ang, first=first, U=U, L=L))
    return out


def cmd_metrics(args) -> int:
    from .logio import read_record

    rec = read_record(args.log)
    m = record_metrics(rec, args.kind, args.length, None if args.zigzag_angle is None else np.radians(args.zigzag_angle))
    print(f"{rec.name} ({m['kind']}, {rec.source})")
    print_metrics(m)
    if args.json:
        with StagedOutput(Path(args.json).parent or ".") as stage:
            dump_json(m, stage.path(Path(args.json).name))
    return 0


# --------------------------------------------------------------------------- reproduce (main job)

def cmd_reproduce(args) -> int:
    from .reproduce import reproduce

    return reproduce(args)


# --------------------------------------------------------------------------- main

def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="mmg", description="MMG ship manoeuvring: simulate, analyse, identify.")
    sub = ap.add_subparsers(dest="command", required=True)

    p = sub.add_parser("simulate", help="simulate a trial from its YAML config")
    p.add_argument("config", help="trial YAML (configs/trials/*.yaml)")
    p.add_argument("--out", required=True, help="output folder (log.csv, truth.csv, metrics.json, PNGs)")
    p.add_argument("--show", action="store_true", help="also show the figures on screen")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("metrics", help="manoeuvre metrics from a log (project log, truth file or FRT-DS-ESSO CSV)")
    p.add_argument("log")
    p.add_argument("--kind", choices=["turning", "zigzag", "stype"], help="override the manoeuvre kind")
    p.add_argument("--length", type=float, help="ship length L [m] when the log does not say")
    p.add_argument("--zigzag-angle", type=float, help="switching heading [deg] for a zigzag log without rudder")
    p.add_argument("--json", help="also write the metrics to this JSON file")
    p.set_defaults(func=cmd_metrics)

    p = sub.add_parser("reproduce", help="the main job: reproduce the papers on the default Esso Osaka configs")
    p.add_argument("--out", default="out", help="output folder (default: out)")
    p.add_argument("--full", action="store_true",
                   help="also the Monte Carlo runs (EKF and output error, 20 seeds) and the full Nomoto Table 8 (~25 min)")
    p.set_defaults(func=cmd_reproduce)

    for mod in ("trials.nomoto_cli", "ekf.cli", "trials.sensitivity_cli"):
        try:
            m = importlib.import_module(mod)
        except ModuleNotFoundError as e:
            if e.name != mod:
                raise
            continue
        m.register(sub)
    return ap


def main(argv=None) -> int:
    ap = build_parser()
    args = ap.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
