"""How :func:`~trials.measured.diagnose.diagnose` searches: :class:`DiagnoseOptions`."""
from __future__ import annotations

from dataclasses import dataclass, field

from .rules import module_rule, rule

__all__ = ["DiagnoseOptions", "SCREEN_NFEV"]


_RULES = {"SCREEN_NFEV": "screen_nfev"}
"""The module's name of a number of the diagnosis rules (:mod:`.rules`), read-only: ``SCREEN_NFEV``, the
evaluation budget of a candidate's first (screening) fit; see :func:`diagnose`."""
__getattr__ = module_rule(__name__, _RULES)


@dataclass(frozen=True)
class DiagnoseOptions:
    """How :func:`diagnose` searches (each field also a keyword argument of it).

    Attributes
    ----------
    wind : bool or None
        Wind loads in the model from the start: ``False`` (default: wind is then a candidate),
        ``True``, or ``None`` as the ship config says.
    candidates : list of str, optional
        Effect names to try (default: every registered effect).
    segment_s : float, optional
        Segment length [s] (default ``segment_length`` of the diagnosis rules, :mod:`.rules`, times
        sqrt(L/g)).
    stride : int, optional
        Use every ``stride``-th sample in the fits (default: samples ``stride_spacing`` of the rules
        times sqrt(L/g) apart; at least 1).
    max_nfev, screen_nfev : int
        Evaluation budgets of a fit (defaults: ``max_nfev`` and ``screen_nfev`` of the rules): every
        candidate is first fitted (warm, from the current model) with ``screen_nfev``; one the budget
        stopped whose dBIC is positive or whose z clears the threshold is fitted on, up to ``max_nfev``
        in all.
    per_run : bool
        With several records, also diagnose each alone (``runs``).
    ship_free : sequence of str, optional
        The ship's own parameters fitted with the effects (:func:`_ship_free`).
    say : callable, optional
        Where the progress lines go (nowhere when omitted).
    backend : str
        How the per-record diagnoses (``per_run``) are spread: ``"serial"`` (default), ``"loky"``
        (this machine's cores) or ``"dask"`` (the workers of ``client``): the same numbers either way
        (:func:`diagnose_each`).
    client : distributed.Client, optional
        The dask client for ``backend="dask"`` (default: the current one).
    n_jobs : int, optional
        Local workers of ``backend="loky"`` (default: every usable core).
    candidate_start : {"config", "current"}
        Where a candidate's fit starts the ship's own terms: ``"config"`` (default: the config's
        values, the priors' means, with the effects already named at their fitted values) or
        ``"current"`` (the model of the round before, e.g. the baseline fit).  A baseline without
        the effect bends the ship to mimic it (a 1 kn current on a zigzag: Y_rr 7 prior std out),
        and a fit started in that bend stays near it (the current then named at 0.32 m/s for 0.51).
    """

    wind: bool | None = False
    candidates: object = None
    segment_s: float | None = None
    stride: int | None = None
    max_nfev: int = field(default_factory=lambda: rule("max_nfev"))
    per_run: bool = False
    ship_free: object = None
    say: object = None
    screen_nfev: int = field(default_factory=lambda: rule("screen_nfev"))
    backend: str = "serial"
    client: object = None
    n_jobs: int | None = None
    candidate_start: str = "config"
