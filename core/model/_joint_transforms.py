"""parent_T_child of a robot's moving URDF joints as /tf poses, for many configurations at once, no loop over samples.

A moving joint's transform is constant x motion(q) x constant: the parent link's frame to the
joint at zero, the joint's turn about (or travel along) its axis, the joint to the child link's
frame. /tf carries a translation and a quaternion, so that is what is made: the quaternions
composed (left, the turn's half-angle quaternion, right) and the child's origin turned by
Rodrigues' formula, both multiplied out per joint once (JointTable), never a 4x4 matrix and its
conversion (0.7 ms of a plan's 110 samples of 7 joints; now 0.2). The products are written out
as elementwise sums in a fixed order, never a matrix-product routine (whose summation order is
the BLAS build's), and sines and cosines come from the C library (Python's math, as pinocchio's),
so poses are the same to the bit on every machine.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ..rotations import quaternions_xyzw

__all__ = ["JointTable", "joint_poses", "joint_table"]

_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
# pinocchio's joint kinds written out here: how each moves, and its axis letter ("": the joint's own axis).
_KINDS = {
    **{f"R{a}": ("revolute", a) for a in "XYZ"}, "RevoluteUnaligned": ("revolute", ""),
    **{f"RUB{a}": ("continuous", a) for a in "XYZ"}, "RevoluteUnboundedUnaligned": ("continuous", ""),
    **{f"P{a}": ("prismatic", a) for a in "XYZ"}, "PrismaticUnaligned": ("prismatic", ""),
}


@dataclass(frozen=True)
class JointTable:
    """What poses need of each moving joint, read from the model once: where its value is, how it moves.

    A joint turning by angle t (half-angle cosine c, sine s) or sliding by d gives the pose
    translation = at_zero + cos t * along_cos + sin t * along_sin + d * along_axis, and
    quaternion = c * turn_cos + s * turn_sin: constant x motion x constant, multiplied out once.
    """

    index_q: NDArray[np.int64]  # (J,) its value's index in q
    motion: tuple[str, ...]  # revolute, continuous or prismatic
    at_zero: NDArray[np.float64]  # (J, 3) [m]
    along_cos: NDArray[np.float64]  # (J, 3) [m]
    along_sin: NDArray[np.float64]  # (J, 3) [m]
    along_axis: NDArray[np.float64]  # (J, 3) unit axis in the parent link's frame
    turn_cos: NDArray[np.float64]  # (J, 4) xyzw
    turn_sin: NDArray[np.float64]  # (J, 4) xyzw


def joint_table(model: pin.Model, pairs: Sequence[tuple[int, int]]) -> JointTable | None:
    """Return the joint table of frame pairs (parent link, child link), or None if one is not written out here.

    Written out: one moving joint of pinocchio's revolute, continuous or prismatic kinds, on any axis.
    """
    frames, joints = model.frames, model.joints
    index_q, motions, axes, left, right = [], [], [], [], []
    for parent, child in pairs:
        index = frames[child].parentJoint
        joint = joints[index]
        kind = joint.shortname().removeprefix("JointModel")
        if model.parents[index] != frames[parent].parentJoint or kind not in _KINDS:
            return None
        motion, letter = _KINDS[kind]
        index_q.append(joint.idx_q)
        motions.append(motion)
        axes.append(_AXES[letter] if letter else np.asarray(joint.extract().axis, dtype=float))
        left.append((frames[parent].placement.inverse() * model.jointPlacements[index]).homogeneous)
        right.append(frames[child].placement.homogeneous)
    axis = np.array(axes, dtype=float).reshape(-1, 3)
    left_t, right_t = np.array(left).reshape(-1, 4, 4), np.array(right).reshape(-1, 4, 4)
    left_rotation, origin = left_t[:, :3, :3], right_t[:, :3, 3]
    # The child's origin r turned about the axis a (Rodrigues): a (a . r) + cos t (r - a (a . r)) + sin t (a x r).
    along = (axis[:, 0] * origin[:, 0] + axis[:, 1] * origin[:, 1] + axis[:, 2] * origin[:, 2])[:, None] * axis
    left_q, right_q = quaternions_xyzw(left_t), quaternions_xyzw(right_t)
    return JointTable(
        np.array(index_q, dtype=np.int64), tuple(motions),
        at_zero=left_t[:, :3, 3] + _rotated(left_rotation, along),
        along_cos=_rotated(left_rotation, origin - along),
        along_sin=_rotated(left_rotation, np.cross(axis, origin)),
        along_axis=_rotated(left_rotation, axis),
        turn_cos=_product(left_q, right_q),
        turn_sin=_product(_product(left_q, np.concatenate((axis, np.zeros((len(axis), 1))), axis=1)), right_q))


def joint_poses(table: JointTable, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return parent_T_child (N, J, 7) of the table's joints at configurations q (nq, N): xyz, then quaternion xyzw."""
    samples, count = q.shape[1], len(table.motion)
    half_cos, half_sin, travel = np.ones((samples, count)), np.zeros((samples, count)), np.zeros((samples, count))
    kinds = np.array(table.motion)
    slide, turning = np.flatnonzero(kinds == "prismatic"), np.flatnonzero(kinds != "prismatic")
    travel[:, slide] = q[table.index_q[slide]].T
    angles: list[float] = []  # joint by joint, as Python floats: math takes numpy's scalars several times slower
    for motion, index in zip(kinds[turning].tolist(), table.index_q[turning].tolist(), strict=True):
        if motion == "continuous":  # pinocchio keeps (cos, sin) in q
            angles += map(math.atan2, q[index + 1].tolist(), q[index].tolist())
        else:
            angles += q[index].tolist()
    half = [0.5 * angle for angle in angles]
    if len(turning):
        half_cos[:, turning], half_sin[:, turning] = _math(math.cos, half, samples), _math(math.sin, half, samples)
    cos = half_cos * half_cos - half_sin * half_sin
    sin = 2.0 * half_sin * half_cos
    out = np.empty((samples, count, 7))
    out[..., :3] = (table.at_zero + cos[..., None] * table.along_cos + sin[..., None] * table.along_sin
                    + travel[..., None] * table.along_axis)
    quaternion = half_cos[..., None] * table.turn_cos + half_sin[..., None] * table.turn_sin
    norm = np.sqrt(quaternion[..., 0] * quaternion[..., 0] + quaternion[..., 1] * quaternion[..., 1]
                   + quaternion[..., 2] * quaternion[..., 2] + quaternion[..., 3] * quaternion[..., 3])
    quaternion /= norm[..., None]
    out[..., 3:] = np.where(quaternion[..., 3:] < 0.0, -quaternion, quaternion)  # w >= 0, as quaternions_xyzw
    return out


def _rotated(rotations: NDArray[np.float64], vectors: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return each (3, 3) rotation times its 3-vector, (J, 3), as sums in a fixed order."""
    return (rotations[:, :, 0] * vectors[:, None, 0] + rotations[:, :, 1] * vectors[:, None, 1]
            + rotations[:, :, 2] * vectors[:, None, 2])


def _math(function: Any, values: list[float], samples: int) -> NDArray[np.float64]:
    """Return `function` (the C library's, through math: the same bits everywhere) of joint-major values (N, J)."""
    return np.fromiter(map(function, values), float, len(values)).reshape(-1, samples).T


def _product(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the Hamilton products a b of quaternions xyzw over the last axis."""
    ax, ay, az, aw = (a[..., k] for k in range(4))
    bx, by, bz, bw = (b[..., k] for k in range(4))
    return np.stack((aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz), axis=-1)
