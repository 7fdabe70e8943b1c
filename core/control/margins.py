"""Margins to the tolerances: per joint, how far the error stayed inside its tolerance, in [rad]."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

import numpy as np
from numpy.typing import NDArray

from .tolerances import SegmentTolerances, tolerance_limits

__all__ = ["merged_margins", "span_margins"]


def span_margins(
    joints: tuple[str, ...], magnitude: NDArray[np.float64], tolerances: SegmentTolerances,
    path_checked: NDArray[np.bool_], starts: NDArray[np.intp], ends: NDArray[np.intp],
    goal: NDArray[np.bool_],
) -> list[dict[str, float]]:
    """Return per span the smallest position tolerance - |error| over the checks that ran.

    `magnitude` is |position error| per cycle and joint, (K, n), the spans stacked; span s
    starts at cycle `starts[s]`. It counts its path-checked cycles up to `ends[s]`, and the
    goal check of cycle `ends[s]` if `goal[s]`. A goal margin before the last cycle says
    nothing: the robot may still be on its way in. Joints without a finite margin (none
    checked, or a diverged error) are left out.
    """
    path, _ = tolerance_limits(tolerances.state)
    goal_tolerance, _ = tolerance_limits(tolerances.goal)
    values = path - magnitude
    values[~path_checked] = np.inf
    for end, stop in zip(ends.tolist(), [*starts[1:].tolist(), len(values)], strict=True):
        values[end + 1 : stop] = np.inf
    margin = np.where(path > 0.0, np.minimum.reduceat(values, starts, axis=0), np.inf)
    goal_margin = goal_tolerance - magnitude[ends]
    margin = np.where((goal_tolerance > 0.0) & goal[:, None], np.minimum(margin, goal_margin),
                      margin)
    return [
        {j: float(m) for j, m in zip(joints, row.tolist(), strict=True) if math.isfinite(m)}
        for row in margin
    ]


def merged_margins(margins: Iterable[Mapping[str, float]]) -> dict[str, float]:
    """Return per joint the smallest of several executions' margins, in [rad]."""
    merged: dict[str, float] = {}
    for each in margins:
        for joint, margin in each.items():
            merged[joint] = min(margin, merged.get(joint, margin))
    return merged
