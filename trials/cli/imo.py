"""``mmg imo``: the IMO manoeuvring standards checked on a ship, with their uncertainty
(:func:`trials.imo.result.imo`, :func:`trials.imo.report.write_report`)."""
from __future__ import annotations

import sys

from .common import _output_path, _positive_int, _seed, _whole, backend_client, check_backend_options


def cmd_imo(args) -> int:
    from mmg.errors import InputError
    from mmg.ship import load_ship

    from ..files.output import StagedOutput, check_output_dir
    from ..imo.report import interval_text, write_report
    from ..imo.result import imo
    from ..imo.sampling import covariance_of, local_executor
    from ..imo.standard import approach_speed, plan, speed_label

    check_backend_options(args)
    check_output_dir(args.out)
    ship = load_ship(args.ship)
    try:
        target = ship if args.scale_to is None else load_ship(args.scale_to)
    except InputError as e:
        raise InputError("--scale-to", args.scale_to, e.message) from None
    try:
        if args.speed is not None:
            plan(target, args.speed)               # a bad speed: one line before any run
        else:
            approach_speed(target)                 # no speed known: the same
        if args.scale_to is not None:
            from ..imo.scaling import scaling
            from ..imo.standard import _parse_speed

            scaling(ship, target, _parse_speed(args.speed or approach_speed(target)[0]))   # another hull form
        if args.samples and (args.scale_to is None or ship.covariance is not None):
            covariance_of(ship)                    # no covariance, a bad one: the same
    except InputError as e:
        if e.source not in ("speed", "samples"):
            raise
        raise InputError(f"--{e.source}", e.field, e.message) from None
    if args.samples:
        print(f"{args.samples} parameter samples, every manoeuvre each, on {args.jobs or 'all usable'} cores",
              file=sys.stderr, flush=True)
    with backend_client(args) as client:
        ex = local_executor(args.jobs, progress=bool(args.samples), backend=args.backend, client=client)
        res = imo(ship, speed=args.speed, samples=args.samples, seed=args.seed, executor=ex, scale_to=target
                  if args.scale_to is not None else None)
    with StagedOutput(args.out) as stage:
        names = write_report(res, stage.dir)
    print(f"{res.ship} at {speed_label(res.speed, res.u0)}, L/V = {res.L_over_V:.3g} s: "
          f"wrote {', '.join(names)} to {args.out}")
    for w in res.warnings:
        print(f"warning: {w}")
    if res.doubts.reason:
        print(f"verdicts: {res.doubts.reason}")
    for r in res.rows():
        val = "-" if r["value"] is None else f"{r['value']:.3g} {r['unit']}"
        extra = ""
        if r["interval"]:
            extra = f"  90 % {interval_text(r['interval'], r['unit'])}  P = {r['probability']:.3f}"
        print(f"  {r['name']:40s} {val:>10s}  limit {r['limit']:.3g} {r['unit']}{extra}  {r['verdict']}")
    widths = res.interval_widths()
    if widths:
        print("90 % interval widths, all uncertainty / identified covariance only (scale effects fixed):")
        for w in widths:
            a, b = ("-" if x is None else f"{x:.3g}" for x in (w["width"], w["width_identified"]))
            share = "-" if w["scaling_share"] is None else f"{100 * w['scaling_share']:.0f} %"
            print(f"  {w['name']:40s} {a:>8s} / {b:<8s} {w['unit']:3s}  from the scaling: {share}")
    return 0


def _speed_text(text: str) -> str:
    """``--speed`` as the standard's speed text: a value with its unit as given, a bare number in m/s (the one
    rule of :func:`trials.cli.common.quantity`, which checks it)."""
    from .common import quantity

    quantity("speed", "m/s", 0.0, lo_open=True)(text)
    t = text.strip()
    try:
        float(t)
    except ValueError:
        return t
    return f"{t} m/s"


def add_parser(sub) -> None:
    """The imo subcommand of ``mmg`` (its options, help and function)."""
    p = sub.add_parser("imo", help="check the IMO manoeuvring standards (MSC.137(76)) on a ship, with their "
                                   "uncertainty from its parameters' covariance and its identification's warnings "
                                   "(no pass from an unfinished fit); writes DIR/imo.json, DIR/imo.md")
    p.add_argument("ship", help="bundled ship name (esso_osaka) or ship YAML (mmg identify's DIR/ship.yaml)")
    p.add_argument("--out", required=True, metavar="DIR", type=_output_path,
                   help="output folder (imo.json, imo.md, tracks.png, zigzags.png, distributions.png)")
    p.add_argument("--speed", type=_speed_text, default=None,
                   help="approach speed with its unit ('10 kn', '0.5 m/s') or a bare number in m/s (default: the "
                        "ship's bundled trials')")
    p.add_argument("--samples", type=_whole(0, "--samples"), default=0, metavar="N",
                   help="parameter samples from the ship's covariance (default 0: its own parameters only)")
    p.add_argument("--scale-to", default=None, metavar="SHIP",
                   help="the full-scale ship (bundled name or YAML, same hull form) to Froude-scale this model to, "
                        "with the scale effects (friction line, wake, rudder inflow) and their uncertainty "
                        "(docs/imo.md)")
    p.add_argument("--seed", type=_seed, default=0, help="seed of the parameter samples (default 0)")
    p.add_argument("--jobs", type=_positive_int, default=None, help="worker processes (default: all usable cores)")
    p.add_argument("--backend", choices=("serial", "loky", "dask"), default="loky",
                   help="where the samples run: serial, loky (this machine's cores, default) or dask (--scheduler's "
                        "cluster, or a local one of --jobs workers; optional extra mmg-toolkit[dask])")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="with --backend dask: a running dask scheduler (tcp://host:8786)")
    p.set_defaults(func=cmd_imo)
