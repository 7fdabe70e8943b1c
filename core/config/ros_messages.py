"""Readers for the ROS message types MoveIt's YAML files are made of: headers, states, points and poses.

A message field left out takes its ROS 2 default (zero, empty; a quaternion's w is 1).
Points, vectors and quaternions may be written as lists ([x, y, z], [x, y, z, w], as
MotionBenchMaker writes them) or as mappings ({x: .., y: .., z: ..}, as ROS 2 writes them).
Coordinates, joint positions and quaternion parts are finite and within MAX_MAGNITUDE.
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ConfigError
from .fields import check_keys, coordinate, coordinates, mapping
from .poses import is_identity, pose_matrix

__all__ = [
    "header_frame",
    "is_empty_pose",
    "joint_positions",
    "point",
    "pose",
    "quaternion",
    "robot_state",
    "string_list",
    "transform",
    "yaml_list",
]

logger = logging.getLogger(__name__)

_ROBOT_STATE_KEYS = {"joint_state", "multi_dof_joint_state", "attached_collision_objects", "is_diff"}
_JOINT_STATE_KEYS = {"header", "name", "position", "velocity", "effort"}
_MULTI_DOF_KEYS = {"header", "joint_names", "transforms", "twist", "wrench"}
_HEADER_KEYS = {"stamp", "frame_id", "seq"}  # seq: headers written by ROS 1


def header_frame(entry: dict[str, Any], where: str, default: str) -> str:
    """Return a message's header.frame_id without a leading slash, or `default` when empty."""
    header = mapping(entry.get("header"), f"{where}.header")
    check_keys(header, _HEADER_KEYS, f"{where}.header")
    frame = header.get("frame_id", "")
    if not isinstance(frame, str):
        raise ConfigError(f"{where}.header.frame_id: expected a frame name, got {frame!r}")
    return frame.lstrip("/") or default


def robot_state(value: Any, where: str) -> tuple[dict[str, float], list[Any]]:
    """Return a moveit_msgs/RobotState's joint positions and its attached objects (as written)."""
    entry = mapping(value, where)
    check_keys(entry, _ROBOT_STATE_KEYS, where)
    joints = joint_positions(entry.get("joint_state"), f"{where}.joint_state")
    multi = mapping(entry.get("multi_dof_joint_state"), f"{where}.multi_dof_joint_state")
    check_keys(multi, _MULTI_DOF_KEYS, f"{where}.multi_dof_joint_state")
    names = string_list(multi.get("joint_names"), f"{where}.multi_dof_joint_state.joint_names")
    for k, item in enumerate(yaml_list(multi.get("transforms"), f"{where}.multi_dof_joint_state.transforms")):
        at = f"{where}.multi_dof_joint_state.transforms[{k}]"
        if not is_identity(transform(item, at)):
            joint = names[k] if k < len(names) else "?"
            raise ConfigError(f"{at}: joint '{joint}' is away from the identity; moveplan plans in the URDF "
                              "root frame and cannot move a virtual joint")
    return joints, yaml_list(entry.get("attached_collision_objects"), f"{where}.attached_collision_objects")


def joint_positions(value: Any, where: str) -> dict[str, float]:
    """Return joint name -> position of a sensor_msgs/JointState."""
    entry = mapping(value, where)
    check_keys(entry, _JOINT_STATE_KEYS, where)
    names = string_list(entry.get("name"), f"{where}.name")
    positions = yaml_list(entry.get("position"), f"{where}.position")
    if len(positions) != len(names):
        raise ConfigError(f"{where}.position: {len(positions)} positions for {len(names)} names")
    if len(set(names)) != len(names):
        twice = next(name for name in names if names.count(name) > 1)
        raise ConfigError(f"{where}.name: joint '{twice}' is listed twice")
    return {name: coordinate(v, f"{where}.position[{i}]")
            for i, (name, v) in enumerate(zip(names, positions, strict=True))}

def yaml_list(value: Any, where: str) -> list[Any]:
    """Return `value` if it is a list, [] if it is missing, else raise ConfigError at `where`."""
    if value is None:
        return []
    if not isinstance(value, list):
        raise ConfigError(f"{where}: expected a list, got {type(value).__name__}")
    return value


def string_list(value: Any, where: str) -> list[str]:
    """Return `value` if it is a list of strings ([] if missing), else raise ConfigError at `where`."""
    items = yaml_list(value, where)
    for i, item in enumerate(items):
        if not isinstance(item, str):
            raise ConfigError(f"{where}[{i}]: expected a name, got {item!r}")
    return items


def point(value: Any, where: str) -> list[float]:
    """Return [x, y, z] of a Point or Vector3 written as a list or a mapping (missing fields are 0)."""
    if isinstance(value, list):
        if len(value) != 3:
            raise ConfigError(f"{where}: expected [x, y, z], got {value!r}")
        return coordinates(value, where)
    entry = mapping(value, where)
    check_keys(entry, {"x", "y", "z"}, where)
    return [coordinate(entry.get(axis, 0.0), f"{where}.{axis}") for axis in "xyz"]


def quaternion(value: Any, where: str) -> list[float] | None:
    """Return [x, y, z, w] of a Quaternion written as a list or a mapping; None means the identity.

    Missing fields take ROS 2's defaults (w = 1). All zeros is read as the identity, as MoveIt does.
    """
    if value is None:
        return None
    quat = _quaternion_values(value, where)
    if not any(quat):
        logger.warning("%s: quaternion of zeros read as the identity, as MoveIt does", where)
        return None
    return quat


def _quaternion_values(value: Any, where: str) -> list[float]:
    """Return [x, y, z, w] as written (the identity when missing)."""
    if value is None:
        return [0.0, 0.0, 0.0, 1.0]
    if isinstance(value, list):
        if len(value) != 4:
            raise ConfigError(f"{where}: expected [x, y, z, w], got {value!r}")
        return coordinates(value, where)
    entry = mapping(value, where)
    check_keys(entry, {"x", "y", "z", "w"}, where)
    return [coordinate(entry.get(axis, 1.0 if axis == "w" else 0.0), f"{where}.{axis}") for axis in "xyzw"]


def pose(value: Any, where: str) -> NDArray[np.float64]:
    """Return the 4x4 transform of a geometry_msgs/Pose {position, orientation}; missing parts are identity."""
    entry = mapping(value, where)
    check_keys(entry, {"position", "orientation"}, where)
    xyz = point(entry.get("position", [0.0, 0.0, 0.0]), f"{where}.position")
    return pose_matrix(xyz, None, quaternion(entry.get("orientation"), f"{where}.orientation"), where)


def transform(value: Any, where: str) -> NDArray[np.float64]:
    """Return the 4x4 transform of a geometry_msgs/Transform {translation, rotation}."""
    entry = mapping(value, where)
    check_keys(entry, {"translation", "rotation"}, where)
    xyz = point(entry.get("translation", [0.0, 0.0, 0.0]), f"{where}.translation")
    return pose_matrix(xyz, None, quaternion(entry.get("rotation"), f"{where}.rotation"), where)


def is_empty_pose(value: Any, where: str) -> bool:
    """Return True for a pose left out, or written as all zeros (MoveIt's isEmpty)."""
    if value is None:
        return True
    entry = mapping(value, where)
    position = point(entry.get("position", [0.0, 0.0, 0.0]), f"{where}.position")
    orientation = _quaternion_values(entry.get("orientation"), f"{where}.orientation")
    return not any(position) and not any(orientation)
