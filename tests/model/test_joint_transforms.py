"""/tf's joint poses, written out for all samples at once, are pinocchio's to rounding and the same every run."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model._joint_transforms import joint_table
from moveplan.core.model.robot import Robot
from moveplan.core.rotations import tf_poses

ROBOTS = [ROOT / "configs" / "ur10e", ROOT / "configs" / "panda", ROOT / "configs" / "excavator",
          ROOT / "tests" / "data" / "mbm" / "panda_robot",
          ROOT / "tests" / "data" / "limits_start"]  # revolute, prismatic and continuous joints, axes X, Y and Z


def _pinocchios(robot: Robot, values: np.ndarray) -> np.ndarray:
    """Return parent_T_child of every moving URDF joint as /tf poses, asked of pinocchio sample by sample."""
    moving = [j for j in robot.config.urdf_joints.values() if j.type != "fixed"]
    frames = [(robot.model.getFrameId(j.parent), robot.model.getFrameId(j.child)) for j in moving]
    data = robot.model.createData()
    out = []
    for q in robot.configurations(values, robot.neutral()).T:
        pin.framesForwardKinematics(robot.model, data, q)
        out.append([(data.oMf[p].inverse() * data.oMf[c]).homogeneous for p, c in frames])
    return tf_poses(np.array(out))


def _random_values(robot: Robot, count: int) -> np.ndarray:
    rng = np.random.default_rng(7)
    low = np.where(np.isfinite(robot.lower), robot.lower, -2 * np.pi)
    high = np.where(np.isfinite(robot.upper), robot.upper, 2 * np.pi)
    return low + rng.random((count, robot.dof)) * (high - low)


@pytest.mark.parametrize("source", ROBOTS, ids=lambda p: Path(p).name)
def test_every_robots_tf_poses_are_pinocchios_to_rounding(source: Path) -> None:
    robot = Robot(load_robot_config(source))
    values = _random_values(robot, 50)
    samples = robot.tf_samples(np.arange(50.0), values, robot.neutral())
    assert samples.poses.shape == (50, len(samples.parents), 7)
    expected = _pinocchios(robot, values)
    assert np.abs(samples.poses[..., :3] - expected[..., :3]).max() < 1e-14
    # A quaternion and its negative are one rotation; w >= 0 picks one, but w ~ 0 may round either way.
    rotations = np.minimum(np.abs(samples.poses[..., 3:] - expected[..., 3:]).max(-1),
                           np.abs(samples.poses[..., 3:] + expected[..., 3:]).max(-1))
    assert rotations.max() < 1e-14
    assert (samples.poses[..., 6] >= 0).all()
    again = robot.tf_samples(np.arange(50.0), values, robot.neutral())
    assert again.poses.tobytes() == samples.poses.tobytes()


def test_a_robot_whose_joints_are_not_written_out_gets_pinocchios_own() -> None:
    robot = Robot(load_robot_config(ROOT / "configs" / "ur10e"))
    # Two links that no single joint joins (the base and the wrist) are not a joint written out.
    assert joint_table(robot.model, [(robot.model.getFrameId("base_link"), robot.model.getFrameId("wrist_3_link"))]) \
        is None
    robot._joint_table = None  # as for such a robot: every sample asked of pinocchio
    values = _random_values(robot, 10)
    samples = robot.tf_samples(np.arange(10.0), values, robot.neutral())
    assert samples.poses.tobytes() == _pinocchios(robot, values).tobytes()
