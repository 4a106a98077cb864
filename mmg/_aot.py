"""Ahead-of-time compiled simulator kernels: a simulation in a fresh process without numba.

The simulator's hot loop (:func:`mmg.kernel.simulate_kernel`) is compiled once, by
``numba.pycc``, into an extension module, from the very same Python function the JIT compiles
(one definition of the physics; the states are the JIT's to the last bit, a test checks).  The
module imports only numpy, so a process that simulates and does nothing else never imports numba
(whose import and typing registries cost about 0.3 s, more than the simulated turn itself,
``bench/bench_startup.py``).

The module is a cache entry like numba's own: built on first use (about 8 s, instead of the JIT's
compile of the same functions), into the folder of :mod:`mmg`'s compiled code
(:func:`mmg._jit.cache_folder`, named by a hash of every source file of the package), under a name
that also carries numba's version, so an edit of any file of the model or an upgrade builds a new
one.  Where it cannot be built (no C compiler, ``Python.h`` missing) a marker file records why and
the JIT is used from then on; ``MMG_AOT=0`` in the environment always uses the JIT.

``numba.pycc`` is marked pending deprecation by numba; it is kept because without it a fresh
process's 35 deg turn takes 2.3-2.5x as long (numba imported and the JIT's cache loaded: 0.96 s
against 0.41 s, 1.65x shipmmg's 0.58 s turn, whose speed is the target; 2.1-2.6 s against 0.8-1.0 s
on a loaded machine; ``bench/bench_startup.py``, 2026-12-04).  Where a numba has dropped it, the build fails, the
marker is written and the JIT runs (same numbers).

The compiled module holds the GIL while it runs (``pycc`` exports cannot release it), so calls from
threads other than the main one use the JIT kernels (``nogil``: a thread pool's runs go on in
parallel).
"""
from __future__ import annotations

import contextlib
import hashlib
import importlib.machinery
import importlib.util
import os
import tempfile
import threading
from pathlib import Path

from mmg._signals import deferred as signals_deferred

__all__ = ["kernels", "enabled", "module_path", "module_name", "build", "simulate_kernel", "build_deferred"]

# C-contiguous arrays: the layout the JIT's own callers pass, so the callees the build compiles are
# the JIT's specialisations (shared through numba's cache) and not a second, any-layout set
SIG_SIMULATE = ("i8(f8[::1], f8, i8, f8[::1], f8[:,::1], i8[::1], i8[::1], f8[::1], i8, f8[::1], f8[::1], f8[::1], "
                "f8[::1], f8[:,::1], f8[::1])")

_lock = threading.Lock()
_module = None
_tried = False
_deferred = 0


@contextlib.contextmanager
def build_deferred():
    """Inside: the compiled module is used if it is already built, but not built now (the JIT runs
    instead; a later call outside builds it).  For a command whose second core is busy compiling
    other code on a cold cache: the JIT's kernel costs less to compile than the module's build."""
    global _deferred
    with _lock:
        _deferred += 1
    try:
        yield
    finally:
        with _lock:
            _deferred -= 1


def enabled() -> bool:
    """False when ``MMG_AOT=0`` is set (always use the JIT)."""
    return os.environ.get("MMG_AOT", "1").strip() not in ("0", "false", "no", "off")


def _numba_version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("numba")
    except PackageNotFoundError:                  # pragma: no cover - numba is a dependency
        return "none"


def module_name() -> str:
    """The extension module's name for the current sources and numba."""
    from ._jit import source_key

    return "_mmg_aot_" + hashlib.sha256(f"{source_key(__name__)} {_numba_version()}".encode()).hexdigest()[:16]


def module_path() -> Path:
    """Where the compiled module for the current sources is (or will be) cached."""
    from ._jit import cache_folder

    folder = cache_folder(__name__)
    if folder is None:
        raise OSError("no writable cache folder for the compiled module")
    return folder / (module_name() + importlib.machinery.EXTENSION_SUFFIXES[0])


def _load(path: Path):
    name = path.name.split(".")[0]
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def build(path: Path | None = None) -> Path:
    """Compile the module into ``path`` (:func:`module_path` when omitted) and return it.

    Compiled in a temporary folder beside the target and moved into place (atomic: a process
    building the same module at the same time leaves one complete file); nothing is left behind
    when the build fails or is interrupted."""
    import shutil
    import warnings

    with warnings.catch_warnings():              # pycc is "pending deprecation" (numba >= 0.57); still built
        warnings.simplefilter("ignore")
        from numba.pycc import CC

    from . import kernel
    from ._jit import materialize

    materialize()                                # the real dispatchers, not their stand-ins
    path = module_path() if path is None else Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    name = path.name.split(".")[0]
    tmp = Path(tempfile.mkdtemp(prefix=f".{name}-", dir=path.parent))
    old = tempfile.tempdir
    try:
        tempfile.tempdir = str(tmp)              # pycc's own build folder goes in there too
        cc = CC(name, source_module=__name__)
        cc.output_dir = str(tmp)
        sim = kernel.simulate_kernel

        @cc.export("simulate_kernel", SIG_SIMULATE)
        def _simulate(x0, dt, nsteps, p, poly, ha, ht, hc, kind, cpar, st, sd, sn, states, orders):
            return sim(x0, dt, nsteps, p, poly, ha, ht, hc, kind, cpar, st, sd, sn, states, orders)

        _defer_signals_in_toolchain(cc)
        cc.compile()
        os.replace(tmp / cc.output_file, path)
    finally:
        tempfile.tempdir = old
        shutil.rmtree(tmp, ignore_errors=True)
    return path


def _defer_signals_in_toolchain(cc) -> None:
    """The C compiler and linker runs of a pycc build with the interrupt deferred until they end
    (about a second each).  Interrupted, Python would unwind and remove the build folder while the
    compiler it started still writes into it (its "can't create ...o" on the terminal after
    "interrupted").  The Python part of the build (typing, LLVM) stays interruptible.  Where
    pycc's toolchain is not where this numba keeps it, the whole compile is deferred instead."""
    tc = getattr(cc, "_toolchain", None)
    names = ("compile_objects", "link_shared")
    if tc is None or not all(callable(getattr(tc, n, None)) for n in names):
        compile_ = cc.compile

        def compile_all():
            with signals_deferred():
                compile_()

        cc.compile = compile_all
        return
    for n in names:
        def deferred(*a, _f=getattr(tc, n), **k):
            with signals_deferred():
                return _f(*a, **k)

        setattr(tc, n, deferred)


def kernels():
    """The compiled module (attribute ``simulate_kernel``), built on first use;
    None where it is disabled, cannot be built, or the caller is not the main thread (module docstring)."""
    global _module, _tried
    if threading.current_thread() is not threading.main_thread() or not enabled():
        return None
    if _module is not None or _tried:
        return _module
    with _lock:
        if _module is not None or _tried:
            return _module
        try:
            path = module_path()
        except OSError:                           # nowhere to keep it: the JIT it is
            _tried = True
            return None
        if _deferred and not path.is_file():
            return None                           # not now, and not marked as tried: built later
        _tried = True
        failed = path.with_name(path.name.split(".")[0] + ".failed")
        try:
            if not path.is_file():
                if failed.is_file():
                    return None
                try:
                    build(path)
                except Exception as e:            # no compiler, no Python headers: the JIT it is
                    try:
                        failed.parent.mkdir(parents=True, exist_ok=True)
                        failed.write_text(f"{type(e).__name__}: {e}\n")
                    except OSError:
                        pass
                    return None
            _module = _load(path)
        except (ImportError, OSError):
            _module = None
        return _module


def simulate_kernel():
    """The simulator kernel to call here: the compiled module's, or the JIT's."""
    k = kernels()
    if k is not None:
        return k.simulate_kernel
    from .kernel import simulate_kernel as jit

    return jit

