"""Straight-line tip motion, like MoveIt's compute_cartesian_path.

The tip's position moves along a line and its orientation is slerped. Each
waypoint is solved by IK seeded with the previous one (never restarted, so it
cannot jump branches); between waypoints the joint-space midpoint must stay
within 1 mm and 0.01 rad of the Cartesian midpoint (MoveIt's CartesianPrecision),
else the interval is bisected. Collisions, limits, IK failures and jumps cut
the path short; the fraction achieved is reported with the reason.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import GoalUnreachable
from ..model import Robot, solve_ik
from ..rotations import matrix_from_rotation_vector, rotation_vector
from ..trajectory import interpolate
from ..types import frozen_array
from .goals import pose_error

__all__ = ["LinearPath", "straight_line"]

_STEP_M = 0.005
_STEP_RAD = 0.05
_PRECISION_M = 0.001
_PRECISION_RAD = 0.01
_MIN_INTERVAL = 1e-5
_CHECK_RESOLUTION = 0.005


@dataclass(frozen=True)
class LinearPath:
    """Joint waypoints of a straight-line motion and how much of the line they cover.

    Attributes:
        waypoints: Group values, shape (K, dof), first = start.
        fraction: Fraction of the line achieved, in [0, 1].
        reason: Why the path stops short ("" when complete).
        stopped_at: Tip position in the planning frame where it stopped [m].
    """

    waypoints: NDArray[np.float64]
    fraction: float
    reason: str
    stopped_at: NDArray[np.float64]

    def __post_init__(self) -> None:
        object.__setattr__(self, "waypoints", frozen_array(self.waypoints, (None, None), "waypoints"))
        object.__setattr__(self, "stopped_at", frozen_array(self.stopped_at, (3,), "stopped_at"))


def straight_line(
    robot: Robot,
    link: str,
    start: NDArray[np.float64],
    target: NDArray[np.float64],
    base: NDArray[np.float64],
    free_batch: Callable[[NDArray[np.float64]], NDArray[np.bool_]],
    colliding_pair: Callable[[NDArray[np.float64]], tuple[str, str] | None],
) -> LinearPath:
    """Return the joint path moving `link` in a straight line from where it is to `target` (root frame)."""
    origin = robot.frame_pose(robot.configuration(start, base), link)
    rotation = rotation_vector(origin[:3, :3].T @ target[:3, :3])
    distance = float(np.linalg.norm(target[:3, 3] - origin[:3, 3]))
    count = max(1, int(np.ceil(max(distance / _STEP_M, float(np.linalg.norm(rotation)) / _STEP_RAD))))

    def pose_at(s: float) -> NDArray[np.float64]:
        pose = np.eye(4)
        pose[:3, 3] = origin[:3, 3] + s * (target[:3, 3] - origin[:3, 3])
        pose[:3, :3] = origin[:3, :3] @ matrix_from_rotation_vector(s * rotation)
        return pose

    waypoints = [np.asarray(start, dtype=float)]
    reached = 0.0
    for k in range(1, count + 1):
        try:
            segment = _segment(robot, link, base, pose_at, reached, k / count, waypoints[-1])
        except _Stop as stop:
            return _stopped(robot, link, base, waypoints, reached, str(stop))
        for values in segment:
            states = interpolate(waypoints[-1], values, _CHECK_RESOLUTION)
            free = free_batch(states)
            if not free.all():
                pair = colliding_pair(robot.configuration(states[int(np.argmin(free))], base)) or ("?", "?")
                return _stopped(robot, link, base, waypoints, reached, f"collision: {pair[0]} touches {pair[1]}")
            waypoints.append(values)
        reached = k / count
    return LinearPath(np.array(waypoints), 1.0, "", target[:3, 3])


class _Stop(Exception):
    """The line cannot be followed past this point; the message says why."""


def _segment(
    robot: Robot,
    link: str,
    base: NDArray[np.float64],
    pose_at: Callable[[float], NDArray[np.float64]],
    s0: float,
    s1: float,
    q0: NDArray[np.float64],
) -> list[NDArray[np.float64]]:
    """Return waypoints from s0 (at q0, excluded) to s1 meeting the midpoint precision, bisecting if needed."""
    q1 = _ik(robot, link, base, pose_at(s1), q0)
    mid = robot.frame_pose(robot.configuration((q0 + q1) / 2, base), link)
    position, angle = pose_error(mid, pose_at((s0 + s1) / 2))
    if position <= _PRECISION_M and angle <= _PRECISION_RAD:
        return [q1]
    if s1 - s0 < _MIN_INTERVAL:
        raise _Stop(f"joint-space jump ({position * 1e3:.1f} mm off the line between IK solutions)")
    first = _segment(robot, link, base, pose_at, s0, (s0 + s1) / 2, q0)
    return first + _segment(robot, link, base, pose_at, (s0 + s1) / 2, s1, first[-1])


def _ik(
    robot: Robot, link: str, base: NDArray[np.float64], pose: NDArray[np.float64], seed: NDArray[np.float64]
) -> NDArray[np.float64]:
    try:
        return solve_ik(robot, pose, link, seed, base=base, max_attempts=1).values
    except GoalUnreachable as exc:
        raise _Stop(f"no IK solution within the joint limits ({exc})") from None


def _stopped(
    robot: Robot, link: str, base: NDArray[np.float64], waypoints: list[NDArray[np.float64]], reached: float,
    reason: str,
) -> LinearPath:
    where = robot.frame_pose(robot.configuration(waypoints[-1], base), link)[:3, 3]
    return LinearPath(np.array(waypoints), reached, reason, where)
