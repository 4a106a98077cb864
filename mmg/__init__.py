"""MMG ship manoeuvring: simulate ships in sea trials, record the trial logs, measure them.

The public API, in one namespace::

    import mmg
    ship = mmg.load_ship("esso_osaka")                  # a bundled ship, or a ship YAML path
    trial = mmg.zigzag(ship, rudder="20 deg", heading="20 deg", speed="10 kn", duration="3000 s")
    res = mmg.simulate(trial)                           # or mmg.simulate("zz20")
    res.metrics()["overshoots_deg"]
    res.to_pandas(); res.plot("track"); res.log(seed=1)
    est = mmg.estimate("zz20")                          # the augmented EKF on the simulated log
    est.to_pandas(); est.plot()
    m3 = mmg.load_ship("esso_osaka_3m")                 # measured records (FRT-DS-ESSO, logs, truth files)
    pred = mmg.predict(m3, ["turn.csv"]); pred.to_pandas(); pred.runs[0].plot()
    ident = mmg.identify(m3, ["turn.csv", "zigzag.csv"]); ident.fit.to_pandas(); ident.scores()
    diag = mmg.diagnose(m3, ["turn.csv"])               # which effect the model misses
    rep = mmg.imo("esso_osaka"); rep.to_pandas()         # the IMO manoeuvring standards (samples=N: uncertain)

Values with a dimension are strings with their unit, as in the YAML configs
(``"20 deg"``, ``"10 kn"``, ``"3000 s"``); plain numbers and wrong units are refused
with :class:`InputError`.

Names are imported on first use, so ``import mmg`` is cheap (no numpy, numba, pandas,
scipy or matplotlib until something needs them).  The physics lives in the submodules
(:mod:`mmg.ship`, :mod:`mmg.model`, :mod:`mmg.simulation`, ...); trials, logs and
metrics in the :mod:`trials` package; estimators in :mod:`ekf`.
"""
from __future__ import annotations

from importlib import import_module as _import_module

from .errors import InputError
from .resources import package_version as _package_version

__version__: str = _package_version()
"""The installed ``mmg-toolkit`` version (``"0+unknown"`` when not installed)."""

# name -> (module, attribute): imported on first access (PEP 562)
_LAZY = {
    "load_ship": ("mmg.ship", "load_ship"),
    "Ship": ("mmg.ship", "Ship"),
    "load_trial": ("trials.runs.trial", "load_trial"),
    "Trial": ("trials.runs.trial", "Trial"),
    "make_trial": ("trials.runs.trial", "make_trial"),
    "zigzag": ("trials.runs.trial", "zigzag"),
    "turning": ("trials.runs.trial", "turning"),
    "stype": ("trials.runs.trial", "stype"),
    "schedule": ("trials.runs.trial", "schedule"),
    "stopping": ("trials.runs.trial", "stopping"),
    "AsternOrder": ("mmg.engine_order", "AsternOrder"),
    "simulate": ("trials.runs.run", "run_trial"),
    "TrialRun": ("trials.runs.run", "TrialRun"),
    "estimate": ("trials.estimates.estimation", "estimate"),
    "predict": ("trials.measured.predict", "predict"),
    "replay_record": ("trials.measured.predict", "replay_record"),
    "identify": ("trials.measured.identify", "identify"),
    "cross_validate": ("trials.measured.identify", "cross_validate"),
    "diagnose": ("trials.measured.diagnose", "diagnose"),
    "imo": ("trials.imo.result", "imo"),
    "ImoResult": ("trials.imo.result", "ImoResult"),
    "config_dir": ("mmg.resources", "config_dir"),
    "config_path": ("mmg.resources", "config_path"),
    "ship_path": ("mmg.resources", "ship_path"),
    "trial_path": ("mmg.resources", "trial_path"),
}

__all__ = ["__version__", "InputError", *_LAZY]


def __getattr__(name: str):
    try:
        module, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'mmg' has no attribute {name!r}") from None
    value = getattr(_import_module(module), attr)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
