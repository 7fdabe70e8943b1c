"""Whether a joint goal's values are in the units of their joints: metres, or radians rather than unitless degrees."""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import ConfigError, UsageError
from .fields import DEGREES, beyond_a_turn, more_than_a_turn
from .goals import JointGoal
from .robot_config import RobotConfig

__all__ = ["check_joint_units"]


def check_joint_units(goal: JointGoal, config: RobotConfig, group_joints: Sequence[str]) -> None:
    """Raise for a joint value whose unit is wrong for its joint; return None.

    A value in degrees on a prismatic joint (in [m]) is refused, and so is a revolute or
    continuous joint's value without a unit beyond a full turn (2*pi) and outside the
    joint's limits (a continuous joint has none): degrees written without their unit. A goal
    from a MoveIt message or a plan file (no `source`) is in [rad] by convention and passes;
    joints the robot lacks, and a complete goal whose count does not fit `group_joints`, are
    left to the goal's use, which names them.

    Raises:
        UsageError: For a goal from a flag (its `source` starts with "--").
        ConfigError: For a goal from a file.
    """
    names = goal.joints if goal.joints is not None else tuple(group_joints)
    if not goal.source or len(names) != len(goal.values):
        return
    error = UsageError if goal.source.startswith("--") else ConfigError
    degrees = goal.degrees or (False,) * len(goal.values)
    for k, (joint, value) in enumerate(zip(names, goal.values, strict=True)):
        if joint not in config.urdf_joints or joint not in config.limits:
            continue
        kind, limit = config.urdf_joints[joint].type, config.limits[joint]
        if degrees[k] and kind == "prismatic":
            raise error(f"{_written_at(goal, k, joint)}: '{joint}' is a prismatic joint, in [m]; "
                        f"'{DEGREES}' is for revolute joints")
        outside = limit.continuous or not limit.lower <= value <= limit.upper
        if not degrees[k] and kind in ("revolute", "continuous") and more_than_a_turn(value) and outside:
            limits = "" if limit.continuous else f" and outside its limits [{limit.lower:g}, {limit.upper:g}]"
            raise error(f"{_written_at(goal, k, joint)}: {beyond_a_turn(value, limits)}")


def _written_at(goal: JointGoal, index: int, joint: str) -> str:
    """Return where value `index` (of `joint`) was written: `--joints elbow_joint`, `F: steps[0].joints[2] (j)`."""
    if goal.source.startswith("--"):
        return f"{goal.source} {joint}"
    return f"{goal.source}.{joint}" if goal.joints is not None else f"{goal.source}[{index}] ({joint})"
