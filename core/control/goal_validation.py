"""The JointTrajectoryController's goal validation: a trajectory it would refuse, refused before it runs.

ros2_controllers' validate_trajectory_msg rejects a goal whose time_from_start is not
strictly increasing ("Time between points 3 and 4 is not strictly increasing, it is
0.300000 and 0.300000 respectively") or whose fields do not match the joints. A NaN or
infinite value would pass JTC's size checks and then command the hardware with it; a
simulation cannot say what a robot does with that, so moveplan refuses such a goal as
well, naming the point, joint and field.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..types import JointTrajectory

__all__ = ["FLT_EPSILON", "validate_goal", "validate_goal_end"]

FLT_EPSILON = float(np.finfo(np.float32).eps)
"""What JTC compares the last point's velocities with (std::numeric_limits<float>::epsilon())."""


def validate_goal(trajectory: JointTrajectory, where: str) -> None:
    """Raise InputError if JTC would refuse `trajectory` as a goal, or it holds a non-finite value.

    Args:
        trajectory: One step's trajectory, as sent to the controller.
        where: What the message names first: "plan.mcap: step 'approach' on /planned_trajectory".

    Raises:
        InputError: A time, position, velocity or acceleration is NaN or infinite, or the
            times are not strictly increasing.

    """
    times = trajectory.times_s
    fields = (("time_from_start", times[:, None]), ("positions", trajectory.positions),
              ("velocities", trajectory.velocities), ("accelerations", trajectory.accelerations))
    for field, values in fields:
        bad = ~np.isfinite(values)
        if bad.any():
            point, column = (int(i) for i in np.argwhere(bad)[0])
            joint = "" if field == "time_from_start" else f" of joint {trajectory.joint_names[column]}"
            count = int(bad.sum())
            more = f" ({count} non-finite values in {field})" if count > 1 else ""
            raise InputError(
                f"{where}: invalid goal, the controller would reject it: {field}{joint} at point "
                f"#{point} (t={_time(times, point)}) is {values[point, column]}{more}")
    steps = np.diff(times)
    if np.any(steps <= 0.0):
        i = int(np.flatnonzero(steps <= 0.0)[0])
        raise InputError(
            f"{where}: invalid goal, the controller would reject it: Time between points {i} and "
            f"{i + 1} is not strictly increasing, it is {times[i]:f} and {times[i + 1]:f} respectively")


def validate_goal_end(trajectory: JointTrajectory, allow_nonzero_velocity: bool, where: str) -> None:
    """Raise InputError if JTC with `allow_nonzero_velocity_at_trajectory_end: false` would refuse `trajectory`.

    ros2_controllers' validate_trajectory_msg refuses a goal whose last point has a velocity
    above FLT_EPSILON (test_trajectory_actions.cpp, test_allow_nonzero_velocity_at_trajectory_end_false);
    a point without velocities passes.
    """
    if allow_nonzero_velocity or not trajectory.has_velocities:
        return
    last = trajectory.velocities[-1]
    moving = np.flatnonzero(np.abs(last) > FLT_EPSILON)
    if moving.size:
        i = int(moving[0])
        raise InputError(
            f"{where}: invalid goal, the controller would reject it: Velocity of last trajectory point of joint "
            f"{trajectory.joint_names[i]} is not zero: {last[i]:.15f} (allow_nonzero_velocity_at_trajectory_end "
            "is false, Jazzy's default)")


def _time(times: np.ndarray, point: int) -> str:
    value = float(times[point])
    return f"{value:.6f} s" if np.isfinite(value) else str(value)
