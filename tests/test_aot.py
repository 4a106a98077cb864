"""The ahead-of-time compiled simulator (:mod:`mmg._aot`) and the lazy ``njit`` (:mod:`mmg._jit`).

* the compiled module's kernel gives the JIT kernel's states, step for step, for a turn, a
  zigzag (the heading-switch law in the loop) and the cross-flow hull with a steady wind and a
  current; its ``rhs`` / ``forces`` give the straight-run solver the JIT's equilibrium;
* a fresh process that only simulates imports neither numba nor scipy, pandas or matplotlib;
* calls from a thread other than the main one get the JIT (``nogil``) kernel;
* a module that cannot be built leaves a marker and the JIT is used, with the same results;
* the lazy ``njit``: stand-ins become numba dispatchers in the modules' namespaces, and
  compiled code outside the project can call a stand-in.
"""
from __future__ import annotations

import math
import subprocess
import sys
import threading

import numpy as np
import pytest

from mmg import _aot
from mmg import model as M
from mmg.effects import effect_set
from mmg.integrate import CommandLaw
from mmg.ship import load_ship
from mmg.simulation import prepare
from mmg.units import DEG, KNOT

from .conftest import REPO


@pytest.fixture(scope="module")
def aot():
    k = _aot.kernels()
    if k is None:
        pytest.skip("the ahead-of-time module cannot be built here (no C compiler or MMG_AOT=0)")
    return k


def _both(pk, x0, law, duration, dt, aot):
    from mmg.kernel import simulate_kernel as jit

    out = []
    for kern in (aot.simulate_kernel, jit):
        nsteps = int(round(duration / dt))
        states, orders = np.empty((nsteps + 1, 8)), np.empty(nsteps + 1)
        n = kern(np.asarray(x0, float), float(dt), nsteps, *pk.args(), int(law.kind), law.params, law.t,
                 law.delta, law.n, states, orders)
        out.append((n, states[:n], orders[:n]))
    return out


@pytest.mark.parametrize("case", ["turn", "zigzag", "wind_current"])
def test_compiled_module_gives_the_jit_states(aot, case):
    if case == "wind_current":
        ship = load_ship("esso_osaka_3m_crossflow")
        es = effect_set({"wind": {"true_speed_mps": 1.8, "true_from_deg": 60.0},
                         "current": {"speed_mps": 0.05, "direction_deg": 200.0}})
    else:
        ship, es = load_ship("esso_osaka"), None
    s = math.sqrt(ship.particulars.L / 325.0)
    pk, eq = prepare(ship, 10 * KNOT * s, effects=es)
    if case == "zigzag":
        law = CommandLaw.heading_switch(20 * DEG, 20 * DEG, -20 * DEG, 1)
    else:
        law = CommandLaw.schedule([0.0, 10.0 * s, 1e4], [0.0, 35 * DEG, 35 * DEG])
    (na, sa, oa), (nj, sj, oj) = _both(pk, eq.state(), law, 600.0 * s, 0.1 * s, aot)
    assert na == nj == sa.shape[0]
    np.testing.assert_allclose(sa, sj, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(oa, oj)
    if case == "zigzag":                                   # the law switched in the loop: both sides ordered
        assert (oa > 0).any() and (oa < 0).any()
    assert abs(sa[-1, M.PSI_]) > 10 * DEG                  # the ship turned: the rudder and hull acted


def test_straight_run_interpreted_agrees_with_the_compiled_model(monkeypatch):
    """The straight-run solver evaluates rhs and forces by the interpreter (mmg._jit.interpreted):
    the same solution as with the JIT-compiled functions, and no numba in the evaluation."""
    import mmg.equilibrium as E
    from mmg.model import forces, rhs

    wind_current = effect_set({"wind": {"true_speed_mps": 1.8, "true_from_deg": 60.0},
                               "current": {"speed_mps": 0.05, "direction_deg": 200.0},
                               "rudder_offset": {"offset_deg": 1.0}})
    for name, es in (("esso_osaka", None), ("esso_osaka_3m", None), ("esso_osaka_3m_crossflow", None),
                     ("esso_osaka_3m_crossflow", wind_current)):
        ship = load_ship(name)
        u0 = 10 * KNOT * math.sqrt(ship.particulars.L / 325.0)
        a = E.straight_run(ship, u0, effects=es)
        with monkeypatch.context() as m:
            m.setattr(E, "model_functions", lambda: (rhs, forces))
            b = E.straight_run(ship, u0, effects=es)
        for f in ("u", "v", "delta", "n", "power_W", "K_Q_scale"):
            assert math.isclose(getattr(a, f), getattr(b, f), rel_tol=1e-10, abs_tol=1e-13), (name, f)
        assert a.residual < 1e-9 and b.residual < 1e-9


def test_interpreted_model_is_pure_python():
    """interpreted() reaches every compiled callee by its Python original (no dispatcher left in the
    copies' namespaces), and agrees with the compiled rhs at random states to rounding."""
    import numpy as np

    from mmg import _jit
    from mmg.model import pack, rhs

    f = _jit.interpreted(rhs)
    clones = set(_jit._interpreted.values())
    seen, todo = set(), [f]
    while todo:                                   # every function the copy can reach by a global name
        g = todo.pop()
        if g in seen:
            continue
        seen.add(g)
        for name in _jit._global_names(g.__code__):
            v = g.__globals__.get(name)
            assert type(v) is not _jit.LazyJit and not type(v).__module__.startswith("numba"), (g.__name__, name)
            if v in clones:
                todo.append(v)
    assert {"hull_primed", "propeller", "rudder", "term_value"} <= {g.__name__ for g in seen}
    pk = pack(load_ship("esso_osaka"), 5.0e6)
    rng = np.random.default_rng(3)
    for _ in range(50):
        x = np.array([rng.uniform(0.5, 8), rng.uniform(-1, 1), rng.uniform(-0.02, 0.02), 0, 0, 0,
                      rng.uniform(-0.6, 0.6), rng.uniform(0.3, 2)])
        o1, o2 = np.zeros(8), np.zeros(8)
        rhs(x, 0.1, *pk.args(), o1)
        f(x, 0.1, *pk.args(), o2)
        np.testing.assert_allclose(o2, o1, rtol=1e-12, atol=1e-14 * np.abs(o1).max())


def test_other_threads_get_the_jit_kernel(aot):
    from mmg.kernel import simulate_kernel as jit

    got = []
    t = threading.Thread(target=lambda: got.append((_aot.kernels(), _aot.simulate_kernel())))
    t.start()
    t.join()
    assert got[0][0] is None and got[0][1] is jit
    assert _aot.simulate_kernel() is aot.simulate_kernel


@pytest.fixture
def no_compiler(tmp_path, monkeypatch):
    """A fresh process's view of an empty cache in ``tmp_path`` where every build fails (no C
    compiler); yields the list of the build's calls."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("MMG_AOT", raising=False)
    monkeypatch.setattr(_aot, "_module", None)
    monkeypatch.setattr(_aot, "_tried", False)
    calls = []

    def build(path=None):
        calls.append(path)
        raise OSError("no C compiler here")

    monkeypatch.setattr(_aot, "build", build)
    return calls


def test_a_failed_build_leaves_a_marker_and_the_jit_runs(no_compiler, monkeypatch):
    calls = no_compiler
    assert _aot.kernels() is None
    marker = _aot.module_path().with_name(_aot.module_name() + ".failed")
    assert marker.is_file() and "no C compiler" in marker.read_text()
    monkeypatch.setattr(_aot, "_tried", False)          # a new process: the marker stops a second try
    assert _aot.kernels() is None and len(calls) == 1
    assert not any(p.name.startswith(".") for p in marker.parent.iterdir())   # no build folder left
    from mmg.kernel import simulate_kernel as jit

    assert _aot.simulate_kernel() is jit


def test_module_name_follows_the_sources(tmp_path, monkeypatch):
    """The module is named by the sources' key (mmg._jit.source_key) and lives in their cache folder:
    another key, another module (no stale kernel is loaded)."""
    from mmg import _jit

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    a, folder = _aot.module_name(), _aot.module_path().parent
    assert folder.name == _jit.source_key("mmg")
    monkeypatch.setitem(_jit._keys, "mmg", "mmg-0000000000000000")
    assert _aot.module_name() != a and _aot.module_path().parent.name == "mmg-0000000000000000"


FRESH = """
import sys, mmg
r = mmg.simulate(mmg.turning('esso_osaka', rudder='35 deg', speed='10 kn', duration='600 s'))
print(round(r.metrics()['advance_L'], 4))
print(sorted(m for m in ('numba', 'scipy', 'pandas', 'matplotlib', 'filterpy') if m in sys.modules))
"""


def test_a_fresh_simulation_imports_only_what_it_needs(aot):
    out = subprocess.run([sys.executable, "-c", FRESH], cwd=REPO, capture_output=True, text=True, check=True)
    adv, mods = out.stdout.strip().splitlines()
    assert mods == "[]", out.stdout
    assert 2.5 < float(adv) < 4.5                          # a 35 deg turn's advance, about 3.5 L


def test_lazy_njit_makes_dispatchers_and_external_code_can_call_them():
    import numba

    from mmg import _jit

    @_jit.njit(cache=False)
    def twice(x):
        return 2.0 * x

    assert twice(3.0) == 6.0                              # calling it makes the dispatcher (or it is one)
    assert _jit.materialized()
    d = twice.dispatcher if isinstance(twice, _jit.LazyJit) else twice
    assert isinstance(d, numba.core.registry.CPUDispatcher)
    assert not isinstance(M.rhs, _jit.LazyJit)            # the model's stand-ins were replaced in place

    @numba.njit
    def outside(x):                                       # numba code outside: calls a stand-in
        return twice(x) + 1.0

    assert outside(2.0) == 5.0


def test_a_stand_in_is_typed_by_numba_before_anything_was_made():
    """In a fresh process, numba code outside the project calling a project function before any of
    ours ran: the stand-in's ``_numba_type_`` makes the dispatchers and types the call."""
    code = ("import numba\nfrom mmg import _jit\nfrom mmg.nondim import r_prime\n"
            "assert isinstance(r_prime, _jit.LazyJit) and not _jit.materialized()\n"
            "f = numba.njit(lambda r: r_prime(r, 2.0, 4.0))\nprint(f(1.0))")
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True)
    assert float(out.stdout) == pytest.approx(0.5)            # r' = r L / U


def test_a_deferred_build_uses_the_jit_now_and_builds_later(no_compiler):
    """Inside build_deferred() a missing module is not built (the JIT runs) and the refusal is not
    remembered: the first call outside builds it."""
    calls = no_compiler
    from mmg.kernel import simulate_kernel as jit

    with _aot.build_deferred():
        assert _aot.simulate_kernel() is jit and _aot.kernels() is None
    assert calls == []
    assert _aot.kernels() is None and len(calls) == 1  # built (tried) now, outside


def test_interrupt_waits_for_the_c_compiler():
    """An interrupt while pycc's C compiler or linker runs is delivered when that run ends: the
    compiler is never cut off (it would write into a removed folder, or a killed compiler would
    mark the module unbuildable); the Python part stays interruptible."""
    import os
    import signal
    import time

    events = []

    class Toolchain:
        def compile_objects(self, *a, **k):
            os.kill(os.getpid(), signal.SIGINT)          # a Ctrl-C while "the compiler" runs
            time.sleep(0.1)
            events.append("compiled")
            return ["x.o"]

        def link_shared(self, *a, **k):
            events.append("linked")

    class CC:
        _toolchain = Toolchain()

        def compile(self):
            self._toolchain.compile_objects()
            events.append("after compile_objects")       # never reached: the interrupt comes first
            self._toolchain.link_shared()

    cc = CC()
    _aot._defer_signals_in_toolchain(cc)
    with pytest.raises(KeyboardInterrupt):
        cc.compile()
    assert events == ["compiled"]

    class Bare:                                          # no toolchain where expected: the whole compile deferred
        def compile(self):
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.1)
            events.append("bare compiled")

    bare = Bare()
    _aot._defer_signals_in_toolchain(bare)
    with pytest.raises(KeyboardInterrupt):
        bare.compile()
    assert events[-1] == "bare compiled"
    assert not signal.pthread_sigmask(signal.SIG_BLOCK, []) & {signal.SIGINT, signal.SIGTERM}
