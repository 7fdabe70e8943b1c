"""MoveGroupCommander's target arguments (lists, dicts, JointState, Pose, PoseStamped, pose lists) as pipeline goals."""

from __future__ import annotations

import reprlib
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..core.config import JointGoal, PoseGoal
from ..core.errors import UsageError
from .conversions import list_to_pose, pose_to_list
from .msgs import JointState, Pose, PoseStamped

__all__ = ["finite_number", "frame_name", "joint_goal", "pose_goal"]


def joint_goal(arg1: Any, arg2: Any, joints: tuple[str, ...], where: str) -> JointGoal:
    """Return the joint goal of set_joint_value_target's arguments: a list, a dict, a JointState or (name, value).

    Raises:
        UsageError: Not one of those shapes, a complete list of the wrong length, or a value that is no number.
    """
    if isinstance(arg1, str):
        if arg2 is None:
            raise UsageError(f"{where}('{arg1}'): a joint name needs a value: {where}('{arg1}', value)")
        return JointGoal.by_name({arg1: finite_number(arg2, f"{where}('{arg1}')")})
    if arg2 is not None:
        raise UsageError(f"{where}: too many arguments for a {type(arg1).__name__} target")
    if isinstance(arg1, JointState):
        if len(arg1.name) != len(arg1.position):
            raise UsageError(f"{where}: JointState has {len(arg1.name)} names and {len(arg1.position)} positions")
        pairs = zip(arg1.name, arg1.position, strict=True)
        return JointGoal.by_name({str(n): finite_number(v, f"{where}: {n}") for n, v in pairs})
    if isinstance(arg1, Mapping):
        return JointGoal.by_name({str(n): finite_number(v, f"{where}: {n}") for n, v in arg1.items()})
    if isinstance(arg1, str | bytes) or not hasattr(arg1, "__iter__"):
        raise UsageError(f"{where}: expected a list of joint values, a dict joint: value, a JointState or "
                         f"(joint name, value), got {type(arg1).__name__}")
    values = [finite_number(v, where) for v in np.ravel(np.asarray(list(arg1), dtype=object))]
    if len(values) != len(joints):
        raise UsageError(f"{where}: {len(values)} joint values; the group has {len(joints)} joints: "
                         f"{', '.join(joints)}")
    return JointGoal(tuple(values))


def pose_goal(pose: Any, link: str, reference_frame: str, where: str) -> PoseGoal:
    """Return the goal of `link` at a Pose or pose list (in `reference_frame`) or a PoseStamped (in its own frame).

    Raises:
        UsageError: Not a Pose, PoseStamped or list of 6 or 7 numbers, or an orientation that is no rotation.
    """
    frame = reference_frame
    if isinstance(pose, PoseStamped):
        frame = frame_name(pose.header.frame_id, f"{where}: header.frame_id") or reference_frame
        values = pose_to_list(pose.pose)
    elif isinstance(pose, Pose):
        values = pose_to_list(pose)
    elif isinstance(pose, str | bytes) or not hasattr(pose, "__iter__"):
        raise UsageError(f"{where}: expected a Pose, a PoseStamped or a list [x, y, z, qx, qy, qz, qw] or "
                         f"[x, y, z, roll, pitch, yaw], got {type(pose).__name__}")
    else:
        values = list(pose)
    try:
        parsed = list_to_pose(values)  # 6 or 7 finite numbers, an orientation that is a rotation
    except UsageError as exc:
        raise UsageError(f"{where}: {exc}") from None
    xyz = (parsed.position.x, parsed.position.y, parsed.position.z)
    if len(values) == 6:
        roll, pitch, yaw = (float(v) for v in values[3:])
        return PoseGoal(xyz=xyz, rpy=(roll, pitch, yaw), frame=frame, link=link)
    q = parsed.orientation
    return PoseGoal(xyz=xyz, quat=(q.x, q.y, q.z, q.w), frame=frame, link=link)


def frame_name(value: Any, where: str) -> str:
    """Return a frame name without tf1's leading slash; UsageError naming `where` if it is no string."""
    if not isinstance(value, str):
        raise UsageError(f"{where}: expected a frame name, got {value!r}")
    return value.lstrip("/")


def finite_number(value: Any, where: str) -> float:
    """Return `value` as a finite float, else raise UsageError naming `where`."""
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):  # OverflowError: an integer of 400 digits
        raise UsageError(f"{where}: expected a number, got {reprlib.repr(value)}") from None
    if not np.isfinite(number):
        raise UsageError(f"{where}: expected a finite number, got {number}")
    return number
