"""The public Python API (the ``mmg`` facade) and the README's "Python" example."""
import dataclasses
import re
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import yaml  # noqa: E402

import mmg  # noqa: E402
from mmg.units import DEG, KNOT  # noqa: E402

from .conftest import CONFIGS, REPO  # noqa: E402

LOG_COLUMNS = ["time_s", "lat_deg", "lon_deg", "heading_deg", "speed_kn", "rpm"]


@pytest.fixture(scope="module")
def zz20():
    return mmg.simulate(mmg.load_trial("zz20"))


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


# --------------------------------------------------------------------------- the facade

def test_import_mmg_is_cheap():
    code = ("import sys, mmg; heavy = [m for m in ('pandas', 'matplotlib', 'scipy', 'filterpy', 'numba') "
            "if m in sys.modules]; print(heavy); assert not heavy, heavy; print(mmg.__version__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO)
    assert out.returncode == 0, out.stdout + out.stderr


def test_all_names_resolve_and_version():
    for name in mmg.__all__:
        assert getattr(mmg, name) is not None, name
    assert set(dir(mmg)) >= set(mmg.__all__)
    for name in ("load_ship", "load_trial", "simulate", "turning", "zigzag", "Ship", "Trial",
                 "InputError", "config_path"):
        assert name in mmg.__all__
    from importlib.metadata import version

    assert mmg.__version__ == version("mmg-toolkit")
    assert mmg.InputError is __import__("mmg.errors").errors.InputError
    with pytest.raises(AttributeError):
        mmg.no_such_name  # noqa: B018


def test_readme_python_example_runs(tmp_path, monkeypatch):
    text = (REPO / "README.md").read_text()
    m = re.search(r"^## Python\n.*?^```python\n(.*?)^```", text, re.S | re.M)
    assert m, "README.md has no '## Python' section with a python code block"
    monkeypatch.chdir(tmp_path)
    exec(compile(m.group(1), "README.md (Python)", "exec"), {"__name__": "__readme__"})
    assert (tmp_path / "zz20_track.png").stat().st_size > 1000


def test_physics_simulate_unchanged(esso):
    from mmg.integrate import CommandLaw
    from mmg.simulation import simulate

    r = simulate(esso, CommandLaw.schedule([0.0, 100.0], [35 * DEG, 35 * DEG]), 100.0, 0.1, 10 * KNOT)
    assert r.t[-1] == pytest.approx(100.0) and r.r[-1] > 0


# --------------------------------------------------------------------------- builders and loaders

def test_zigzag_builder_equals_bundled_zz20(zz20):
    ship = mmg.load_ship("esso_osaka")
    trial = mmg.zigzag(ship, rudder="20 deg", heading="20 deg", speed="10 kn", duration="3000 s")
    bundled = zz20.trial
    for f in ("u0", "n0", "trim", "duration", "dt", "kind", "manoeuvre", "effects", "ship"):
        assert getattr(trial, f) == getattr(bundled, f), f
    res = mmg.simulate(trial)
    np.testing.assert_array_equal(res.states, zz20.states)
    np.testing.assert_array_equal(res.orders, zz20.orders)
    # the ship by bundled name gives the same trial, with the ship file recorded
    by_name = mmg.zigzag("esso_osaka", rudder="20 deg", speed="10 kn", duration="3000 s")
    assert by_name.ship == bundled.ship and by_name.manoeuvre == bundled.manoeuvre
    assert by_name.ship_path == bundled.ship_path == str(mmg.config_path("ships", "esso_osaka.yaml"))


def test_turning_builder_equals_bundled_st35():
    st35 = mmg.simulate("st35")
    built = mmg.simulate(mmg.turning("esso_osaka", rudder="35 deg", speed="10 kn", duration="3000 s"))
    np.testing.assert_array_equal(built.states, st35.states)
    m = built.metrics()
    assert 2.0 < m["tactical_diameter_L"] < 6.0 and m["advance_L"] > 2.0


def test_zz20_metrics_sane_and_port_starboard_symmetric(zz20):
    m = zz20.metrics()
    assert m["kind"] == "zigzag" and m["completed"]
    ov = np.asarray(m["overshoots_deg"])
    assert len(ov) >= 4
    assert np.all((ov > 3) & (ov < 25)), ov  # a large tanker at 20/20: about 10 deg
    port = mmg.simulate(mmg.zigzag("esso_osaka", rudder="20 deg", speed="10 kn", duration="3000 s", first="port"))
    # the first order goes the other way and the heading mirrors
    assert np.sign(port.orders[5]) == -np.sign(zz20.orders[5]) == -1
    i = int(np.argmax(np.abs(zz20.psi[:6000])))
    assert port.psi[i] == pytest.approx(-zz20.psi[i], rel=0.1)
    # Y_0, N_0 break the symmetry slightly: the overshoots agree within 1 deg
    np.testing.assert_allclose(port.metrics()["overshoots_deg"][:3], ov[:3], atol=1.0)


def test_stype_and_schedule_builders():
    st = mmg.stype("esso_osaka", rudder="35 deg", switch_heading="120 deg", speed="10 kn", duration="3000 s")
    bundled = mmg.load_trial("stype120")
    assert st.manoeuvre == bundled.manoeuvre and st.kind == "stype"
    sc = mmg.schedule("esso_osaka", table=[[0, 0], [100, 0], [100.1, 20], [500, 20]], speed="10 kn",
                      duration="500 s")
    r = mmg.simulate(sc)
    assert abs(r.orders[500]) < 1e-12 and r.orders[2000] == pytest.approx(20 * DEG)


def test_load_trial_dict_round_trip_equals_file():
    path = CONFIGS / "trials" / "zz20.yaml"
    data = yaml.safe_load(path.read_text())
    assert data["ship"] == "esso_osaka"  # bundled trials name their ship by bundled name
    from_file = mmg.load_trial(path)
    from_dict = mmg.load_trial(data)
    assert from_dict.path == "<dict>"
    assert dataclasses.replace(from_dict, path=from_file.path) == from_file
    assert mmg.load_trial("zz20") == from_file
    # a dict naming its ship by absolute path
    data["ship"] = str(CONFIGS / "ships" / "kvlcc2_l7.yaml")
    assert mmg.load_trial(data).ship == mmg.load_ship("kvlcc2_l7")


def test_trial_ship_path_relative_to_the_trial_file(tmp_path, monkeypatch):
    (tmp_path / "ships").mkdir()
    (tmp_path / "trials").mkdir()
    (tmp_path / "ships" / "mine.yaml").write_text((CONFIGS / "ships" / "kvlcc2_l7.yaml").read_text())
    d = yaml.safe_load((CONFIGS / "trials" / "st35.yaml").read_text())
    d["ship"] = "../ships/mine.yaml"
    p = tmp_path / "trials" / "t.yaml"
    p.write_text(yaml.safe_dump(d))
    monkeypatch.chdir(REPO)  # not where the ship file is: the path is relative to the trial file
    t = mmg.load_trial(p)
    assert t.ship == mmg.load_ship("kvlcc2_l7")
    assert t.ship_path == str((tmp_path / "ships" / "mine.yaml").resolve())
    d["ship"] = "kvlcc2_l7"  # a bundled name from a trial file anywhere
    p.write_text(yaml.safe_dump(d))
    assert mmg.load_trial(p).ship_path == str(mmg.config_path("ships", "kvlcc2_l7.yaml"))
    d["ship"] = "no_such_ship"
    p.write_text(yaml.safe_dump(d))
    with pytest.raises(mmg.InputError, match=r"t\.yaml: ship: no bundled ship 'no_such_ship'.*esso_osaka"):
        mmg.load_trial(p)
    d["ship"] = "../ships/missing.yaml"
    p.write_text(yaml.safe_dump(d))
    with pytest.raises(mmg.InputError, match="ship file ../ships/missing.yaml not found"):
        mmg.load_trial(p)


def test_load_ship_by_name_or_path():
    by_name = mmg.load_ship("esso_osaka")
    assert by_name.name == "Esso Osaka"
    assert mmg.load_ship(CONFIGS / "ships" / "esso_osaka.yaml") == by_name
    assert mmg.load_ship(str(CONFIGS / "ships" / "esso_osaka.yaml")) == by_name
    assert isinstance(by_name, mmg.Ship)
    with pytest.raises(mmg.InputError, match="no bundled ship of that name.*kvlcc2_l7"):
        mmg.load_ship("esso")
    with pytest.raises(mmg.InputError, match="file not found"):
        mmg.load_ship("/nonexistent/ship.yaml")
    with pytest.raises(mmg.InputError, match="no bundled trial of that name"):
        mmg.load_trial("zz21")


@pytest.mark.parametrize("kw, field, match", [
    ({"rudder": 20}, "manoeuvre.rudder", "has no unit"),
    ({"rudder": 0.35}, "manoeuvre.rudder", "has no unit"),
    ({"rudder": "20 m"}, "manoeuvre.rudder", "not a angle"),
    ({"rudder": "20deg", "heading": "20 s"}, "manoeuvre.heading", "not a angle"),
    ({"rudder": "40 deg"}, "manoeuvre.rudder", "steering gear limit"),
    ({"speed": "10 deg"}, "approach.speed", "not a speed"),
    ({"speed": 5.0}, "approach.speed", "has no unit"),
    ({"duration": "3000 kn"}, "duration", "not a time"),
    ({"dt": "0.1"}, "dt", "not a time"),  # (units.py reads "0.1" as 0. with unit "1")
    ({"first": "left"}, "manoeuvre.first", "starboard"),
    ({"bogus": 1}, "", "unexpected keyword"),
])
def test_bad_arguments_refused(kw, field, match):
    args = {"rudder": "20 deg", "heading": "20 deg", "speed": "10 kn", "duration": "3000 s"} | kw
    with pytest.raises((mmg.InputError, TypeError), match=match) as e:
        mmg.zigzag("esso_osaka", **args)
    if field:
        assert e.type is mmg.InputError and e.value.field == field and "\n" not in str(e.value)


def test_bad_dict_refused():
    data = yaml.safe_load((CONFIGS / "trials" / "st35.yaml").read_text())
    data["manoeuvre"]["rudder"] = 35
    with pytest.raises(mmg.InputError, match=r"<dict>: manoeuvre.rudder: 35 has no unit.*'35 deg'"):
        mmg.load_trial(data)
    with pytest.raises(mmg.InputError, match="expected a Ship"):
        mmg.zigzag(42, rudder="20 deg", speed="10 kn", duration="3000 s")


# --------------------------------------------------------------------------- the result

def test_to_pandas(zz20):
    df = zz20.to_pandas()
    assert df.index.name == "t" and len(df) == len(zz20.t)
    np.testing.assert_array_equal(df.index.to_numpy(), zz20.t)
    for i, name in enumerate(zz20.state_names):
        np.testing.assert_array_equal(df[name].to_numpy(), zz20.states[:, i])
        np.testing.assert_array_equal(getattr(zz20, name), zz20.states[:, i])
    np.testing.assert_allclose(df["psi_deg"], np.degrees(zz20.psi))
    assert df["heading_deg"].between(0, 360, inclusive="left").all()
    np.testing.assert_allclose(df["U"], np.hypot(df["u"], df["v"]))
    assert df["U_kn"].iloc[0] == pytest.approx(10.0, abs=1e-6)
    np.testing.assert_allclose(df["rpm"], 60 * df["n"])
    np.testing.assert_allclose(df["delta_order_deg"], np.degrees(zz20.orders))
    # drift angle: beta > 0 in a starboard turn (v < 0)
    i = int(np.argmax(zz20.r))
    assert zz20.v[i] < 0 and df["beta"].iloc[i] > 0
    assert df.attrs["trial"] == "ZZ20" and df.attrs["ship"] == "Esso Osaka"


def test_log_seed(zz20):
    a, b = zz20.log(seed=1), zz20.log(seed=2)
    assert list(a.columns) == list(b.columns) == LOG_COLUMNS
    assert len(a) == len(b) == 601
    np.testing.assert_array_equal(a["time_s"], b["time_s"])
    assert not np.allclose(a["lat_deg"], b["lat_deg"], rtol=0, atol=1e-9)
    assert not np.allclose(a["heading_deg"], b["heading_deg"])
    # the same seed, the same log; no seed: the trial's
    np.testing.assert_array_equal(zz20.log(seed=1).to_numpy(), a.to_numpy())
    np.testing.assert_array_equal(zz20.log().to_numpy(), zz20.log(seed=zz20.trial.log.seed).to_numpy())
    # the noise is small: both logs follow the same track
    np.testing.assert_allclose(a["heading_deg"].to_numpy()[:50], b["heading_deg"].to_numpy()[:50], atol=0.05)
    truth = zz20.truth()
    assert truth["psi_rad"].to_numpy()[-1] == zz20.psi[-1]


def test_plot(zz20):
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    fig = zz20.plot()
    assert isinstance(fig, Figure) and len(fig.axes) == 5
    assert fig.axes[0].get_ylabel().startswith("heading")
    track = zz20.plot("track", show=False)
    # a long track comes in stacked same-scale parts (trials.files.plots.track_layout), each drawing the track
    assert isinstance(track, Figure) and track.axes and all(a.lines for a in track.axes)
    f, ax = plt.subplots()
    assert zz20.plot(kind="track", ax=ax) is f and ax.lines
    f5, axs = plt.subplots(5, 1)
    assert zz20.plot(ax=axs) is f5
    with pytest.raises(mmg.InputError, match="unknown plot kind"):
        zz20.plot("bode")
    with pytest.raises(mmg.InputError, match="5 axes"):
        zz20.plot(ax=axs[:2])


def test_repr(zz20):
    r = repr(zz20)
    assert "ZZ20" in r and "Esso Osaka" in r and "3000 s" in r
    t = repr(zz20.trial)
    assert "ZZ20" in t and "zigzag" in t and "rudder=20 deg" in t and "Esso Osaka" in t and "3000 s" in t
    assert len(t) < 300


def test_simulate_accepts_names_paths_and_dicts(zz20):
    assert np.array_equal(mmg.simulate("zz20").states, zz20.states)
    path = CONFIGS / "trials" / "zz20.yaml"
    assert np.array_equal(mmg.simulate(path).states, zz20.states)
    assert np.array_equal(mmg.simulate(yaml.safe_load(path.read_text())).states, zz20.states)
