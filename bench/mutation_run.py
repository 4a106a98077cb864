#!/usr/bin/env python
"""Mutation run: does the fast test suite catch wrong physics?

For each mutation the script copies the repository's files (``git ls-files``
plus untracked, not-ignored files, as they are on disk when the run starts)
into a temporary directory, applies *one* change there, and runs the fast
tests in that copy::

    python -m pytest -q -m "not slow" -x -p no:cacheprovider [PATHS]

with ``PYTHONPATH`` pointing at the copy, so the mutated copy is imported and
not the editable install.  That is checked, not assumed: a small pytest plugin
(written to the temp dir, loaded with ``-p``) records the file of every
``mmg``/``trials``/``ekf``/``tests`` module loaded in the test process, and the
run is reported as an error if any of them comes from outside the copy.  The
unmutated copy is run first; tests that already fail there are deselected in
the mutated runs (and listed), so "caught" means "a test that passes on the
original fails on the mutant".

Mutations (``--list`` prints them):

* ``code hull_primed: flip <coef>`` -- the sign of one coefficient's contribution where
  the hull terms enter the force (``mmg/model.py`` ``hull_primed``: the product for that
  axis and term is negated), for each of the 16 Esso Osaka coefficients;
* ``code term_value: flip '<term>'`` -- one Kijima term's value (``mmg/terms.py``), which
  flips the Y and N coefficients of that term together;
* ``config: flip <coef>`` -- the sign of one coefficient in ``configs/ships/esso_osaka.yaml``;
* T_E doubled (config; packing; the linear branch of eq. 20), engine power x 1.05
  (config ``watts_per_hp``; config ``SHP_0``; ``mmg.equilibrium.engine_power``; packing);
* ``extra: ...`` -- a few other physics slips (rudder, propeller, wake, equations of motion,
  shaft inertia units), for information.

Each copy starts without numba caches (they live in ``__pycache__``, which is not
copied): numba does not invalidate a cached function when a function it calls
changed in another file, so reusing caches could hide a mutation of
``mmg/terms.py``.  Two mutations run at once by default (``--jobs``).

Examples::

    python bench/mutation_run.py --tests tests/test_physics_reference.py tests/test_steering_engine.py tests/test_physics.py
    python bench/mutation_run.py                       # the whole fast suite
    python bench/mutation_run.py --only "config: T_E x2"
    python bench/mutation_run.py --all                 # no -x: which tests, new and old, fail for each mutation
    python bench/mutation_run.py --list
"""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import fnmatch
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import yaml

REPO = Path(__file__).resolve().parents[1]
SHIP = "configs/ships/esso_osaka.yaml"
MODEL = "mmg/model.py"
TERMS = "mmg/terms.py"
EQUILIBRIUM = "mmg/equilibrium.py"
PACKAGES = ("mmg", "trials", "ekf", "tests")

GUARD = textwrap.dedent('''
    """pytest plugin of bench/mutation_run.py: records where the project's modules were imported from."""
    import json, os, sys

    import pytest


    def _files():
        out = {}
        for name, mod in list(sys.modules.items()):
            if name.split(".")[0] in %r:
                f = getattr(mod, "__file__", None)
                if f:
                    out[name] = os.path.realpath(f)
        return out


    def pytest_sessionstart(session):
        import mmg.model  # noqa: F401  (the physics under test must come from the copy)

        root = os.path.realpath(os.environ["MUTATION_GUARD_ROOT"])
        f = os.path.realpath(sys.modules["mmg.model"].__file__)
        if not f.startswith(root + os.sep):
            pytest.exit("mutation_guard: mmg.model imported from %%s, not from the copy %%s" %% (f, root), returncode=97)


    def pytest_sessionfinish(session, exitstatus):
        with open(os.environ["MUTATION_GUARD_OUT"], "w") as fh:
            json.dump(_files(), fh)
''' % (PACKAGES,))


# --------------------------------------------------------------------------- mutations


@dataclass(frozen=True)
class Mutation:
    name: str
    path: str                            # file in the repo, relative
    apply: Callable[[str], str]          # original text -> mutated text (raises if the pattern is not there once)
    group: str = ""


class PatternError(RuntimeError):
    pass


def replace_once(old: str, new: str) -> Callable[[str], str]:
    def f(text: str) -> str:
        k = text.count(old)
        if k != 1:
            raise PatternError(f"expected {old!r} once, found it {k} times")
        return text.replace(old, new)

    return f


def regex_once(pattern: str, repl: Callable[[re.Match], str]) -> Callable[[str], str]:
    rx = re.compile(pattern, re.M)

    def f(text: str) -> str:
        hits = list(rx.finditer(text))
        if len(hits) != 1:
            raise PatternError(f"expected /{pattern}/ once, found it {len(hits)} times")
        m = hits[0]
        return text[: m.start()] + repl(m) + text[m.end():]

    return f


def flip_term_return(tid: int) -> Callable[[str], str]:
    """In term_value: the first ``return EXPR`` after ``if tid == <tid>:`` becomes ``return -(EXPR)``."""
    return regex_once(rf"(^\s*if tid == {tid}:\n(?:\s*[^\n]*\n)*?\s*return )([^\n]+)$",
                      lambda m: f"{m.group(1)}-({m.group(2)})")


def flip_config_coef(name: str) -> Callable[[str], str]:
    return regex_once(rf'^(\s*{re.escape(name)}:\s*\{{\s*term:\s*"[^"]*",\s*value:\s*)([-+0-9.eE]+)',
                      lambda m: m.group(1) + repr(-float(m.group(2))))


def scale_config_list(key: str, factor: float) -> Callable[[str], str]:
    def repl(m):
        vals = [float(s) * factor for s in m.group(2).split(",")]
        return m.group(1) + "[" + ", ".join(repr(v) for v in vals) + "]"

    return regex_once(rf"^(\s*{re.escape(key)}:\s*)\[([^\]]*)\]", repl)


def scale_config_scalar(key: str, factor: float, unit: str = "") -> Callable[[str], str]:
    u = rf"\s*{re.escape(unit)}" if unit else ""
    return regex_once(rf"^(\s*{re.escape(key)}:\s*)([-+0-9.eE]+)(?={u})",
                      lambda m: m.group(1) + repr(float(m.group(2)) * factor))


def mutations(snapshot: Path) -> list[Mutation]:
    ship = yaml.safe_load((snapshot / SHIP).read_text())
    coefs = list(ship["hull"]["coefficients"])           # the order HullModel (and hull_coef) keeps
    terms = {c["term"] for c in ship["hull"]["coefficients"].values()}
    term_ids = {"1": 0, "beta": 1, "r": 2, "beta|beta|": 3, "r|r|": 4, "beta^2*r": 5, "beta*r^2": 6,
                "r*sin(beta)": 7, "cos(beta)^2": 8}
    out: list[Mutation] = []
    hull_line = "        val = hull_coef[i] * term_value(hull_term[i], beta, vp, rp)"
    axes = {"X": 0, "Y": 1, "N": 2}
    for name, c in ship["hull"]["coefficients"].items():
        # the contribution of (axis, term): exactly this coefficient for the Esso Osaka; another ship is
        # touched only if it has the same term on the same axis (KVLCC2: Y_r, N_r)
        a, tid = axes[name.split("_", 1)[0]], term_ids[c["term"]]
        out.append(Mutation(f"code hull_primed: flip {name}", MODEL, replace_once(
            hull_line, f"        val = (-1.0 if (hull_axis[i] == {a} and hull_term[i] == {tid}) else 1.0) "
                       "* hull_coef[i] * term_value(hull_term[i], beta, vp, rp)"),
            "hull (code, one coefficient)"))
    for term, tid in term_ids.items():
        if term in terms:
            out.append(Mutation(f"code term_value: flip '{term}'", TERMS, flip_term_return(tid), "hull (code, one term)"))
    for name in coefs:
        out.append(Mutation(f"config: flip {name}", SHIP, flip_config_coef(name), "hull (config)"))
    out += [
        Mutation("config: T_E x2", SHIP, scale_config_scalar("T_E", 2.0, "s"), "steering"),
        Mutation("code pack: T_E x2", MODEL, replace_once(
            "p[P_TE], p[P_RATE], p[P_DMAX] = st.T_E, st.rate_max, st.delta_max",
            "p[P_TE], p[P_RATE], p[P_DMAX] = 2.0 * st.T_E, st.rate_max, st.delta_max"), "steering"),
        Mutation("code steering_rate: T_E x2 in linear branch", MODEL, replace_once(
            "        return err / p[P_TE]", "        return err / (2.0 * p[P_TE])"), "steering"),
        Mutation("config: watts_per_hp x1.05", SHIP, scale_config_scalar("watts_per_hp", 1.05), "engine"),
        Mutation("config: SHP_0 x1.05", SHIP, scale_config_list("SHP_0", 1.05), "engine"),
        Mutation("code engine_power: x1.05", EQUILIBRIUM, replace_once(
            "    return ship.engine.watts_per_hp * float(", "    return 1.05 * ship.engine.watts_per_hp * float("),
            "engine"),
        Mutation("code pack: P_0 x1.05", MODEL, replace_once(
            "    p[P_POWER] = engine_power_W", "    p[P_POWER] = 1.05 * engine_power_W"), "engine"),
    ]
    extra = [
        ("drift angle sign", MODEL, "    beta = np.arctan(-v / u)", "    beta = np.arctan(v / u)"),
        ("wake exp(+4 beta_P^2)", MODEL, "np.exp(-p[P_CWAKE] * bp * bp)", "np.exp(p[P_CWAKE] * bp * bp)"),
        ("beta_P = beta + x_P' r'", MODEL, "    bp = beta - p[P_XP] * rp", "    bp = beta + p[P_XP] * rp"),
        ("thrust (1 + t_P)", MODEL, "    XP = (1.0 - tP) *", "    XP = (1.0 + tP) *"),
        ("slipstream 8 K_T -> 4 K_T", MODEL, "np.sqrt(1.0 + 8.0 * KT", "np.sqrt(1.0 + 4.0 * KT"),
        ("rudder v_R sign", MODEL, "    vR = U * g * bR", "    vR = -U * g * bR"),
        ("rudder X_R (1 + t_R)", MODEL, "    XR = -(1.0 - p[P_TR])", "    XR = -(1.0 + p[P_TR])"),
        ("rudder N_R x_R - a_H x_H", MODEL, "    NR = -(p[P_XR] + p[P_AH] * p[P_XH])", "    NR = -(p[P_XR] - p[P_AH] * p[P_XH])"),
        ("EoM surge -(m+m_y) v r", MODEL, "    out[U_] = (X + (m + my) * v * r", "    out[U_] = (X - (m + my) * v * r"),
        ("EoM sway (m+m_y) u r", MODEL, "    b1 = Y - (m + mx) * u * r", "    b1 = Y - (m + my) * u * r"),
        ("EoM x_G coupling sign", MODEL, "    a12 = xG * m", "    a12 = -xG * m"),
        ("shaft inertia in kgf m s^2 (x9.81)", MODEL, "    p[P_SHAFT_I] = en.shaft_inertia_coefficient * pr.D**5",
         "    p[P_SHAFT_I] = 9.81 * en.shaft_inertia_coefficient * pr.D**5"),
    ]
    out += [Mutation(f"extra: {n}", path, replace_once(a, b), "extra") for n, path, a, b in extra]
    out.append(Mutation("extra: config rate_max x1.1", SHIP, scale_config_scalar("rate_max", 1.1, "deg/s"), "extra"))
    return out


# --------------------------------------------------------------------------- running


def repo_files() -> list[str]:
    """Tracked and untracked-not-ignored files that exist on disk now."""
    out = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                         cwd=REPO, check=True, capture_output=True).stdout.decode()
    files = sorted({f for f in out.split("\0") if f})
    return [f for f in files if (REPO / f).is_file()]


def snapshot(dest: Path) -> int:
    files = repo_files()
    for f in files:
        target = dest / f
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(REPO / f, target)
    return len(files)


_CHILDREN: set = set()
_STOP = threading.Event()
_CHILDREN_LOCK = threading.Lock()


def _run(cmd, cwd, env, timeout) -> subprocess.CompletedProcess:
    """subprocess.run that remembers the child (its own process group) so a SIGTERM of this script ends it."""
    if _STOP.is_set():
        raise RuntimeError("stopped by SIGTERM")
    proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    with _CHILDREN_LOCK:
        _CHILDREN.add(proc)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        _kill(proc)
        proc.communicate()
        raise
    finally:
        with _CHILDREN_LOCK:
            _CHILDREN.discard(proc)
    return subprocess.CompletedProcess(cmd, proc.returncode, out, err)


def _kill(proc) -> None:
    try:
        os.killpg(proc.pid, signal.SIGTERM)     # the pytest run and its workers (joblib, dask), by group id
    except ProcessLookupError:
        pass


def _on_sigterm(signum, frame):
    _STOP.set()
    with _CHILDREN_LOCK:
        for proc in list(_CHILDREN):
            _kill(proc)
    raise SystemExit(128 + signum)               # runs the finally blocks: temp copies are removed


@dataclass
class Outcome:
    name: str
    caught: str             # "yes", "no", "error", "n/a"
    first_failure: str
    seconds: float
    detail: str = ""
    failures: tuple = ()


_FAIL = re.compile(r"^(FAILED|ERROR) (.+?)( - .*)?$", re.M)   # "FAILED node id - reason" (ids may hold spaces)


def run_copy(base: Path, pristine: Path, mut: Mutation | None, tests: list[str], deselect: list[str],
             timeout: float, keep: bool, exitfirst: bool = True, ignore: tuple = ()) -> tuple[Outcome, list[str]]:
    name = mut.name if mut else "(none: original code)"
    if _STOP.is_set():
        return Outcome(name, "error", "", 0.0, "stopped by SIGTERM"), []
    t0 = time.time()
    work = Path(tempfile.mkdtemp(prefix="m-", dir=base))
    main = work / "main"
    shutil.copytree(pristine, main, symlinks=True)
    shared = REPO.parent / "shared"
    if shared.is_dir():                 # tests look for ../shared/data next to the repo: link, never copy
        (work / "shared").symlink_to(shared)
    try:
        if mut is not None:
            f = main / mut.path
            old = f.read_text()
            try:
                new = mut.apply(old)
            except PatternError as e:
                return Outcome(name, "n/a", "", 0.0, f"mutation not applicable: {e}"), []
            assert new != old
            if mut.path.endswith((".yaml", ".yml")):
                yaml.safe_load(new)     # still a valid config
            f.write_text(new)
        env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST_", "MUTATION_GUARD"))}
        env.update(PYTHONPATH=os.pathsep.join([str(main), str(base / "guard")]),
                   MUTATION_GUARD_ROOT=str(main), MUTATION_GUARD_OUT=str(work / "imports.json"),
                   OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1", NUMBA_NUM_THREADS="1",
                   MPLBACKEND="Agg", COLUMNS="400")    # wide terminal: pytest's one-line failure reasons untruncated
        env.pop("NUMBA_CACHE_DIR", None)
        cmd = [sys.executable, "-m", "pytest", "-q", "-m", "not slow"] + (["-x"] if exitfirst else []) + [
            "-p", "no:cacheprovider", "-p", "mutation_guard", "-rfE", f"--junitxml={work / 'junit.xml'}"]
        for d in deselect:
            cmd += ["--deselect", d]
        cmd += [f"--ignore={p}" for p in ignore]
        cmd += tests
        try:
            proc = _run(cmd, main, env, timeout)
        except subprocess.TimeoutExpired:
            return Outcome(name, "yes" if mut else "error", f"(timeout after {timeout:.0f} s)", time.time() - t0), []
        log = proc.stdout + proc.stderr
        if keep:
            (work / "pytest.log").write_text(" ".join(cmd) + "\n\n" + log)
        if proc.returncode == 97 or not (work / "imports.json").exists():
            return Outcome(name, "error", "", time.time() - t0, "import check failed:\n" + log[-3000:]), []
        leaks = {m: p for m, p in json.loads((work / "imports.json").read_text()).items()
                 if not p.startswith(os.path.realpath(main) + os.sep)}
        if leaks:
            return Outcome(name, "error", "", time.time() - t0, f"modules imported from outside the copy: {leaks}"), []
        hits = list(_FAIL.finditer(proc.stdout))
        reasons = {m.group(2): (m.group(3) or "")[3:][:300] for m in hits}   # pytest's one-line reasons
        # failures in the order the tests ran (the -r summary lists failures before setup errors)
        failures = _junit_failures(work / "junit.xml") or [m.group(2) for m in hits]
        why = reasons.get(failures[0], "") if failures else ""
        secs = time.time() - t0
        if proc.returncode == 0:
            return Outcome(name, "no", "", secs), []
        if proc.returncode == 1 and failures:
            return Outcome(name, "yes", failures[0], secs, why, tuple(failures)), failures
        tail = "\n".join(log.strip().splitlines()[-15:])
        if mut is not None and failures:
            return Outcome(name, "yes", failures[0], secs, f"pytest exit {proc.returncode}: {why}",
                           tuple(failures)), failures
        return Outcome(name, "error", "", secs, f"pytest exit {proc.returncode}:\n{tail}"), failures
    finally:
        if not keep:
            shutil.rmtree(work, ignore_errors=True)


NEW_TESTS = ("tests/test_physics_reference.py", "tests/test_steering_engine.py")


def _junit_failures(path: Path) -> list[str]:
    """Node ids of the failed/errored tests in run order, from pytest's JUnit XML."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError):
        return []
    out = []
    for case in root.iter("testcase"):
        if any(child.tag in ("failure", "error") for child in case):
            mod, name = case.get("classname", ""), case.get("name", "")
            parts = mod.split(".")
            # classname is "tests.test_x" or "tests.test_x.TestClass"
            k = next((i for i in range(len(parts), 0, -1) if Path(*parts[:i]).with_suffix(".py").name.startswith("test_")),
                     len(parts))
            node = "/".join(parts[:k]) + ".py" + "".join("::" + c for c in parts[k:]) + "::" + name
            if node not in out:
                out.append(node)
    return out


def table(rows: list[Outcome], counts: bool = False) -> str:
    """The result table; with ``counts`` (runs without -x) also how many tests failed, in the new files and in
    the others (the older suite)."""
    w = max(len("mutation"), *(len(r.name) for r in rows))
    head = f"{'mutation':<{w}} | caught | first failing test"
    rule = f"{'-' * w}-|--------|-------------------"
    if counts:
        head += " | failing: new files / other tests (first other)"
        rule += "-|------------------"
    lines = [head, rule]
    for r in rows:
        first = r.first_failure or (r.detail.splitlines()[0] if r.detail else "")
        line = f"{r.name:<{w}} | {r.caught:<6} | {first}"
        if counts:
            new = [f for f in r.failures if f.startswith(NEW_TESTS)]
            old = [f for f in r.failures if not f.startswith(NEW_TESTS)]
            line += f" | {len(new)} / {len(old)}" + (f" ({old[0]})" if old else "")
        lines.append(line)
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tests", nargs="+", default=[], metavar="PATHS",
                    help="test files/node ids to run (relative to the repo); default: the whole fast suite")
    ap.add_argument("--ignore", action="append", default=[], metavar="PATH",
                    help="leave this test file out (pytest --ignore; repeatable), e.g. a timing-sensitive one")
    ap.add_argument("--only", action="append", default=[], metavar="NAME",
                    help="run only this mutation (exact name or fnmatch pattern; repeatable)")
    ap.add_argument("--list", action="store_true", help="list the mutations and exit")
    ap.add_argument("--diff", action="store_true", help="print each (selected) mutation as a diff and exit")
    ap.add_argument("--jobs", type=int, default=2, help="mutations run at once (default 2)")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds per pytest run")
    ap.add_argument("--all", action="store_true",
                    help="run every test (no -x) and count the failing ones, in the new test files and in the others")
    ap.add_argument("--keep", action="store_true", help="keep the temp copies (with pytest.log)")
    ap.add_argument("--no-baseline", action="store_true", help="skip the run of the unmutated copy")
    ap.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    args = ap.parse_args(argv)
    signal.signal(signal.SIGTERM, _on_sigterm)

    base = Path(tempfile.mkdtemp(prefix="mmg-mutation-"))
    try:
        pristine = base / "pristine"
        nfiles = snapshot(pristine)
        (base / "guard").mkdir()
        (base / "guard" / "mutation_guard.py").write_text(GUARD)
        muts = mutations(pristine)
        if args.list:
            for m in muts:
                print(f"{m.name}    [{m.path}]")
            return 0
        if args.only:
            muts = [m for m in muts if any(m.name == p or fnmatch.fnmatchcase(m.name, p) for p in args.only)]
            if not muts:
                print(f"no mutation matches {args.only}; see --list", file=sys.stderr)
                return 2
        if args.diff:
            import difflib

            for m in muts:
                old = (pristine / m.path).read_text()
                try:
                    new = m.apply(old)
                except PatternError as e:
                    print(f"### {m.name}: NOT APPLICABLE ({e})")
                    continue
                print(f"### {m.name}")
                sys.stdout.writelines(difflib.unified_diff(old.splitlines(True), new.splitlines(True), m.path, m.path, n=0))
            return 0
        print(f"snapshot of {nfiles} files of {REPO} in {pristine}")
        print(f"tests: {' '.join(args.tests) if args.tests else '(whole fast suite)'}"
              + (f" without {', '.join(args.ignore)}" if args.ignore else "") + f"; {len(muts)} mutation(s), "
              f"{args.jobs} at a time", flush=True)

        deselect: list[str] = []
        if not args.no_baseline:
            base_out, base_fail = run_copy(base, pristine, None, args.tests, [], args.timeout, args.keep,
                                           exitfirst=False, ignore=tuple(args.ignore))
            print(f"baseline (unmutated copy): {'passes' if base_out.caught == 'no' else 'FAILS'} "
                  f"in {base_out.seconds:.0f} s", flush=True)
            if base_out.caught == "error":
                print(base_out.detail, file=sys.stderr)
                return 3
            if base_fail:
                deselect = base_fail
                print("  tests failing on the original, deselected in the mutated runs:\n    " + "\n    ".join(base_fail))

        rows: dict[str, Outcome] = {}
        lock = threading.Lock()
        t_start = time.time()
        with cf.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            futs = {pool.submit(run_copy, base, pristine, m, args.tests, deselect, args.timeout, args.keep,
                                not args.all, tuple(args.ignore)): m
                    for m in muts}
            for k, fut in enumerate(cf.as_completed(futs), 1):
                m = futs[fut]
                try:
                    out = fut.result()[0]
                except Exception as e:  # a bug here must not lose the other results
                    out = Outcome(m.name, "error", "", 0.0, repr(e))
                rows[m.name] = out
                with lock:
                    what = out.first_failure or (out.detail.splitlines()[0] if out.detail else "")
                    print(f"[{k}/{len(muts)}] {m.name}: caught={out.caught} {what} ({out.seconds:.0f} s, "
                          f"{time.time() - t_start:.0f} s elapsed)", flush=True)
                    if out.first_failure and out.detail:
                        print(f"      why: {out.detail.splitlines()[0][:200]}", flush=True)
        ordered = [rows[m.name] for m in muts]
        print()
        print(table(ordered, counts=args.all))
        if args.all:
            esc_old = [r.name for r in ordered if r.caught == "yes" and all(f.startswith(NEW_TESTS) for f in r.failures)]
            print(f"\ncaught only by {' and '.join(NEW_TESTS)} ({len(esc_old)}): {', '.join(esc_old) or 'none'}")
        n_yes = sum(r.caught == "yes" for r in ordered)
        print(f"\n{n_yes} of {len(ordered)} mutations caught; "
              f"escaped: {', '.join(r.name for r in ordered if r.caught == 'no') or 'none'}")
        errs = [r for r in ordered if r.caught in ("error", "n/a")]
        for r in errs:
            print(f"\n{r.name}: {r.caught}\n{r.detail}", file=sys.stderr)
        if args.json:
            Path(args.json).write_text(json.dumps([r.__dict__ for r in ordered], indent=1))
        return 0 if not errs else 1
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
        else:
            print(f"temp copies kept in {base}")


if __name__ == "__main__":
    sys.exit(main())
