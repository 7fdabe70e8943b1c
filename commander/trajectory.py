"""Planned motions as moveit_msgs/RobotTrajectory messages and back, and MoveIt's error codes for failed plans.

A trajectory plan() returns remembers the step it came from, so that executing it unchanged
executes (and saves) exactly what was planned, to the last bit; an edited one is read back
from its fields.
"""

from __future__ import annotations

import reprlib
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.errors import (
    GoalInCollision,
    GoalOutsideLimits,
    GoalUnreachable,
    GoalViolatesConstraints,
    NoPlan,
    PlanningFailed,
    PlanningTimeExceeded,
    SolutionsCollide,
    StartInCollision,
    StartOutsideLimits,
    StartViolatesConstraints,
    UsageError,
)
from ..core.types import JointTrajectory, StepResult
from .msgs import Duration, Header, JointTrajectoryPoint, MoveItErrorCodes, RobotTrajectory
from .msgs import JointTrajectory as JointTrajectoryMsg

__all__ = ["error_code", "from_message", "to_message"]

_STEP = "_moveplan_step"  # attribute of a returned message: the step it was made from
_TIME_MATCH_S = 1e-8  # time_from_start holds whole nanoseconds: a planned time comes back within 0.5 ns

# Most specific first: StartInCollision and GoalInCollision are both InCollision.
_CODES: tuple[tuple[type[NoPlan], int], ...] = (
    (StartViolatesConstraints, MoveItErrorCodes.START_STATE_VIOLATES_PATH_CONSTRAINTS),
    (GoalViolatesConstraints, MoveItErrorCodes.GOAL_VIOLATES_PATH_CONSTRAINTS),
    (StartInCollision, MoveItErrorCodes.START_STATE_IN_COLLISION),
    (GoalInCollision, MoveItErrorCodes.GOAL_IN_COLLISION),
    (StartOutsideLimits, MoveItErrorCodes.START_STATE_INVALID),
    (GoalOutsideLimits, MoveItErrorCodes.GOAL_STATE_INVALID),
    (GoalUnreachable, MoveItErrorCodes.NO_IK_SOLUTION),
    (PlanningTimeExceeded, MoveItErrorCodes.TIMED_OUT),
    (PlanningFailed, MoveItErrorCodes.PLANNING_FAILED),
)


def error_code(error: NoPlan | None, pilz: bool = False) -> MoveItErrorCodes:
    """Return MoveIt's error code for why a plan failed (SUCCESS for None), its message the error's.

    With `pilz`, a collision is INVALID_MOTION_PLAN: Pilz plans without checking, and move_group
    refuses the motion it planned (pilz_industrial_motion_planner's python_move_group_planning.py).
    """
    if error is None:
        return MoveItErrorCodes(MoveItErrorCodes.SUCCESS, "", "moveplan")
    if pilz and isinstance(error, StartInCollision | GoalInCollision | SolutionsCollide | PlanningFailed):
        return MoveItErrorCodes(MoveItErrorCodes.INVALID_MOTION_PLAN, str(error), "moveplan")
    value = next((code for kind, code in _CODES if isinstance(error, kind)), MoveItErrorCodes.FAILURE)
    return MoveItErrorCodes(value, str(error), "moveplan")


def to_message(step: StepResult | None, frame: str) -> RobotTrajectory:
    """Return the RobotTrajectory of a planned step (an empty one for None), its header in `frame`."""
    message = RobotTrajectory(JointTrajectoryMsg(Header(frame_id=frame)))
    if step is None:
        return message
    trajectory = step.trajectory
    message.joint_trajectory.joint_names = list(trajectory.joint_names)
    message.joint_trajectory.points = [
        JointTrajectoryPoint(positions=p.tolist(), velocities=v.tolist(), accelerations=a.tolist(),
                             time_from_start=Duration.from_sec(float(t)))
        for t, p, v, a in zip(trajectory.times_s, trajectory.positions, trajectory.velocities,
                              trajectory.accelerations, strict=True)
    ]
    setattr(message, _STEP, step)
    return message


def from_message(message: Any, joints: Sequence[str], where: str) -> StepResult:
    """Return the step a RobotTrajectory (or a trajectory_msgs JointTrajectory) holds, for the group's `joints`.

    The trajectory's joints must be group joints, in any order; velocities and accelerations left
    empty are zero (every point a stop).

    Raises:
        UsageError: No points, a joint outside the group, a point of the wrong size, or times that
            do not increase; the message begins with `where`.
    """
    source = message.joint_trajectory if hasattr(message, "joint_trajectory") else message
    if not hasattr(source, "joint_names") or not hasattr(source, "points"):
        raise UsageError(f"{where}: expected a RobotTrajectory or a trajectory_msgs JointTrajectory, "
                         f"got {type(message).__name__}")
    for key in ("joint_names", "points"):
        value = getattr(source, key)
        if isinstance(value, str) or not hasattr(value, "__iter__"):
            raise UsageError(f"{where}: {key}: expected a list, got {reprlib.repr(value)}")
    names = [str(n) for n in source.joint_names]
    points = list(source.points)
    for k, point in enumerate(points):
        if not all(hasattr(point, key) for key in ("positions", "velocities", "accelerations")) \
                or not hasattr(getattr(point, "time_from_start", None), "to_sec"):
            raise UsageError(f"{where}: points[{k}]: expected a JointTrajectoryPoint with a Duration "
                             f"time_from_start, got {reprlib.repr(point)}")
    if not points:
        raise UsageError(f"{where}: the trajectory has no points")
    unknown = [n for n in names if n not in joints]
    if unknown or len(set(names)) != len(names) or not names:
        raise UsageError(f"{where}: joint_names {names}: expected distinct joints of the group ({', '.join(joints)})")
    columns = [_field(points, key, len(names), where) for key in ("positions", "velocities", "accelerations")]
    try:
        times = np.array([p.time_from_start.to_sec() for p in points], dtype=float)
    except (TypeError, ValueError):
        raise UsageError(f"{where}: points hold a time_from_start that is not a number of seconds") from None
    try:
        trajectory = JointTrajectory(tuple(names), times, *columns)
    except ValueError as exc:
        raise UsageError(f"{where}: {exc}") from None
    planned: StepResult | None = getattr(message, _STEP, None)
    if planned is not None and _same(planned.trajectory, trajectory):
        return planned
    return StepResult(name="trajectory", goal={"trajectory": {"points": len(points)}}, planner="given",
                      planning_time_s=0.0, trajectory=trajectory)


def _field(points: list[Any], key: str, width: int, where: str) -> NDArray[np.float64]:
    """Return one field of every point as an array (K, width); a field empty on every point is zeros."""
    try:
        rows = [list(getattr(p, key)) for p in points]
    except TypeError:
        raise UsageError(f"{where}: points hold {key} that are not lists of numbers") from None
    if key != "positions" and not any(rows):
        return np.zeros((len(points), width))
    for k, row in enumerate(rows):
        if len(row) != width:
            raise UsageError(f"{where}: points[{k}].{key} has {len(row)} values; the trajectory has {width} joints")
    try:
        return np.array(rows, dtype=float)
    except (TypeError, ValueError):
        raise UsageError(f"{where}: points hold {key} that are not numbers") from None


def _same(planned: JointTrajectory, given: JointTrajectory) -> bool:
    """Return True if `given` is `planned` read back from its message, unchanged."""
    return (planned.joint_names == given.joint_names and planned.positions.shape == given.positions.shape
            and bool(np.array_equal(planned.positions, given.positions))
            and bool(np.array_equal(planned.velocities, given.velocities))
            and bool(np.array_equal(planned.accelerations, given.accelerations))
            and bool(np.allclose(planned.times_s, given.times_s, rtol=0.0, atol=_TIME_MATCH_S)))
