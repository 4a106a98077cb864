"""What an identified ship's own fit says of it, carried into the IMO verdicts (``mmg imo``).

``mmg identify`` writes an ``identification:`` section into the ship.yaml it makes
(:func:`trials.measured.identify.identification_summary`, read by :mod:`mmg.ship` as
:class:`mmg.ship.IdentificationNotes`): whether every fit stage converged, its warnings, how the
covariance was made and the training records its model replays worse than the initial one.

A criterion computed from such a ship is only as good as the fit.  Two findings say the fit is not
finished, whatever its covariance: a stage stopped at its evaluation limit (the values are not the
optimum the covariance is about) and a training record replayed worse than by the model the fit
started from (the fit made its own data worse).  With either, no criterion is reported as passed:
a verdict ``"pass"`` (probability >= 0.95 with samples, the value within its limit without) becomes
``"undecided"`` with the reason (:meth:`IdentificationDoubts.verdict`).  A ``"fail"`` stands.  A
ship without the section (a config of one's own, a bundled one) has no doubts: its verdicts stand.
"""
from __future__ import annotations

from dataclasses import dataclass

from mmg.ship import Ship

__all__ = ["IdentificationDoubts", "identification_doubts", "DOWNGRADED"]

DOWNGRADED = "undecided"
"""The verdict a pass becomes on a ship whose identification is in doubt."""


@dataclass(frozen=True)
class IdentificationDoubts:
    """The identification's warnings and, where it did not finish, why no criterion may pass.

    Attributes
    ----------
    warnings : tuple of str
        The identification's warnings (its section's ``warnings``), one sentence each.
    reason : str or None
        Why a pass is not claimed (the fit did not converge, or replays training records worse than
        the initial model); None: the verdicts stand.
    """

    warnings: tuple = ()
    reason: str | None = None

    def verdict(self, verdict: str) -> str:
        """``verdict`` as reported: a pass becomes :data:`DOWNGRADED` when there is a :attr:`reason`."""
        return DOWNGRADED if self.reason is not None and verdict == "pass" else verdict


def identification_doubts(ship: Ship) -> IdentificationDoubts:
    """The :class:`IdentificationDoubts` of ``ship`` from its ``identification:`` section (none without one).

    Parameters
    ----------
    ship : Ship
        A ship, e.g. loaded from ``mmg identify``'s ``DIR/ship.yaml``.

    Returns
    -------
    IdentificationDoubts
        ``reason`` is set when the section says ``converged: false`` or names training records replayed
        worse than the initial model (``training_replays_worse``).
    """
    notes = ship.identification
    if notes is None:
        return IdentificationDoubts()
    why = []
    if not notes.converged:
        why.append("the identification did not converge (a fit stage stopped at its evaluation limit)")
    worse = list(notes.training_replays_worse)
    if worse:
        why.append(f"the identified model replays {len(worse)} of its own training records worse than the "
                   f"initial model ({', '.join(worse)})")
    reason = None if not why else ("; ".join(why) + ": no criterion is reported as passed (a pass is "
                                                    f"'{DOWNGRADED}')")
    return IdentificationDoubts(tuple(notes.warnings), reason)
