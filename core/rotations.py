"""Rotations, in one convention: ROS's.

- Quaternions are [x, y, z, w], as geometry_msgs/Quaternion; one handed out has w >= 0 (q and
  -q are one rotation).
- Roll, pitch and yaw are URDF's rpy and tf's "sxyz": about the fixed x, y and z axes, so
  R = Rz(yaw) Ry(pitch) Rx(roll).
- Rotation matrices are 3x3 float64 arrays; a rotation vector is axis times angle in [rad].

pinocchio computes what reaches a plan (so that a plan file is the same to the last bit on
every machine); it is imported when first needed, so that reading a plan file or `--help`
loads none of it. Many transforms at once (a plan's /tf samples) take numpy's vectorised path.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "MIN_QUATERNION_NORM", "matrix_from_quaternion", "matrix_from_rpy", "matrix_from_rotation_vector",
    "quaternion_from_matrix", "quaternions_xyzw", "rotation_angle", "rotation_vector", "rpy_from_matrix", "tf_poses",
]

MIN_QUATERNION_NORM = 1e-9
"""A quaternion shorter than this is no rotation (MoveIt refuses it too)."""


def matrix_from_rpy(roll: float, pitch: float, yaw: float) -> NDArray[np.float64]:
    """Return the rotation Rz(yaw) Ry(pitch) Rx(roll) of angles in [rad]."""
    import pinocchio as pin

    rotation: NDArray[np.float64] = pin.rpy.rpyToMatrix(roll, pitch, yaw)
    return rotation


def rpy_from_matrix(rotation: NDArray[np.float64]) -> tuple[float, float, float]:
    """Return (roll, pitch, yaw) in [rad] of a rotation; pitch in [-pi/2, pi/2]."""
    import pinocchio as pin

    roll, pitch, yaw = (float(a) for a in pin.rpy.matrixToRpy(rotation))
    return roll, pitch, yaw


def matrix_from_quaternion(xyzw: Sequence[float] | NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the rotation of a quaternion [x, y, z, w] of any nonzero length (it is normalised).

    Raises:
        ValueError: The quaternion is shorter than MIN_QUATERNION_NORM; callers name the input.
    """
    import pinocchio as pin

    x, y, z, w = (float(c) for c in xyzw)
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    if norm < MIN_QUATERNION_NORM:
        raise ValueError("a quaternion [x, y, z, w] of zero norm is not a rotation")
    rotation: NDArray[np.float64] = pin.Quaternion(w / norm, x / norm, y / norm, z / norm).toRotationMatrix()
    return rotation


def quaternion_from_matrix(rotation: NDArray[np.float64]) -> tuple[float, float, float, float]:
    """Return the unit quaternion (x, y, z, w), w >= 0, of a rotation."""
    import pinocchio as pin

    x, y, z, w = (float(c) for c in pin.Quaternion(rotation).normalized().coeffs())
    sign = -1.0 if w < 0 else 1.0
    return sign * x, sign * y, sign * z, sign * w


def rotation_vector(rotation: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the rotation vector (axis times angle in [rad], angle in [0, pi]) of a rotation: SO(3)'s log."""
    import pinocchio as pin

    vector: NDArray[np.float64] = pin.log3(rotation)
    return vector


def rotation_angle(rotation: NDArray[np.float64]) -> float:
    """Return the angle in [rad], in [0, pi], a rotation turns about its axis."""
    # The trace's rounding can step outside [-1, 1] near 0 and pi.
    return float(np.arccos(np.clip((np.trace(rotation) - 1.0) / 2.0, -1.0, 1.0)))


def matrix_from_rotation_vector(vector: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the rotation of a rotation vector (axis times angle in [rad]): SO(3)'s exp."""
    import pinocchio as pin

    rotation: NDArray[np.float64] = pin.exp3(vector)
    return rotation


def tf_poses(transforms: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the /tf poses (..., 7) of 4x4 transforms (..., 4, 4): translation xyz, then quaternion xyzw, w >= 0."""
    return np.concatenate((transforms[..., :3, 3], quaternions_xyzw(transforms)), axis=-1)


def quaternions_xyzw(transforms: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the rotations of 4x4 (or 3x3) transforms (..., 4, 4) as unit quaternions xyzw with w >= 0."""
    if transforms.size <= _FEW * transforms.shape[-1] ** 2:
        try:
            return np.reshape([_quaternion_xyzw(*m) for m in transforms[..., :3, :3].reshape(-1, 9).tolist()],
                              (*transforms.shape[:-2], 4))
        except (ValueError, ZeroDivisionError):
            pass  # not a rotation: numpy's nan and inf, below
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = np.moveaxis(
        transforms[..., :3, :3], (-2, -1), (0, 1)
    )
    trace = m00 + m11 + m22
    # Shepperd's method: divide by the largest of the four candidates, for accuracy. All
    # four are computed and one kept, so the others may divide by zero or take sqrt(< 0).
    with np.errstate(divide="ignore", invalid="ignore"):
        s = 2.0 * np.sqrt(1.0 + trace)
        q0 = [(m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, s / 4]
        s = 2.0 * np.sqrt(1.0 + m00 - m11 - m22)
        q1 = [s / 4, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s]
        s = 2.0 * np.sqrt(1.0 + m11 - m00 - m22)
        q2 = [(m01 + m10) / s, s / 4, (m12 + m21) / s, (m02 - m20) / s]
        s = 2.0 * np.sqrt(1.0 + m22 - m00 - m11)
        q3 = [(m02 + m20) / s, (m12 + m21) / s, s / 4, (m10 - m01) / s]
    # np.select takes the first true condition, like an if/elif chain.
    conditions = [trace > 0.0, (m00 > m11) & (m00 > m22), m11 > m22]
    candidates = [np.stack(q, axis=-1) for q in (q0, q1, q2, q3)]
    xyzw = np.select([c[..., None] for c in conditions], candidates[:3], candidates[3])
    # The norm as a plain sum over the last axis, not BLAS: the same bits for one transform
    # or many, whatever the machine.
    xyzw /= np.linalg.norm(xyzw, axis=-1, keepdims=True)
    result: NDArray[np.float64] = np.where(xyzw[..., 3:] < 0.0, -xyzw, xyzw)
    return result


_FEW = 64
"""Up to this many transforms, each is worked out in plain floats: numpy's ~50 operations cost 0.07 ms at any count."""


def _quaternion_xyzw(
    m00: float, m01: float, m02: float, m10: float, m11: float, m12: float, m20: float, m21: float, m22: float
) -> tuple[float, float, float, float]:
    """Return `quaternions_xyzw` of one rotation, its operations in the same order: the same bits.

    Raises ValueError or ZeroDivisionError where numpy would give nan or inf (not a rotation).
    """
    trace = m00 + m11 + m22
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        x, y, z, w = (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, s / 4
    elif m00 > m11 and m00 > m22:
        s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        x, y, z, w = s / 4, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s
    elif m11 > m22:
        s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        x, y, z, w = (m01 + m10) / s, s / 4, (m12 + m21) / s, (m02 - m20) / s
    else:
        s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        x, y, z, w = (m02 + m20) / s, (m12 + m21) / s, s / 4, (m10 - m01) / s
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    return (-x, -y, -z, -w) if w < 0.0 else (x, y, z, w)
