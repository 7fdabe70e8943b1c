"""A joint-space polyline with its corners rounded, as a piecewise polynomial of the path parameter.

A polyline cannot be followed without stopping at its corners. Here each corner is
replaced by a quartic that leaves the incoming segment and joins the outgoing one
with matching position, direction and zero curvature, so the path is twice
continuously differentiable and the rest of every segment is followed exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ..types import frozen_array

__all__ = ["BlendedPath", "blended_path", "distinct_waypoints"]

_REPEAT = 1e-12  # [rad] a waypoint within this of the one before in every joint repeats it


@dataclass(frozen=True)
class BlendedPath:
    """Straight pieces and corner blends, each a polynomial of degree <= 4 in the path parameter.

    The path parameter s [rad] is the arc length along the straight pieces; a blend spans
    the arc length of the two segment ends it replaces, so dq/ds has unit length at both
    of its ends and is a mean of the two directions in between (shorter, 0 at a reversal).

    Attributes:
        breaks: Path parameter at the start of each piece, and at the end of the path, shape (P + 1,).
        coefficients: Per piece, the coefficients of (s - start)^0..4, shape (P, 5, n).
        turns: Per piece, |d_out - d_in| of the corner it rounds (d: the segments' unit
            directions; 2 at a reversal), 0 for a straight piece, shape (P,).
    """

    breaks: NDArray[np.float64]
    coefficients: NDArray[np.float64]
    turns: NDArray[np.float64]
    # Per power k of (s - start), the coefficients of q, dq/ds and d2q/ds2 per piece, shape (5, 3, P, n).
    _table: NDArray[np.float64] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        breaks = frozen_array(self.breaks, (None,), "breaks")
        coefficients = frozen_array(self.coefficients, (len(breaks) - 1, 5, None), "coefficients")
        if (breaks[1:] <= breaks[:-1]).any():
            raise ValueError("breaks must be strictly increasing")
        object.__setattr__(self, "breaks", breaks)
        object.__setattr__(self, "coefficients", coefficients)
        object.__setattr__(self, "turns", frozen_array(self.turns, (len(coefficients),), "turns"))
        powers = coefficients.transpose(1, 0, 2)
        table = np.zeros((5, 3, *powers.shape[1:]))
        table[:, 0] = powers
        table[:4, 1] = powers[1:] * _FIRST
        table[:3, 2] = powers[2:] * _SECOND
        table.setflags(write=False)
        object.__setattr__(self, "_table", table)

    @property
    def blend(self) -> NDArray[np.bool_]:
        """Return per piece True if it rounds a corner."""
        return self.turns > 0.0

    @property
    def length(self) -> float:
        """Return the path parameter at the end of the path in [rad]."""
        return float(self.breaks[-1])

    def __call__(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Return the joint positions and their first and second derivatives by s at `s`, each (len(s), n)."""
        positions, first, second = self._evaluate(s, self._table)
        return positions, first, second

    def derivatives(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Return the first and second derivatives of the joint positions by s at `s`, each (len(s), n)."""
        first, second = self._evaluate(s, self._table[:4, 1:])  # of degree <= 3
        return first, second

    def _evaluate(self, s: NDArray[np.float64], table: NDArray[np.float64]) -> NDArray[np.float64]:
        """Return the polynomials of `table` (per power, shape (k, m, P, n)) at `s`, shape (m, len(s), n)."""
        # Among the inner breaks only: the first and the last piece extend beyond the path's ends.
        piece = np.searchsorted(self.breaks[1:-1], s, side="right")
        x = (s - self.breaks[piece])[:, None]
        terms = np.take(table, piece, axis=2)
        result: NDArray[np.float64] = terms[-1] * x
        for term in terms[-2:0:-1]:
            result += term
            result *= x
        result += terms[0]
        return result


# What the derivatives by s multiply the coefficients of (s - start)^1..4 and ^2..4 by.
_FIRST = np.array([1.0, 2.0, 3.0, 4.0])[:, None, None]
_SECOND = np.array([2.0, 6.0, 12.0])[:, None, None]


def blended_path(waypoints: npt.ArrayLike, max_step: float, fraction: float) -> BlendedPath:
    """Return the polyline through `waypoints` with each corner rounded within a fraction of a step of it.

    Each segment divides into equal steps, as few as keep every joint within `max_step`
    [rad] per step. A corner's blend takes the same arc length h from both of its segments:
    `fraction` of the shorter of their steps, and at most half of either segment. It strays
    from the polyline by at most 3/16 h |d_out - d_in| (d: the segments' unit directions),
    at its middle. Repeated waypoints are dropped (distinct_waypoints); at least two distinct
    ones are needed.

    Args:
        waypoints: Joint positions, shape (m, n).
        max_step: The largest joint motion of a step, in [rad].
        fraction: How much of a step a blend takes from each segment.
    """
    points = np.asarray(waypoints, dtype=np.float64)
    steps = points[1:] - points[:-1]
    moves = np.abs(steps).max(axis=1)  # of the largest joint
    if not (moves > _REPEAT).all():
        points = distinct_waypoints(points)
        steps = points[1:] - points[:-1]
        moves = np.abs(steps).max(axis=1)
    if len(points) < 2:
        raise ValueError("a path needs two distinct waypoints")
    lengths = np.sqrt((steps * steps).sum(axis=1))
    directions = steps / lengths[:, None]
    reach = np.minimum(fraction / np.ceil(moves / max_step), 0.5) * lengths
    turns = directions[1:] - directions[:-1]
    turn = np.sqrt((turns * turns).sum(axis=1))
    # Each blend is symmetric: the same arc length taken from both segments.
    half = np.zeros(len(points))
    half[1:-1] = np.where(turn > 1e-9, np.minimum(reach[:-1], reach[1:]), 0.0)
    # Pieces in order: straight 0, blend 1, straight 1, ..., blend m-2, straight m-2; empty ones dropped.
    count, n = len(steps), points.shape[1]
    coefficients = np.zeros((2 * count - 1, 5, n))
    span = np.zeros(2 * count - 1)
    straight = coefficients[::2]
    straight[:, 0], straight[:, 1] = points[:-1] + half[:-1, None] * directions, directions
    span[::2] = lengths - half[:-1] - half[1:]
    # q(x) = corner - h d_in + x d_in + turn (x^3 / 4h^2 - x^4 / 16h^3), x in [0, 2h]: it leaves
    # the incoming segment and joins the outgoing one with equal direction and zero curvature.
    h = half[1:-1, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        blend = coefficients[1::2]
        blend[:, 0], blend[:, 1] = points[1:-1] - h * directions[:-1], directions[:-1]
        blend[:, 3], blend[:, 4] = turns / (4 * h**2), -turns / (16 * h**3)
    span[1::2] = 2 * half[1:-1]
    keep = span > 1e-12
    turned = np.zeros(2 * count - 1)
    turned[1::2] = turn
    return BlendedPath(np.concatenate(([0.0], span[keep].cumsum())), coefficients[keep], turned[keep])


def distinct_waypoints(waypoints: npt.ArrayLike) -> NDArray[np.float64]:
    """Return the waypoints without repeats, from the first to the last as given (one point if all repeat).

    A waypoint repeats the one kept before it if no joint differs by more than 1e-12 rad;
    a repeat at the end replaces the waypoints it repeats, so the path ends where they do.
    """
    points = np.asarray(waypoints, dtype=np.float64)
    if (np.abs(points[1:] - points[:-1]).max(axis=1) > _REPEAT).all():
        return points
    kept = [0]
    for i in range(1, len(points) - 1):
        if np.abs(points[i] - points[kept[-1]]).max() > _REPEAT:
            kept.append(i)
    while len(kept) > 1 and np.abs(points[-1] - points[kept[-1]]).max() <= _REPEAT:
        kept.pop()
    if np.abs(points[-1] - points[kept[-1]]).max() > _REPEAT:
        kept.append(len(points) - 1)
    return points[kept]
