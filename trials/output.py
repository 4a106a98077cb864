"""Output folders written all-or-nothing, and JSON that understands numpy."""
from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np


class StagedOutput:
    """Write files into a temporary folder and move them into ``out`` only on success."""

    def __init__(self, out: str | Path):
        self.out = Path(out)
        self.out.parent.mkdir(parents=True, exist_ok=True) if self.out.parent != Path("") else None
        self.tmp = Path(tempfile.mkdtemp(prefix=".staging-", dir=self.out.parent if str(self.out.parent) else "."))

    def path(self, name: str) -> Path:
        p = self.tmp / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return p

    def commit(self) -> None:
        self.out.mkdir(parents=True, exist_ok=True)
        for p in sorted(self.tmp.rglob("*")):
            if p.is_file():
                dst = self.out / p.relative_to(self.tmp)
                dst.parent.mkdir(parents=True, exist_ok=True)
                os.replace(p, dst)
        shutil.rmtree(self.tmp, ignore_errors=True)

    def abort(self) -> None:
        shutil.rmtree(self.tmp, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.commit()
        else:
            self.abort()
        return False


def _json_default(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(type(o))


def dump_json(obj, path: Path) -> None:
    with open(path, "w") as fh:
        json.dump(obj, fh, indent=2, default=_json_default)
