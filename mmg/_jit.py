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
"""
from __future__ import annotations

import sys
import threading

__all__ = ["njit", "LazyJit", "materialize", "materialized", "interpreted", "carray", "readonly"]

_registry: list["LazyJit"] = []
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
            if _done:                              # numba is in use already: the dispatcher itself
                import numba

                return numba.njit(**options)(func)
            lj = LazyJit(func, options)
            _registry.append(lj)
        return lj

    if args and callable(args[0]) and not options and len(args) == 1:
        return wrap(args[0])
    return wrap


def _make(lj: LazyJit) -> None:
    import numba

    if lj._dispatcher is None:
        lj._dispatcher = numba.njit(**lj.options)(lj.py_func)


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
