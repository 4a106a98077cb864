"""Properties of the trial and ship schema: any input gives a result or InputError.

The inputs are the bundled trials and ships mutated at random (random values of random types
at random keys, random unit strings, NaN, inf and huge numbers, deleted keys, extra keys), as
mappings and as YAML text (with duplicated, dropped and garbled lines).  Only validation runs:
nothing is simulated.  A config that is accepted must hold finite numbers only.
"""
import copy
import dataclasses
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings, strategies as st

from mmg.errors import InputError
from mmg.limits import MAX_STEPS
from mmg.resources import bundled
from mmg.ship import Ship, load_ship, parse_yaml, ship_from_dict
from mmg.units import UNITS, to_si
from trials.runs.trial import Trial, load_trial, trial_from_dict

from .conftest import CONFIGS

SETTINGS = dict(deadline=None, database=None, derandomize=False,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much])

TRIALS = {n: yaml.safe_load((CONFIGS / "trials" / f"{n}.yaml").read_text()) for n in bundled("trials")}
SHIPS = {n: yaml.safe_load((CONFIGS / "ships" / f"{n}.yaml").read_text()) for n in bundled("ships")}
TRIAL_DIR = CONFIGS / "trials"

ALL_UNITS = sorted({u for table in UNITS.values() for u in table})

# --------------------------------------------------------------------------- strategies


def _all_keys(node, out):
    if isinstance(node, dict):
        for k, v in node.items():
            out.add(k)
            _all_keys(v, out)
    elif isinstance(node, list):
        for v in node:
            _all_keys(v, out)
    return out


KNOWN_KEYS = sorted(_all_keys(list(TRIALS.values()) + list(SHIPS.values()), set()) |
                    {"execute", "table", "file", "amplitude", "period", "current", "rudder_offset", "bias", "P"},
                    key=str)

numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-10**6, max_value=10**6),
    st.sampled_from([0, -0.0, 1e-300, 5e-324, 1e300, 10**400, -10**400, float("nan"), float("inf"), -float("inf"),
                     2**63, -1, 1e-9, 1e9]),
)
number_text = st.one_of(
    numbers.map(repr),
    st.sampled_from(["1e400", "-1e400", "nan", "inf", ".5", "5.", "1_000", "0x10", "1e", "--1", "+3", "1e-400",
                     "0", "10", "0.1", "３"]),
)
unit_text = st.one_of(st.sampled_from(ALL_UNITS), st.sampled_from(["", "1", "0", "K", "KN", "degs", "m/s^2", "1/m", "°"]),
                      st.text(alphabet="abcdefghkmnrs/^*0123456789 ", max_size=6))
quantities = st.builds(lambda n, sep, u: f"{n}{sep}{u}", number_text, st.sampled_from([" ", "", "  ", "\t"]), unit_text)
scalars = st.one_of(st.none(), st.booleans(), numbers, quantities, number_text,
                    st.text(max_size=12), st.sampled_from(["solve", "starboard", "port", "turning", "zigzag", "stype",
                                                          "sine", "sawtooth", "schedule", "constant_rpm",
                                                          "constant_power", "kijima", "mmg2015", "beta", "r", "1",
                                                          "kvlcc2_l7", "esso_osaka", "../ships/kvlcc2_l7.yaml",
                                                          "../ships/esso_osaka.yaml", "zz10.yaml", ".", "..", "/",
                                                          "~nosuchuser/x.yaml", "a" * 300, "x\x00y", "/dev/null"]))
values = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                        st.dictionaries(st.one_of(st.sampled_from(KNOWN_KEYS),
                                                                                  st.text(max_size=6)), inner,
                                                                        max_size=3)),
                      max_leaves=8)
tables = st.lists(st.lists(st.one_of(numbers, st.floats(-50, 4000)), min_size=0, max_size=4), max_size=6)


def paths(node, prefix=()):
    """Every path into a nested dict/list (the root excluded)."""
    if isinstance(node, dict):
        items = node.items()
    elif isinstance(node, list):
        items = enumerate(node)
    else:
        return
    for k, v in items:
        yield prefix + (k,)
        yield from paths(v, prefix + (k,))


def containers(node, prefix=()):
    if isinstance(node, dict):
        yield prefix
        for k, v in node.items():
            yield from containers(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from containers(v, prefix + (i,))


def get(node, path):
    for p in path:
        node = node[p]
    return node


def rescale(v, factor, unit):
    """A quantity string with its number multiplied and, maybe, its unit swapped."""
    if not isinstance(v, str) or " " not in v.strip():
        return v
    num, old = v.strip().split(None, 1)
    try:
        x = float(num) * factor
    except ValueError:
        return v
    return f"{x!r} {unit or old}"


@st.composite
def mutated(draw, base: dict):
    data = copy.deepcopy(base)
    for _ in range(draw(st.integers(1, 3))):
        op = draw(st.sampled_from(["nudge", "set", "delete", "add", "rescale", "nudge", "table", "set"]))
        ps = list(paths(data))
        if op == "add" or not ps:
            cs = list(containers(data))
            parent = get(data, draw(st.sampled_from(cs)))
            parent[draw(st.one_of(st.sampled_from(KNOWN_KEYS), st.text(max_size=6), st.integers(-3, 3)))] = draw(values)
            continue
        path = draw(st.sampled_from(ps))
        parent, key = get(data, path[:-1]), path[-1]
        if op == "set":
            parent[key] = draw(values)
        elif op == "delete":
            del parent[key]
        elif op == "nudge":  # a plausible change: the same unit, a factor of 0.3-3
            v, factor = parent[key], draw(st.floats(0.3, 3.0))
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                parent[key] = v * factor if abs(v) < 1e300 else v
            else:
                parent[key] = rescale(v, factor, None)
        elif op == "rescale":
            parent[key] = rescale(parent[key], draw(st.sampled_from([1e-9, 1e-3, -1, 0, 0.5, 2, 60, 1e3, 1e9, 1e300])),
                                  draw(st.one_of(st.none(), st.sampled_from(ALL_UNITS))))
        else:  # a schedule manoeuvre with a random table
            data["manoeuvre"] = {"kind": "schedule", "table": draw(tables)}
    return data


def finite_everywhere(obj, where="") -> None:
    """Every number reachable from an accepted Trial or Ship is finite."""
    if dataclasses.is_dataclass(obj):
        for f in dataclasses.fields(obj):
            finite_everywhere(getattr(obj, f.name), f"{where}.{f.name}")
    elif isinstance(obj, dict):
        for k, v in obj.items():
            finite_everywhere(v, f"{where}.{k}")
    elif isinstance(obj, (list, tuple)):
        for i, v in enumerate(obj):
            finite_everywhere(v, f"{where}.{i}")
    elif isinstance(obj, np.ndarray):
        assert np.all(np.isfinite(obj)), where
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool):
        assert math.isfinite(obj), where


def one_line_error(e: InputError) -> None:
    assert isinstance(e.source, str) and isinstance(e.field, str) and e.message
    assert "\n" not in str(e) and "\r" not in str(e), repr(str(e))


def check_trial(call):
    try:
        t = call()
    except InputError as e:
        one_line_error(e)
        return None
    assert isinstance(t, Trial)
    finite_everywhere(t)
    assert 0 < t.dt <= t.duration and t.duration / t.dt <= MAX_STEPS * (1 + 1e-12)
    assert 0 < t.u0 and abs(t.manoeuvre.get("rudder", 0.0)) <= t.ship.steering.delta_max + 1e-12
    return t


def check_ship(call):
    try:
        s = call()
    except InputError as e:
        one_line_error(e)
        return None
    assert isinstance(s, Ship)
    finite_everywhere(s)
    assert s.particulars.L > 0 and s.propeller.D > 0 and s.steering.rate_max > 0 and s.steering.delta_max > 0
    return s


# --------------------------------------------------------------------------- properties

trial_inputs = st.sampled_from(sorted(TRIALS)).flatmap(lambda n: mutated(TRIALS[n]))
ship_inputs = st.sampled_from(sorted(SHIPS)).flatmap(lambda n: mutated(SHIPS[n]))


@settings(max_examples=150, **SETTINGS)
@given(trial_inputs)
def test_any_mutated_trial_mapping_gives_a_trial_or_input_error(data):
    check_trial(lambda: trial_from_dict(data, source="<hypothesis>", base=TRIAL_DIR))


@settings(max_examples=200, **SETTINGS)
@given(ship_inputs)
def test_any_mutated_ship_mapping_gives_a_ship_or_input_error(data):
    check_ship(lambda: ship_from_dict(data, source="<hypothesis>"))


def _garble(text: str, draw) -> str:
    lines = text.splitlines(keepends=True)
    for _ in range(draw(st.integers(0, 3))):
        if not lines:
            break
        i = draw(st.integers(0, len(lines) - 1))
        op = draw(st.sampled_from(["dup", "drop", "insert", "indent", "truncate"]))
        if op == "dup":
            lines.insert(i, lines[i])
        elif op == "drop":
            del lines[i]
        elif op == "insert":
            j = draw(st.integers(0, len(lines[i])))
            lines[i] = lines[i][:j] + draw(st.text(max_size=4)) + lines[i][j:]
        elif op == "indent":
            lines[i] = "  " + lines[i]
        else:
            lines = lines[:i]
    return "".join(lines)


@st.composite
def trial_and_ship_texts(draw):
    trial = draw(trial_inputs)
    if isinstance(trial.get("ship"), str) and trial["ship"] in SHIPS and draw(st.booleans()):
        trial["ship"] = "ship.yaml"  # the mutated ship file written next to it
    ship = draw(ship_inputs)
    as_text = lambda d: yaml.safe_dump(d, allow_unicode=draw(st.booleans()), sort_keys=False)
    texts = []
    for d in (trial, ship):
        try:
            t = as_text(d)
        except yaml.YAMLError:
            t = "{}"
        texts.append(_garble(t, draw))
    encoding = draw(st.sampled_from(["utf-8", "utf-8", "utf-16", "latin-1"]))
    return texts[0], texts[1], encoding


@pytest.fixture(scope="module")
def folder():
    with tempfile.TemporaryDirectory(prefix="mmg-properties-") as d:
        (Path(d) / "adir").mkdir()
        yield Path(d)


@settings(max_examples=80, **SETTINGS)
@given(trial_and_ship_texts())
def test_any_garbled_yaml_file_gives_a_result_or_input_error(folder, texts):
    trial_text, ship_text, encoding = texts
    tp, sp = folder / "trial.yaml", folder / "ship.yaml"
    for p, text in ((tp, trial_text), (sp, ship_text)):
        try:
            p.write_bytes(text.encode(encoding))
        except UnicodeEncodeError:
            p.write_bytes(text.encode("utf-8"))
    t = check_trial(lambda: load_trial(tp))
    check_ship(lambda: load_ship(sp))
    if t is not None and t.ship_path == str(sp.resolve()):
        assert t.ship == load_ship(sp)


@settings(max_examples=100, **SETTINGS)
@given(st.one_of(st.text(max_size=40), st.binary(max_size=40).map(lambda b: b.decode("latin-1"))))
def test_any_text_parses_as_yaml_or_input_error(text):
    try:
        parse_yaml(text, "<text>")
    except InputError as e:
        one_line_error(e)


@settings(max_examples=200, **SETTINGS)
@given(st.one_of(quantities, number_text, st.text(max_size=12), numbers, st.none(), st.booleans()),
       st.sampled_from(sorted(UNITS)))
def test_to_si_gives_a_finite_number_or_value_error(value, dimension):
    try:
        x = to_si(value, dimension)
    except ValueError as e:
        assert "\n" not in str(e)
        return
    assert math.isfinite(x)
    assert isinstance(value, str) and value.split()  # a number alone never passes


@settings(max_examples=40, **SETTINGS)
@given(st.lists(st.lists(st.one_of(number_text, st.text(max_size=5)), min_size=0, max_size=4), max_size=5),
       st.sampled_from(["time_s,rudder_deg", "time_s,rudder_deg,rpm", "time_s", "rudder_deg,time_s", "", "a,b"]))
def test_any_schedule_csv_gives_a_trial_or_input_error(folder, rows, header):
    csv = folder / "sched.csv"
    csv.write_text(header + "\n" + "\n".join(",".join(r) for r in rows) + "\n")
    data = copy.deepcopy(TRIALS["zz10"])
    data["manoeuvre"] = {"kind": "schedule", "file": str(csv)}
    check_trial(lambda: trial_from_dict(data, source="<hypothesis>", base=TRIAL_DIR))


@settings(max_examples=40, **SETTINGS)
@given(st.lists(st.builds(lambda k, v: f"{k}={v}",
                          st.sampled_from(["P0.u", "P0.n", "P0.Y_beta", "P0", "R.ZZ20.u", "R.ZZ20", "R.default.n", "Q",
                                           "dt", "P0_is", "initial.scale", "initial.values.Y_r", "fit_checks.froude_max",
                                           "divergence.nis_max", "P0_default_relative_std", "dt.x", "P0..u", "x"]),
                          st.one_of(number_text, quantities, st.sampled_from(["std", "variance", "[1", "{a: 1}", "",
                                                                              "true", "null"]))),
                max_size=3))
def test_any_estimation_setting_gives_a_config_or_input_error(sets):
    from ekf.estimate import P0_for, load_config

    try:
        cfg = load_config(None, sets)
    except InputError as e:
        one_line_error(e)
        return
    assert math.isfinite(cfg["dt_s"]) and cfg["dt_s"] > 0
    P0 = P0_for(cfg, ("Y_beta", "N_r"), {"Y_beta": 0.4, "N_r": -0.05})
    assert np.all(np.isfinite(P0)) and np.all(np.diag(P0) > 0)
