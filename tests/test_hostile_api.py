"""moveplan.commander misused: a setter given NaN, infinity or the wrong type raises the commander's
error naming the method and the value at once, never a ValueError or AttributeError from deep inside."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest
from conftest import UR10E

from moveplan import commander as moveit_commander
from moveplan.core.errors import UsageError

Group = moveit_commander.MoveGroupCommander


@pytest.fixture(scope="module")
def group() -> Group:
    moveit_commander.RobotCommander(str(UR10E))
    return moveit_commander.MoveGroupCommander("manipulator")


@pytest.mark.parametrize(("call", "message"), [
    (lambda g: g.set_planning_time(math.nan), "set_planning_time: expected a finite number, got nan"),
    (lambda g: g.set_planning_time(math.inf), "set_planning_time: expected a finite number, got inf"),
    (lambda g: g.set_planning_time("5"), "set_planning_time: expected a finite number, got '5'"),
    (lambda g: g.set_planning_time(1e9), "set_planning_time: expected a positive number of seconds up to 1e+06"),
    (lambda g: g.set_goal_tolerance(math.nan), "set_goal_tolerance: expected a finite number, got nan"),
    (lambda g: g.set_goal_joint_tolerance(-0.1), "set_goal_joint_tolerance: expected a tolerance >= 0, got -0.1"),
    (lambda g: g.set_num_planning_attempts(1.5), "set_num_planning_attempts: expected an integer >= 0, got 1.5"),
    (lambda g: g.set_planner_id(3), "set_planner_id: expected a planner's name, got 3"),
    (lambda g: g.execute(None), "execute: expected a RobotTrajectory or a trajectory_msgs JointTrajectory, got "
                                "NoneType"),
    (lambda g: g.set_pose_target(None), "set_pose_target: expected a Pose, a PoseStamped or a list"),
])
def test_a_setter_given_nan_infinity_or_the_wrong_type_names_the_method_and_value(
    group: Group, call: Callable[[Group], Any], message: str
) -> None:
    with pytest.raises(UsageError) as raised:
        call(group)
    assert str(raised.value).startswith(message)
    assert isinstance(raised.value, moveit_commander.MoveItCommanderException)


def test_a_refused_planning_time_leaves_the_one_set_before(group: Group) -> None:
    group.set_planning_time(2.0)
    with pytest.raises(UsageError):
        group.set_planning_time(math.nan)
    assert group.get_planning_time() == 2.0
