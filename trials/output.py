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


class Folder:
    """A plain output folder with the ``.path(name)`` interface of :class:`StagedOutput` (created on use)."""

    def __init__(self, out: str | Path):
        self.out = Path(out)

    def path(self, name: str) -> Path:
        p = self.out / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return p


def out_path(out):
    """``out`` when it already has ``.path(name)`` (a :class:`StagedOutput`), else a :class:`Folder` on it."""
    return out if hasattr(out, "path") else Folder(out)


def fmt(v, nd: int = 4) -> str:
    """A value for a printed table: 4 significant digits, lists as [a, b, ...], None as '-'."""
    if v is None:
        return "-"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(f"{x:.{min(nd, 2)}f}" for x in v) + "]"
    if isinstance(v, (float, np.floating)):
        return f"{v:.{nd}g}"
    return str(v)


def write_trial_outputs(run, stage, show: bool = False) -> dict:
    """log.csv, truth.csv, metrics.json, track.png, histories.png of one simulated trial; returns the metrics."""
    from .logio import write_csv
    from .plots import plot_histories, plot_track

    stage = out_path(stage)
    meta = run.log_meta()
    write_csv(stage.path("log.csv"), run.log(), meta)
    write_csv(stage.path("truth.csv"), run.truth(), meta)
    m = run.metrics()
    dump_json(m, stage.path("metrics.json"))
    r, sh = run.result, run.trial.ship.particulars
    plot_track(r.t, r.x, r.y, r.psi, sh.L, sh.B, f"{run.trial.name} ({run.trial.ship.name})", stage.path("track.png"), show=show)
    plot_histories(r.t, r.psi, r.delta, r.r, r.U, r.n, f"{run.trial.name} ({run.trial.ship.name})",
                   stage.path("histories.png"), delta_order=r.orders, show=show)
    return m
