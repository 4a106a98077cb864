"""``mmg imo`` / ``mmg.imo``: the IMO manoeuvring criteria (MSC.137(76)) and their uncertainty.

The limits are checked against the standard's table written out here (not read from the code), the
full-scale Esso Osaka's figures against the same manoeuvres simulated through ``mmg.simulate`` from
the bundled trial YAMLs and the trial builders (another path: other durations, other construction),
the CLI's JSON against its schema.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

import mmg
from trials.cli import main

# ----------------------------------------------------------------- the standard, written out independently
# IMO Resolution MSC.137(76), Annex 5.3: (L/V [s], 10/10 first overshoot limit, second) [deg]
ZZ10_TABLE = [
    (5.0, 10.0, 25.0),
    (9.99, 10.0, 25.0),
    (10.0, 10.0, 25.0),          # 5 + 10/2, 17.5 + 7.5: continuous at 10 s
    (20.0, 15.0, 32.5),          # 5 + 10,   17.5 + 15
    (29.0, 19.5, 39.25),         # 5 + 14.5, 17.5 + 21.75
    (30.0, 20.0, 40.0),
    (40.0, 20.0, 40.0),
    (63.2, 20.0, 40.0),
]
FIXED = {"advance": 4.5, "tactical diameter": 5.0, "initial turning track reach": 2.5,
         "20/20 first overshoot": 25.0}
UNITS = {"advance": "L", "tactical diameter": "L", "initial turning track reach": "L", "10/10 first overshoot": "deg",
         "10/10 second overshoot": "deg", "20/20 first overshoot": "deg", "stopping track reach": "L"}
PER_SIDE = ("advance", "tactical diameter", "initial turning track reach", "10/10 first overshoot",
            "10/10 second overshoot", "20/20 first overshoot")
EXPECTED_NAMES = {f"{c}, {s}" for c in PER_SIDE for s in ("starboard", "port")} | {"stopping track reach"}


@pytest.mark.parametrize("LV, first, second", ZZ10_TABLE)
def test_limits_follow_the_standard(LV, first, second):
    from trials.analysis.metrics import imo_criteria
    from trials.imo.standard import criteria

    lim = {c.name: c.limit for c in criteria(LV)}
    assert set(lim) == EXPECTED_NAMES
    for s in ("starboard", "port"):
        assert lim[f"10/10 first overshoot, {s}"] == pytest.approx(first, abs=1e-12)
        assert lim[f"10/10 second overshoot, {s}"] == pytest.approx(second, abs=1e-12)
        for name, v in FIXED.items():
            assert lim[f"{name}, {s}"] == v
    assert lim["stopping track reach"] == 15.0
    # the older per-ship table (mmg reproduce) reads the same limits: one definition of each
    old = {r["criterion"]: r["limit"] for r in imo_criteria(LV, 1.0, {"advance_L": 1.0}, {"overshoots_deg": [1.0, 1.0]},
                                                              {"overshoots_deg": [1.0]})}
    assert old["10/10 first overshoot (deg)"] == pytest.approx(first, abs=1e-12)
    assert old["10/10 second overshoot (deg)"] == pytest.approx(second, abs=1e-12)
    assert old["advance (L)"] == 4.5 and old["tactical diameter (L)"] == 5.0
    assert old["20/20 first overshoot (deg)"] == 25.0


# ----------------------------------------------------------------- the CLI on the full-scale ship

@pytest.fixture(scope="module")
def cli_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("imo") / "out"
    code = main(["imo", "esso_osaka", "--out", str(out)])
    assert code == 0
    return out, json.loads((out / "imo.json").read_text())


def _simulated(trial):
    m = mmg.simulate(trial).metrics()
    ov = m.get("overshoots_deg") or []
    return m, ov


def test_figures_equal_those_of_simulate(cli_run):
    """The turning and zigzag figures of imo.json are those of the same manoeuvres through mmg.simulate:
    starboard from the bundled YAMLs (3000 s runs), port from the trial builders."""
    _, doc = cli_run
    got = {c["name"]: c["value"] for c in doc["criteria"]}
    ship = mmg.load_ship("esso_osaka")
    kw = {"speed": "10 kn", "duration": "3000 s"}
    runs = {"starboard": (_simulated("st35"), _simulated("zz10"), _simulated("zz20")),
            "port": (_simulated(mmg.turning(ship, rudder="-35 deg", **kw)),
                     _simulated(mmg.zigzag(ship, rudder="10 deg", heading="10 deg", first="port", **kw)),
                     _simulated(mmg.zigzag(ship, rudder="20 deg", heading="20 deg", first="port", **kw)))}
    for side, ((turn, _), (z10, ov10), (_, ov20)) in runs.items():
        want = {"advance": turn["advance_L"], "tactical diameter": turn["tactical_diameter_L"],
                "initial turning track reach": z10["distance_to_second_execute_L"],
                "10/10 first overshoot": ov10[0], "10/10 second overshoot": ov10[1], "20/20 first overshoot": ov20[0]}
        for name, v in want.items():
            assert got[f"{name}, {side}"] == pytest.approx(v, rel=1e-9, abs=1e-12), (name, side)
    # the stopping test: the stopping builder's run through mmg.simulate (another duration: it ends at the stop)
    stop = mmg.simulate(mmg.stopping(ship, dt="0.5 s", **kw)).metrics()      # imo's stopping step (L/V / 120)
    assert stop["stopped"] and got["stopping track reach"] == pytest.approx(stop["track_reach_L"], rel=1e-9)
    # and the verdicts are those values against the standard's limits (L/V = 325 m / 10 kn = 63.2 s)
    lim = {**FIXED, "10/10 first overshoot": 20.0, "10/10 second overshoot": 40.0, "stopping track reach": 15.0}
    for c in doc["criteria"]:
        assert c["verdict"] == ("pass" if c["value"] <= lim[c["name"].split(",")[0]] else "fail")


def test_cli_writes_the_exact_schema(cli_run):
    out, doc = cli_run
    assert list(doc) == ["ship", "warnings", "criteria"]
    assert doc["ship"] == "Esso Osaka" and doc["warnings"] == []
    assert {c["name"] for c in doc["criteria"]} == EXPECTED_NAMES
    assert len(doc["criteria"]) == len(EXPECTED_NAMES)
    for c in doc["criteria"]:
        assert list(c) == ["name", "value", "unit", "limit", "interval", "probability", "verdict"]
        assert c["unit"] == UNITS[c["name"].split(",")[0]]
        assert c["interval"] is None and c["probability"] is None
        assert isinstance(c["value"], float) and c["verdict"] in ("pass", "fail")
    assert {c["name"]: c["limit"] for c in doc["criteria"]}["stopping track reach"] == 15.0
    md = (out / "imo.md").read_text()
    assert "MSC.137(76)" in md and "MSC/Circ.1053" in md and "four-quadrant" in md
    assert "head reach" in md and "lateral deviation" in md and "20 L" in md and "(stopping.png)" in md
    for name in EXPECTED_NAMES:
        assert f"| {name} |" in md
    for fig in ("tracks.png", "zigzags.png", "stopping.png"):
        assert (out / fig).stat().st_size > 10000


@pytest.mark.parametrize("argv, names", [
    (["imo", "no_such_ship"], "no_such_ship"),
    (["imo", "esso_osaka", "--speed", "0"], "--speed"),
    (["imo", "esso_osaka", "--speed", "-2 kn"], "--speed"),
    (["imo", "esso_osaka_3m"], "--speed"),                    # no bundled trial gives its speed
    (["imo", "esso_osaka", "--samples", "4"], "--samples"),   # no covariance in the bundled ship
])
def test_bad_input_is_one_line(argv, names, tmp_path, capsys):
    out = tmp_path / "o"
    assert main(argv + ["--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and names in err[0]
    assert not out.exists()


# ----------------------------------------------------------------- uncertainty

from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402


def serial(func, tasks):
    """An executor of our own: a plain loop (the plug-in point a distributed one uses)."""
    serial.calls += 1
    return [func(t) for t in tasks]


serial.calls = 0


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(n=st.integers(2, 5), seed=st.integers(0, 2**31 - 1))
def test_sampled_parameters_have_the_given_covariance(n, seed):
    from trials.imo.sampling import draw

    rng = np.random.default_rng(seed)
    a = rng.normal(size=(n, n))
    scale = 10.0 ** rng.uniform(-4, 1, n)                    # parameters of very different sizes
    cov = (a @ a.T + 0.05 * np.eye(n)) * np.outer(scale, scale)
    mean = rng.normal(size=n) * scale
    N = 20000
    x = draw(mean, cov, N, seed=seed + 1)
    assert x.shape == (N, n)
    S = np.cov(x, rowvar=False)
    sd = np.sqrt(np.diag(cov))
    # standard error of a sample covariance: sqrt((C_ii C_jj + C_ij^2) / N); 5 of them
    tol = 5.0 * np.sqrt((np.outer(sd, sd) ** 2 + cov ** 2) / N)
    assert np.all(np.abs(S - cov) <= tol)
    assert np.all(np.abs(x.mean(axis=0) - mean) <= 5.0 * sd / np.sqrt(N))


@settings(max_examples=200, deadline=None)
@given(v=st.lists(st.one_of(st.none(), st.floats(-1e3, 1e3)), min_size=1, max_size=60),
       limit=st.floats(-1e3, 1e3))
def test_probability_and_verdict(v, limit):
    from trials.imo.sampling import summarise

    s = summarise(v, limit)
    met = [x is not None and x <= limit for x in v]
    assert s["probability"] == pytest.approx(sum(met) / len(v), abs=1e-12)
    want = "pass" if s["probability"] >= 0.95 else "fail" if s["probability"] <= 0.05 else "undecided"
    assert s["verdict"] == want
    if all(met):                                      # every sample (so the whole interval) below the limit
        assert s["probability"] == 1.0 and s["verdict"] == "pass"
    if not any(met):                                  # every sample above it (or none gave the figure)
        assert s["probability"] == 0.0 and s["verdict"] == "fail"
    lo, hi = s["interval"]
    if None not in (lo, hi, s["median"]):
        assert lo <= s["median"] <= hi
        finite = [x for x in v if x is not None]
        assert min(finite) <= lo and hi <= max(finite)


def test_covariance_refused_or_marginalised():
    from mmg.errors import InputError
    from trials.imo.sampling import covariance_of

    ship = mmg.load_ship("esso_osaka")
    c = [[4.0, 1.0, 0.5], [1.0, 9.0, 2.0], [0.5, 2.0, 1.0]]
    names, mean, mat, notes = covariance_of(ship, {"names": ["N_r", "wind_scale", "kappa"], "matrix": c})
    assert names == ["N_r", "kappa"] and len(notes) == 1 and "wind_scale" in notes[0]
    assert mat.tolist() == [[4.0, 0.5], [0.5, 1.0]]           # the marginal: correlations of the rest kept
    assert mean.tolist() == [ship.hull.value("N_r"), ship.rudder.kappa]
    for bad in ({"names": ["N_r", "Y_r"], "matrix": [[1.0, 2.0], [2.0, 1.0]]},   # not positive semi-definite
                {"names": ["N_r", "Y_r"], "matrix": [[1.0, 0.5], [0.4, 1.0]]},   # not symmetric
                {"names": ["N_r"], "matrix": [[1.0, 0.0], [0.0, 1.0]]},          # wrong shape
                {"names": ["no_such"], "matrix": [[1.0]]}):
        with pytest.raises(InputError):
            covariance_of(ship, bad)


def test_samples_are_written_into_the_ship():
    """Samples at one point (zero variance) about another N_r give that ship's figures, as mmg.simulate
    runs it; the interval closes on them and the probability is 1 or 0."""
    ship = mmg.load_ship("esso_osaka")
    nr = 0.8 * ship.hull.value("N_r")
    before = serial.calls
    res = mmg.imo(ship, samples=3, cov={"names": ["N_r"], "values": [nr], "matrix": [[0.0]]}, executor=serial)
    assert serial.calls == before + 1
    want = mmg.simulate(mmg.turning(ship.with_hull({"N_r": nr}), rudder="35 deg", speed="10 kn",
                                    duration="3000 s")).metrics()["tactical_diameter_L"]
    own = mmg.simulate("st35").metrics()["tactical_diameter_L"]
    assert abs(want - own) > 0.05                          # the change shows
    row = {r["name"]: r for r in res.rows()}["tactical diameter, starboard"]
    assert row["value"] == pytest.approx(want, rel=1e-9)
    assert row["interval"] == pytest.approx([want, want], rel=1e-9)
    assert row["probability"] == (1.0 if want <= 5.0 else 0.0)
    assert res.nominal["tactical diameter, starboard"] == pytest.approx(own, rel=1e-9)


def test_identify_writes_the_covariance_imo_samples(tmp_path):
    """mmg identify's ship.yaml carries the fit's covariance (names, units, values and the linearised
    posterior: the data's information over its residual variance and correlation time, the prior at its
    stated std, the start-state nuisances marginalised out), and imo samples that ship from it."""
    from tests.test_identify import SHIP, _synthetic_runs
    from trials.measured.identify import identify, write_identification

    ship = mmg.load_ship(SHIP)
    runs = _synthetic_runs(ship, seeds=(0,), duration=40.0)
    free = ["N_r", "Y_r", "kappa", "m_y"]
    ident = identify(ship, runs, free=free, segment_s=(20.0,), say=lambda m: None, max_nfev=3)
    path = write_identification(ident, mmg.config_path("ships", f"{SHIP}.yaml"), tmp_path)["ship"]
    back = mmg.load_ship(path)
    c = back.covariance
    f = ident.fit
    assert list(c.names) == free and list(c.units) == ["1", "1", "1", "kg"]
    shared = [i for i, p in enumerate(f.free) if p.name in free]
    assert len(f.free) > len(free)                              # the start-state offsets were fitted too
    assert np.allclose(c.values, np.asarray(f.theta)[shared], rtol=1e-8)
    n = len(f.free)
    sd2 = f.ss_data / (f.n_residuals - n - n)                   # data rows N - n, less the n fitted
    sig = np.array([p.sigma for p in f.free])
    want = np.linalg.inv(f.info_data / (sd2 * max(ident.tau, 1.0)) + np.diag(sig ** -2.0))[np.ix_(shared, shared)]
    assert np.allclose(np.asarray(c.matrix), want, rtol=1e-6, atol=0)
    res = mmg.imo(path, speed="0.5 m/s", samples=4, executor=serial, seed=3)
    assert res.parameters["names"] == free and res.n_samples == 4
    for r in res.rows():
        lo, hi = r["interval"]
        assert lo <= r["value"] <= hi and 0.0 <= r["probability"] <= 1.0


def test_cli_samples_on_both_cores_match_a_serial_run(tmp_path):
    """mmg imo --samples on a ship.yaml with a covariance: the schema with intervals, the convergence
    in imo.md, the distributions figure; the process pool gives the serial executor's numbers."""
    from trials.measured.identify import ship_yaml

    ship = mmg.load_ship("esso_osaka")
    names = ["N_r", "Y_r", "epsilon"]
    vals = [ship.hull.value("N_r"), ship.hull.value("Y_r"), ship.rudder.epsilon]
    sd = np.abs(vals) * np.array([0.15, 0.1, 0.05])
    corr = np.array([[1.0, 0.6, 0.2], [0.6, 1.0, 0.0], [0.2, 0.0, 1.0]])
    cov = {"names": names, "units": ["1"] * 3, "values": vals, "matrix": (corr * np.outer(sd, sd)).tolist()}
    yml = tmp_path / "ship.yaml"
    yml.write_text(ship_yaml(mmg.config_path("ships", "esso_osaka.yaml"), {}, "a covariance (test)", cov))
    out = tmp_path / "out"
    assert main(["imo", str(yml), "--speed", "10 kn", "--samples", "16", "--seed", "5", "--jobs", "2",
                 "--out", str(out)]) == 0
    doc = json.loads((out / "imo.json").read_text())
    ser = mmg.imo(str(yml), speed="10 kn", samples=16, seed=5, executor=serial)
    assert doc == ser.as_dict()
    for c in doc["criteria"]:
        assert list(c) == ["name", "value", "unit", "limit", "interval", "probability", "verdict"]
        assert len(c["interval"]) == 2 and 0.0 <= c["probability"] <= 1.0
        assert c["verdict"] in ("pass", "fail", "undecided")
    md = (out / "imo.md").read_text()
    assert "## Convergence" in md and "N = 2" in md and "N = 16" in md and ">= 0.95" in md
    assert (out / "distributions.png").stat().st_size > 10000
    conv = ser.convergence("advance, port")
    assert [x["n"] for x in conv] == [2, 4, 8, 16]
    for side in ("starboard", "port"):                # the extreme samples' turns, run again, for the tracks figure
        v = ser.samples[f"tactical diameter, {side}"]
        got = {w: ser.sample_runs[f"turning circle, {side}: {w} sample"][1]["tactical_diameter_L"]
               for w in ("smallest", "median", "largest")}
        assert got["smallest"] == pytest.approx(min(v), rel=1e-12) and got["largest"] == pytest.approx(max(v), rel=1e-12)
        assert got["median"] == pytest.approx(sorted(v)[len(v) // 2], rel=1e-12)


@pytest.mark.parametrize("below, above, verdict", [(100, 0, "pass"), (95, 5, "pass"), (94, 6, "undecided"),
                                                   (93, 7, "undecided"), (50, 50, "undecided"), (6, 94, "undecided"),
                                                   (5, 95, "fail"), (0, 100, "fail")])
def test_verdict_thresholds(below, above, verdict):
    """pass from a probability of 0.95, fail up to 0.05 (the rule in the docstring and the report)."""
    from trials.imo.sampling import summarise

    s = summarise([1.0] * below + [3.0] * above, 2.0)
    assert s["probability"] == pytest.approx(below / 100.0) and s["verdict"] == verdict


@pytest.mark.parametrize("cov, field", [
    ({"names": ["N_r", "Y_r"], "units": ["1", "1"], "values": [0.0, 0.0], "matrix": [[1.0, 0.5], [0.4, 1.0]]},
     "covariance.matrix.1.0"),
    ({"names": ["N_r", "Y_r"], "units": ["1", "1"], "values": [0.0, 0.0], "matrix": [[1.0, 2.0], [2.0, 1.0]]},
     "covariance.matrix"),
    ({"names": ["N_r", "N_r"], "units": ["1", "1"], "values": [0.0, 0.0], "matrix": [[1.0, 0.0], [0.0, 1.0]]},
     "covariance.names"),
    ({"names": ["N_r"], "units": ["1", "1"], "values": [0.0], "matrix": [[1.0]]}, "covariance.units"),
    ({"names": ["N_r"], "units": ["1"], "values": [0.0], "matrix": [[-1.0]]}, "covariance.matrix.0.0"),
])
def test_a_bad_covariance_section_is_refused_naming_it(cov, field, tmp_path):
    from mmg.errors import InputError
    from trials.measured.identify import ship_yaml

    yml = tmp_path / "ship.yaml"
    yml.write_text(ship_yaml(mmg.config_path("ships", "esso_osaka.yaml"), {}, "bad covariance (test)", cov))
    with pytest.raises(InputError) as e:
        mmg.load_ship(yml)
    assert e.value.field == field and "\n" not in str(e.value)


def test_samples_on_a_dask_cluster_match_a_serial_run(tmp_path):
    """The same samples through a dask LocalCluster (the executor of --backend dask) give the serial
    run's numbers, criterion by criterion."""
    distributed = pytest.importorskip("distributed")
    from trials.imo.sampling import local_executor

    ship = mmg.load_ship("esso_osaka")
    cov = {"names": ["N_r"], "values": [ship.hull.value("N_r")], "matrix": [[(0.1 * ship.hull.value("N_r")) ** 2]]}
    ser = mmg.imo(ship, samples=4, cov=cov, seed=2, executor=serial)
    with distributed.LocalCluster(n_workers=2, processes=False, threads_per_worker=1,
                                  dashboard_address=":0") as cluster, distributed.Client(cluster) as client:
        par = mmg.imo(ship, samples=4, cov=cov, seed=2, executor=local_executor(backend="dask", client=client))
    assert par.as_dict() == ser.as_dict()
    assert par.samples == ser.samples


def test_interval_text_has_its_unit_and_says_unbounded():
    """A 90 % interval on the console carries the criterion's unit; an end among failed samples (None) is
    'unbounded', not a bare '-' that reads as a missing figure."""
    from trials.imo.report import interval_text

    assert interval_text([2.1849, 3.5], "L") == "[2.18, 3.5] L"
    assert interval_text([2.1849, None], "L") == "[2.18, unbounded] L"
    assert interval_text(None, "deg") == "-"
