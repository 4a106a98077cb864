"""Whole-step switch search for a rebuilt open-loop rudder (``rudder="reconstructed"``)."""
from __future__ import annotations

import numpy as np

from .trial import OETrial
from .trial import switch_steps as switches  # steps k at which the order changes (order[k] != order[k-1])


def _shifted(order: np.ndarray, k: int, d: int) -> np.ndarray | None:
    """The order with its switch at step k moved by d = +-1 step, or None if it would meet another switch."""
    o = order.copy()
    if d < 0:
        if k - 1 < 1 or o[k - 2] != o[k - 1]:
            return None
        o[k - 1] = o[k]
    else:
        if k + 1 >= len(o) or o[k + 1] != o[k]:
            return None
        o[k] = o[k - 1]
    return o


def search_switches(trials: list[OETrial], theta, nuis, verbose: bool = False) -> int:
    """Move each rudder switch of the open-loop orders by whole steps while that lowers the trial's cost.

    The orders rebuilt from the recovered heading switch up to a step (0.1 s) away from the true
    ones, which the positions (noise ~0.05 m) see as hundreds of sigma; the switch steps are
    integer unknowns, found here switch by switch in time order with theta fixed. Returns the
    number of moves (in place on ``trials[i].order``).
    """
    moves = 0
    for i, tr in enumerate(trials):
        if tr.order is None:
            continue
        r = tr.residuals(theta, nuis[i])
        best = r @ r
        for k in switches(tr.order):
            kk = k
            for d in (-1, +1):
                while True:
                    o = _shifted(tr.order, kk, d)
                    if o is None:
                        break
                    old = tr.order
                    tr.order = o
                    r = tr.residuals(theta, nuis[i])
                    c = r @ r
                    if c < best:
                        best = c
                        kk += d
                        moves += 1
                    else:
                        tr.order = old
                        break
        if verbose:
            print(f"    switches of {tr.name}: cost {0.5 * best:.6g}", flush=True)
    return moves


