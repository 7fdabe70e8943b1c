"""Straight-line tip motion, like MoveIt's compute_cartesian_path.

The tip's position moves along a line and its orientation is slerped. Each
waypoint is solved by IK seeded with the previous one (never restarted, so it
cannot jump branches); between waypoints the joint-space midpoint must stay
within 1 mm and 0.01 rad of the Cartesian midpoint (MoveIt's CartesianPrecision),
else the interval is bisected. Collisions, limits, IK failures and jumps cut
the path short; the fraction achieved is reported with the reason.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import GoalUnreachable, PlanningFailed
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
_ARC_TOLERANCE_M = 1e-5  # start and goal this close to one circle about a CIRC center; points this far off a line


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
    arc: tuple[str, NDArray[np.float64]] | None = None,
) -> LinearPath:
    """Return the joint path moving `link` in a straight line from where it is to `target` (root frame).

    With `arc` ("interim" or "center", a point in the root frame), the link's origin moves on the
    circle through the interim point, or about the center (the shorter way), as Pilz's CIRC;
    the orientation turns as on a line. Raises PlanningFailed for a circle the points do not make.
    """
    origin = robot.frame_pose(robot.configuration(start, base), link)
    rotation = rotation_vector(origin[:3, :3].T @ target[:3, :3])
    position_at, distance = _line(origin[:3, 3], target[:3, 3]) if arc is None else _circle(
        origin[:3, 3], target[:3, 3], *arc)
    count = max(1, int(np.ceil(max(distance / _STEP_M, float(np.linalg.norm(rotation)) / _STEP_RAD))))

    def pose_at(s: float) -> NDArray[np.float64]:
        pose = np.eye(4)
        pose[:3, 3] = position_at(s)
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


def _line(a: NDArray[np.float64], b: NDArray[np.float64]) -> tuple[Callable[[float], NDArray[np.float64]], float]:
    """Return the position at s in [0, 1] along the segment a-b, and its length [m]."""
    return (lambda s: a + s * (b - a)), float(np.linalg.norm(b - a))


def _circle(
    a: NDArray[np.float64], b: NDArray[np.float64], kind: str, point: NDArray[np.float64]
) -> tuple[Callable[[float], NDArray[np.float64]], float]:
    """Return the position at s in [0, 1] along Pilz's CIRC arc from a to b, and the arc's length [m].

    "center": about `point`, the shorter way (a and b the same distance from it, not opposite);
    "interim": the circle through a, `point` and b, passing `point`.
    """
    if kind == "center":
        center = point
        ra, rb = a - center, b - center
        if abs(np.linalg.norm(ra) - np.linalg.norm(rb)) > _ARC_TOLERANCE_M:
            raise PlanningFailed(f"CIRC: start and goal are {np.linalg.norm(ra):.4f} m and {np.linalg.norm(rb):.4f} m "
                                 "from the center; a circle needs them the same distance from it")
        normal = np.cross(ra, rb)
        if np.linalg.norm(normal) < _ARC_TOLERANCE_M * max(float(np.linalg.norm(ra)), 1e-9):
            raise PlanningFailed("CIRC: start, center and goal lie on one line; the circle's plane is not defined "
                                 "(give an interim point instead)")
        angle = math.atan2(float(np.linalg.norm(normal)), float(ra @ rb))
    else:
        normal = np.cross(point - a, b - a)
        if np.linalg.norm(normal) < _ARC_TOLERANCE_M * max(float(np.linalg.norm(b - a)), 1e-9):
            raise PlanningFailed("CIRC: start, interim point and goal lie on one line; no circle passes through them")
        center = _circumcenter(a, point, b)
        ra = a - center
        angle = _angle_about(ra, b - center, normal / np.linalg.norm(normal))
    axis = normal / np.linalg.norm(normal)
    radius = float(np.linalg.norm(ra))

    def position_at(s: float) -> NDArray[np.float64]:
        turn = s * angle
        return center + ra * math.cos(turn) + np.cross(axis, ra) * math.sin(turn) + axis * (axis @ ra) * (
            1.0 - math.cos(turn))

    return position_at, radius * angle


def _circumcenter(a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the center of the circle through three points that are not on one line."""
    ab, ac = b - a, c - a
    n = np.cross(ab, ac)
    return a + (np.cross(n, ab) * (ac @ ac) + np.cross(ac, n) * (ab @ ab)) / (2.0 * (n @ n))


def _angle_about(u: NDArray[np.float64], v: NDArray[np.float64], axis: NDArray[np.float64]) -> float:
    """Return the angle in (0, 2 pi) turning u to v counterclockwise about `axis`."""
    angle = math.atan2(float(axis @ np.cross(u, v)), float(u @ v))
    return angle if angle > 0 else angle + 2 * math.pi


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
