"""The JointTrajectoryController's tolerances per joint, and the errors they are compared with.

They follow ros2_controllers' Jazzy-era joint_trajectory_controller (tolerances.hpp):
path tolerances while the trajectory runs, goal tolerances at and after its last point,
and a tolerance of 0 that is not checked. `judging` applies them to time series.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ..config import ControllerConfig
from ..errors import InputError, UnknownName
from ..trajectory import shortest_angular_distance
from ..types import GoalTolerances, JointTolerance, JointTrajectory

__all__ = [
    "ERASE",
    "SegmentTolerances",
    "StateTolerance",
    "check_goal_joints",
    "check_state_tolerance_per_joint",
    "goal_segment_tolerances",
    "in_controller_order",
    "position_error",
    "segment_tolerances",
    "tolerance_limits",
    "unchecked_joints",
    "velocity_error_computable",
]

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class StateTolerance:
    """Tolerances on position [rad], velocity [rad]/[s], acceleration [rad]/[s]^2; 0 = unchecked."""

    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass(frozen=True)
class SegmentTolerances:
    """The tolerances of one execution, per joint (JTC's SegmentTolerances).

    Attributes:
        joint_names: Joint order of `state` and `goal`.
        state: Path tolerances, checked while the trajectory runs.
        goal: Goal tolerances, checked at and after the last point.
        goal_time_s: Time after the last point to reach the goal in [s]; 0 = no limit.
    """

    joint_names: tuple[str, ...]
    state: tuple[StateTolerance, ...]
    goal: tuple[StateTolerance, ...]
    goal_time_s: float


def segment_tolerances(controller: ControllerConfig) -> SegmentTolerances:
    """Return the controller's default tolerances, built as JTC's get_segment_tolerances does."""
    joints = controller.joints
    path = controller.trajectory_tolerance
    goal = controller.goal_tolerance
    stopped = controller.stopped_velocity_tolerance
    return SegmentTolerances(
        joint_names=joints,
        state=tuple(StateTolerance(position=path.get(j, 0.0)) for j in joints),
        goal=tuple(StateTolerance(position=goal.get(j, 0.0), velocity=stopped) for j in joints),
        goal_time_s=controller.goal_time_s,
    )


def tolerance_limits(
    tolerances: Sequence[StateTolerance],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the position and velocity tolerances per joint, as arrays."""
    position = np.array([t.position for t in tolerances], dtype=np.float64)
    velocity = np.array([t.velocity for t in tolerances], dtype=np.float64)
    return position, velocity


def check_state_tolerance_per_joint(
    position_error: float,
    velocity_error: float,
    acceleration_error: float,
    tolerance: StateTolerance,
) -> bool:
    """Return True if the errors are within `tolerance`; only strictly above a nonzero one fails."""
    return not (
        (tolerance.position > 0.0 and abs(position_error) > tolerance.position)
        or (tolerance.velocity > 0.0 and abs(velocity_error) > tolerance.velocity)
        or (tolerance.acceleration > 0.0 and abs(acceleration_error) > tolerance.acceleration)
    )


def position_error(
    reference: npt.ArrayLike, actual: npt.ArrayLike, continuous: npt.ArrayLike | None = None
) -> NDArray[np.float64]:
    """Return reference - actual in [rad] or [m], as the shortest angle for continuous joints.

    Jazzy wraps only joints that are continuous in the URDF; Humble-era JTC wrapped all.
    """
    difference = np.asarray(reference, dtype=np.float64) - np.asarray(actual, dtype=np.float64)
    if continuous is None or not np.any(continuous):
        return difference
    wrapped = shortest_angular_distance(actual, reference)
    return np.where(np.asarray(continuous, dtype=bool), wrapped, difference)


def velocity_error_computable(controller: ControllerConfig) -> bool:
    """Return True if JTC computes velocity errors: velocity state, velocity or effort command.

    Otherwise the error stays 0, so velocity tolerances (stopped_velocity_tolerance too)
    never fail: a quirk of Jazzy-era compute_error_for_joint, kept on purpose.
    """
    commands = controller.command_interfaces
    velocity_state = "velocity" in controller.state_interfaces
    return velocity_state and ("velocity" in commands or "effort" in commands)


def in_controller_order(
    trajectory: JointTrajectory, controller: ControllerConfig, hold: NDArray[np.float64] | None = None
) -> JointTrajectory:
    """Return the trajectory with columns in the controller's joint order, as JTC sorts goals.

    A goal leaving joints out is refused, unless the controller has allow_partial_joints_goal:
    then each joint left out holds at `hold` (the robot's positions, in the controller's
    order), with zero velocity and acceleration, as JTC's fill_partial_goal fills it.

    Raises:
        UnknownName: A joint the controller does not drive.
        InputError: Joints left out, and partial goals not allowed (or `hold` not given).
    """
    missing = check_goal_joints(trajectory.joint_names, controller)
    if missing and hold is None:
        raise InputError(f"Joints on incoming trajectory don't match the controller joints: controller "
                         f"'{controller.name}' also has {', '.join(missing)} (the robot's positions to hold "
                         "them at are not known here)")
    if trajectory.joint_names == controller.joints:
        return trajectory
    count = len(trajectory.times_s)
    columns = []
    for k, joint in enumerate(controller.joints):
        if joint in trajectory.joint_names:
            index = trajectory.joint_names.index(joint)
            columns.append((trajectory.positions[:, index], trajectory.velocities[:, index],
                            trajectory.accelerations[:, index]))
        else:
            assert hold is not None
            columns.append((np.full(count, float(hold[k])), np.zeros(count), np.zeros(count)))
    positions, velocities, accelerations = (np.stack([c[i] for c in columns], axis=1) for i in range(3))
    return JointTrajectory(controller.joints, trajectory.times_s, positions, velocities, accelerations,
                           has_velocities=trajectory.has_velocities, has_accelerations=trajectory.has_accelerations)


def check_goal_joints(joints: Sequence[str], controller: ControllerConfig) -> list[str]:
    """Return the controller's joints a goal naming `joints` leaves out, if JTC accepts such a goal.

    Raises:
        UnknownName: A joint the controller does not drive.
        InputError: Joints left out and the controller does not allow partial goals (JTC's message).
    """
    for joint in joints:
        if joint not in controller.joints:
            raise UnknownName("joint", joint, f"controller '{controller.name}'", controller.joints)
    missing = [j for j in controller.joints if j not in joints]
    if missing and not controller.allow_partial_joints_goal:
        raise InputError(f"Joints on incoming trajectory don't match the controller joints: controller "
                         f"'{controller.name}' also has {', '.join(missing)} (partial goals are not allowed)")
    return missing


def unchecked_joints(controller: ControllerConfig) -> dict[str, tuple[str, ...]]:
    """Return per check (path, goal) the joints whose tolerance is 0, which JTC does not check."""
    return {
        "path": tuple(j for j in controller.joints if not controller.trajectory_tolerance.get(j, 0.0) > 0.0),
        "goal": tuple(j for j in controller.joints if not controller.goal_tolerance.get(j, 0.0) > 0.0),
    }


ERASE = -1.0
"""A goal's tolerance of -1 erases the controller's: nothing is checked (control_msgs/JointTolerance)."""

_FLT_EPSILON = float(np.finfo(np.float32).eps)


def goal_segment_tolerances(defaults: SegmentTolerances, goal: GoalTolerances | None) -> SegmentTolerances:
    """Return the tolerances of one goal: the controller's, replaced by those the goal carries.

    As JTC's get_segment_tolerances (tolerances.hpp; test_tolerances.cpp): a value > 0 replaces
    the default, 0 keeps it, -1 erases it (0: not checked); any other negative value, or a joint
    the controller does not drive, makes the whole goal use the defaults, with a warning, as JTC
    logs an error and goes on. Accelerations are kept but not checked: JTC computes no
    acceleration error for a position or velocity command.
    """
    if goal is None:
        return defaults
    try:
        goal_time = _resolved(defaults.goal_time_s, goal.goal_time_s, "goal_time_tolerance")
        state = _joint_tolerances(defaults.state, goal.path, defaults.joint_names, "path_tolerance")
        final = _joint_tolerances(defaults.goal, goal.goal, defaults.joint_names, "goal_tolerance")
    except ValueError as exc:
        _log.warning("%s; the controller's tolerances apply to this goal, as JTC applies them", exc)
        return defaults
    return SegmentTolerances(defaults.joint_names, state, final, goal_time)


def _joint_tolerances(defaults: tuple[StateTolerance, ...], given: Sequence[JointTolerance],
                      joints: tuple[str, ...], field_name: str) -> tuple[StateTolerance, ...]:
    active = list(defaults)
    for tolerance in given:
        if tolerance.name not in joints:
            raise ValueError(f"joint '{tolerance.name}' specified in goal.{field_name} does not exist")
        i = joints.index(tolerance.name)
        where = f"joint '{tolerance.name}' specified in goal.{field_name}"
        active[i] = StateTolerance(
            _resolved(defaults[i].position, tolerance.position, f"{where} position"),
            _resolved(defaults[i].velocity, tolerance.velocity, f"{where} velocity"),
            _resolved(defaults[i].acceleration, tolerance.acceleration, f"{where} acceleration"),
        )
    return tuple(active)


def _resolved(default: float, given: float, what: str) -> float:
    """Return a tolerance a goal gives: > 0 it, -1 erased (0), 0 the default; ValueError for another negative."""
    if given > 0.0:
        return given
    if abs(given - ERASE) < _FLT_EPSILON:
        return 0.0
    if given < 0.0 or not np.isfinite(given):
        raise ValueError(f"{what} is invalid ({given:g}; > 0, 0 for the controller's or -1 to erase it)")
    return default
