"""Goals: turn a step's typed goal into target joint values, or a target pose, for the planning group.

Joint goals may be complete (one value per group joint, in group order) or
partial (joint: value; the others keep their start values). Named goals are
SRDF group_states. Every target is checked against the joint limits.

Pose and shift goals become a pose of the tip link in the planning frame,
evaluated with the robot where the step starts (frames on moving links move). A
position goal (a MoveIt request's position constraint alone) leaves the orientation
free: it takes the orientation of the inverse-kinematics solution nearest the start.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..config import JointGoal, NamedGoal, PoseGoal, PositionGoal, ShiftGoal, pose_matrix
from ..errors import ConfigError, GoalOutsideLimits, OutsideLimits, UnknownName, UsageError
from ..model import Robot, Scene, solve_ik
from ..rotations import matrix_from_rpy, rotation_angle, rpy_from_matrix

__all__ = [
    "check_limits", "joint_target", "named_state", "orientation_tolerance", "pose_error", "tip_target",
]

# [rad]: solve_ik's default, for goals that fix the orientation.
_ORIENTATION_TOLERANCE = 1e-3

# Goals written at a limit by hand ("3.14" for pi) must not fail on rounding.
_LIMIT_SLACK = 1e-6


def named_state(robot: Robot, name: str, start: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return group values of an SRDF group_state; joints it leaves out keep their `start` value."""
    states = robot.config.srdf.group_states.get(robot.group.name, {})
    if name not in states:
        raise UnknownName("named state", name, f"group '{robot.group.name}' of {robot.config.srdf_path}", states)
    return _apply(robot, states[name], start, f"{robot.config.srdf_path} group_state '{name}'")


def joint_target(
    robot: Robot, goal: JointGoal | NamedGoal, start: NDArray[np.float64], source: str,
    outside: type[OutsideLimits] = GoalOutsideLimits,
) -> NDArray[np.float64]:
    """Return the group values a joints or named goal asks for, checked against the limits.

    `source` names where the goal came from: a flag ("--joints"; a malformed one is a
    UsageError) or a file (a ConfigError). A value outside its limits raises `outside`.
    """
    if isinstance(goal, NamedGoal):
        target = named_state(robot, goal.name, start)
    elif (named := goal.named_values) is not None:
        target = _apply(robot, named, start, source)
    else:
        if len(goal.values) != robot.dof:
            # A count that does not fit is a malformed flag (exit 2) or a malformed file (exit 3).
            error = UsageError if source.startswith("--") else ConfigError
            raise error(
                f"{source}: joint goal has {len(goal.values)} values; group '{robot.group.name}' has "
                f"{robot.dof} joints: {', '.join(robot.joint_names)}"
            )
        target = np.array(goal.values, dtype=float)
    check_limits(robot, target, outside)
    return target


def check_limits(
    robot: Robot, values: NDArray[np.float64], outside: type[OutsideLimits] = GoalOutsideLimits
) -> None:
    """Raise `outside` for the first joint outside its position limits."""
    for i, joint in enumerate(robot.joint_names):
        if robot.continuous[i]:
            continue
        if not robot.lower[i] - _LIMIT_SLACK <= values[i] <= robot.upper[i] + _LIMIT_SLACK:
            raise outside(joint, float(values[i]), float(robot.lower[i]), float(robot.upper[i]))


def _apply(robot: Robot, values: dict[str, float], start: NDArray[np.float64], source: str) -> NDArray[np.float64]:
    """Return `start` with the group joints of `values` set; a mimic joint's value must be the one its leader gives."""
    target = start.copy()
    mimics = {m.joint: m for m in robot.mimics}
    for joint, value in values.items():
        if joint in robot.joint_names:
            target[robot.joint_names.index(joint)] = value
        elif joint not in mimics:
            raise UnknownName("joint", joint, f"group '{robot.group.name}' ({source})", robot.joint_names)
    for joint in values.keys() & mimics.keys():
        mimic = mimics[joint]
        follows = mimic.multiplier * target[mimic.leader] + mimic.offset
        # A mimic joint follows its leader (MoveIt overwrites its value); a value it cannot take is a mistake.
        if abs(values[joint] - follows) > _LIMIT_SLACK:
            leader = robot.joint_names[mimic.leader]
            error = UsageError if source.startswith("--") else ConfigError
            raise error(f"{source}: joint '{joint}' mimics '{leader}', so it is at {follows:g} there, not "
                        f"{values[joint]:g}: set '{leader}' only")
    return target


def tip_target(
    robot: Robot, scene: Scene, goal: PoseGoal | ShiftGoal, q: NDArray[np.float64], source: str
) -> tuple[str, NDArray[np.float64]]:
    """Return (link, `root_T_link`) that a pose or shift goal asks for, from configuration `q`.

    A position goal's orientation is the one where inverse kinematics from `q`, with the
    orientation free, puts the link (GoalUnreachable when no configuration reaches the position).
    """
    if isinstance(goal, ShiftGoal):
        return robot.group.tip, _shifted(robot, scene, goal, q)
    link = goal.link or robot.group.tip
    frame = goal.frame or robot.root_link
    anchor, anchor_T_frame = scene.anchor(frame, robot)
    root_T_frame = robot.frame_pose(q, anchor) @ anchor_T_frame
    # What the pose leaves out is the frame's own: no offset, no rotation.
    target = root_T_frame @ pose_matrix(goal.xyz, goal.rpy, goal.quat, source)
    if isinstance(goal, PositionGoal):
        solution = solve_ik(robot, target, link, robot.values(q), base=q, orientation_tolerance=math.inf)
        reached = robot.frame_pose(robot.configuration(solution.values, q), link)
        target[:3, :3] = reached[:3, :3]
    return link, target


def orientation_tolerance(goal: PoseGoal | ShiftGoal) -> float:
    """Return the orientation error in [rad] inverse kinematics may leave for a goal: inf for a position goal."""
    return math.inf if isinstance(goal, PositionGoal) else _ORIENTATION_TOLERANCE


def _shifted(robot: Robot, scene: Scene, shift: ShiftGoal, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the tip pose moved by `shift` from where it is in `q`."""
    now = robot.frame_pose(q, robot.group.tip)
    t = np.array(shift.translation())
    rpy = np.array(shift.rotation())
    delta = pose_matrix(list(t), list(rpy), None, "shift")
    frame = shift.frame
    if frame == "tool":
        return now @ delta
    goal = now.copy()
    if frame == "moveit":
        # MoveGroupCommander.shift_pose_target: add to [x, y, z, roll, pitch, yaw] of the
        # pose in the planning frame, angles as fixed-axis (sxyz) Euler angles.
        goal[:3, 3] += t
        goal[:3, :3] = matrix_from_rpy(*(np.array(rpy_from_matrix(now[:3, :3])) + rpy))
        return goal
    if frame in ("base", "planning"):
        axes = np.eye(3)
    else:
        anchor, anchor_T_frame = scene.anchor(frame, robot)
        axes = (robot.frame_pose(q, anchor) @ anchor_T_frame)[:3, :3]
    # Along and about the frame's axes, turning about the tip's own position.
    goal[:3, 3] += axes @ t
    goal[:3, :3] = axes @ delta[:3, :3] @ axes.T @ now[:3, :3]
    return goal


def pose_error(reached: NDArray[np.float64], target: NDArray[np.float64]) -> tuple[float, float]:
    """Return the distance in [m] and rotation angle in [rad] between two poses."""
    angle = rotation_angle(reached[:3, :3].T @ target[:3, :3])
    return float(np.linalg.norm(reached[:3, 3] - target[:3, 3])), angle
