"""Certification between states: the clearances of a motion's checked states cover every configuration between them.

A state at which every checked pair is at least r apart (its *radius*) proves free every
configuration the motion passes while no robot point has moved r from it, before or after:
travel (core/collision/_certify.py) bounds that motion, and two shapes' distance changes by no
more than their relative motion. The motion from its first state to its last is free once each
two neighbours' radii add up to at least their travel apart. Where they do not, the neighbours
are asked whether every checked pair is far enough apart to close the gap (coal, with that as
its security margin: half the gap, or what a neighbour with more than half leaves), and where
that fails too, the state halfway between is checked: a graze between two
states is found some ten halvings of 5 mm down, and two states closer than coal's contact
distance (core/collision/checker.py CONTACT_M) that still do not cover each other touch.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ._certify import MAX_STATES, Between
from .checker import CONTACT_M

__all__ = ["Judge", "RUN", "Within", "needed", "run_margins", "uncovered_collision"]

Judge = Callable[[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]],
                 tuple[NDArray[np.bool_], NDArray[np.float64]]]
"""Per state (rows of group values, at the travel values given) whether it is free, and its radius [m] (0 if not);
the third argument is the radius worth proving per state."""
RUN = 5
"""Consecutive states one check proves free where no filter gives clearances (`run_margins`)."""
Within = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.bool_]]
"""Per state (rows of group values) whether every checked pair is at least its margin [m] apart."""


def uncovered_collision(
    states: NDArray[np.float64], travel: NDArray[np.float64], radius: NDArray[np.float64], between: Between,
    judge: Judge, within: Within,
) -> NDArray[np.float64] | None:
    """Return a state between free `states` that collides (the earliest found), or None if the motion is free.

    `radius[k]` bounds every checked pair's distance at `states[k]` from below; `travel` is
    ascending; `between` gives the motion's states at travel values.

    Raises:
        InputError: The motion would take more than MAX_STATES states (a path sliding along a
            surface micrometres away for metres).
    """
    radius = radius.copy()
    found: NDArray[np.float64] | None = None
    while len(travel) > 1:
        gap = np.diff(travel)
        need = needed(travel, radius)
        short = np.flatnonzero(radius < need)
        if len(short):
            margin = needed(travel, radius, short)
            apart = within(states[short], margin)
            radius[short[apart]] = margin[apart]
        open_ = np.flatnonzero(radius[:-1] + radius[1:] < gap)
        if not len(open_):
            break
        if len(travel) + len(open_) > MAX_STATES:
            raise InputError(f"a motion passes so close to an obstacle for so long that certifying it takes more than "
                             f"moveplan's {MAX_STATES:,} collision checks")
        middle = (travel[open_] + travel[open_ + 1]) / 2
        added = between(middle)
        free, added_radius = judge(added, middle, _ladder(gap[open_] / 4))  # half its gaps to the neighbours
        free &= gap[open_] > 2 * CONTACT_M  # neighbours this close that do not cover each other touch
        if not free.all():
            first = int(np.argmin(free))
            found = added[first]
            # Only a collision before it can be an earlier one.
            keep = travel < middle[first]
            states, travel, radius = states[keep], travel[keep], radius[keep]
            middle, added, added_radius = middle[:first], added[:first], added_radius[:first]
        order = np.argsort(np.concatenate((travel, middle)), kind="stable")
        states = np.concatenate((states, added))[order]
        travel = np.concatenate((travel, middle))[order]
        radius = np.concatenate((radius, added_radius))[order]
    return found


def needed(
    travel: NDArray[np.float64], radius: NDArray[np.float64], rows: NDArray[np.intp] | None = None
) -> NDArray[np.float64]:
    """Return per state the radius [m] that covers the gaps to its neighbours, given theirs; of `rows`, rounded up.

    Half a gap, less where the neighbour has more than half. Rounded up to a quarter power of
    two, the margins asked of coal are a few distinct values, one batch each.
    """
    gap = np.diff(travel)
    before, after = np.minimum(gap / 2, gap - radius[:-1]), np.minimum(gap / 2, gap - radius[1:])
    need = np.maximum(np.insert(before, 0, 0.0), np.append(after, 0.0))
    return need if rows is None else _ladder(need[rows])


def _ladder(margin: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return each margin [m] rounded up to a quarter power of two."""
    return np.maximum(margin, 2.0 ** (np.ceil(4.0 * np.log2(margin)) / 4.0))


def run_margins(
    travel: NDArray[np.float64], step_m: float
) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.intp], NDArray[np.float64]]:
    """Return per run of RUN states its middle and the margin [m] proving it free; per state its run and radius.

    A middle state whose checked pairs are all a margin apart proves every state of its run
    free, with the margin less its distance in travel from the middle as radius. The margin
    leaves the run's end states at least `step_m` / 2: with states at most `step_m` apart,
    neighbouring runs that both pass cover the motion between them.
    """
    count = len(travel)
    starts = np.arange(0, count, RUN)
    middle = np.minimum(starts + RUN // 2, count - 1)
    run = np.arange(count) // RUN
    offset = np.abs(travel - travel[middle[run]])
    margin = _ladder(np.maximum.reduceat(offset, starts) + step_m / 2)
    return middle, margin, run, margin[run] - offset
