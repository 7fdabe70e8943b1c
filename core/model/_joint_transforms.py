"""parent_T_child of a robot's moving URDF joints for many configurations at once, with no loop over the samples.

A moving joint's transform is constant x motion(q) x constant: the parent link's frame to the
joint at zero, the joint's turn about (or travel along) its axis, the joint to the child link's
frame. The products are written out as elementwise sums in a fixed order, never a matrix-product
routine (whose summation order is the BLAS build's), and sines and cosines come from the C
library (Python's math, as pinocchio's), so transforms are the same to the bit on every machine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

__all__ = ["JointTable", "joint_table", "joint_transforms"]

_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
# pinocchio's joint kinds written out here: how each moves, and its axis letter ("": the joint's own axis).
_KINDS = {
    **{f"R{a}": ("revolute", a) for a in "XYZ"}, "RevoluteUnaligned": ("revolute", ""),
    **{f"RUB{a}": ("continuous", a) for a in "XYZ"}, "RevoluteUnboundedUnaligned": ("continuous", ""),
    **{f"P{a}": ("prismatic", a) for a in "XYZ"}, "PrismaticUnaligned": ("prismatic", ""),
}


@dataclass(frozen=True)
class JointTable:
    """What transforms need of each moving joint, read from the model once: where its value is, how it moves."""

    index_q: NDArray[np.int64]  # (J,) its value's index in q
    motion: tuple[str, ...]  # revolute, continuous or prismatic
    axes: NDArray[np.float64]  # (J, 3) unit axes
    left: NDArray[np.float64]  # (J, 4, 4) parent link frame to the joint at zero
    right: NDArray[np.float64]  # (J, 4, 4) the joint to the child link frame


def joint_table(model: pin.Model, pairs: list[tuple[int, int]]) -> JointTable | None:
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
    return JointTable(np.array(index_q, dtype=np.int64), tuple(motions), np.array(axes, dtype=float).reshape(-1, 3),
                      np.array(left).reshape(-1, 4, 4), np.array(right).reshape(-1, 4, 4))


def joint_transforms(table: JointTable, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return parent_T_child (N, J, 4, 4) of the table's joints at configurations q (nq, N)."""
    samples, count = q.shape[1], len(table.motion)
    cos, sin, travel = np.ones((samples, count)), np.zeros((samples, count)), np.zeros((samples, count))
    for column, (motion, index) in enumerate(zip(table.motion, table.index_q, strict=True)):
        values = q[index]
        if motion == "prismatic":
            travel[:, column] = values
        elif motion == "continuous":  # pinocchio keeps (cos, sin) in q
            cos[:, column], sin[:, column] = values, q[index + 1]
        else:
            cos[:, column] = list(map(math.cos, values))
            sin[:, column] = list(map(math.sin, values))
    # Rodrigues' rotation (the identity where cos 1, sin 0: a prismatic joint), then its travel along the axis.
    axes = table.axes
    x, y, z = axes[:, 0], axes[:, 1], axes[:, 2]
    zero = np.zeros(count)
    cross = np.stack((np.stack((zero, -z, y), -1), np.stack((z, zero, -x), -1), np.stack((-y, x, zero), -1)), -2)
    outer = axes[:, :, None] * axes[:, None, :]
    own = np.zeros((samples, count, 4, 4))
    own[..., :3, :3] = (cos[..., None, None] * np.eye(3) + sin[..., None, None] * cross
                        + (1.0 - cos)[..., None, None] * outer)
    own[..., :3, 3] = travel[..., None] * axes
    own[..., 3, 3] = 1.0
    return _product(_product(table.left, own), table.right)


def _product(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return a @ b over the last two axes (4 x 4), summed k = 0..3 in that order."""
    out = a[..., :, 0:1] * b[..., 0:1, :]
    for k in range(1, 4):
        out = out + a[..., :, k : k + 1] * b[..., k : k + 1, :]
    return out
