"""What the command modules share: the argument types of their options (one-line refusals of an
empty output path, a non-positive number, ...; :func:`quantity` for every dimensional option), the
metrics printout and the "wrote ..." listing.  Imports only the standard library at import time
(:mod:`mmg.units` inside :func:`quantity`'s parser, :mod:`trials.files.output` inside
:func:`print_metrics`)."""
from __future__ import annotations

import argparse
import os
import sys

METRIC_KEYS = ["trial", "kind", "execute_s", "approach_speed_mps", "rudder_deg", "approach_speed_kn", "approach_rpm", "trim_rudder_deg", "advance_L", "transfer_L",
               "tactical_diameter_L", "steady_diameter_L", "speed_loss", "overshoots_deg", "initial_turning_time_s",
               "period_s", "final_heading_change_deg", "track_reach_L", "head_reach_L", "lateral_deviation_L",
               "time_to_stop_s"]


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


def quantity(dimension: str, bare: str, lo: float | None = None, hi: float | None = None, *,
             lo_open: bool = False, words: dict | None = None):
    """The argparse type of every dimensional option: the value in SI.

    A value with its unit (``'3 m'``, ``'0.3 m/s'``, ``'10 kn'``, ``'20 deg'``) is read by
    :func:`mmg.units.to_si` in any unit of ``dimension``; a bare number is in ``bare``, the unit the
    option's help states (SI, or degrees for an angle).

    Parameters
    ----------
    dimension : str
        A key of :data:`mmg.units.UNITS` (``"length"``, ``"speed"``, ``"angle"``, ``"time"``, ...).
    bare : str
        The unit of a number given without one (a unit of ``dimension``).
    lo, hi : float, optional
        Bounds in SI (``lo_open``: ``lo`` itself refused), as :func:`mmg.units.to_si` takes them.
    words : dict, optional
        Words that stand for a value (``{"inf": math.inf}``), case-insensitive.

    Returns
    -------
    callable
        ``text -> float`` raising :class:`argparse.ArgumentTypeError` in one line.
    """
    def parse(text: str):
        from mmg.units import to_si

        t = text.strip()
        if words and t.lower() in words:
            return words[t.lower()]
        try:
            float(t)
            t = f"{t} {bare}"                       # a bare number: in the unit the help states
        except ValueError:
            pass
        try:
            return to_si(t, dimension, lo, hi, lo_open=lo_open)
        except ValueError as e:
            raise argparse.ArgumentTypeError(f"{e} (a bare number is in {bare})") from None
    return parse


def _rudder_timing(text: str) -> float | None:
    """--rudder-timing: a prior std > 0 (a time, bare number in s), 'inf' (no prior) or 'none' (no timing nuisances)."""
    return quantity("time", "s", 0.0, lo_open=True, words={"none": None, "inf": float("inf")})(text)


def print_metrics(m: dict, out=None) -> None:
    """The main metrics of a trial or record, one per line (a key's suffix is its unit: _s, _deg, _L, ...;
    the speed loss, a fraction, as per cent of the approach speed)."""
    from ..files.output import fmt

    out = out or sys.stdout
    for k in METRIC_KEYS:
        if k in m:
            v = m[k]
            text = (f"{100 * v:.1f} % of the approach speed" if k == "speed_loss" and isinstance(v, (int, float))
                    else fmt(v))
            print(f"  {k:26s} {text}", file=out)


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


# --------------------------------------------------------------------------- outputs apart from inputs

INPUT_OPTIONS = {"log": "LOG", "logs": "LOG", "train": "--train", "test": "--test", "ship": "--ship",
                 "initial": "--initial", "config": "--config", "truth": "--truth", "trials": "TRIAL",
                 "inputs": "LOG_OR_TRIAL", "ekf_comparison": "--ekf-comparison", "ekf_summary": "--ekf-summary"}
"""The argument names (argparse ``dest``) of every input file of every command, with the option shown."""

OUTPUT_OPTIONS = {"json": "--json", "out_ship": "--out-ship", "out": "--out", "plots": "--plots"}
"""The argument names of every output (a file or a folder) of every command, with the option shown."""

FOLDER_FILES = {"simulate": {"out": ("log.csv", "truth.csv", "metrics.json", "track.png", "histories.png")},
                "identify": {"out": ("ship.yaml", "report.md")},
                "imo": {"out": ("imo.json", "imo.md", "tracks.png", "zigzags.png", "distributions.png")}}
"""The files a command's output folder is known to receive (replaced there when the run succeeds)."""


def _paths(value) -> list[str]:
    if value is None:
        return []
    return [str(v) for v in (value if isinstance(value, (list, tuple)) else [value])]


def _same(a: str, b: str) -> bool:
    """The two paths name one file (symlinks, relative paths and hard links resolved)."""
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def _outputs(args) -> list[tuple[str, str]]:
    """(option, path) of every file or folder ``args``' command writes, the files inside a folder where known."""
    outs = []
    for dest, opt in OUTPUT_OPTIONS.items():
        for p in _paths(getattr(args, dest, None)):
            outs.append((opt, p))
            for name in FOLDER_FILES.get(getattr(args, "command", None), {}).get(dest, ()):
                outs.append((opt, os.path.join(p, name)))
            if dest == "plots":        # <record stem>.png per record (mmg predict, mmg diagnose)
                outs += [(opt, os.path.join(p, os.path.splitext(os.path.basename(r))[0] + ".png"))
                         for r in _paths(getattr(args, "logs", None))]
    if getattr(args, "command", None) == "nomoto" and getattr(args, "json", None):
        outs.append(("--json", os.path.splitext(args.json)[0] + ".png"))      # its plot, beside it
    return outs


def check_outputs_apart(args) -> None:
    """Refuse, before any work, an output that is the same file as an input or as another output.

    Every output path (``--json``, ``--out-ship``, ``--plots``, ``--out`` and the files known to be
    written in such a folder, :data:`FOLDER_FILES`) against every input file that exists (records,
    ``--train``/``--test``, ``--ship``/``--initial``/``--config``, ``--truth``, trial YAMLs) and against
    each other; symlinks, relative paths and hard links resolved.  One :class:`~mmg.errors.InputError`
    naming both; nothing read or written yet.
    """
    from mmg.errors import InputError

    ins = [(opt, p) for dest, opt in INPUT_OPTIONS.items() for p in _paths(getattr(args, dest, None))
           if os.path.isfile(p)]
    for dest in ("ship", "initial"):          # a bundled ship name resolves to its YAML
        name = getattr(args, dest, None)
        if isinstance(name, str) and not os.path.isfile(name):
            try:
                from mmg.resources import ship_path

                ins.append((INPUT_OPTIONS[dest], str(ship_path(name))))
            except Exception:                  # noqa: BLE001 - the command itself says what is wrong with it
                pass
    outs = _outputs(args)
    for i, (oopt, out) in enumerate(outs):
        for iopt, inp in ins:
            if _same(out, inp):
                raise InputError(oopt, out, f"is the input {inp} ({iopt}): writing it would destroy the input; "
                                            "give another output path")
        for oopt2, out2 in outs[i + 1:]:
            if _same(out, out2) and not (oopt == oopt2 and os.path.normpath(out) == os.path.normpath(out2)):
                raise InputError(oopt, out, f"is also the output of {oopt2} ({out2}): give each output its own path")


# --------------------------------------------------------------------------- notes held until the run proceeds

import logging  # noqa: E402


class HeldNotes(logging.Handler):
    """The library's logged notes (WARNING and above: a reader's "note: ... kept as NaN", a skipped
    effect) held while a command reads and checks its inputs, so that a refusal stays one line; printed
    on stderr, in order, by :func:`release_notes` once the command proceeds (its first progress line,
    or its end), and from then on as they come.  Dropped when the command is refused."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.held: list[str] = []
        self.passing = False

    def emit(self, record) -> None:
        msg = record.getMessage()
        if self.passing:
            print(msg, file=sys.stderr, flush=True)
        else:
            self.held.append(msg)

    def print_held(self) -> None:          # (not ``release``: the Handler's lock method)
        self.passing = True
        held, self.held = self.held, []
        for msg in held:
            print(msg, file=sys.stderr, flush=True)


_held: list[HeldNotes] = []


def release_notes() -> None:
    """Print the notes held so far (the command proceeds: its inputs are read and accepted)."""
    for h in _held:
        h.print_held()


def add_backend_options(p, what: str) -> None:
    """``--backend``, ``--scheduler``, ``--jobs``: where ``what`` runs (the same numbers on every backend)."""
    p.add_argument("--backend", choices=("serial", "loky", "dask"), default="loky",
                   help=f"where {what} run: serial, loky (this machine's cores, default) or dask (a cluster: "
                        "--scheduler ADDRESS, or a local one; optional extra mmg-toolkit[dask])")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="with --backend dask: the address of a running dask scheduler (tcp://host:8786); "
                        "default a local cluster of --jobs workers")
    p.add_argument("--jobs", type=_whole(1, "--jobs"), default=None,
                   help="local workers (default: every core this process may use)")


def check_backend_options(args) -> None:
    """Refuse, before any work, ``--scheduler`` without ``--backend dask`` and dask without its extra."""
    from mmg.errors import InputError

    if args.backend != "dask" and getattr(args, "scheduler", None):
        raise InputError("--scheduler", args.scheduler, "needs --backend dask")
    if args.backend == "dask":
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise InputError("--backend", "dask", "needs the optional extra: pip install 'mmg-toolkit[dask]'") from None


class backend_client:
    """Context manager: the ``distributed.Client`` of ``args.backend == "dask"`` (``args.scheduler``'s
    cluster, or a local one of ``args.jobs`` workers that it closes on exit); None otherwise.  A missing
    extra or an unreachable scheduler: one line naming the option."""

    def __init__(self, args):
        self.args, self.client, self.cluster = args, None, None

    def __enter__(self):
        from mmg.errors import InputError

        a = self.args
        check_backend_options(a)
        if a.backend != "dask":
            return None
        from distributed import Client, LocalCluster
        from ..files.output import children_ignore_sigint

        with children_ignore_sigint():      # a terminal's Ctrl-C reaches this process only, which closes them
            if a.scheduler:
                try:
                    self.client = Client(a.scheduler, timeout="10s")
                except (OSError, TimeoutError) as e:
                    raise InputError("--scheduler", a.scheduler, f"no dask scheduler answers there ({e})") from None
            else:
                from ..files.sweep import default_jobs

                self.cluster = LocalCluster(n_workers=a.jobs or default_jobs(), processes=True, threads_per_worker=1,
                                            dashboard_address=":0")
                self.client = Client(self.cluster)
        return self.client

    def __exit__(self, *exc):
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()
        return False
