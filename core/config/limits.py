"""Joint limits as MoveIt merges them: the URDF's limits, overridden by joint_limits.yaml."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import ConfigError, UnknownName
from .fields import boolean, check_keys, load_yaml, mapping, number
from .urdf import MOVABLE_JOINT_TYPES, UrdfJoint

__all__ = ["JointLimit", "merge_limits", "parse_joint_limits"]

# ros2_control joint_limits_rosparam.hpp's keys, and MoveIt's angle_wraparound.
_LIMIT_KEYS = {
    "has_position_limits", "min_position", "max_position", "has_velocity_limits", "max_velocity",
    "has_acceleration_limits", "max_acceleration", "has_deceleration_limits", "max_deceleration",
    "has_jerk_limits", "max_jerk", "has_effort_limits", "max_effort", "angle_wraparound",
}
_TOP_KEYS = {
    "joint_limits", "default_velocity_scaling_factor", "default_acceleration_scaling_factor", "cartesian_limits",
}
_DEFAULT_SCALING = 0.1  # MoveIt's default_{velocity,acceleration}_scaling_factor


@dataclass(frozen=True)
class JointLimit:
    """Merged limits of one joint in [rad] (or [m]), [rad]/[s], [rad]/[s]^2, with their sources."""

    lower: float
    upper: float
    max_velocity: float
    max_acceleration: float
    continuous: bool
    source: dict[str, str]


def parse_joint_limits(path: Path | None) -> tuple[dict[str, dict[str, Any]], float, float]:
    """Return joint_limits.yaml's entries by joint and its default velocity and acceleration scaling."""
    if path is None:
        return {}, _DEFAULT_SCALING, _DEFAULT_SCALING
    top = mapping(load_yaml(path), str(path))
    # MoveIt loads this file under robot_description_planning; accept it written either way.
    if "robot_description_planning" in top:
        top = mapping(top["robot_description_planning"], f"{path}: robot_description_planning")
    check_keys(top, _TOP_KEYS, str(path))
    scales = []
    for key in ("default_velocity_scaling_factor", "default_acceleration_scaling_factor"):
        value = number(top.get(key, _DEFAULT_SCALING), f"{path}: {key}", positive=True)
        if value > 1.0:
            raise ConfigError(f"{path}: {key}: expected a number in (0, 1], got {value}")
        scales.append(value)
    entries = mapping(top.get("joint_limits"), f"{path}: joint_limits")
    overrides: dict[str, dict[str, Any]] = {}
    for joint, entry in entries.items():
        where = f"{path}: joint_limits.{joint}"
        entry = mapping(entry, where)
        check_keys(entry, _LIMIT_KEYS, where)
        overrides[joint] = entry
    return overrides, scales[0], scales[1]


def merge_limits(
    urdf_path: Path,
    joints: dict[str, UrdfJoint],
    limits_path: Path | None,
    overrides: dict[str, dict[str, Any]],
) -> dict[str, JointLimit]:
    """Return the limits of every movable URDF joint: the URDF's, overridden where joint_limits.yaml says so."""
    for joint in overrides:
        if joint not in joints:
            raise UnknownName("joint", joint, f"{limits_path}: joint_limits", joints)
    limits: dict[str, JointLimit] = {}
    for joint in joints.values():
        if joint.type not in MOVABLE_JOINT_TYPES:
            continue
        continuous = joint.type == "continuous"
        lower, upper = (-math.pi, math.pi) if continuous else (joint.lower, joint.upper)
        velocity, acceleration = joint.velocity, math.nan
        urdf_name, file_name = urdf_path.name, limits_path.name if limits_path else ""
        source = {"position": urdf_name, "velocity": urdf_name, "acceleration": ""}
        entry = overrides.get(joint.name, {})
        where = f"{limits_path}: joint_limits.{joint.name}"
        if _flag(entry, "has_position_limits", where) and not continuous:
            lower = number(entry.get("min_position", lower), f"{where}.min_position")
            upper = number(entry.get("max_position", upper), f"{where}.max_position")
            source["position"] = file_name
        if _flag(entry, "has_velocity_limits", where):
            velocity = number(entry.get("max_velocity"), f"{where}.max_velocity", positive=True)
            source["velocity"] = file_name
        if _flag(entry, "has_acceleration_limits", where):
            acceleration = number(entry.get("max_acceleration"), f"{where}.max_acceleration", positive=True)
            source["acceleration"] = file_name
        if not lower <= upper:
            raise ConfigError(f"{urdf_path}: joint '{joint.name}': lower limit {lower} above upper {upper}")
        limits[joint.name] = JointLimit(lower, upper, velocity, acceleration, continuous, source)
    return limits


def _flag(entry: dict[str, Any], key: str, where: str) -> bool:
    """Return a has_*_limits flag of a joint's entry: absent is false, anything but a YAML boolean an error."""
    return key in entry and boolean(entry[key], f"{where}.{key}")
