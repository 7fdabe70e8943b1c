"""Eleven real MoveIt 2 config packages, laid out as a colcon workspace's src/, used as they are.

Each loads with no environment set (vendors' packages through their launch files, with the one
launch argument that picks the robot of a family), plans a joint goal and a pose goal in its arm
group, the files read back in rosbags, and the plan executes on the fake controller with the
package's own controllers (UR: the driver's ur_controllers.yaml, as its launch file loads it;
TIAGo: tiago_controller_configuration's arm controller, as its bringup spawns it).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from conftest import REALWORLD as SRC
from conftest import Cli
from rosbags.highlevel import AnyReader

from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model.robot import Robot

pytestmark = pytest.mark.realworld


@dataclass(frozen=True)
class Package:
    """A config package of the workspace, the group its users plan with and the flags its launch file implies."""

    path: str
    group: str
    flags: tuple[str, ...] = ()
    controllers: str = ""  # a controllers file outside the package (execute --controllers)
    launch_args: tuple[str, ...] = ()  # --launch-arg NAME:=VALUE, the robot of a family


UR_FLAGS = ("--urdf", "package://ur_description/urdf/ur.urdf.xacro", "--xacro-arg", "ur_type:=ur5e",
            "--xacro-arg", "name:=ur")
PACKAGES = {
    "fanuc": Package("moveit_resources/fanuc_moveit_config", "manipulator"),
    "panda": Package("moveit_resources/panda_moveit_config", "panda_arm"),
    "dual_arm_panda": Package("moveit_resources/dual_arm_panda_moveit_config", "left_panda_arm"),
    "ur5e": Package("Universal_Robots_ROS2_Driver/ur_moveit_config", "ur_manipulator", UR_FLAGS,
                    "Universal_Robots_ROS2_Driver/ur_robot_driver/config/ur_controllers.yaml"),
    "gen3": Package("ros2_kortex/kortex_moveit_config/kinova_gen3_7dof_robotiq_2f_85_moveit_config", "manipulator"),
    # Its launch files name a URDF xacro refuses (a macro parameter the arm's macro lacks): the Setup
    # Assistant's copy named like the SRDF is the one that expands.
    "gen3_lite": Package("ros2_kortex/kortex_moveit_config/kinova_gen3_lite_moveit_config", "arm", (
        "--urdf", "package://kinova_gen3_lite_moveit_config/config/gen3_lite.urdf.xacro")),
    "irb1200": Package("abb_ros2/robot_specific_config/abb_irb1200_5_90_moveit_config", "manipulator"),
    "fr3": Package("franka_ros2/franka_fr3_moveit_config", "fr3_arm"),
    "kr6_r700_sixx": Package("kuka_robot_descriptions/kuka_kr_moveit_config", "manipulator"),
    "wx250s": Package("interbotix_ros_manipulators/interbotix_ros_xsarms/interbotix_xsarm_moveit", "interbotix_arm",
                      launch_args=("robot_model:=wx250s",)),
    "tiago": Package("tiago_moveit_config", "arm",
                     controllers="tiago_robot/tiago_controller_configuration/config/arm_controller.yaml"),
}


@pytest.fixture(autouse=True)
def no_ros_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    """Users run moveplan from a plain shell: no sourced workspace."""
    for name in ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH"):
        monkeypatch.delenv(name, raising=False)


def _goal(package: Package) -> tuple[Robot, np.ndarray, np.ndarray]:
    """Return the robot, its start values and a joint goal a fifth of the way from the start to mid-range."""
    flags = dict(zip(package.flags[::2], package.flags[1::2], strict=True))
    args = dict(a.split(":=") for a in package.flags[3::2]) if package.flags else {}
    config = load_robot_config(SRC / package.path, urdf=flags.get("--urdf"), xacro_args=args,
                               launch_args=dict(a.split(":=") for a in package.launch_args))
    robot = Robot(config, package.group)
    start = np.array([config.initial_positions[j] for j in robot.group.joints])
    lower = np.array([max(config.limits[j].lower, -np.pi) for j in robot.group.joints])
    upper = np.array([min(config.limits[j].upper, np.pi) for j in robot.group.joints])
    goal = start + 0.2 * ((lower + upper) / 2 + 0.5 - start)
    return robot, start, np.clip(goal, lower, upper)


def _read_back(path: Path) -> set[str]:
    """Return the topics of an MCAP file after deserialising every message with rosbags."""
    with AnyReader([path]) as reader:
        for connection, _, raw in reader.messages():
            reader.deserialize(raw, connection.msgtype)
        return {c.topic for c in reader.connections}


@pytest.mark.parametrize("name", PACKAGES)
def test_a_real_config_plans_joint_and_pose_goals_and_executes(name: str, cli: Cli, tmp_path: Path) -> None:
    package = PACKAGES[name]
    robot, start, goal = _goal(package)
    launch = [word for arg in package.launch_args for word in ("--launch-arg", arg)]
    config = [*package.flags, *launch, "--robot", SRC / package.path, "--group", package.group, "--seed", 0]
    joints = ",".join(f"{j}={v:.6f}" for j, v in zip(robot.group.joints, goal, strict=True))
    result = cli("plan", *config, "--joints", joints, "-o", tmp_path / "joint.mcap")
    assert result.exit_code == 0, result.stderr
    tip = robot.frame_pose(robot.configuration(goal), robot.group.tip)
    position, quaternion = tip[:3, 3], _quaternion(tip[:3, :3])
    pose = ",".join(f"{v:.6f}" for v in (*position, *quaternion))
    result = cli("plan", *config, "--pose", pose, "--frame", robot.root_link, "-o", tmp_path / "pose.mcap")
    assert result.exit_code == 0, result.stderr
    for file in ("joint.mcap", "pose.mcap"):
        assert "/planned_trajectory" in _read_back(tmp_path / file)
    controllers = ("--controllers", SRC / package.controllers) if package.controllers else ()
    code, report = cli.json("execute", tmp_path / "pose.mcap", "--fake", *controllers, "-o", tmp_path / "run.mcap")
    assert code == 0 and report["result"]["name"] == "SUCCESSFUL", report
    assert "/joint_states" in _read_back(tmp_path / "run.mcap")


def _quaternion(rotation: np.ndarray) -> tuple[float, float, float, float]:
    """Return (x, y, z, w) of a rotation matrix."""
    import pinocchio as pin

    q = pin.Quaternion(rotation)
    return q.x, q.y, q.z, q.w
