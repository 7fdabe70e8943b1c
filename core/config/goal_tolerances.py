"""The tolerances a step's goal carries, as control_msgs/FollowJointTrajectory's goal fields read in YAML.

    tolerances:
      path_tolerance: [{name: elbow_joint, position: 0.05}]
      goal_tolerance: [{name: elbow_joint, position: 0.01, velocity: 0.1}]
      goal_time_tolerance: 0.5

Each value is as control_msgs/JointTolerance means it: > 0 replaces the controller's tolerance
for this goal, 0 keeps the controller's, -1 erases it (nothing checked). Other negative values,
and joints the controller does not drive, make the controller ignore every tolerance of the
goal and use its own, as JTC does (core/control/tolerances.py resolves them when executing).
"""

from __future__ import annotations

from typing import Any

from ..errors import ConfigError
from ..types import GoalTolerances, JointTolerance
from .fields import check_keys, mapping, number

__all__ = ["parse_goal_tolerances"]

_KEYS = {"path_tolerance", "goal_tolerance", "goal_time_tolerance"}
_JOINT_KEYS = {"name", "position", "velocity", "acceleration"}


def parse_goal_tolerances(value: Any, where: str) -> GoalTolerances:
    """Return a step's `tolerances` mapping as GoalTolerances; ConfigError naming the key for a malformed one."""
    entry = mapping(value, where)
    check_keys(entry, _KEYS, where)
    return GoalTolerances(
        path=_joints(entry.get("path_tolerance"), f"{where}.path_tolerance"),
        goal=_joints(entry.get("goal_tolerance"), f"{where}.goal_tolerance"),
        goal_time_s=number(entry.get("goal_time_tolerance", 0.0), f"{where}.goal_time_tolerance"),
    )


def _joints(value: Any, where: str) -> tuple[JointTolerance, ...]:
    if value is None:
        return ()
    if not isinstance(value, list):
        raise ConfigError(f"{where}: expected a list of {{name, position, velocity, acceleration}}")
    tolerances = []
    for k, item in enumerate(value):
        at = f"{where}[{k}]"
        joint = mapping(item, at)
        check_keys(joint, _JOINT_KEYS, at)
        name = joint.get("name")
        if not isinstance(name, str) or not name:
            raise ConfigError(f"{at}.name: expected a joint name, got {name!r}")
        tolerances.append(JointTolerance(name, *(number(joint.get(key, 0.0), f"{at}.{key}")
                                                 for key in ("position", "velocity", "acceleration"))))
    return tuple(tolerances)
