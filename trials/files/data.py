"""Where the real FRT-DS-ESSO records (free-running runs of the 3 m Esso Osaka model) are found."""
from __future__ import annotations

import os
from pathlib import Path

__all__ = ["FRT_ENV", "FRT_MISSING", "frt_folder", "frt_place"]

FRT_ENV = "MMG_FRT_DATA"
"""The environment variable naming the FRT-DS-ESSO folder (the one holding ``zigzag/``, ``turning/``, ...)."""

FRT_MISSING = f"FRT-DS-ESSO records not found (set {FRT_ENV}=/path/to/frt-ds-esso)"
"""What a user is told when :func:`frt_folder` finds no records."""


def frt_place() -> Path:
    """Where the FRT-DS-ESSO folder is looked for: ``$MMG_FRT_DATA`` when set, else
    ``../shared/data/frt-ds-esso`` beside the repository checkout (it may not exist)."""
    env = os.environ.get(FRT_ENV)
    return Path(env) if env else Path(__file__).resolve().parents[3] / "shared" / "data" / "frt-ds-esso"


def frt_folder() -> Path | None:
    """The FRT-DS-ESSO folder (:func:`frt_place`: ``$MMG_FRT_DATA``, else ``../shared/data/frt-ds-esso``
    beside the repository checkout); None when it holds no records (no ``*/*.csv`` in it).

    Returns
    -------
    pathlib.Path or None
    """
    folder = frt_place()
    return folder if folder.is_dir() and next(folder.glob("*/*.csv"), None) is not None else None
