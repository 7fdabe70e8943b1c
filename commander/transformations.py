"""ROS 1's tf.transformations as scripts use it: 4x4 matrices, quaternions [x, y, z, w], Euler angles of any axes.

tf.transformations is Christoph Gohlke's transformations.py of 2009. Its Euler angle code
lives on, unchanged, in the transforms3d package (transforms3d.euler), which this module calls
for every one of the 24 axis conventions ("sxyz", the default, is roll, pitch, yaw about the
fixed x, y, z axes; "rzyx" the same angles about the moving axes). transforms3d writes
quaternions [w, x, y, z]; tf, and this module, [x, y, z, w]. quaternion_from_matrix is tf's own
algorithm, so a script's numbers are the ones it got under ROS.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray
from transforms3d import euler as _euler

from ..core.errors import UsageError
from ..core.rotations import MIN_QUATERNION_NORM

__all__ = [
    "concatenate_matrices", "euler_from_matrix", "euler_from_quaternion", "euler_matrix", "identity_matrix",
    "inverse_matrix", "is_same_transform", "quaternion_about_axis", "quaternion_conjugate", "quaternion_from_euler",
    "quaternion_from_matrix", "quaternion_inverse", "quaternion_matrix", "quaternion_multiply", "quaternion_slerp",
    "random_quaternion", "rotation_matrix", "translation_from_matrix", "translation_matrix", "unit_vector",
    "vector_norm",
]

_EPS = np.finfo(float).eps * 4.0  # tf's
# 's' static (fixed) or 'r' rotating axes, then the axes in the order the angles turn about them.
_AXES = ("sxyz", "sxyx", "sxzy", "sxzx", "syzx", "syzy", "syxz", "syxy", "szxy", "szxz", "szyx", "szyz",
         "rzyx", "rxyx", "ryzx", "rxzx", "rxzy", "ryzy", "rzxy", "ryxy", "ryxz", "rzxz", "rxyz", "rzyz")


def _axes(axes: str) -> str:
    """Return `axes` if it is one of the 24 conventions, else raise UsageError listing them."""
    if axes not in _AXES:
        raise UsageError(f"axes {axes!r}: expected one of {', '.join(_AXES)} ('s' static or 'r' rotating axes, "
                         "then the three axes in order)")
    return axes


def _quaternion(quaternion: npt.ArrayLike) -> NDArray[np.float64]:
    """Return a quaternion [x, y, z, w] as 4 finite floats of nonzero norm, else raise UsageError."""
    q = np.asarray(quaternion, dtype=float).ravel()
    norm = float(np.linalg.norm(q)) if q.shape == (4,) else 0.0
    if not math.isfinite(norm) or norm < MIN_QUATERNION_NORM:
        raise UsageError(f"quaternion {list(q)}: expected [x, y, z, w] of nonzero finite norm")
    return q


def identity_matrix() -> NDArray[np.float64]:
    """Return the 4x4 identity matrix."""
    return np.identity(4)


def translation_matrix(direction: npt.ArrayLike) -> NDArray[np.float64]:
    """Return the 4x4 matrix translating by `direction` [x, y, z]."""
    matrix = np.identity(4)
    matrix[:3, 3] = np.asarray(direction, dtype=float)[:3]
    return matrix


def translation_from_matrix(matrix: npt.ArrayLike) -> NDArray[np.float64]:
    """Return the translation [x, y, z] of a 4x4 matrix."""
    return np.array(matrix, dtype=float, copy=True)[:3, 3]


def rotation_matrix(angle: float, direction: npt.ArrayLike, point: npt.ArrayLike | None = None
                    ) -> NDArray[np.float64]:
    """Return the 4x4 matrix rotating by `angle` [rad] about the axis `direction` through `point` (default: origin)."""
    matrix = np.identity(4)
    matrix[:3, :3] = quaternion_matrix(quaternion_about_axis(angle, direction))[:3, :3]
    if point is not None:
        p = np.asarray(point, dtype=float)[:3]
        matrix[:3, 3] = p - matrix[:3, :3] @ p
    return matrix


def euler_matrix(ai: float, aj: float, ak: float, axes: str = "sxyz") -> NDArray[np.float64]:
    """Return the 4x4 rotation of Euler angles `ai`, `aj`, `ak` [rad] about `axes`."""
    matrix = np.identity(4)
    matrix[:3, :3] = _euler.euler2mat(ai, aj, ak, _axes(axes))
    return matrix


def euler_from_matrix(matrix: npt.ArrayLike, axes: str = "sxyz") -> tuple[float, float, float]:
    """Return the Euler angles [rad] about `axes` of the rotation in a 3x3 or 4x4 matrix."""
    ai, aj, ak = _euler.mat2euler(np.asarray(matrix, dtype=float)[:3, :3], _axes(axes))
    return float(ai), float(aj), float(ak)


def euler_from_quaternion(quaternion: npt.ArrayLike, axes: str = "sxyz") -> tuple[float, float, float]:
    """Return the Euler angles [rad] about `axes` of a quaternion [x, y, z, w]."""
    return euler_from_matrix(quaternion_matrix(quaternion), axes)


def quaternion_from_euler(ai: float, aj: float, ak: float, axes: str = "sxyz") -> NDArray[np.float64]:
    """Return the quaternion [x, y, z, w] of Euler angles `ai`, `aj`, `ak` [rad] about `axes`."""
    w, x, y, z = _euler.euler2quat(ai, aj, ak, _axes(axes))
    return np.array([x, y, z, w])


def quaternion_about_axis(angle: float, axis: npt.ArrayLike) -> NDArray[np.float64]:
    """Return the quaternion [x, y, z, w] of a rotation by `angle` [rad] about `axis`."""
    q = np.zeros(4)
    q[:3] = np.asarray(axis, dtype=float)[:3]
    length = vector_norm(q)
    if length > _EPS:
        q *= math.sin(angle / 2.0) / length
    q[3] = math.cos(angle / 2.0)
    return q


def quaternion_matrix(quaternion: npt.ArrayLike) -> NDArray[np.float64]:
    """Return the 4x4 rotation of a quaternion [x, y, z, w], normalised first.

    Raises:
        UsageError: The quaternion is zero or not finite.
    """
    q = _quaternion(quaternion)
    x, y, z, w = q / np.linalg.norm(q)
    matrix = np.identity(4)
    matrix[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    return matrix


def quaternion_from_matrix(matrix: npt.ArrayLike) -> NDArray[np.float64]:
    """Return the quaternion [x, y, z, w] of the rotation in a 3x3 or 4x4 matrix (tf's algorithm and sign)."""
    m = np.identity(4)
    m[:3, :3] = np.asarray(matrix, dtype=float)[:3, :3]
    q = np.empty(4)
    t = float(np.trace(m))
    if t > m[3, 3]:
        q[3] = t
        q[2] = m[1, 0] - m[0, 1]
        q[1] = m[0, 2] - m[2, 0]
        q[0] = m[2, 1] - m[1, 2]
    else:
        i, j, k = 0, 1, 2
        if m[1, 1] > m[0, 0]:
            i, j, k = 1, 2, 0
        if m[2, 2] > m[i, i]:
            i, j, k = 2, 0, 1
        t = m[i, i] - (m[j, j] + m[k, k]) + m[3, 3]
        q[i] = t
        q[j] = m[i, j] + m[j, i]
        q[k] = m[k, i] + m[i, k]
        q[3] = m[k, j] - m[j, k]
    q *= 0.5 / math.sqrt(t * m[3, 3])
    return q


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


def quaternion_conjugate(quaternion: npt.ArrayLike) -> NDArray[np.float64]:
    """Return the conjugate [-x, -y, -z, w] of a quaternion."""
    x, y, z, w = np.asarray(quaternion, dtype=float)
    return np.array([-x, -y, -z, w], dtype=float)


def quaternion_inverse(quaternion: Sequence[float]) -> NDArray[np.float64]:
    """Return the inverse of a quaternion (its conjugate over its squared norm)."""
    q = _quaternion(quaternion)
    return quaternion_conjugate(q) / float(np.dot(q, q))


def quaternion_slerp(quat0: Sequence[float], quat1: Sequence[float], fraction: float, spin: int = 0,
                     shortestpath: bool = True) -> NDArray[np.float64]:
    """Return the spherical linear interpolation `fraction` of the way from quat0 to quat1 (tf's)."""
    q0, q1 = unit_vector(quat0), unit_vector(quat1)
    if fraction == 0.0:
        return q0
    if fraction == 1.0:
        return q1
    d = float(np.dot(q0, q1))
    if abs(abs(d) - 1.0) < _EPS:
        return q0
    if shortestpath and d < 0.0:
        d, q1 = -d, -q1
    angle = math.acos(d) + spin * math.pi
    if abs(angle) < _EPS:
        return q0
    isin = 1.0 / math.sin(angle)
    return (q0 * math.sin((1.0 - fraction) * angle) + q1 * math.sin(fraction * angle)) * isin


def random_quaternion(rand: npt.ArrayLike | None = None) -> NDArray[np.float64]:
    """Return a uniformly random unit quaternion [x, y, z, w] (from three numbers in [0, 1] if given)."""
    r = np.random.rand(3) if rand is None else np.asarray(rand, dtype=float)[:3]
    r1, r2 = math.sqrt(1.0 - r[0]), math.sqrt(r[0])
    t1, t2 = 2 * math.pi * r[1], 2 * math.pi * r[2]
    return np.array([math.sin(t1) * r1, math.cos(t1) * r1, math.sin(t2) * r2, math.cos(t2) * r2])


def concatenate_matrices(*matrices: npt.ArrayLike) -> NDArray[np.float64]:
    """Return the product of 4x4 matrices, the first leftmost."""
    result = np.identity(4)
    for matrix in matrices:
        result = result @ np.asarray(matrix, dtype=float)
    return result


def inverse_matrix(matrix: npt.ArrayLike) -> NDArray[np.float64]:
    """Return the inverse of a square matrix."""
    return np.linalg.inv(np.asarray(matrix, dtype=float))


def is_same_transform(matrix0: npt.ArrayLike, matrix1: npt.ArrayLike) -> bool:
    """Return True if two 4x4 matrices are the same transform (each scaled so that [3, 3] is 1)."""
    m0, m1 = np.array(matrix0, dtype=float), np.array(matrix1, dtype=float)
    return bool(np.allclose(m0 / m0[3, 3], m1 / m1[3, 3]))


def vector_norm(data: npt.ArrayLike, axis: int | None = None) -> float | NDArray[np.float64]:
    """Return the Euclidean length of a vector (of each along `axis`)."""
    array = np.asarray(data, dtype=float)
    if axis is None:
        return float(math.sqrt(float(np.dot(array.ravel(), array.ravel()))))
    return np.asarray(np.sqrt(np.sum(array * array, axis=axis)))


def unit_vector(data: npt.ArrayLike, axis: int | None = None) -> NDArray[np.float64]:
    """Return a vector (each along `axis`) divided by its length."""
    array = np.array(data, dtype=float, copy=True)
    if axis is None:
        return array / math.sqrt(float(np.dot(array.ravel(), array.ravel())))
    return np.asarray(array / np.expand_dims(np.sqrt(np.sum(array * array, axis=axis)), axis), dtype=float)
