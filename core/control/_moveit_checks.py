"""MoveIt's checks around an execution: the start state before sending it, the duration envelope after.

They follow MoveIt's TrajectoryExecutionManager: a trajectory whose first point is too
far from the current state is not sent, and an execution that runs longer than the
planned duration allows is stopped.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..config import ExecutionConfig
from .results import START_STATE_INVALID, ToleranceReport, Violation, result_of
from .tolerances import position_error

__all__ = ["Timeout", "check_start_state", "expected_duration_s"]


@dataclass(frozen=True)
class Timeout:
    """When an unfinished execution is given up: after `time_s` [s], saying `message`."""

    time_s: float
    message: str


def expected_duration_s(duration_s: float, execution: ExecutionConfig) -> float:
    """Return MoveIt's upper bound on the execution time in [s]: duration x scaling + margin."""
    scaling = execution.allowed_execution_duration_scaling
    return float(duration_s * scaling + execution.allowed_goal_duration_margin)


def check_start_state(
    joint_names: Sequence[str],
    start: npt.ArrayLike,
    first_point: npt.ArrayLike,
    allowed_start_tolerance: float,
    continuous: npt.ArrayLike | None = None,
) -> ToleranceReport | None:
    """Return a failed report if the start is too far from the first point, else None.

    MoveIt's TrajectoryExecutionManager check before it sends a trajectory: per joint
    distance (shortest angle for continuous joints) strictly above
    `allowed_start_tolerance` fails; a tolerance of 0 skips the check.
    """
    if allowed_start_tolerance <= 0.0:
        return None
    reference = np.asarray(first_point, dtype=np.float64)
    actual = np.asarray(start, dtype=np.float64)
    error = position_error(reference, actual, continuous)
    violations = tuple(
        Violation("start_tolerance", joint, 0.0, float(reference[j]), float(actual[j]),
                  float(error[j]), allowed_start_tolerance)
        for j, joint in enumerate(joint_names)
        if not abs(error[j]) <= allowed_start_tolerance  # a NaN state is no start within it
    )
    if not violations:
        return None
    first = violations[0]
    message = (
        f"Invalid Trajectory: start point deviates from current robot state more than "
        f"{allowed_start_tolerance:g} at joint '{first.joint}' (expected {first.reference:.6g}, "
        f"current {first.actual:.6g})"
    )
    return ToleranceReport(result_of(START_STATE_INVALID, message), violations, {}, 0)
