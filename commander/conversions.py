"""moveit_commander.conversions' list helpers, and poses and transforms as 4x4 matrices.

Lists are MoveIt's: [x, y, z, qx, qy, qz, qw] or [x, y, z, roll, pitch, yaw] (fixed-axis
angles in [rad]).
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.config import MAX_MAGNITUDE
from ..core.errors import UsageError
from .msgs import Point, Pose, PoseStamped, Quaternion, Transform, Vector3
from .transformations import quaternion_from_euler, quaternion_from_matrix, quaternion_matrix

__all__ = [
    "list_to_pose", "list_to_pose_stamped", "list_to_transform", "matrix_to_pose", "matrix_to_transform",
    "pose_to_list", "pose_to_matrix", "transform_to_list", "transform_to_matrix",
]


def pose_to_list(pose: Pose) -> list[float]:
    """Return [x, y, z, qx, qy, qz, qw] of a Pose."""
    p, q = pose.position, pose.orientation
    return [p.x, p.y, p.z, q.x, q.y, q.z, q.w]


def list_to_pose(values: Sequence[float]) -> Pose:
    """Return the Pose of [x, y, z, qx, qy, qz, qw] or [x, y, z, roll, pitch, yaw].

    Raises:
        UsageError: Not 6 or 7 finite numbers.
    """
    numbers = _numbers(values, "pose list")
    if len(numbers) == 6:
        roll, pitch, yaw = numbers[3:]
        quaternion = list(quaternion_from_euler(roll, pitch, yaw))
    elif len(numbers) == 7:
        quaternion = numbers[3:]
        quaternion_matrix(quaternion)  # refuses a zero quaternion here, not when planning
    else:
        raise UsageError(f"pose list {list(values)}: expected [x, y, z, qx, qy, qz, qw] or [x, y, z, roll, pitch, "
                         f"yaw], got {len(numbers)} numbers")
    return Pose(Point(*numbers[:3]), Quaternion(*quaternion))


def list_to_pose_stamped(values: Sequence[float], target_frame: str) -> PoseStamped:
    """Return the PoseStamped of a pose list in `target_frame`."""
    stamped = PoseStamped(pose=list_to_pose(values))
    stamped.header.frame_id = target_frame
    return stamped


def transform_to_list(transform: Transform) -> list[float]:
    """Return [x, y, z, qx, qy, qz, qw] of a Transform."""
    t, q = transform.translation, transform.rotation
    return [t.x, t.y, t.z, q.x, q.y, q.z, q.w]


def list_to_transform(values: Sequence[float]) -> Transform:
    """Return the Transform of [x, y, z, qx, qy, qz, qw] or [x, y, z, roll, pitch, yaw]."""
    pose = list_to_pose(values)
    return Transform(Vector3(pose.position.x, pose.position.y, pose.position.z), pose.orientation)


def pose_to_matrix(pose: Pose, where: str = "pose") -> NDArray[np.float64]:
    """Return the 4x4 matrix of a Pose (its quaternion normalised); `where` names it in errors."""
    return _matrix(pose_to_list(pose), where)


def transform_to_matrix(transform: Transform, where: str = "transform") -> NDArray[np.float64]:
    """Return the 4x4 matrix of a Transform (its quaternion normalised)."""
    return _matrix(transform_to_list(transform), where)


def matrix_to_pose(matrix: NDArray[np.float64]) -> Pose:
    """Return the Pose of a 4x4 matrix, its quaternion's w >= 0."""
    x, y, z = (float(v) for v in matrix[:3, 3])
    q = quaternion_from_matrix(matrix)
    return Pose(Point(x, y, z), Quaternion(*(float(v) for v in (-q if q[3] < 0 else q))))


def matrix_to_transform(matrix: NDArray[np.float64]) -> Transform:
    """Return the Transform of a 4x4 matrix."""
    pose = matrix_to_pose(matrix)
    return Transform(Vector3(pose.position.x, pose.position.y, pose.position.z), pose.orientation)


def _matrix(values: list[float], where: str) -> NDArray[np.float64]:
    """Return the 4x4 matrix of [x, y, z, qx, qy, qz, qw]."""
    numbers = _numbers(values, where)
    # A scene file's coordinates have the same bound: at 1e18 m the collision library's bounding volumes break.
    if any(abs(v) > MAX_MAGNITUDE for v in numbers[:3]):
        raise UsageError(f"{where}: position {numbers[:3]} is out of range; coordinates are limited to "
                         f"|value| <= {MAX_MAGNITUDE:,.0f} m")
    try:
        matrix = quaternion_matrix(numbers[3:])
    except UsageError:
        raise UsageError(f"{where}: orientation {numbers[3:]} is not a rotation: expected a quaternion "
                         "[x, y, z, w] of nonzero norm") from None
    matrix[:3, 3] = numbers[:3]
    return matrix


def _numbers(values: Any, where: str) -> list[float]:
    """Return `values` as a list of finite floats, else raise UsageError naming `where`."""
    try:
        numbers = [float(v) for v in values]
    except (TypeError, ValueError, OverflowError):  # OverflowError: an integer of 400 digits
        raise UsageError(f"{where}: expected numbers, got {reprlib.repr(values)}") from None
    if not all(math.isfinite(v) for v in numbers):
        raise UsageError(f"{where}: expected finite numbers, got {numbers}")
    return numbers
