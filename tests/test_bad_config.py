"""Bad configs: one line naming the file and the field, exit status 2, nothing written.

One parametrised test per family: inputs that could give a traceback, runs
that would do unbounded work, nonsense that could be accepted silently, unitless or
wrong-unit numbers, and ship-file errors blamed on the ship file.
"""
from pathlib import Path

import numpy as np
import pytest
import yaml

from mmg.errors import InputError
from mmg.limits import MAX_STEPS
from mmg.ship import load_ship, ship_from_dict
from mmg.units import to_si
from trials.cli import main
from trials.runs.trial import load_trial, make_trial

from .conftest import CONFIGS

TRIAL = (CONFIGS / "trials" / "zz10.yaml").read_text()
SHIP = (CONFIGS / "ships" / "esso_osaka.yaml").read_text()
KVLCC2 = CONFIGS / "ships" / "kvlcc2_l7.yaml"


def write_case(tmp_path: Path, trial_edit=None, ship_edit=None, trial_text=None, ship_text=None):
    """A trial file (ZZ10) naming a ship file (Esso Osaka) in tmp_path, each edited as a dict or given as text."""
    ship = yaml.safe_load(SHIP)
    if ship_edit:
        ship_edit(ship)
    sp = tmp_path / "ship.yaml"
    if ship_text is not None:
        sp.write_bytes(ship_text) if isinstance(ship_text, bytes) else sp.write_text(ship_text)
    else:
        sp.write_text(yaml.safe_dump(ship))
    data = yaml.safe_load(TRIAL)
    data["ship"] = "ship.yaml"
    if trial_edit:
        trial_edit(data)
    tp = tmp_path / "trial.yaml"
    if trial_text is not None:
        tp.write_bytes(trial_text) if isinstance(trial_text, bytes) else tp.write_text(trial_text)
    else:
        tp.write_text(yaml.safe_dump(data))
    return tp, sp


def refused(capsys, tmp_path, argv, *needles):
    """``mmg argv --out OUT`` exits 2 with one stderr line holding every needle; nothing is written."""
    out = tmp_path / "out"
    before = set(tmp_path.iterdir())
    code = main(argv + ["--out", str(out)])
    cap = capsys.readouterr()
    err = cap.err.strip().splitlines()
    assert code == 2, (code, cap.err)
    assert len(err) == 1, err
    for n in needles:
        assert str(n) in err[0], (n, err[0])
    assert "Traceback" not in cap.err
    assert not out.exists()
    assert set(tmp_path.iterdir()) == before, "something was left behind"
    return err[0]


def trial_error(capsys, tmp_path, field, source="trial", **kw):
    tp, sp = write_case(tmp_path, **kw)
    src = {"trial": tp, "ship": sp}[source]
    return refused(capsys, tmp_path, ["simulate", str(tp)], f"{src}: {field}")


def ship_set(section, key, value):
    return lambda s: s[section].update({key: value})


def trial_set(*path_and_value):
    *path, key, value = path_and_value

    def edit(d):
        for p in path:
            d = d.setdefault(p, {})
        d[key] = value
    return edit


# --------------------------------------------------------------------------- family 1: tracebacks, now one line

NAN, INF = float("nan"), float("inf")

TRACEBACKS = {
    "binary trial YAML": dict(trial_text=b"\xff\xfe\x00\x01binary\x89PNG", field=""),
    "latin-1 trial YAML": dict(trial_text="name: Z\u00fcrich\n".encode("latin-1"), field=""),
    "NUL byte in the YAML": dict(trial_text="name: a\x00b\n", field=""),
    "binary ship YAML": dict(ship_text=b"\x00\xff" * 40, field="", source="ship"),
    "negative log.seed": dict(trial_edit=trial_set("log", "seed", -1), field="log.seed"),
    "1e400 kn": dict(trial_edit=trial_set("approach", "speed", "1e400 kn"), field="approach.speed"),
    "nan kn": dict(trial_edit=trial_set("approach", "speed", "nan kn"), field="approach.speed"),
    ".nan duration": dict(trial_edit=trial_set("duration", NAN), field="duration"),
    ".nan hull coefficient": dict(ship_edit=lambda s: s["hull"]["coefficients"]["Y_r"].update(value=NAN),
                                  field="hull.coefficients.Y_r.value", source="ship"),
    ".inf mass": dict(ship_edit=ship_set("mass", "m_prime", INF), field="mass.m_prime", source="ship"),
    "-.inf K_T": dict(ship_edit=lambda s: s["propeller"].update(K_T=[0.3, -INF]), field="propeller.K_T.1",
                      source="ship"),
    "ragged schedule table": dict(trial_edit=trial_set("manoeuvre", {"kind": "schedule", "table": [[0, 0], [10, 5, 1], [20, 5]]}),
                                  field="manoeuvre.table.1"),
    "non-numeric schedule table": dict(trial_edit=trial_set("manoeuvre", {"kind": "schedule", "table": [[0, 0], [10, "five"]]}),
                                       field="manoeuvre.table.1.1"),
    "schedule table not a list of rows": dict(trial_edit=trial_set("manoeuvre", {"kind": "schedule", "table": [1, 2, 3]}),
                                              field="manoeuvre.table.0"),
    "dt 1e-9 s": dict(trial_edit=trial_set("dt", "1e-9 s"), field="dt"),
    "duration 1e9 s": dict(trial_edit=trial_set("duration", "1e9 s"), field="duration"),
    "malformed date in the YAML": dict(trial_text="name: ZZ\ndescription: 2020-13-45\n", field=""),
    "deeply nested YAML": dict(trial_text="name: " + "[" * 5000, field=""),
}


@pytest.mark.parametrize("case", sorted(TRACEBACKS))
def test_tracebacks_are_one_line(case, tmp_path, capsys):
    kw = dict(TRACEBACKS[case])
    field, source = kw.pop("field"), kw.pop("source", "trial")
    trial_error(capsys, tmp_path, field, source, **kw)


@pytest.mark.parametrize("where", ["trial", "ship", "schedule file"])
def test_a_directory_where_a_file_is_expected(where, tmp_path, capsys):
    (tmp_path / "adir").mkdir()
    if where == "trial":
        refused(capsys, tmp_path, ["simulate", str(tmp_path / "adir")], "adir", "directory")
    elif where == "ship":
        tp, _ = write_case(tmp_path, trial_edit=trial_set("ship", "adir/"))
        refused(capsys, tmp_path, ["simulate", str(tp)], f"{tp}: ship", "directory")
    else:
        tp, _ = write_case(tmp_path, trial_edit=trial_set("manoeuvre", {"kind": "schedule", "file": "adir"}))
        refused(capsys, tmp_path, ["simulate", str(tp)], f"{tp}: manoeuvre.file", "directory")


CSV_CASES = {
    "ragged row": ("time_s,rudder_deg\n0,0\n10,5,7,8\n20,5\n", ""),
    "text in a number": ("time_s,rudder_deg\n0,0\n10,five\n", "rudder_deg"),
    "empty cell": ("time_s,rudder_deg\n0,0\n10,\n", "rudder_deg"),
    "unknown column": ("time_s,rudder_deg,RPM\n0,0,50\n10,5,50\n", "RPM"),
    "missing column": ("time_s\n0\n10\n", "rudder_deg"),
    "empty file": ("", ""),
    "binary": (b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe", ""),
    "one row": ("time_s,rudder_deg\n0,0\n", ""),
    "times not increasing": ("time_s,rudder_deg\n0,0\n10,5\n5,5\n", "time_s"),
}


@pytest.mark.parametrize("case", sorted(CSV_CASES))
def test_bad_schedule_csv_names_the_csv_and_column(case, tmp_path, capsys):
    text, column = CSV_CASES[case]
    csv = tmp_path / "sched.csv"
    csv.write_bytes(text) if isinstance(text, bytes) else csv.write_text(text)
    tp, _ = write_case(tmp_path, trial_edit=trial_set("manoeuvre", {"kind": "schedule", "file": "sched.csv"}))
    refused(capsys, tmp_path, ["simulate", str(tp)], f"{csv}: {column}" if column else str(csv))


@pytest.mark.parametrize("sets, field", [
    (["P0.n=1e300"], "P0.n"),                         # not numpy.linalg.LinAlgError: singular matrix
    (["P0_is=std", "P0.u=1e-300"], "P0.u"),           # a variance that underflows to 0
    (["P0.Y_beta=inf"], "P0.Y_beta"),
    (["P0=1"], "P0"),                                 # not AttributeError
    (["R.ZZ20=3"], "R.ZZ20"),
    (["P0_default_relative_std=1e200"], "P0_default_relative_std"),
    (["P0.u=[1"], "P0.u"),
    (["dt=0.1"], "dt"),
])
def test_absurd_estimation_settings_are_refused(sets, field, tmp_path, capsys):
    argv = ["estimate", "zz20", "--no-plots"]
    for s in sets:
        argv += ["--set", s]
    refused(capsys, tmp_path, argv, field)


def test_estimation_config_file_duplicate_key_and_binary(tmp_path, capsys):
    cfg = tmp_path / "est.yaml"
    cfg.write_text("Q: 0.0\nQ: 1.0\n")
    refused(capsys, tmp_path, ["estimate", "zz20", "--config", str(cfg)], f"{cfg}: Q", "duplicate key")
    cfg.write_bytes(b"\xff\x00\x00")
    refused(capsys, tmp_path, ["estimate", "zz20", "--config", str(cfg)], str(cfg), "UTF-8")


# --------------------------------------------------------------------------- family 2: unbounded work


@pytest.mark.parametrize("duration, dt", [("1e6 s", "0.1 s"), ("1e7 s", "0.1 s"), ("1e7 s", "1 s"),
                                          ("300000 s", "0.1 s"), ("1000 h", "0.1 s")])
def test_unbounded_runs_are_refused_before_allocating(duration, dt, tmp_path, capsys):
    line = trial_error(capsys, tmp_path, "duration", trial_edit=lambda d: d.update(duration=duration, dt=dt))
    assert "steps" in line and f"{MAX_STEPS:,}" in line and ("GB" in line or "TB" in line)
    assert "shorten the duration or lengthen dt" in line


def test_the_largest_allowed_run_is_accepted():
    t = make_trial("esso_osaka", {"kind": "turning", "rudder": "35 deg"}, speed="10 kn",
                   duration=f"{MAX_STEPS * 0.1:g} s", dt="0.1 s")
    assert t.duration / t.dt == pytest.approx(MAX_STEPS)
    with pytest.raises(InputError, match="steps") as e:
        make_trial("esso_osaka", {"kind": "turning", "rudder": "35 deg"}, speed="10 kn",
                   duration=f"{MAX_STEPS * 0.1 + 1:g} s", dt="0.1 s")
    assert e.value.field == "duration"


# --------------------------------------------------------------------------- family 3: nonsense accepted silently

DUP_TRIAL = TRIAL.replace("dt: 0.1 s\n", "dt: 0.1 s\ndt: 0.2 s\n")
DUP_NESTED = TRIAL.replace("  rudder: 10 deg\n", "  rudder: 10 deg\n  rudder: 20 deg\n")
DUP_SHIP = SHIP.replace("  L: 325.0 m\n", "  L: 325.0 m\n  L: 32.5 m\n")

NONSENSE = {
    "duplicate top-level key": dict(trial_text=DUP_TRIAL, field="dt"),
    "duplicate nested key": dict(trial_text=DUP_NESTED, field="manoeuvre.rudder"),
    "duplicate key in the ship": dict(ship_text=DUP_SHIP, field="particulars.L", source="ship"),
    "negative noise": dict(trial_edit=trial_set("log", "noise", "heading", "-0.1 deg"), field="log.noise.heading"),
    "latitude 95 deg": dict(trial_edit=trial_set("log", "start_lat", "95 deg"), field="log.start_lat"),
    "current 1000 kn": dict(trial_edit=trial_set("disturbances", "current", {"speed": "1000 kn", "direction": "0 deg"}),
                            field="disturbances.current.speed"),
    "negative current": dict(trial_edit=trial_set("disturbances", "current", {"speed": "-1 kn", "direction": "0 deg"}),
                             field="disturbances.current.speed"),
    "execute before 0": dict(trial_edit=trial_set("manoeuvre", {"kind": "turning", "rudder": "35 deg", "execute": "-5 s"}),
                             field="manoeuvre.execute"),
    "execute after the end": dict(trial_edit=trial_set("manoeuvre", {"kind": "turning", "rudder": "35 deg",
                                                                      "execute": "3000 s"}), field="manoeuvre.execute"),
    "rate_max 0": dict(ship_edit=lambda s: s["steering"].update(rate_max="0 deg/s"), field="steering.rate_max",
                       source="ship"),
    "rate_max negative": dict(ship_edit=lambda s: s["steering"].update(rate_max="-2 deg/s"), field="steering.rate_max",
                              source="ship"),
    "delta_max negative": dict(ship_edit=lambda s: s["steering"].update(delta_max="-35 deg"),
                               field="steering.delta_max", source="ship"),
    "D negative (blamed on the ship)": dict(ship_edit=lambda s: s["propeller"].update(D="-9.1 m"), field="propeller.D",
                                            source="ship"),
    "rpm schedule on a constant-power engine": dict(
        trial_edit=trial_set("manoeuvre", {"kind": "schedule", "table": [[0, 0, 54], [100, 10, 60], [200, 10, 60]]}),
        field="manoeuvre.table"),
    "zigzag with a negative rudder": dict(trial_edit=trial_set("manoeuvre", "rudder", "-10 deg"), field="manoeuvre.rudder"),
    "log interval below dt": dict(trial_edit=trial_set("log", "interval", "1e-9 s"), field="log.interval"),
    "sine period of one step": dict(trial_edit=trial_set("manoeuvre", {"kind": "sine", "amplitude": "10 deg",
                                                                        "period": "0.2 s"}), field="manoeuvre.period"),
    "dt beyond the steering time constant": dict(trial_edit=lambda d: d.update(dt="5 s"), field="dt"),
    "speed outside the engine data": dict(trial_edit=trial_set("approach", "speed", "1 kn"), field="approach.speed"),
    "seed true": dict(trial_edit=trial_set("log", "seed", True), field="log.seed"),
    "boolean hull coefficient": dict(ship_edit=lambda s: s["hull"]["coefficients"]["N_r"].update(value=True),
                                     field="hull.coefficients.N_r.value", source="ship"),
    "no N coefficient": dict(ship_edit=lambda s: s["hull"].update(coefficients={k: v for k, v in s["hull"]["coefficients"].items()
                                                                                 if not k.startswith("N_")}),
                             field="hull.coefficients", source="ship"),
    "mass primed on the wrong reference": dict(ship_edit=ship_set("mass", "m_prime", 0.0181), field="mass.m_prime",
                                               source="ship"),
}


@pytest.mark.parametrize("case", sorted(NONSENSE))
def test_nonsense_is_refused(case, tmp_path, capsys):
    kw = dict(NONSENSE[case])
    field, source = kw.pop("field"), kw.pop("source", "trial")
    trial_error(capsys, tmp_path, field, source, **kw)


def test_an_rpm_schedule_is_accepted_by_a_constant_rpm_engine():
    t = make_trial(KVLCC2, {"kind": "schedule", "table": [[0, 0, 1077], [10, 10, 1100], [40, 10, 1100]]},
                   speed="1.179 m/s", duration="40 s", dt="0.02 s")
    assert t.manoeuvre["table"][0, 2] == pytest.approx(1077 / 60)


# --------------------------------------------------------------------------- family 4: units and plausible ranges


@pytest.mark.parametrize("value", ["0.1", "10", "1e3", " 35 ", 0.1, 10, "inf"])
def test_a_number_without_a_unit_says_so(value):
    with pytest.raises(ValueError, match="has no unit"):
        to_si(value, "time")


@pytest.mark.parametrize("value, dimension, si", [("0.1 s", "time", 0.1), ("20deg", "angle", 0.3490658503988659),
                                                  ("2 1/s", "revolutions", 2.0), ("1.5 min", "time", 90.0),
                                                  ("-3e-1 m", "length", -0.3), (".5 kn", "speed", 0.5 * 1852 / 3600)])
def test_quantities_still_parse(value, dimension, si):
    assert to_si(value, dimension) == pytest.approx(si)


UNIT_CASES = {
    "dt '0.1'": (dict(trial_edit=trial_set("dt", "0.1")), "dt", "has no unit"),
    "duration '10'": (dict(trial_edit=trial_set("duration", "10")), "duration", "has no unit"),
    "speed 1000 kn": (dict(trial_edit=trial_set("approach", "speed", "1000 kn")), "approach.speed", "wrong unit"),
    "speed in m/s meant as kn on a model": (dict(trial_edit=trial_set("approach", "speed", "15 m/s"),
                                                 ship_text=KVLCC2.read_text()), "approach.speed", "Froude"),
    "rudder 400 deg": (dict(trial_edit=trial_set("manoeuvre", "rudder", "400 deg")), "manoeuvre.rudder", "wrong unit"),
    "rudder in rad meant as deg": (dict(trial_edit=trial_set("manoeuvre", "rudder", "10 rad")), "manoeuvre.rudder",
                                   "wrong unit"),
    "latitude in rad": (dict(trial_edit=trial_set("log", "start_lat", "35 rad")), "log.start_lat", "latitude"),
    "rpm 1e5": (dict(trial_edit=trial_set("approach", "rpm", "1e5 rpm")), "approach.rpm", "wrong unit"),
}


@pytest.mark.parametrize("case", sorted(UNIT_CASES))
def test_wrong_unit_or_implausible_value_in_a_trial(case, tmp_path, capsys):
    kw, field, why = UNIT_CASES[case]
    line = trial_error(capsys, tmp_path, field, **kw)
    assert why in line


SHIP_UNIT_CASES = {
    "L 1e5 m": (("particulars", "L", "1e5 m"), "wrong unit"),
    "L in km": (("particulars", "L", "325 km"), "wrong unit"),
    "L without a unit": (("particulars", "L", 325), "has no unit"),
    "L '325'": (("particulars", "L", "325"), "has no unit"),
    "rho in t/m^3": (("particulars", "rho", "1.025 kg/m^3"), "wrong unit"),
    "delta_max 400 deg": (("steering", "delta_max", "400 deg"), "wrong unit"),
    "rate_max 2.34 rad/s": (("steering", "rate_max", "2.34 rad/s"), "wrong unit"),
    "breadth above the length": (("particulars", "B", "400 m"), "L/B"),
}


@pytest.mark.parametrize("case", sorted(SHIP_UNIT_CASES))
def test_wrong_unit_or_implausible_value_in_a_ship(case, tmp_path, capsys):
    (section, key, value), why = SHIP_UNIT_CASES[case]
    line = trial_error(capsys, tmp_path, f"{section}.{key}", "ship", ship_edit=ship_set(section, key, value))
    assert why in line


# --------------------------------------------------------------------------- family 5: the ship file is blamed


@pytest.mark.parametrize("edit, field", [
    (ship_set("propeller", "D", "-1 m"), "propeller.D"),
    (ship_set("rudder", "t_R", 1.5), "rudder.t_R"),
    (ship_set("propeller", "Y_P_astern", 0.8), "propeller.Y_P_astern"),
    (ship_set("engine", "mode", "diesel"), "engine.mode"),
    (lambda s: s.pop("steering"), "steering"),
    (ship_set("particulars", "colour", "red"), "particulars.colour"),
])
def test_a_ship_file_error_names_the_ship_file_not_the_trial(edit, field, tmp_path, capsys):
    tp, sp = write_case(tmp_path, ship_edit=edit)
    line = refused(capsys, tmp_path, ["simulate", str(tp)], f"{sp}: {field}")
    assert str(tp) not in line
    with pytest.raises(InputError) as e:
        load_trial(tp)
    assert (e.value.source, e.value.field) == (str(sp), field)
    with pytest.raises(InputError) as e:
        load_ship(sp)
    assert (e.value.source, e.value.field) == (str(sp), field)


def test_ship_from_dict_names_its_source():
    data = yaml.safe_load(SHIP)
    data["particulars"]["L"] = "1e5 m"
    with pytest.raises(InputError) as e:
        ship_from_dict(data, "my_ship.yaml")
    assert (e.value.source, e.value.field) == ("my_ship.yaml", "particulars.L")
    with pytest.raises(InputError, match="expected a mapping"):
        ship_from_dict([1, 2], "my_ship.yaml")


def test_every_bundled_config_still_loads():
    from mmg.resources import bundled

    for name in bundled("ships"):
        load_ship(name)
    for name in bundled("trials"):
        load_trial(name)


# --------------------------------------------------------------------------- approach.rpm against approach.speed
# (an "approach.rpm: 5 rpm" far below the speed's must be refused, not run with the shaft at -7.8 rpm).  Rhee & Kim's
# published approach of the Esso Osaka is 54.12 rpm at 10 kn (Table 4); MMG 2015 gives the KVLCC2
# L7 model 17.95 rps at 1.179 m/s (its model-scale self-propulsion point, which the constant-rpm
# motor holds while the ship runs to the speed it gives).

THREE_M = CONFIGS / "ships" / "esso_osaka_3m.yaml"

RPM_CASES = {
    "far below: the propeller would not push ahead": ("5 rpm", None, "zero-thrust"),
    "the wrong sign": ("-54 rpm", None, "positive"),
    "constant power, pushes but too low": ("30 rpm", None, "cannot hold"),
    "constant power, too high": ("70 rpm", None, "cannot hold"),
    "beyond any engine": ("1e5 rpm", None, "wrong unit"),
    "a model below its zero-thrust rpm": ("100 rpm", THREE_M, "zero-thrust"),
    "a model's motor far above the straight run's rpm": ("6000 rpm", THREE_M, "times the rpm of the straight run"),
}


@pytest.mark.parametrize("case", sorted(RPM_CASES))
def test_an_approach_rpm_the_speed_cannot_have_is_refused(case, tmp_path, capsys):
    rpm, ship, why = RPM_CASES[case]
    edit = trial_set("approach", "rpm", rpm)
    if ship is not None:
        def edit(d, rpm=rpm):
            d["approach"] = {"speed": "0.45 m/s", "rpm": rpm}
            d.update(dt="0.02 s", duration="60 s", log={"interval": "0.1 s"})
    line = trial_error(capsys, tmp_path, "approach.rpm", trial_edit=edit,
                       ship_text=None if ship is None else ship.read_text())
    assert why in line
    if ship is None and why in ("zero-thrust", "cannot hold"):          # names the rpm the speed needs
        import re

        need = float(re.search(r"needs ([0-9.]+) rpm", line).group(1))
        assert need == pytest.approx(54.12, rel=0.01)


def test_the_published_approach_rpm_is_honoured(tmp_path):
    """Rhee & Kim's 54.12 rpm at 10 kn: a steady straight run (the rpm and speed held before the
    rudder moves); MMG 2015's 17.95 rps for the KVLCC2 model at 1.179 m/s: the motor holds it and
    the ship runs up from the approach speed, the shaft never reversing."""
    import mmg

    tp, _ = write_case(tmp_path, trial_edit=lambda d: (d["approach"].update(rpm="54.12 rpm"), d.update(duration="60 s")))
    r = mmg.simulate(load_trial(tp))
    assert r.completed and r.equilibrium.residual < 1e-4         # 0.05 rpm off the solved 54.21: nearly steady
    assert np.all(np.abs(r.n * 60 / 54.12 - 1) < 0.01) and r.u[0] == pytest.approx(10 * 1852 / 3600)
    k = make_trial(KVLCC2, {"kind": "turning", "rudder": "35 deg"}, speed="1.179 m/s", rpm="17.95 1/s",
                   duration="30 s", dt="0.05 s", trim=False)
    r = mmg.simulate(k)
    assert r.completed and np.all(r.n == 17.95) and r.u[0] == pytest.approx(1.179)


def test_a_constant_power_straight_run_beyond_zero_torque_is_refused():
    """The library route (no trial file): at 5 rpm and 10 kn K_Q(J) < 0, so calibrating the shaft
    there gave a negative K_Q scale: the propeller's torque became a drive and the shaft ran
    through zero.  Now: ValueError, no run."""
    from mmg.equilibrium import straight_run

    with pytest.raises(ValueError, match="K_Q"):
        straight_run(load_ship(CONFIGS / "ships" / "esso_osaka.yaml"), 10 * 1852 / 3600, n=5 / 60)
