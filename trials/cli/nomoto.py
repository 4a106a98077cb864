"""``mmg nomoto`` (Nomoto K, T from a zigzag record, :func:`trials.analysis.nomoto_report.identify_log`) and
``mmg nomoto-paper`` (Artyszuk 2018 Tables 1-8, :func:`trials.papers.artyszuk.reproduce`)."""
from __future__ import annotations

from pathlib import Path

from mmg.errors import InputError

from .common import _output_path, quantity


def cmd_nomoto(args) -> int:
    from contextlib import nullcontext

    from ..analysis.nomoto_report import identify_log, report, write_identification
    from ..files.output import StagedOutput, check_output_file

    if args.json is not None:
        if Path(args.json).suffix.lower() == ".png":
            raise InputError("--json", args.json, "ends in .png, the name of the plot written beside it")
        check_output_file(args.json, also=[Path(args.json).with_suffix(".png")])
    # the JSON's folder staged for the JSON and its plot only: what else it holds is not this run's business
    with StagedOutput(Path(args.json).parent, report=False) if args.json is not None else nullcontext() as stage:
        ident, note = identify_log(args.log, args.length, args.speed, output_error=not args.no_output_error)
        if args.json is not None:
            write_identification(ident, stage.path(Path(args.json).name))
    if note:                                     # the files are in place: now the console
        print(note)
    print(report(ident))
    if args.json is not None:
        print(f"wrote {args.json} and {Path(args.json).with_suffix('.png')}")
    return 0


def cmd_nomoto_paper(args) -> int:
    from ..papers import artyszuk as a
    from ..files.output import StagedOutput, check_output_dir

    check_output_dir(args.out)
    with StagedOutput(args.out) as stage:
        tables = a.reproduce(fast=args.fast)
        paths = a.write_tables(tables, stage.dir)
    print("\n".join(a.text_parts(tables)))
    print(f"\nwrote {len(paths)} files to {args.out}")
    return 0


def add_parser(sub) -> None:
    """The nomoto and nomoto-paper subcommands of ``mmg`` (its options, help and function)."""
    p = sub.add_parser("nomoto", help="identify 1st/2nd-order Nomoto K, T (T1, T2, T3) from a zigzag log")
    p.add_argument("log", help="zigzag record (project log/truth CSV or FRT-DS-ESSO CSV)")
    p.add_argument("--length", type=quantity("length", "m", 0.0, lo_open=True), required=True,
                   help="ship length L with its unit ('3 m'), a bare number in m")
    p.add_argument("--speed", type=quantity("speed", "m/s", 0.0, lo_open=True),
                   help="speed U for s' = tU/L with its unit ('0.3 m/s', '10 kn'), a bare number in m/s "
                        "(default: mean approach speed)")
    p.add_argument("--json", type=_output_path, help="write results to this JSON file (plot PNG next to it)")
    p.add_argument("--no-output-error", action="store_true", help="skip the output-error fit")
    p.set_defaults(func=cmd_nomoto)

    p = sub.add_parser("nomoto-paper", help="reproduce Artyszuk (2018) Tables 1-8 (CSV + Markdown)")
    p.add_argument("--out", default="out/nomoto-paper", type=_output_path, help="output folder")
    p.add_argument("--fast", action="store_true", help="skip the output-error fits of the extended Table 8")
    p.set_defaults(func=cmd_nomoto_paper)
