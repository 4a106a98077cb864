"""mmg diagnose over several records: the per-record diagnoses (JSON ``runs``) give the same named
effects and values on every backend (serial, this machine's cores, a dask cluster)."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest


@pytest.fixture(scope="module")
def records():
    import mmg
    from trials.measured.diagnose import RecordNoise, synthetic_record

    ship = mmg.load_ship("esso_osaka_3m")
    recs = [synthetic_record(ship, "zigzag", {"current": {"speed_mps": 0.012, "direction_deg": 70.0}},
                             noise=RecordNoise(seed=4), name="zz_current"),
            synthetic_record(ship, "zigzag", {}, noise=RecordNoise(seed=5), name="zz_clean"),
            synthetic_record(ship, "zigzag", {"current": {"speed_mps": 0.02, "direction_deg": 200.0}},
                             noise=RecordNoise(seed=6), name="zz_current2")]
    return ship, recs


def _summary(runs):
    return [(r.named, {e: {k: round(v, 12) for k, v in p.items()} for e, p in r.parameters.items()},
             [[(c["effect"], c["delta_bic"], c["z"]) for c in rd["candidates"]] for rd in r.rounds],
             {k: round(v, 12) for k, v in r.rms_after.items()}) for r in runs]


@pytest.fixture(scope="module")
def serial(records):
    from trials.measured.diagnose import DiagnoseOptions, diagnose_each

    ship, recs = records
    return diagnose_each(ship, recs, DiagnoseOptions(candidates=["current"]))


def test_serial_diagnoses_name_what_each_record_has(serial):
    assert [r.named for r in serial] == [["current"], [], ["current"]]
    assert serial[2].parameters["current"]["speed_mps"] == pytest.approx(0.02, rel=0.3)


def test_dask_gives_the_same_diagnoses(records, serial):
    distributed = pytest.importorskip("distributed")
    from trials.measured.diagnose import DiagnoseOptions, diagnose_each

    ship, recs = records
    with distributed.LocalCluster(n_workers=2, processes=False, threads_per_worker=1,
                                  dashboard_address=":0") as cluster, distributed.Client(cluster) as client:
        par = diagnose_each(ship, recs, DiagnoseOptions(candidates=["current"], backend="dask", client=client))
    assert _summary(par) == _summary(serial)
    assert [r.records[0].name for r in par] == [r.records[0].name for r in serial]   # record order kept


def test_joint_diagnosis_runs_match_the_records_alone(records, serial):
    """The joint diagnosis's ``runs`` (loky, two local processes) are the records diagnosed alone."""
    from trials.measured.diagnose import diagnose

    ship, recs = records
    d = diagnose(ship, recs, candidates=["current"], per_run=True, backend="loky", n_jobs=2)
    assert _summary(d.runs) == _summary(serial)
    assert np.isfinite(d.rms_after["heading"])


def test_scheduler_without_dask_is_refused(tmp_path):
    r = subprocess.run([sys.executable, "-m", "trials.cli", "diagnose", "--ship", "esso_osaka_3m", __file__,
                        "--json", str(tmp_path / "d.json"), "--scheduler", "tcp://127.0.0.1:1"],
                       capture_output=True, text=True)
    assert r.returncode == 2
    lines = [ln for ln in r.stderr.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and "--scheduler" in lines[0] and "--backend dask" in lines[0], r.stderr
    assert not (tmp_path / "d.json").exists()


@pytest.mark.parametrize("cmd", [["montecarlo", "{out}", "--seeds", "1"], ["imo", "esso_osaka", "--out", "{out}"],
                                 ["output-error", "{out}", "--seeds", "1"]])
def test_every_cluster_command_refuses_a_scheduler_without_dask(tmp_path, cmd):
    out = tmp_path / "out"
    argv = [a.replace("{out}", str(out)) for a in cmd] + ["--scheduler", "tcp://127.0.0.1:1"]
    r = subprocess.run([sys.executable, "-m", "trials.cli", *argv], capture_output=True, text=True)
    assert r.returncode == 2, r.stderr
    lines = [ln for ln in r.stderr.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and "--backend dask" in lines[0], r.stderr
    assert not out.exists()
