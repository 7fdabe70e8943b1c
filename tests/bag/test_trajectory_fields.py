"""A JointTrajectory whose points carry positions only, as ros2_controllers' action tests send, read and written."""

from __future__ import annotations

import numpy as np
from rosbags.typesys import Stores, get_typestore

from moveplan.core.bag.cdr.bulk import joint_trajectory_cdr
from moveplan.core.bag.cdr.messages import trajectory_from_message
from moveplan.core.types import JointTrajectory

STORE = get_typestore(Stores.ROS2_JAZZY)
TYPE = "trajectory_msgs/msg/JointTrajectory"


def test_positions_only_points_are_written_empty_and_read_back_as_positions_only() -> None:
    positions = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    trajectory = JointTrajectory(("joint1", "joint2", "joint3"), [0.2, 0.3], positions, np.zeros((2, 3)),
                                 np.zeros((2, 3)), has_velocities=False, has_accelerations=False)
    message = STORE.deserialize_cdr(joint_trajectory_cdr(trajectory, "base"), TYPE)
    assert [len(p.velocities) for p in message.points] == [0, 0]  # an independent reader sees them empty
    assert [len(p.accelerations) for p in message.points] == [0, 0]
    back = trajectory_from_message(message)
    assert not back.has_velocities and not back.has_accelerations
    np.testing.assert_array_equal(back.positions, positions)


def test_positions_and_velocities_without_accelerations_read_as_such() -> None:
    positions = np.array([[0.0], [4.0]])
    trajectory = JointTrajectory(("joint1",), [1.0, 3.0], positions, [[-2.0], [10.0]], np.zeros((2, 1)),
                                 has_accelerations=False)
    back = trajectory_from_message(STORE.deserialize_cdr(joint_trajectory_cdr(trajectory, "base"), TYPE))
    assert back.has_velocities and not back.has_accelerations
    np.testing.assert_array_equal(back.velocities, [[-2.0], [10.0]])
