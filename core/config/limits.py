"""Joint limits as MoveIt merges them: the URDF's limits, overridden by joint_limits.yaml."""

from __future__ import annotations

import difflib
import logging
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ._urdf import MOVABLE_JOINT_TYPES, UrdfJoint
from .fields import MAX_MAGNITUDE, boolean, check_keys, load_yaml, mapping, number
from .motion import MIN_SCALING, is_scaling

__all__ = [
    "DEFAULT_ACCELERATION", "DEFAULT_SOURCE", "JointLimit", "is_moveit_joint_limits", "merge_limits",
    "parse_joint_limits",
]

logger = logging.getLogger(__name__)

DEFAULT_ACCELERATION = 1.0
"""Acceleration limit in [rad]/[s]^2 (or [m]/[s]^2) of a joint the config gives none.

MoveIt 1's (IterativeParabolicTimeParameterization's DEFAULT_ACCEL_MAX): conservative, as arms
publish a few [rad]/[s]^2 (the Panda 1.9 to 5, UR's MoveIt configs 5 to 10). MoveIt 2 Jazzy
refuses to time such a joint; so does merge_limits with `strict`.
"""

DEFAULT_SOURCE = "default"
"""JointLimit.source value of a limit no file gives (DEFAULT_ACCELERATION)."""

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
    """Merged limits of one joint in [rad] (or [m]), [rad]/[s], [rad]/[s]^2, with their sources.

    `source` maps position, velocity and acceleration to the name of the file the limit comes
    from, or DEFAULT_SOURCE for an acceleration limit no file gives.
    """

    lower: float
    upper: float
    max_velocity: float
    max_acceleration: float
    continuous: bool
    source: dict[str, str]


def is_moveit_joint_limits(path: Path) -> bool:
    """Return True if a joint_limits.yaml is MoveIt's (not, say, a description package's own URDF limits)."""
    top = load_yaml(path)
    return not isinstance(top, dict) or not top or bool(set(_unwrapped(top, path)) & _TOP_KEYS)


def parse_joint_limits(path: Path | None) -> tuple[dict[str, dict[str, Any]], float, float]:
    """Return joint_limits.yaml's entries by joint and its default velocity and acceleration scaling.

    The file may hold them as MoveIt's loader does, under `robot_description_planning`, or as
    move_group's node parameters (`move_group: ros__parameters: robot_description_planning:`).
    """
    if path is None:
        return {}, _DEFAULT_SCALING, _DEFAULT_SCALING
    top = _unwrapped(mapping(load_yaml(path), str(path)), path)
    check_keys(top, _TOP_KEYS, str(path))
    scales = []
    for key in ("default_velocity_scaling_factor", "default_acceleration_scaling_factor"):
        value = number(top.get(key, _DEFAULT_SCALING), f"{path}: {key}", positive=True)
        if not is_scaling(value):
            raise ConfigError(f"{path}: {key}: expected a number in [{MIN_SCALING:g}, 1], got {value:g} "
                              "(the bounds of --velocity-scaling and --acceleration-scaling)")
        scales.append(value)
    entries = mapping(top.get("joint_limits"), f"{path}: joint_limits")
    overrides: dict[str, dict[str, Any]] = {}
    ignored: dict[str, list[str]] = {}
    for joint, entry in entries.items():
        where = f"{path}: joint_limits.{joint}"
        entry = mapping(entry, where)
        for key in [k for k in entry if k not in _LIMIT_KEYS and isinstance(entry[k], bool)]:
            # A switch MoveIt does not read (KUKA writes has_jerk: false): MoveIt ignores it, and so does moveplan.
            ignored.setdefault(str(key), []).append(str(joint))
            entry = {k: v for k, v in entry.items() if k != key}
        check_keys(entry, _LIMIT_KEYS, where)  # an unknown number would change a limit: a typo must not pass
        overrides[joint] = entry
    switches = sorted(k for k in _LIMIT_KEYS if k.startswith("has_") or k == "angle_wraparound")
    for key, joints in ignored.items():  # one line a switch, not one a joint
        near = difflib.get_close_matches(key, switches, n=1)
        logger.warning("%s: joint_limits: unknown switch '%s' ignored (joints %s), as MoveIt ignores it%s", path, key,
                       ", ".join(joints), f" (did you mean '{near[0]}'?)" if near else "")
    return overrides, scales[0], scales[1]


def _unwrapped(top: dict[str, Any], path: Path) -> dict[str, Any]:
    """Return the limits mapping inside node-parameter and robot_description_planning wrappers."""
    # A ROS 2 parameter file: one node (any name, `/**`), its ros__parameters.
    if len(top) == 1:
        (section,) = top.values()
        if isinstance(section, dict) and "ros__parameters" in section:
            top = mapping(section["ros__parameters"], f"{path}: ros__parameters")
    # MoveIt loads this file under robot_description_planning; accept it written either way.
    if "robot_description_planning" in top:
        top = mapping(top["robot_description_planning"], f"{path}: robot_description_planning")
    return top


def merge_limits(
    urdf_path: Path,
    joints: dict[str, UrdfJoint],
    limits_path: Path | None,
    overrides: dict[str, dict[str, Any]],
    strict: bool = False,
) -> dict[str, JointLimit]:
    """Return the limits of every movable URDF joint: the URDF's, overridden where joint_limits.yaml says so.

    As MoveIt, joint_limits.yaml is read for the URDF's joints only: an entry for another joint
    (a file shared by several robots) is ignored, logged at debug level. A joint without an
    acceleration limit (`has_acceleration_limits: false`, the Setup Assistant's default, or no
    entry) gets DEFAULT_ACCELERATION, its source DEFAULT_SOURCE; planning warns about the ones it
    times (pipeline/plan.py).

    Raises:
        ConfigError: A malformed entry or lower limit above upper; with `strict`, a joint
            without an acceleration limit, mimic joints aside (names the joints and the file).
    """
    for joint in overrides:
        if joint not in joints:
            logger.debug("%s: joint_limits.%s: no such joint in %s; ignored", limits_path, joint, urdf_path.name)
    limits = {
        joint.name: _merged(joint, urdf_path, limits_path, overrides.get(joint.name, {}))
        for joint in joints.values() if joint.type in MOVABLE_JOINT_TYPES
    }
    # A mimic joint follows its leader: MoveIt times only the leader, so only the leader needs a limit.
    defaulted = [j for j, lim in limits.items() if lim.source["acceleration"] == DEFAULT_SOURCE and not joints[j].mimic]
    if strict and defaulted:
        raise ConfigError(f"{limits_path or urdf_path}: no acceleration limit for joints {', '.join(defaulted)} "
                          "(joint_limits.yaml: has_acceleration_limits: true, max_acceleration); without "
                          f"--strict-limits they plan with the default {DEFAULT_ACCELERATION:g} rad/s^2")
    return limits


def _merged(joint: UrdfJoint, urdf_path: Path, limits_path: Path | None, entry: dict[str, Any]) -> JointLimit:
    """Return one joint's limits: the URDF's, overridden by its joint_limits.yaml `entry`."""
    continuous = joint.type == "continuous"
    lower, upper = (-math.pi, math.pi) if continuous else (joint.lower, joint.upper)
    velocity, acceleration = joint.velocity, DEFAULT_ACCELERATION
    urdf_name, file_name = urdf_path.name, limits_path.name if limits_path else ""
    source = {"position": urdf_name, "velocity": urdf_name, "acceleration": DEFAULT_SOURCE}
    where = f"{limits_path}: joint_limits.{joint.name}"
    if _flag(entry, "has_position_limits", where) and not continuous:
        lower = number(entry.get("min_position", lower), f"{where}.min_position", bound=MAX_MAGNITUDE)
        upper = number(entry.get("max_position", upper), f"{where}.max_position", bound=MAX_MAGNITUDE)
        source["position"] = file_name
    if _flag(entry, "has_velocity_limits", where):
        velocity = number(entry.get("max_velocity"), f"{where}.max_velocity", positive=True, bound=MAX_MAGNITUDE)
        source["velocity"] = file_name
    if _flag(entry, "has_acceleration_limits", where):
        acceleration = number(entry.get("max_acceleration"), f"{where}.max_acceleration", positive=True,
                              bound=MAX_MAGNITUDE)
        source["acceleration"] = file_name
    if not lower <= upper:
        raise ConfigError(f"{urdf_path}: joint '{joint.name}': lower limit {lower} above upper {upper}")
    return JointLimit(lower, upper, velocity, acceleration, continuous, source)


def _flag(entry: dict[str, Any], key: str, where: str) -> bool:
    """Return a has_*_limits flag of a joint's entry: absent is false, anything but a YAML boolean an error."""
    return key in entry and boolean(entry[key], f"{where}.{key}")
