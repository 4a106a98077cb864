"""Every number the CLI prints, before and after a change of the code: the same, or where not.

Checks out two git revisions as detached worktrees in a temporary folder (``git worktree add
--detach``; ``--after`` defaults to this working tree as it is, uncommitted edits included), runs the
same ``mmg`` commands in each (``python -m trials.cli ...`` with ``PYTHONPATH`` and the working
folder set to the tree, the import checked to resolve there) and compares every number of their
console output (stdout and stderr) and of the files they write (JSON and YAML walked value by
value, Markdown and CSV read as text):

* ``mmg diagnose --ship esso_osaka`` on each log of the development set
  (``../shared/data/diagnose-dev/data/dev_*.csv``) alone, and once on two logs together (``--jobs``:
  the joint diagnosis and each log's own, JSON ``runs``);
* ``mmg identify --ship esso_osaka_3m`` on four real records (FRT-DS-ESSO, ``$MMG_FRT_DATA`` or
  ``../shared/data/frt-ds-esso``), then ``mmg predict`` of the identified ship on two other records
  (with ``--samples`` bands) and ``mmg imo`` of it (at 0.49 m/s, with ``--samples``);
* ``mmg simulate`` of bundled trials and ``mmg metrics`` of each simulated log.

``--quick``: 4 development logs, 3 trials, 8 IMO samples; default: all 32 logs, every bundled trial
of the before tree (``configs/trials/*.yaml``), 16 IMO samples.

A number is a token such as ``-1.5e-3`` standing apart from words (the ``01`` of ``dev_01`` and the
``0`` of ``w_P0`` are names, not numbers); a JSON or YAML number is a value (booleans count as 0 / 1);
numbers inside JSON or YAML strings are read as in text.  Left out of the comparison, and only these
(:data:`MASKS`, :data:`TIMING_KEYS`): wall-clock timings (``(12 s)`` progress stamps, ``in 131 s``,
a diagnosis' own ``seconds``), paths (a token holding ``/`` and a letter: the two trees' folders
differ) and dates (``2026-12-04``, ``14-Sep-2020``, ``13:51:45``).  Equal means exactly equal unless
``--rtol`` is given (``|a - b| <= rtol * max(|a|, |b|)``); NaN equals NaN.

Every command runs with ``PYTHONHASHSEED=0`` and one BLAS / OpenMP thread, in both trees alike, so
that a difference is the code's and not the run's.

    python bench/before_after.py --before main [--after REV] [--quick] [--only COMMAND ...] [--jobs 2]
        [--rtol 0] [--json bench/out/before_after.json] [--keep]

Prints a table (command | outputs compared | numbers compared | differing, with the first
differences) and writes the same as JSON.  Exit 0 when every number is equal and every command
succeeded in both trees, 1 otherwise, 2 on bad arguments or missing data.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data"

TRAIN = ("turning/turn_14-Sep-2020_13_51_45.csv", "turning/turn_14-Sep-2020_13_39_32.csv",
         "zigzag/zigzag_31-Jul-2020_13_14_21.csv", "zigzag/zigzag_31-Jul-2020_13_04_24.csv")
"""The real records ``mmg identify`` is trained on (relative to the FRT-DS-ESSO folder)."""
TEST = ("turning/turn_14-Sep-2020_14_16_04.csv", "zigzag/zigzag_31-Jul-2020_13_22_52.csv")
"""The other real records the identified ship is predicted on."""
QUICK_TRIALS = ("st35", "zz20", "stype120")
"""Bundled trials of ``--quick`` (a turn, a zigzag, an S-type)."""

MASKS = (
    ("timing", re.compile(r"\(\d+(?:\.\d+)?\s?(?:ms|s|min)\)")),
    ("timing", re.compile(r"\bin \d+(?:\.\d+)?\s?(?:ms|s|min)\b")),
    ("date", re.compile(r"\b\d{4}-\d{2}-\d{2}(?:[T ]\d{2}:\d{2}(?::\d{2}(?:\.\d+)?)?)?")),
    ("date", re.compile(r"\b\d{1,2}-[A-Z][a-z]{2}-\d{4}")),
    ("date", re.compile(r"\b\d{2}:\d{2}:\d{2}\b")),
    ("path", re.compile(r"[^\s'\"`(),;\[\]{}<>]*/[^\s'\"`(),;\[\]{}<>]*")),
)
"""(kind, pattern) of the text left out before numbers are read; a ``path`` match is left out only
when it holds a letter and a digit (``1/2``, ``m/s`` stay)."""
TIMING_KEYS = re.compile(r"^(?:/runs/\d+)?/seconds$")
"""JSON / YAML paths of wall-clock timings (a diagnosis' ``seconds``, also per run)."""
NUMBER = re.compile(r"(?<![\w.])-?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])|(?<![\w.])-?(?:nan|inf)(?![\w.])")
"""A number standing apart from words: ``12``, ``-0.5``, ``2.34e+12``, ``nan``, ``-inf``."""
TEXT_SUFFIXES = {".md", ".csv", ".txt"}
TREE_SUFFIXES = {".json", ".yaml", ".yml"}


# --- reading numbers -------------------------------------------------------------------------------

def mask(text: str) -> str:
    """``text`` with timings, dates and paths (:data:`MASKS`) replaced by a blank."""
    for kind, pat in MASKS:
        if kind == "path":
            text = pat.sub(lambda m: " " if re.search(r"[A-Za-z]", m.group()) and re.search(r"\d", m.group())
                           else m.group(), text)
        else:
            text = pat.sub(" ", text)
    return text


def text_numbers(text: str, where: str = "") -> list:
    """``[(where, value)]`` of every number in ``text`` after :func:`mask`, ``where`` as ``"{where}line N"``."""
    out = []
    for n, line in enumerate(text.splitlines(), 1):
        out += [(f"{where}line {n}", float(m.group())) for m in NUMBER.finditer(mask(line))]
    return out


def tree_numbers(value, path: str = "") -> list:
    """``[(path, value)]`` of every number of a parsed JSON / YAML value, walked depth first; strings
    read by :func:`text_numbers`; timing keys (:data:`TIMING_KEYS`) left out."""
    if TIMING_KEYS.match(path):
        return []
    if isinstance(value, dict):
        return [x for k, v in value.items() for x in tree_numbers(v, f"{path}/{k}")]
    if isinstance(value, (list, tuple)):
        return [x for i, v in enumerate(value) for x in tree_numbers(v, f"{path}/{i}")]
    if isinstance(value, bool):
        return [(path, float(value))]
    if isinstance(value, (int, float)):
        return [(path, float(value))]
    if isinstance(value, str):
        return text_numbers(value, f"{path} ")
    return []


def file_numbers(path: Path) -> tuple | None:
    """``(numbers, keyed)`` of one output file: JSON / YAML walked (``keyed``: by path), other text
    read line by line (also a JSON / YAML file that does not parse); None for a kind not read (a figure)."""
    suffix = path.suffix.lower()
    if suffix in TREE_SUFFIXES:
        text = path.read_text()
        try:
            return tree_numbers(json.loads(text) if suffix == ".json" else yaml.safe_load(text)), True
        except (ValueError, yaml.YAMLError):
            return text_numbers(text), False
    if suffix in TEXT_SUFFIXES:
        return text_numbers(path.read_text()), False
    return None


# --- comparing -------------------------------------------------------------------------------------

def equal(a: float, b: float, rtol: float = 0.0) -> bool:
    """``a`` and ``b`` equal: exactly (``rtol`` 0) or within ``rtol`` of the larger; NaN equals NaN."""
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if a == b:
        return True
    return rtol > 0 and math.isfinite(a) and math.isfinite(b) and abs(a - b) <= rtol * max(abs(a), abs(b))


def compare_numbers(before: list, after: list, rtol: float = 0.0, keyed: bool = False) -> tuple:
    """``(compared, differences)`` of two ``[(where, value)]`` lists.

    ``keyed`` (JSON / YAML): matched by path, a path on one side only is a difference; else (text)
    matched by position, and a different count is one more difference naming both counts.
    Each difference is ``(where, before, after)`` (None for a number absent on that side).
    """
    diffs = []
    if keyed:
        b, a = _by_key(before), _by_key(after)
        for k in list(b) + [k for k in a if k not in b]:
            x, y = b.get(k), a.get(k)
            if x is None or y is None or not equal(x, y, rtol):
                diffs.append((k, x, y))
        return len(set(b) | set(a)), diffs
    for (w, x), (_, y) in zip(before, after):
        if not equal(x, y, rtol):
            diffs.append((w, x, y))
    if len(before) != len(after):
        diffs.append((f"count {len(before)} before, {len(after)} after", None, None))
    return max(len(before), len(after)), diffs


def _by_key(numbers: list) -> dict:
    """``{where: value}``, a repeated ``where`` (several numbers in one string) told apart by ``#i``."""
    out = {}
    for w, v in numbers:
        k, i = w, 1
        while k in out:
            i += 1
            k = f"{w} #{i}"
        out[k] = v
    return out


# --- running ---------------------------------------------------------------------------------------

@dataclass
class Command:
    """One CLI run: its group (the table's row), its name (its output folder), its arguments after
    ``python -m trials.cli``; ``{out}`` and ``{side}`` in them stand for its output folder and the
    side's root."""
    group: str
    name: str
    args: list
    result: dict = field(default_factory=dict)


def plan(dev: Path, frt: Path, trials: list, quick: bool, jobs: int) -> list:
    """The commands as stages: every command of a stage runs at once (up to ``jobs``), a stage after
    the one before it (``predict`` and ``imo`` read ``identify``'s ship, ``metrics`` the simulated logs)."""
    logs = sorted(dev.glob("dev_*.csv"))[: 4 if quick else None]
    j = str(jobs)
    first = [Command("identify", "identify", ["identify", "--ship", "esso_osaka_3m", "--train",
                                              *[str(frt / r) for r in TRAIN], "--out", "{out}", "--jobs", j])]
    first += [Command("diagnose", f"diagnose_{p.stem}", ["diagnose", "--ship", "esso_osaka", "--json",
                                                         "{out}/diagnosis.json", "--jobs", "1", str(p)]) for p in logs]
    first.append(Command("diagnose", "diagnose_joint", ["diagnose", "--ship", "esso_osaka", "--json",
                                                        "{out}/diagnosis.json", "--jobs", j, *map(str, logs[:2])]))
    first += [Command("simulate", f"simulate_{t}", ["simulate", t, "--out", "{out}"]) for t in trials]
    ship = "{side}/identify/ship.yaml"
    second = [Command("predict", "predict", ["predict", "--ship", ship, "--json", "{out}/predict.json",
                                             "--samples", "10", "--seed", "0", *[str(frt / r) for r in TEST]]),
              Command("imo", "imo", ["imo", ship, "--out", "{out}", "--speed", "0.49 m/s", "--samples",
                                     "8" if quick else "16", "--seed", "0", "--jobs", j])]
    second += [Command("metrics", f"metrics_{t}", ["metrics", f"{{side}}/simulate_{t}/log.csv",
                                                   "--json", "{out}/metrics.json"]) for t in trials]
    return [first, second]


GROUPS = ("diagnose", "identify", "predict", "imo", "simulate", "metrics")
NEEDS = {"predict": "identify", "imo": "identify", "metrics": "simulate"}
"""The table's rows, and the row whose outputs another reads."""


def only(stages: list, groups) -> list:
    """``stages`` with the commands of ``groups`` (and of the groups they read) alone; all when None."""
    if not groups:
        return stages
    keep = set(groups) | {NEEDS[g] for g in groups if g in NEEDS}
    return [[c for c in s if c.group in keep] for s in stages]


def child_env(tree: Path, frt: Path) -> dict:
    """The environment of every command: the tree first on ``PYTHONPATH``, the data folder named,
    one BLAS / OpenMP thread, a fixed hash seed, no display."""
    env = dict(os.environ, PYTHONPATH=str(tree), MMG_FRT_DATA=str(frt), PYTHONHASHSEED="0", MPLBACKEND="Agg",
               OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1", NUMBA_NUM_THREADS="1")
    return env


def check_import(tree: Path, env: dict) -> None:
    """Stop (exit 2) unless ``mmg``, ``ekf`` and ``trials`` import from ``tree`` with ``env``."""
    code = "import mmg, ekf, trials.cli; print(mmg.__file__); print(ekf.__file__); print(trials.cli.__file__)"
    out = subprocess.run([sys.executable, "-c", code], cwd=tree, env=env, capture_output=True, text=True)
    files = out.stdout.split()
    if out.returncode != 0 or len(files) != 3 or not all(Path(f).resolve().is_relative_to(tree.resolve()) for f in files):
        stop(f"the package does not import from {tree}: {out.stdout.strip()} {out.stderr.strip()[-300:]}")


def run_one(cmd: Command, tree: Path, side: Path, env: dict) -> None:
    """Run ``cmd`` in ``tree``, its outputs under ``side/<name>``; fills ``cmd.result``."""
    out = side / cmd.name
    out.mkdir(parents=True, exist_ok=True)
    args = [a.replace("{out}", str(out)).replace("{side}", str(side)) for a in cmd.args]
    t0 = time.perf_counter()
    p = subprocess.run(["nice", "-n", "5", sys.executable, "-m", "trials.cli", *args], cwd=tree, env=env,
                       capture_output=True, text=True)
    (out / "stdout.txt").write_text(p.stdout)
    (out / "stderr.txt").write_text(p.stderr)
    cmd.result = {"exit": p.returncode, "seconds": round(time.perf_counter() - t0, 1), "folder": str(out)}


def run_side(stages: list, tree: Path, side: Path, frt: Path, jobs: int) -> float:
    """Run every stage's commands in ``tree`` (``jobs`` at a time); the wall time in s."""
    env = child_env(tree, frt)
    check_import(tree, env)
    t0 = time.perf_counter()
    for stage in stages:
        with ThreadPoolExecutor(max_workers=jobs) as pool:
            list(pool.map(lambda c: run_one(c, tree, side, env), stage))
    return time.perf_counter() - t0


def output_numbers(folder: Path) -> dict:
    """``{relative file name: (numbers, keyed)}`` of every readable output in ``folder``
    (:func:`file_numbers`)."""
    out = {}
    for f in sorted(p for p in folder.rglob("*") if p.is_file()):
        read = file_numbers(f)
        if read is not None:
            out[str(f.relative_to(folder))] = read
    return out


def compare_command(before: Command, after: Command, rtol: float) -> dict:
    """One command's outputs compared: outputs, numbers, differences (the exit status one of them)."""
    b, a = output_numbers(Path(before.result["folder"])), output_numbers(Path(after.result["folder"]))
    diffs, compared = [], 0
    if before.result["exit"] != after.result["exit"]:
        diffs.append((f"{before.name}: exit status", float(before.result["exit"]), float(after.result["exit"])))
    for name in sorted(set(b) | set(a)):
        if name not in b or name not in a:
            diffs.append((f"{before.name}/{name}: only {'after' if name in a else 'before'}", None, None))
            continue
        n, d = compare_numbers(b[name][0], a[name][0], rtol, keyed=b[name][1] and a[name][1])
        compared += n
        diffs += [(f"{before.name}/{name} {w}", x, y) for w, x, y in d]
    return {"outputs": len(set(b) | set(a)), "numbers": compared, "differences": diffs,
            "exit": [before.result["exit"], after.result["exit"]],
            "seconds": [before.result["seconds"], after.result["seconds"]]}


# --- the table -------------------------------------------------------------------------------------

def summarise(stages_b: list, stages_a: list, rtol: float, show: int = 3) -> dict:
    """Per group (the table's rows): commands, outputs, numbers compared, differing, the first ``show``
    differences, exit statuses and each side's command seconds summed."""
    rows = {}
    for cb, ca in zip([c for s in stages_b for c in s], [c for s in stages_a for c in s]):
        r = compare_command(cb, ca, rtol)
        row = rows.setdefault(cb.group, {"commands": 0, "outputs": 0, "numbers": 0, "differing": 0,
                                         "first_differences": [], "failed": [], "seconds": [0.0, 0.0]})
        row["commands"] += 1
        row["outputs"] += r["outputs"]
        row["numbers"] += r["numbers"]
        row["differing"] += len(r["differences"])
        row["first_differences"] += [list(d) for d in r["differences"][: max(0, show - len(row["first_differences"]))]]
        row["failed"] += [f"{cb.name}: exit {r['exit']}"] if any(r["exit"]) else []
        row["seconds"] = [round(row["seconds"][i] + r["seconds"][i], 1) for i in range(2)]
    return rows


def print_table(rows: dict) -> None:
    """The table: command | outputs compared | numbers compared | differing, then the first differences."""
    print(f"{'command':<13} {'runs':>5} {'outputs compared':>17} {'numbers compared':>17} {'differing':>10}")
    for g, r in rows.items():
        print(f"{'mmg ' + g:<13} {r['commands']:>5} {r['outputs']:>17} {r['numbers']:>17} {r['differing']:>10}")
    print(f"{'all':<13} {sum(r['commands'] for r in rows.values()):>5} {sum(r['outputs'] for r in rows.values()):>17} "
          f"{sum(r['numbers'] for r in rows.values()):>17} {sum(r['differing'] for r in rows.values()):>10}")
    for g, r in rows.items():
        for w, x, y in r["first_differences"]:
            print(f"  {g}: {w}: before {x}, after {y}")
        for f in r["failed"]:
            print(f"  {g}: a command failed: {f} (before, after); its stderr.txt says why")


def stop(message: str) -> None:
    """One line on stderr, exit 2."""
    print(f"error: {message}", file=sys.stderr)
    sys.exit(2)


# --- git -------------------------------------------------------------------------------------------

def rev_hash(rev: str) -> str:
    """The commit ``rev`` names (exit 2 when none)."""
    p = subprocess.run(["git", "rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}"], cwd=REPO,
                       capture_output=True, text=True)
    if p.returncode != 0:
        stop(f"--before/--after: no commit named {rev!r} in {REPO}")
    return p.stdout.strip()


def add_worktree(rev: str, where: Path) -> Path:
    """A detached worktree of ``rev`` at ``where``."""
    subprocess.run(["git", "worktree", "add", "--detach", "--quiet", str(where), rev], cwd=REPO, check=True)
    return where


def remove_worktree(where: Path) -> None:
    subprocess.run(["git", "worktree", "remove", "--force", str(where)], cwd=REPO, capture_output=True)


# --- main ------------------------------------------------------------------------------------------

def parse_args(argv=None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", required=True, help="git revision of the code before (e.g. main)")
    ap.add_argument("--after", default=None, help="git revision after (default: this working tree as it is)")
    ap.add_argument("--quick", action="store_true", help="4 development logs, 3 trials, 8 IMO samples")
    ap.add_argument("--jobs", type=int, default=2, help="commands run at once, and --jobs of those that take it")
    ap.add_argument("--only", nargs="+", choices=GROUPS, metavar="COMMAND",
                    help=f"run these commands alone ({', '.join(GROUPS)}; predict and imo bring identify, "
                         "metrics simulate)")
    ap.add_argument("--rtol", type=float, default=0.0, help="relative tolerance (default 0: exactly equal)")
    ap.add_argument("--dev", type=Path, default=DATA / "diagnose-dev" / "data", help="development-set folder")
    ap.add_argument("--frt", type=Path, default=Path(os.environ.get("MMG_FRT_DATA") or DATA / "frt-ds-esso"),
                    help="FRT-DS-ESSO folder (default $MMG_FRT_DATA, else ../shared/data/frt-ds-esso)")
    ap.add_argument("--json", type=Path, default=REPO / "bench" / "out" / "before_after.json", help="summary JSON")
    ap.add_argument("--keep", action="store_true", help="keep the temporary worktrees and outputs (path printed)")
    args = ap.parse_args(argv)
    for name in ("dev", "frt"):
        if not getattr(args, name).is_dir():
            ap.exit(2, f"error: --{name}: folder {getattr(args, name)} not found\n")
    if args.jobs < 1 or args.rtol < 0:
        ap.exit(2, "error: --jobs must be at least 1 and --rtol not negative\n")
    return args


def main(argv=None) -> int:
    args = parse_args(argv)
    before = rev_hash(args.before)
    after = rev_hash(args.after) if args.after else None
    tmp = Path(tempfile.mkdtemp(prefix="before_after_"))
    trees = []
    try:
        tree_b = add_worktree(before, tmp / "tree_before")
        trees.append(tree_b)
        tree_a = add_worktree(after, tmp / "tree_after") if after else REPO
        if after:
            trees.append(tree_a)
        trials = list(QUICK_TRIALS) if args.quick else sorted(p.stem for p in (tree_b / "configs" / "trials").glob("*.yaml"))
        stages = {s: only(plan(args.dev.resolve(), args.frt.resolve(), trials, args.quick, args.jobs), args.only)
                  for s in ("before", "after")}
        wall = {}
        for side, tree in (("before", tree_b), ("after", tree_a)):
            print(f"{side}: {args.before if side == 'before' else args.after or 'working tree'} in {tree}", flush=True)
            wall[side] = round(run_side(stages[side], tree, tmp / side, args.frt.resolve(), args.jobs), 1)
            print(f"{side}: {sum(len(s) for s in stages[side])} commands in {wall[side]} s", flush=True)
        rows = summarise(stages["before"], stages["after"], args.rtol)
        print_table(rows)
        summary = {"before": {"rev": args.before, "commit": before},
                   "after": {"rev": args.after or "working tree", "commit": after or rev_hash("HEAD"),
                             "uncommitted_edits_included": after is None},
                   "mode": "quick" if args.quick else "full", "only": args.only, "rtol": args.rtol, "jobs": args.jobs,
                   "wall_seconds": wall, "rows": rows,
                   "equal": all(r["differing"] == 0 for r in rows.values()),
                   "left_out": {"masks": [[k, p.pattern] for k, p in MASKS], "json_keys": TIMING_KEYS.pattern}}
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(summary, indent=1) + "\n")
        failed = [f for r in rows.values() for f in r["failed"]]
        print(f"{'all numbers equal' if summary['equal'] else 'numbers differ'}"
              f"{f'; {len(failed)} command(s) failed' if failed else ''}; wrote {args.json}")
        return 0 if summary["equal"] and not failed else 1
    finally:
        if args.keep:
            print(f"kept {tmp}")
        else:
            for t in trees:
                remove_worktree(t)
            shutil.rmtree(tmp, ignore_errors=True)
            subprocess.run(["git", "worktree", "prune"], cwd=REPO, capture_output=True)


if __name__ == "__main__":
    sys.exit(main())
