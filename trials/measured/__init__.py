"""Measured records against the model.  Replay of a record against its own rudder and revolutions
(:mod:`.predict`, ``mmg predict``; its 90 % bands from the identified ship's uncertainty, :mod:`.bands`, the
ship drawn from its covariance by :mod:`.draws`, the heading error of the model's form by :mod:`.modelform`;
a learned correction of the residual forces, :mod:`.hybrid`), identification of a ship model from records and its
cross-validation (:mod:`.identify`, ``mmg identify``; whether its stated uncertainty holds from one group
of records to the next, :mod:`.foldspread`), the discrepancy workflow that names the
effect the model is missing (the package :mod:`.diagnose`, ``mmg diagnose``; the effects themselves, and
where to add one, are :mod:`mmg.effects`), and their figures (:mod:`.predict_plots`,
:mod:`.diagnose.plots`).  May import :mod:`mmg`, :mod:`ekf`, :mod:`trials.files` and
:mod:`trials.analysis` (not the simulated trials of :mod:`trials.runs`).

The diagnosis's modules are also importable under their flat names (:data:`MODULE_ALIASES`:
``trials.measured.decision`` is ``trials.measured.diagnose.decision``, the same module object).
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys

MODULE_ALIASES = {
    "decision": "diagnose.decision",
    "calibration": "diagnose.calibration",
    "identifiability": "diagnose.identifiability",
    "diagnose_report": "diagnose.report",
    "diagnose_plots": "diagnose.plots",
    "diagnose_records": "diagnose.records",
}
"""Flat module name in :mod:`trials.measured` -> the module of the :mod:`.diagnose` package it names."""


class _AliasLoader(importlib.abc.Loader):
    def __init__(self, target: str):
        self.target = target

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        # the import system returns what sys.modules holds under the name after this: the target itself
        sys.modules[module.__name__] = importlib.import_module(self.target)


class _AliasFinder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        head, _, tail = fullname.rpartition(".")
        if head != __name__ or tail not in MODULE_ALIASES:
            return None
        return importlib.util.spec_from_loader(fullname, _AliasLoader(f"{__name__}.{MODULE_ALIASES[tail]}"))


if not any(isinstance(f, _AliasFinder) for f in sys.meta_path):
    sys.meta_path.append(_AliasFinder())
