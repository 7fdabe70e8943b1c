"""The part of ROS's tf.transformations that workshop scripts use: quaternions, Euler angles, 4x4 matrices.

Quaternions are [x, y, z, w]; Euler angles are ROS's default "sxyz" (roll, pitch, yaw about
the fixed x, y, z axes, R = Rz(yaw) Ry(pitch) Rx(roll)), the convention of URDF's rpy, of
MoveGroupCommander's six-number poses and of core/rotations.py. Other axis conventions are
refused. The formulas are tf.transformations' own, in numpy: a script's numbers are what they
were under ROS to the last bit, which pinocchio's (core/rotations.py) are not.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ..core.errors import UsageError
from ..core.rotations import MIN_QUATERNION_NORM

__all__ = [
    "euler_from_quaternion", "euler_matrix", "quaternion_from_euler", "quaternion_from_matrix", "quaternion_matrix",
    "quaternion_multiply",
]


def _sxyz(axes: str) -> None:
    """Raise UsageError unless `axes` is "sxyz", the one convention supported."""
    if axes != "sxyz":
        raise UsageError(f"axes '{axes}': only 'sxyz' (roll, pitch, yaw about the fixed x, y, z axes) is supported")


def quaternion_from_euler(ai: float, aj: float, ak: float, axes: str = "sxyz") -> NDArray[np.float64]:
    """Return the quaternion [x, y, z, w] of roll `ai`, pitch `aj`, yaw `ak` in [rad] (fixed axes)."""
    _sxyz(axes)
    return quaternion_from_matrix(euler_matrix(ai, aj, ak))


def euler_matrix(ai: float, aj: float, ak: float, axes: str = "sxyz") -> NDArray[np.float64]:
    """Return the 4x4 rotation Rz(ak) Ry(aj) Rx(ai) of roll, pitch, yaw in [rad]."""
    _sxyz(axes)
    cr, sr, cp, sp, cy, sy = math.cos(ai), math.sin(ai), math.cos(aj), math.sin(aj), math.cos(ak), math.sin(ak)
    matrix = np.eye(4)
    matrix[:3, :3] = [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
    return matrix


def euler_from_quaternion(quaternion: Sequence[float], axes: str = "sxyz") -> tuple[float, float, float]:
    """Return (roll, pitch, yaw) in [rad] of a quaternion [x, y, z, w]."""
    _sxyz(axes)
    r = quaternion_matrix(quaternion)
    cos_pitch = math.hypot(r[0, 0], r[1, 0])
    if cos_pitch > 1e-9:
        return math.atan2(r[2, 1], r[2, 2]), math.atan2(-r[2, 0], cos_pitch), math.atan2(r[1, 0], r[0, 0])
    # Pitch at +-90 degrees: roll and yaw turn about the same axis; all of it goes to roll.
    return math.atan2(-r[1, 2], r[1, 1]), math.atan2(-r[2, 0], cos_pitch), 0.0


def quaternion_matrix(quaternion: Sequence[float]) -> NDArray[np.float64]:
    """Return the 4x4 rotation of a quaternion [x, y, z, w], normalised first.

    Raises:
        UsageError: The quaternion is zero or not finite.
    """
    q = np.asarray(quaternion, dtype=float)
    norm = float(np.linalg.norm(q)) if q.shape == (4,) else 0.0
    if not math.isfinite(norm) or norm < MIN_QUATERNION_NORM:
        raise UsageError(f"quaternion {list(np.ravel(q))}: expected [x, y, z, w] of nonzero finite norm")
    x, y, z, w = q / norm
    matrix = np.eye(4)
    matrix[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    return matrix


def quaternion_from_matrix(matrix: npt.ArrayLike) -> NDArray[np.float64]:
    """Return the quaternion [x, y, z, w] (w >= 0) of the rotation in a 3x3 or 4x4 matrix."""
    r = np.asarray(matrix, dtype=float)[:3, :3]
    # Shepperd's method: divide by the largest of the four candidates, never by a small one.
    candidates = [1.0 + r[0, 0] + r[1, 1] + r[2, 2], 1.0 + r[0, 0] - r[1, 1] - r[2, 2],
                  1.0 - r[0, 0] + r[1, 1] - r[2, 2], 1.0 - r[0, 0] - r[1, 1] + r[2, 2]]
    k = int(np.argmax(candidates))
    s = 2.0 * math.sqrt(max(candidates[k], 0.0))
    if k == 0:
        q = [(r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, s / 4]
    elif k == 1:
        q = [s / 4, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s, (r[2, 1] - r[1, 2]) / s]
    elif k == 2:
        q = [(r[0, 1] + r[1, 0]) / s, s / 4, (r[1, 2] + r[2, 1]) / s, (r[0, 2] - r[2, 0]) / s]
    else:
        q = [(r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, s / 4, (r[1, 0] - r[0, 1]) / s]
    result: NDArray[np.float64] = np.array(q) / np.linalg.norm(q)
    return -result if result[3] < 0 else result


def quaternion_multiply(quaternion1: Sequence[float], quaternion0: Sequence[float]) -> NDArray[np.float64]:
    """Return the product quaternion1 * quaternion0 (rotate by quaternion0, then by quaternion1), [x, y, z, w]."""
    x1, y1, z1, w1 = quaternion1
    x0, y0, z0, w0 = quaternion0
    return np.array([
        w1 * x0 + x1 * w0 + y1 * z0 - z1 * y0,
        w1 * y0 - x1 * z0 + y1 * w0 + z1 * x0,
        w1 * z0 + x1 * y0 - y1 * x0 + z1 * w0,
        w1 * w0 - x1 * x0 - y1 * y0 - z1 * z0,
    ])
