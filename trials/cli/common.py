"""What the command modules share: the argument types of their options (one-line refusals of an
empty output path, a non-positive number, ...), the metrics printout and the "wrote ..." listing.
Imports only the standard library (and :mod:`trials.files.output` inside :func:`print_metrics`)."""
from __future__ import annotations

import argparse
import os
import sys

METRIC_KEYS = ["trial", "kind", "execute_s", "approach_speed_mps", "rudder_deg", "approach_speed_kn", "approach_rpm", "trim_rudder_deg", "advance_L", "transfer_L",
               "tactical_diameter_L", "steady_diameter_L", "speed_loss", "overshoots_deg", "initial_turning_time_s",
               "period_s", "final_heading_change_deg"]


def _whole(minimum: int, what: str):
    """An argparse type: a whole number of at least ``minimum``; the error names ``what`` it is."""
    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if v < minimum:
            raise argparse.ArgumentTypeError(f"{what} must be {minimum} or more, got {v}")
        return v
    return parse


_positive_int = _whole(1, "it")
_seed = _whole(0, "a noise seed")


def _output_path(text: str) -> str:
    """An argparse type for every output option (a folder or file written): an empty path is refused
    (it would otherwise mean "no output" to a command whose option is optional)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"empty path {text!r}: give a file or folder name")
    return text


def _finite_positive(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not (v > 0 and v < float("inf")):
        raise argparse.ArgumentTypeError(f"expected a positive finite number, got {text!r}")
    return v


def _rudder_timing(text: str) -> float | None:
    """--rudder-timing: a prior std [s] > 0, 'inf' (no prior) or 'none' (no timing nuisances)."""
    if text.strip().lower() == "none":
        return None
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not v > 0:
        raise argparse.ArgumentTypeError(f"expected a prior std in seconds > 0, 'inf' or 'none', got {text!r}")
    return v


def print_metrics(m: dict, out=None) -> None:
    """The main metrics of a trial or record, one per line."""
    from ..files.output import fmt

    out = out or sys.stdout
    for k in METRIC_KEYS:
        if k in m:
            print(f"  {k:26s} {fmt(m[k])}", file=out)


def _listing(names) -> str:
    """File names for a 'wrote ...' line; 3 or more of one pattern (convergence_*.png) as one."""
    groups: dict = {}
    for n in names:
        stem, suffix = os.path.splitext(n)
        key = (stem.split("_", 1)[0] + "_*" if "_" in stem else stem, suffix)
        groups.setdefault(key, []).append(n)
    out = []
    for (pat, suffix), ns in groups.items():
        out += [f"{pat}{suffix} ({len(ns)})"] if len(ns) >= 3 else ns
    return ", ".join(out) or "nothing"
