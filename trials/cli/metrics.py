"""``mmg metrics``: turning/zigzag metrics of any record (:func:`trials.analysis.metrics.record_metrics`)."""
from __future__ import annotations

import sys

from .common import _output_path, print_metrics, quantity


def cmd_metrics(args) -> int:
    from ..files.logio import read_record, require_finite
    from ..analysis.metrics import record_metrics
    from ..files.output import check_output_file, dump_json
    from ..files.records import CHANNELS

    if args.json is not None:
        check_output_file(args.json)
    from ..files.shipcheck import check_record_ship, read_for_ship

    if args.length is not None:
        rec = read_for_ship(args.log, args.length)
    else:                    # the header's length, or the FRT-DS-ESSO layout's 3 m model
        rec = read_record(args.log)
        length = rec.meta.get("length_m")
        if isinstance(length, (int, float)) and length > 0:          # none at all: record_metrics says so
            assumed = "model the FRT-DS-ESSO layout assumes when no --length is given"
            check_record_ship(rec, float(length), name=assumed if rec.meta.get("format") == "frt-ds-esso" else None)
    require_finite(rec, CHANNELS, "mmg metrics")      # the track, heading, speeds, rudder, rpm; not the wind
    m = record_metrics(rec, args.kind, args.length, args.zigzag_angle)
    if args.json is not None:
        dump_json(m, args.json)               # first (a temporary file beside it, renamed), then the console
    print(f"{rec.name} ({m['kind']}, {rec.source})")
    print_metrics(m)
    for note in m.get("notes", []):
        print(f"note: {note}", file=sys.stderr)
    return 0


def add_parser(sub) -> None:
    """The metrics subcommand of ``mmg`` (its options, help and function)."""
    p = sub.add_parser("metrics", help="manoeuvre metrics from a log (project log, truth file or FRT-DS-ESSO CSV)")
    p.add_argument("log")
    p.add_argument("--kind", choices=["turning", "zigzag", "stype"], help="override the manoeuvre kind")
    p.add_argument("--length", type=quantity("length", "m", 0.0, lo_open=True),
                   help="ship length L with its unit ('3 m'), a bare number in m, when the log does not say")
    p.add_argument("--zigzag-angle", type=quantity("angle", "deg", 0.0, lo_open=True),
                   help="switching heading with its unit ('20 deg'), a bare number in deg, for a zigzag log "
                        "without rudder")
    p.add_argument("--json", type=_output_path, help="also write the metrics to this JSON file")
    p.set_defaults(func=cmd_metrics)
