"""A lazy ``njit``: numba is imported when compiled code is first needed, not when a module is.

``import numba`` and the typing registries numba loads at its first compiled call cost about
0.3 s of a fresh process, more than a whole simulated turn.  A run that needs no JIT-compiled
code (the simulator's ahead-of-time compiled kernels, :mod:`mmg._aot`; reading a log; metrics)
should not pay it.  Every compiled function of the project is therefore declared with
:func:`njit` from here: it records the Python function and the options and returns a
:class:`LazyJit` stand-in.  The first time any stand-in is called (or numba meets one while
compiling other code), :func:`materialize` imports numba, makes the real dispatcher of every
recorded function, in the order they were declared, and puts each dispatcher in place of its
stand-in in the namespaces of the loaded modules, so that compiled code referring to another
compiled function by its global name sees a numba dispatcher, as it would have without this
module.  Numba's on-disk cache is keyed by the Python function, so cached code is the same.

Numba keys a cached function by its own file alone: an edit of a function it calls or inlines from
another file leaves the old code in the cache, served without a word (an edit of the model once left
the replay returning NaN).  So every compiled function of the project is cached in a folder named
by :func:`source_key`, a hash of every ``.py`` file of its package and of the packages with compiled
code that package imports, found by walking their folders (no list of files to keep): any edit of
their sources, a new file too, compiles into a new folder (:func:`cache_folder`).
"""
from __future__ import annotations

import hashlib
import os
import re
import sys
import threading
import time
from pathlib import Path

__all__ = ["njit", "LazyJit", "materialize", "materialized", "interpreted", "carray", "readonly", "source_key",
           "cache_folder"]

_registry: list["LazyJit"] = []
_packages: set[str] = {__name__.split(".")[0]}   # top-level packages that declare compiled code
_keys: dict[str, str] = {}
_lock = threading.RLock()
_done = False


class LazyJit:
    """Stand-in for ``numba.njit(**options)(py_func)`` until :func:`materialize`."""

    def __init__(self, py_func, options: dict):
        self.py_func = py_func
        self.options = options
        self._dispatcher = None
        self.__name__ = py_func.__name__
        self.__qualname__ = py_func.__qualname__
        self.__doc__ = py_func.__doc__
        self.__module__ = py_func.__module__
        self.__wrapped__ = py_func

    @property
    def dispatcher(self):
        """The numba dispatcher (importing numba and making every declared one first)."""
        if self._dispatcher is None:
            materialize()
        return self._dispatcher

    def __call__(self, *args, **kwargs):
        return self.dispatcher(*args, **kwargs)

    def __getattr__(self, name):                 # signatures, overloads, stats, ...
        if name.startswith("__") or name in ("_dispatcher", "py_func", "options"):
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    @property
    def _numba_type_(self):
        """What numba's ``typeof`` sees when compiled code outside this project meets a stand-in."""
        from numba.core import types

        return types.Dispatcher(self.dispatcher)

    def __repr__(self) -> str:
        state = "compiled" if self._dispatcher is not None else "not yet compiled"
        return f"<LazyJit {self.__module__}.{self.__qualname__} ({state})>"


def njit(*args, **options):
    """``numba.njit`` with the same options, made when compiled code is first needed (module docstring)."""
    def wrap(func):
        with _lock:
            _packages.add(func.__module__.split(".")[0])
            if _done:                              # numba is in use already: the dispatcher itself
                return _dispatcher(func, options)
            lj = LazyJit(func, options)
            _registry.append(lj)
        return lj

    if args and callable(args[0]) and not options and len(args) == 1:
        return wrap(args[0])
    return wrap


def _make(lj: LazyJit) -> None:
    if lj._dispatcher is None:
        lj._dispatcher = _dispatcher(lj.py_func, lj.options)


def _dispatcher(func, options: dict):
    """``numba.njit(**options)(func)``, cached (``cache=True``) in :func:`cache_folder`: numba picks a
    function's cache folder when its dispatcher is made, from ``numba.config.CACHE_DIR``."""
    import numba

    folder = cache_folder(func.__module__) if options.get("cache") else None
    if folder is None:                           # not cached (rather than cached under a stale key)
        return numba.njit(**dict(options, cache=False))(func)
    old = numba.config.CACHE_DIR
    numba.config.CACHE_DIR = str(folder)
    try:
        return numba.njit(**options)(func)
    finally:
        numba.config.CACHE_DIR = old             # other libraries' code keeps its own cache


_IMPORTS = re.compile(rb"^[ \t]*(?:from|import)[ \t]+([A-Za-z_]\w*)", re.M)


def _sources(top: str) -> list[tuple[str, Path]]:
    """The ``.py`` files of top-level package (or script module) ``top``, found by walking its folders,
    with their paths in the package."""
    mod = sys.modules.get(top)
    folders = [Path(d) for d in getattr(mod, "__path__", None) or ()]
    if folders:
        return sorted((f.relative_to(d).as_posix(), f) for d in folders for f in d.rglob("*.py")
                      if "__pycache__" not in f.parts)
    file = getattr(mod, "__file__", None)
    return [(Path(file).name, Path(file))] if file else []


def source_key(module: str) -> str:
    """``"<package>-<hash>"``: a hash of every source file of ``module``'s top-level package and,
    recursively, of the packages declaring compiled code that its files import (read once per process)."""
    top = module.split(".")[0]
    with _lock:
        if top not in _keys:
            h, todo, seen = hashlib.sha256(), [top], set()
            while todo:
                pkg = todo.pop()
                if pkg in seen:
                    continue
                seen.add(pkg)
                for name, f in _sources(pkg):
                    data = f.read_bytes()
                    h.update(f"{pkg}/{name}:{len(data)}:".encode() + data)
                    todo += [n for n in dict.fromkeys(m.decode() for m in _IMPORTS.findall(data)) if n in _packages]
            _keys[top] = f"{top}-{h.hexdigest()[:16]}"
        return _keys[top]


def cache_folder(module: str) -> Path | None:
    """Where the compiled code of ``module`` is cached: ``<root>/<source_key>``, the root being
    ``$NUMBA_CACHE_DIR/mmg-toolkit``, else ``mmg/__pycache__/compiled`` when writable, else
    ``~/.cache/mmg-toolkit`` (None where it cannot be made).  Folders of other sources of the same
    package not used for a week are removed."""
    env = os.environ.get("NUMBA_CACHE_DIR")
    root = Path(env) / "mmg-toolkit" if env else Path(__file__).resolve().parent / "__pycache__" / "compiled"
    try:
        root.mkdir(parents=True, exist_ok=True)
        if not os.access(root, os.W_OK):
            raise OSError(root)
    except OSError:
        root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "mmg-toolkit"
    key = source_key(module)
    folder = root / key
    try:
        if not folder.is_dir():
            folder.mkdir(parents=True)
            _prune(root, key)
        os.utime(folder)                           # in use: not pruned
    except FileExistsError:                        # made by another process just now
        pass
    except OSError:
        return None
    return folder


def _prune(root: Path, key: str) -> None:
    import shutil

    for old in root.glob(key.rsplit("-", 1)[0] + "-*"):
        try:
            if old.name != key and time.time() - old.stat().st_mtime > 7 * 86400:
                shutil.rmtree(old, ignore_errors=True)
        except OSError:
            pass


def _substitute() -> None:
    """Put each dispatcher in place of its stand-in in every loaded module's namespace."""
    for mod in list(sys.modules.values()):
        d = getattr(mod, "__dict__", None)
        if not isinstance(d, dict):
            continue
        for k, v in list(d.items()):
            if type(v) is LazyJit and v._dispatcher is not None:
                d[k] = v._dispatcher


def materialize() -> None:
    """Import numba and make the dispatcher of every function declared with :func:`njit` (idempotent)."""
    global _done
    with _lock:
        if _done and all(lj._dispatcher is not None for lj in _registry):
            return
        for lj in list(_registry):
            _make(lj)
        _done = True
        _substitute()


def materialized() -> bool:
    """Whether numba's dispatchers have been made in this process."""
    return _done


def _python_original(obj):
    """The Python function behind a stand-in or a numba dispatcher, else None."""
    if type(obj) is LazyJit:
        return obj.py_func
    if type(obj).__module__.startswith("numba"):
        return getattr(obj, "py_func", None)
    return None


_interpreted: dict = {}


def interpreted(func):
    """``func`` (a compiled function of the project, or its Python original) run by the interpreter:
    a copy of its Python original whose calls to other compiled functions, by their global names,
    go to their own interpreted copies, recursively.

    The same source as the compiled code, so the same physics; for the few calls where compiling
    would cost seconds and the interpreter microseconds (the straight-run solver's 30-60 model
    evaluations before a simulation, :mod:`mmg.equilibrium`).  Results agree with the compiled
    function's to rounding (``tests/test_aot.py``).  Functions reached through closures are not
    replaced (those of the hot loops; not for use here)."""
    import types

    f = _python_original(func) or func
    with _lock:
        clone = _interpreted.get(f)
        if clone is not None:
            return clone
        g = dict(f.__globals__)
        clone = types.FunctionType(f.__code__, g, f.__name__, f.__defaults__, f.__closure__)
        clone.__kwdefaults__, clone.__doc__, clone.__qualname__ = f.__kwdefaults__, f.__doc__, f.__qualname__
        _interpreted[f] = clone                   # before the callees: a recursive call finds it
        for name in _global_names(f.__code__):
            if _python_original(g.get(name)) is not None:
                g[name] = interpreted(g[name])
        return clone


def _global_names(code) -> set:
    """The names a code object (and the code nested in it) may look up as globals."""
    names = set(code.co_names)
    for c in code.co_consts:
        if hasattr(c, "co_names"):
            names |= _global_names(c)
    return names


def carray(a, dtype=float):
    """``a`` as the array type every compiled call of the project is specialised for: C-contiguous,
    writeable, of ``dtype`` (copied only when it is not already).

    Numba compiles one specialisation per argument type, and read-only or strided is another type
    (a pandas column, a broadcast, a slice): each would cost a compilation of seconds on a cold cache."""
    import numpy as np

    return np.require(a, dtype=dtype, requirements=("C", "W"))


def readonly(a):
    """``a`` (an index array a module hands to its compiled code as a global) made read-only: numba
    freezes a global array as a read-only constant, and a Python caller passing the same array then
    gets the same specialisation instead of a writeable one."""
    a.setflags(write=False)
    return a
