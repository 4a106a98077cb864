"""One sweep mechanism: serial, joblib (loky) and joblib's dask backend give the same numbers."""
from dataclasses import replace

import numpy as np
import pytest

from trials.planning.sensitivity import _task
from trials.files.sweep import run_sweep
from trials.runs.trial import load_trial

from .conftest import CONFIGS


def tasks():
    return [replace(load_trial(CONFIGS / "trials" / f"{s}.yaml"), duration=120.0) for s in ("zz10", "stype60", "st35")]


@pytest.fixture(scope="module")
def serial():
    return run_sweep(_task, tasks(), backend="serial", progress=False)


def test_serial_equals_joblib(serial, capsys):
    par = run_sweep(_task, tasks(), backend="loky", n_jobs=2, labels=["a", "b", "c"])
    err = capsys.readouterr().err
    assert "[3/3]" in err                      # progress shown
    assert [p.trial for p in par] == [s.trial for s in serial]   # task order kept
    for p, s in zip(par, serial):
        assert np.array_equal(p.sums, s.sums)


def test_serial_equals_dask(serial):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, processes=False, threads_per_worker=1,
                                  dashboard_address=":0") as cluster, distributed.Client(cluster) as client:
        par = run_sweep(_task, tasks(), backend="dask", client=client, progress=False)
    for p, s in zip(par, serial):
        assert p.trial == s.trial
        assert np.array_equal(p.sums, s.sums)


def test_unknown_backend():
    with pytest.raises(ValueError, match="unknown sweep backend"):
        run_sweep(abs, [1], backend="mpi")


def _refuse(name):
    from mmg.errors import InputError

    raise InputError(f"{name}.csv", "u", "looks like knots")


def test_an_input_error_in_a_worker_reaches_the_caller_whole():
    """Raised in a loky worker, the error crosses back by pickle with its file, field and message."""
    from mmg.errors import InputError

    with pytest.raises(InputError) as e:
        run_sweep(_refuse, ["run7", "run8"], backend="loky", n_jobs=2, progress=False)
    assert (e.value.source, e.value.field, e.value.message) in {("run7.csv", "u", "looks like knots"), ("run8.csv", "u", "looks like knots")}
