"""Where the bundled configs live: ships, trials, estimation, nomoto, design.

The configs are kept in the top-level ``configs/`` folder of the checkout and are
shipped in the wheel as the data-only package ``mmg.configs`` (``pyproject.toml``
maps ``mmg.configs`` onto ``configs/``).  :func:`config_dir` finds that folder

1. through :mod:`importlib.resources` (``mmg.configs``): a wheel install, where the
   files sit in ``site-packages/mmg/configs``, and an editable install, whose import
   hook maps ``mmg.configs`` onto the checkout's ``configs/``;
2. failing that, next to the ``mmg`` package (``<checkout>/configs``): a plain checkout
   run without installing (``PYTHONPATH=.``) or an editable install made before the
   mapping existed.

Bundled names are file stems: ``ship_path("esso_osaka")`` is
``<config_dir>/ships/esso_osaka.yaml``, ``trial_path("zz20")`` is
``<config_dir>/trials/zz20.yaml``.  Anything that looks like a path (a
:class:`pathlib.Path`, a string with a directory separator or a ``.yaml``/``.yml``
suffix) is taken as a path.

This module imports nothing heavy; ``import mmg`` stays cheap.
"""
from __future__ import annotations

import functools
import importlib.util
import os
from importlib import resources
from pathlib import Path

from .errors import InputError

__all__ = ["config_dir", "config_path", "ship_path", "trial_path", "bundled", "package_version"]

KINDS = ("ships", "trials", "estimation", "nomoto", "design")
"""The sub-folders of the config folder."""

_PACKAGE = "mmg.configs"
_CHECKOUT = Path(__file__).resolve().parent.parent / "configs"


def package_version() -> str:
    """The installed ``mmg-toolkit`` version (``mmg.__version__``).

    Returns
    -------
    str
        From the package metadata; ``"0+unknown"`` in a checkout that was never installed.
    """
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("mmg-toolkit")
    except PackageNotFoundError:
        return "0+unknown"


def _is_config_dir(p: Path) -> bool:
    return (p / "ships").is_dir() and (p / "trials").is_dir()


def _packaged() -> Path | None:
    """The ``mmg.configs`` package folder, when it is installed and on the filesystem."""
    try:
        root = resources.files(_PACKAGE)
    except (ModuleNotFoundError, TypeError):
        return None
    candidates = [root] if isinstance(root, Path) else []
    if not candidates:  # a namespace package: importlib gives a MultiplexedPath
        spec = importlib.util.find_spec(_PACKAGE)
        candidates = [Path(p) for p in (spec.submodule_search_locations or [])] if spec else []
    for c in candidates:
        if _is_config_dir(c):
            return c.resolve()
    return None


@functools.lru_cache(maxsize=None)
def config_dir() -> Path:
    """The folder holding the bundled configs.

    Returns
    -------
    pathlib.Path
        A real filesystem folder with the sub-folders ``ships/``, ``trials/``,
        ``estimation/``, ``nomoto/`` and ``design/``: ``site-packages/mmg/configs`` in a
        wheel install, the checkout's ``configs/`` in an editable install or a checkout.

    Raises
    ------
    mmg.errors.InputError
        When no such folder can be found (e.g. the package was installed from a zip).

    Examples
    --------
    >>> (config_dir() / "ships" / "esso_osaka.yaml").is_file()
    True
    """
    found = _packaged()
    if found is None and _is_config_dir(_CHECKOUT):
        found = _CHECKOUT
    if found is None:
        raise InputError(_PACKAGE, "", "bundled configs not found: neither the installed package "
                                       f"mmg.configs nor {_CHECKOUT} holds ships/ and trials/")
    return found


def config_path(*parts: str | os.PathLike) -> Path:
    """The path of a bundled config file or folder.

    Parameters
    ----------
    *parts : str or os.PathLike
        Path components below :func:`config_dir`, e.g. ``("ships", "esso_osaka.yaml")``
        or ``("estimation/rhee_kim.yaml",)``.  No parts: the config folder itself.

    Returns
    -------
    pathlib.Path
        The existing file or folder.

    Raises
    ------
    mmg.errors.InputError
        When nothing exists at that path (one line naming it).

    Examples
    --------
    >>> config_path("estimation", "rhee_kim.yaml").name
    'rhee_kim.yaml'
    """
    p = config_dir().joinpath(*[os.fspath(x) for x in parts])
    if not p.exists():
        rel = "/".join(os.fspath(x) for x in parts)
        raise InputError(f"configs/{rel}", "", f"no such bundled config (looked in {config_dir()})")
    return p


def bundled(kind: str) -> list[str]:
    """The bundled names of one kind of config (file stems, sorted).

    Parameters
    ----------
    kind : {"ships", "trials", "estimation", "nomoto", "design"}

    Returns
    -------
    list of str
        E.g. ``bundled("ships") == ["esso_osaka", "kvlcc2_l7"]``.
    """
    if kind not in KINDS:
        raise InputError("kind", "", f"unknown config kind {kind!r} (use one of: {', '.join(KINDS)})")
    folder = config_dir() / kind
    return sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []


def _looks_like_path(x) -> bool:
    if isinstance(x, os.PathLike):
        return True
    s = str(x)
    return ("/" in s or os.sep in s or (os.altsep is not None and os.altsep in s)
            or s.endswith((".yaml", ".yml")) or s in (".", ".."))


def _resolve(kind: str, name_or_path: str | os.PathLike, what: str) -> Path:
    if not isinstance(name_or_path, (str, os.PathLike)):
        raise InputError(what, "", f"expected a bundled {what} name or a path, got {type(name_or_path).__name__}")
    if _looks_like_path(name_or_path):
        return Path(name_or_path)
    name = str(name_or_path)
    p = config_dir() / kind / f"{name}.yaml"
    if p.is_file():
        return p
    if Path(name).is_file():  # a file without a suffix in the working directory
        return Path(name)
    raise InputError(name, "", f"no bundled {what} of that name (bundled: {', '.join(bundled(kind))}); "
                               "or give a path to a YAML file")


def ship_path(name_or_path: str | os.PathLike) -> Path:
    """The ship YAML for a bundled ship name or a path.

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A bundled ship name (the file stem: ``"esso_osaka"``, ``"kvlcc2_l7"``) or a path
        to a ship YAML (returned as given, not checked: the loader reports a missing file).

    Returns
    -------
    pathlib.Path

    Raises
    ------
    mmg.errors.InputError
        For a name that is neither bundled nor an existing file.
    """
    return _resolve("ships", name_or_path, "ship")


def trial_path(name_or_path: str | os.PathLike) -> Path:
    """The trial YAML for a bundled trial name or a path.

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A bundled trial name (the file stem: ``"st35"``, ``"zz20"``, ``"zz10"``,
        ``"stype90"``, ...) or a path to a trial YAML (returned as given).

    Returns
    -------
    pathlib.Path

    Raises
    ------
    mmg.errors.InputError
        For a name that is neither bundled nor an existing file.
    """
    return _resolve("trials", name_or_path, "trial")
