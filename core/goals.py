"""Goals: turn a step's goal into target joint values for the planning group.

Joint goals may be complete (one value per group joint, in group order) or
partial (joint: value; the others keep their start values). Named goals are
SRDF group_states. Every target is checked against the joint limits.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from moveplan.core.errors import ConfigError, GoalOutsideLimits, UnknownName, UsageError
from moveplan.core.robot import Robot

__all__ = ["check_limits", "joint_target", "named_state"]

# Goals written at a limit by hand ("3.14" for pi) must not fail on rounding.
_LIMIT_SLACK = 1e-6


def named_state(robot: Robot, name: str, start: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return group values of an SRDF group_state; joints it leaves out keep their `start` value."""
    states = robot.config.srdf.group_states.get(robot.group.name, {})
    if name not in states:
        raise UnknownName("named state", name, f"group '{robot.group.name}' of {robot.config.srdf_path}", states)
    return _apply(robot, states[name], start, f"{robot.config.srdf_path} group_state '{name}'")


def joint_target(robot: Robot, goal: dict[str, Any], start: NDArray[np.float64], source: str) -> NDArray[np.float64]:
    """Return the group values a joints or named goal asks for, checked against the limits."""
    if "named" in goal:
        target = named_state(robot, goal["named"], start)
    else:
        joints = goal["joints"]
        if isinstance(joints, dict):
            target = _apply(robot, joints, start, source)
        else:
            if len(joints) != robot.dof:
                # A count that does not fit is a malformed flag (exit 2) or a malformed file (exit 3).
                error = UsageError if source.startswith("--") else ConfigError
                raise error(
                    f"{source}: joint goal has {len(joints)} values; group '{robot.group.name}' has "
                    f"{robot.dof} joints: {', '.join(robot.joint_names)}"
                )
            target = np.array(joints, dtype=float)
    check_limits(robot, target)
    return target


def check_limits(robot: Robot, values: NDArray[np.float64]) -> None:
    """Raise GoalOutsideLimits for the first joint outside its position limits."""
    for i, joint in enumerate(robot.joint_names):
        if robot.continuous[i]:
            continue
        if not robot.lower[i] - _LIMIT_SLACK <= values[i] <= robot.upper[i] + _LIMIT_SLACK:
            raise GoalOutsideLimits(joint, float(values[i]), float(robot.lower[i]), float(robot.upper[i]))


def _apply(robot: Robot, values: dict[str, float], start: NDArray[np.float64], source: str) -> NDArray[np.float64]:
    target = start.copy()
    for joint, value in values.items():
        if joint not in robot.joint_names:
            raise UnknownName("joint", joint, f"group '{robot.group.name}' ({source})", robot.joint_names)
        target[robot.joint_names.index(joint)] = value
    return target
