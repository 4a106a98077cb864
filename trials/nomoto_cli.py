"""CLI commands ``mmg nomoto`` and ``mmg nomoto-paper`` (registered by trials/cli.py)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from trials.errors import InputError


def register(subparsers) -> None:
    """Add the ``nomoto`` and ``nomoto-paper`` subcommands.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        From ``ArgumentParser.add_subparsers``.
    """
    p = subparsers.add_parser("nomoto", help="identify 1st/2nd-order Nomoto K, T (T1, T2, T3) from a zigzag log")
    p.add_argument("log", help="zigzag record (project log/truth CSV or FRT-DS-ESSO CSV)")
    p.add_argument("--length", type=float, required=True, help="ship length L [m]")
    p.add_argument("--speed", type=float, help="speed U [m/s] for s' = tU/L (default: mean approach speed)")
    p.add_argument("--json", help="write results to this JSON file (plot PNG next to it)")
    p.add_argument("--no-output-error", action="store_true", help="skip the output-error fit")
    p.set_defaults(func=cmd_nomoto)

    p = subparsers.add_parser("nomoto-paper", help="reproduce Artyszuk (2018) Tables 1-8 (CSV + Markdown)")
    p.add_argument("--out", default="out/nomoto-paper", help="output folder")
    p.add_argument("--fast", action="store_true", help="skip the output-error fits of the extended Table 8")
    p.set_defaults(func=cmd_nomoto_paper)


def _f(v, fmt="{:.4g}"):
    return "n/a" if v is None or not np.isfinite(v) else fmt.format(v)


def report(ident) -> str:
    """Plain-text report of a :class:`trials.nomoto.NomotoIdentification`."""
    z = ident.zigzag
    d = ident.to_dict()
    lines = [f"record {z.name}: L = {z.L:g} m, U = {z.U:.4g} m/s, execute at t = {z.t_execute:.4g} s "
             f"to {d['first_execute_to']}, rudder {np.degrees(z.delta0):.3g} deg, yaw rate {z.yaw_rate_source}",
             "points (s' [-], eps' [-], omega' [-], Delta [rad], delta [rad], psi [deg]):"]
    for nm_, v in ident.points.to_dict().items():
        lines.append(f"  {nm_:4s} {v['s']:8.4f} {v['eps']:9.5f} {v['omega']:9.5f} {v['Delta']:9.5f} "
                     f"{v['delta']:9.5f} {v['psi_deg']:9.3f}")
    lines.append("")
    lines.append(f"{'method':34s} {'K':>8s} {'T / T1':>8s} {'T2':>8s} {'T3':>8s} {'psi RMS [deg]':>14s}")
    for _, r in ident.to_pandas().iterrows():
        lines.append(f"{r['method']:34s} {_f(r['K']):>8s} {_f(r['T1']):>8s} {_f(r['T2']):>8s} {_f(r['T3']):>8s} "
                     f"{_f(r['rms_deg'], '{:.3f}'):>14s}")
    for fit in (ident.least_squares, ident.output_error):
        if fit is None:
            continue
        ci = "  ".join(f"{k} [{_f(lo)}, {_f(hi)}]" for k, (lo, hi) in fit.ci95.items() if k != "delta_bias")
        lines.append(f"95 % intervals, {fit.method.replace('_', ' ')}: {ci}")
    note = ident.four_point.note()
    if note:
        lines.append(f"four-point: {note}")
    for fit in (ident.least_squares, ident.output_error):
        if fit is not None and fit.note:
            lines.append(f"{fit.method}: {fit.note}")
    return "\n".join(lines)


def cmd_nomoto(args) -> int:
    """Handler of ``mmg nomoto``: identify, print the table, write JSON and PNG; 2 on bad input."""
    from trials import nomoto as nm
    from trials.logio import read_record

    if args.length is None or not np.isfinite(args.length) or args.length <= 0:
        raise InputError("--length", "", f"ship length must be a positive number of metres, got {args.length}")
    if args.speed is not None and (not np.isfinite(args.speed) or args.speed <= 0):
        raise InputError("--speed", "", f"speed must be a positive number of m/s, got {args.speed}")
    rec = read_record(args.log)
    if rec.delta is None and rec.meta.get("format") == "log":
        from trials.rudder import with_rebuilt_rudder

        rec = with_rebuilt_rudder(rec)
        print(f"{rec.name}: no rudder channel in the log; rudder rebuilt from the {rec.meta.get('kind')} logic in its header")
    ident = nm.identify(rec, args.length, args.speed, output_error=not args.no_output_error)
    print(report(ident))
    if args.json:
        from trials.nomoto_plot import plot_identification
        from trials.output import StagedOutput

        out = Path(args.json)
        with StagedOutput(out.parent) as stage:  # JSON and PNG appear together or not at all
            stage.path(out.name).write_text(json.dumps(ident.to_dict(), indent=2))
            plot_identification(ident, stage.path(out.with_suffix(".png").name))
        print(f"wrote {out} and {out.with_suffix('.png')}")
    return 0


def cmd_nomoto_paper(args) -> int:
    """Handler of ``mmg nomoto-paper``: print and write Tables 1-8 with the paper's values."""
    import pandas as pd

    from trials import artyszuk as a

    tables = a.reproduce(fast=args.fast)
    with pd.option_context("display.width", 200, "display.max_columns", 40, "display.float_format", "{:.5g}".format):
        for key, title in a.TITLES.items():
            print(f"\n{title}")
            print(tables[key].to_string(index=False))
            note = tables.get("notes", {}).get(key)
            if note:
                print(f"note: {note}")
    paths = a.write_tables(tables, args.out)
    print(f"\nwrote {len(paths)} files to {args.out}")
    return 0


def handler(args) -> int:
    """Dispatch to the handler set by :func:`register` (for callers holding parsed args)."""
    return args.func(args)
