"""moveplan.commander: MoveIt's Python API planning, executing and saving on the CLI's pipeline."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import SAMPLES, UR10E, Cli
from rosbags.highlevel import AnyReader
from scipy.spatial.transform import Rotation

from moveplan import commander as moveit_commander
from moveplan.commander.conversions import pose_to_list
from moveplan.commander.msgs import JointState, MoveItErrorCodes, Pose, PoseStamped, RobotState, TransformStamped
from moveplan.commander.ros import rospy, tf2_ros
from moveplan.commander.ros.control_msgs.msg import FollowJointTrajectoryGoal, JointTolerance
from moveplan.commander.ros.tf.transformations import euler_from_quaternion, quaternion_from_euler
from moveplan.core.bag import read_plan
from moveplan.core.config import load_task
from moveplan.core.errors import (
    ConfigError,
    FrameNotFound,
    GoalOutsideLimits,
    InputError,
    UnknownName,
    UsageError,
)
from moveplan.core.pipeline.plan import plan as plan_pipeline
from moveplan.core.pipeline.request import PlanFlags, resolve_request

READY = [0.0, -math.pi / 2, math.pi / 2, -math.pi / 2, -math.pi / 2, 0.0]
HOME = [0.0, -math.pi / 2, -math.pi / 2, 0.0, 0.0, 0.0]
WORKSHOP_SCENE = SAMPLES / "ur10e_workshop_scene.yaml"


@pytest.fixture()
def robot() -> moveit_commander.RobotCommander:
    return moveit_commander.RobotCommander("ur10e", scene=WORKSHOP_SCENE)


@pytest.fixture()
def group(robot: moveit_commander.RobotCommander) -> moveit_commander.MoveGroupCommander:
    return moveit_commander.MoveGroupCommander("manipulator")


def stamped(frame: str, xyz: tuple[float, float, float] = (0, 0, 0), rpy: tuple[float, float, float] = (0, 0, 0),
            ) -> PoseStamped:
    pose = PoseStamped()
    pose.header.frame_id = frame
    pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = xyz
    q = quaternion_from_euler(*rpy)
    pose.pose.orientation.x, pose.pose.orientation.y, pose.pose.orientation.z, pose.pose.orientation.w = q
    return pose


def matrix(pose: Pose) -> np.ndarray:
    result = np.eye(4)
    x, y, z, *quaternion = pose_to_list(pose)
    result[:3, :3] = Rotation.from_quat(quaternion).as_matrix()
    result[:3, 3] = x, y, z
    return result


# Messages and transformations


def test_messages_are_mutable_and_deep_copies_are_independent() -> None:
    pose = Pose()
    pose.position.z += 0.1
    copied = copy.deepcopy(pose)
    copied.position.z += 0.1
    assert pose.position.z == pytest.approx(0.1) and copied.position.z == pytest.approx(0.2)
    assert pose_to_list(Pose()) == [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]


def test_quaternion_from_euler_is_rotation_about_fixed_axes_and_round_trips() -> None:
    angles = (0.3, -1.1, 2.5)
    q = quaternion_from_euler(*angles)
    np.testing.assert_allclose(Rotation.from_quat(q).as_matrix(),
                               Rotation.from_euler("xyz", angles).as_matrix(), atol=1e-12)
    np.testing.assert_allclose(euler_from_quaternion(q), angles, atol=1e-12)


# RobotCommander


def test_robot_commander_reports_groups_frames_and_current_state(robot: moveit_commander.RobotCommander) -> None:
    assert robot.get_group_names() == ["manipulator"]
    assert robot.get_planning_frame() == "base_link"
    state = robot.get_current_state()
    assert isinstance(state, RobotState)
    assert state.joint_state.name[:3] == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"]
    np.testing.assert_allclose(state.joint_state.position, [0.0, -1.57, 0.0, -1.57, 0.0, 0.0])  # mock hardware
    assert "tool0" in robot.get_link_names()


def test_robot_commander_without_robot_reads_moveplan_robot(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("MOVEPLAN_ROBOT", raising=False)
    with pytest.raises(UsageError, match="no robot: give a config .* or set MOVEPLAN_ROBOT"):
        moveit_commander.RobotCommander()
    monkeypatch.setenv("MOVEPLAN_ROBOT", str(UR10E))
    assert moveit_commander.RobotCommander().get_group_names() == ["manipulator"]


def test_unknown_robot_group_and_plant_are_refused_when_created() -> None:
    with pytest.raises(ConfigError, match="no_such_robot: robot config not found"):
        moveit_commander.RobotCommander("no_such_robot")
    with pytest.raises(UsageError, match="unknown plant 'bogus'; known: lag, mirror, pid"):
        moveit_commander.RobotCommander("ur10e", plant="bogus")
    moveit_commander.RobotCommander("ur10e")
    with pytest.raises(UnknownName, match="group 'arm' not found in .*ur10e.srdf; known: manipulator"):
        moveit_commander.MoveGroupCommander("arm")


# Joint and named targets


def test_go_to_joint_goal_lands_exactly_and_moves_the_current_state(group: moveit_commander.MoveGroupCommander) -> None:
    goal = [0.5, -1.2, -1.8, 0.0, 1.57, 0.0]
    assert group.go(goal, wait=True) is True
    np.testing.assert_allclose(group.get_current_joint_values(), goal, atol=1e-6)
    assert group.get_execution_report().result.name == "SUCCESSFUL"
    group.set_joint_value_target({"elbow_joint": -1.0})
    assert group.go()
    np.testing.assert_allclose(group.get_current_joint_values(), [0.5, -1.2, -1.0, 0.0, 1.57, 0.0], atol=1e-6)


def test_plan_returns_moveits_tuple_with_a_timed_trajectory(group: moveit_commander.MoveGroupCommander) -> None:
    group.set_named_target("ready")
    success, trajectory, planning_time, error_code = group.plan()
    assert success is True and error_code.val == MoveItErrorCodes.SUCCESS
    assert 0.0 < planning_time < 5.0
    points = trajectory.joint_trajectory.points
    assert trajectory.joint_trajectory.joint_names == group.get_active_joints()
    assert trajectory.joint_trajectory.header.frame_id == "base_link"
    times = [p.time_from_start.to_sec() for p in points]
    assert times[0] == 0.0 and all(b > a for a, b in zip(times, times[1:], strict=False))
    np.testing.assert_allclose(points[0].positions, group.get_current_joint_values(), atol=1e-12)
    np.testing.assert_allclose(points[-1].positions, READY, atol=1e-12)
    assert len(points[-1].velocities) == len(points[-1].accelerations) == 6
    np.testing.assert_allclose(group.get_current_joint_values(), [0.0, -1.57, 0.0, -1.57, 0.0, 0.0])  # not moved


def test_scaling_factors_lengthen_the_motion_as_moveit_does(group: moveit_commander.MoveGroupCommander) -> None:
    group.set_max_velocity_scaling_factor(1.0)
    group.set_max_acceleration_scaling_factor(1.0)
    fast = group.plan("ready")[1].joint_trajectory.points[-1].time_from_start.to_sec()
    group.set_max_velocity_scaling_factor(0.1)
    group.set_max_acceleration_scaling_factor(0.1)
    slow = group.plan("ready")[1].joint_trajectory.points[-1].time_from_start.to_sec()
    assert slow > 3 * fast
    with pytest.raises(UsageError, match="set_max_velocity_scaling_factor: expected a value in the range"):
        group.set_max_velocity_scaling_factor(0.0)
    with pytest.raises(UsageError, match="set_max_acceleration_scaling_factor"):
        group.set_max_acceleration_scaling_factor(1.5)


def test_bad_joint_targets_raise_the_clis_typed_errors(group: moveit_commander.MoveGroupCommander, cli: Cli,
                                                       tmp_path: Path) -> None:
    with pytest.raises(UnknownName) as raised:
        group.set_joint_value_target({"elbow": 1.0})
    result = cli("plan", "--robot", UR10E, "--joints", "elbow=1.0", "-o", tmp_path / "out.mcap")
    shared = "joint 'elbow' not found in group 'manipulator'"
    assert str(raised.value).startswith(shared) and shared in result.stderr
    with pytest.raises(UsageError, match="set_joint_value_target: 3 joint values; the group has 6 joints"):
        group.set_joint_value_target([0.1, 0.2, 0.3])
    with pytest.raises(GoalOutsideLimits, match="goal for joint 'elbow_joint' is 7 rad, outside its limits"):
        group.set_joint_value_target("elbow_joint", 7.0)
    with pytest.raises(UnknownName, match="named state 'nowhere' not found .* known: home, ready, up"):
        group.set_named_target("nowhere")


def test_a_partial_joint_target_keeps_the_previous_targets_values(group: moveit_commander.MoveGroupCommander) -> None:
    # MoveIt's joint state target (moveit_commander test/python_moveit_commander.py, test_target_setting):
    # it starts at the model's default values, and a partial target changes only the joints it names.
    assert group.get_joint_value_target() == [0.0] * 6
    group.set_joint_value_target([0.3] * 6)
    group.set_joint_value_target("shoulder_pan_joint", 0.5)
    assert group.get_joint_value_target() == [0.5] + [0.3] * 5
    group.set_joint_value_target({"wrist_3_joint": 0.1})
    assert group.get_joint_value_target() == [0.5] + [0.3] * 4 + [0.1]
    group.set_pose_target(stamped("target_1"))
    assert group.get_joint_value_target() == [0.5] + [0.3] * 4 + [0.1]  # a pose target leaves it as it is


def test_remembered_values_are_named_targets(group: moveit_commander.MoveGroupCommander) -> None:
    group.remember_joint_values("bent", [0.2, -1.0, 1.0, -1.0, -1.5, 0.0])
    assert "bent" in group.get_named_targets() and "home" in group.get_named_targets()
    assert group.go("bent")
    np.testing.assert_allclose(group.get_current_joint_values(), [0.2, -1.0, 1.0, -1.0, -1.5, 0.0], atol=1e-6)
    assert group.get_named_target_values("home")["elbow_joint"] == pytest.approx(-math.pi / 2)


# Pose targets


def test_pose_target_in_a_scene_frame_lands_on_the_frame(group: moveit_commander.MoveGroupCommander) -> None:
    group.set_pose_target(stamped("target_2", (0, 0, 0.1), (math.pi, 0, 0)))
    assert group.go()
    tool = matrix(group.get_current_pose().pose)
    target = np.eye(4)
    target[:3, :3] = Rotation.from_euler("xyz", (0, 0.7330383, 0)).as_matrix()
    target[:3, 3] = 0.7, -0.2, 0.3
    np.testing.assert_allclose(tool[:3, 3], (target @ [0, 0, 0.1, 1])[:3], atol=1e-4)
    np.testing.assert_allclose(tool[:3, 2], -target[:3, 2], atol=1e-3)  # the tool points at the target


def test_pose_goals_land_where_the_cli_sample_does(group: moveit_commander.MoveGroupCommander) -> None:
    sample = plan_pipeline(resolve_request(load_task(SAMPLES / "ur10e_tilted_approach.yaml"), PlanFlags()))
    group.go("ready")
    group.set_max_velocity_scaling_factor(0.3)
    group.set_max_acceleration_scaling_factor(0.3)
    success, trajectory, _, _ = group.plan(stamped("target_2", (0, 0, 0.1), (math.pi, 0, 0)))
    assert success
    np.testing.assert_allclose(trajectory.joint_trajectory.points[-1].positions,
                               sample.steps[0].trajectory.positions[-1], atol=1e-6)


def test_pose_lists_of_six_and_seven_numbers_are_the_same_pose(group: moveit_commander.MoveGroupCommander) -> None:
    group.go("ready")
    here = group.get_current_pose().pose
    as_rpy = [here.position.x, here.position.y, here.position.z - 0.1,
              *euler_from_quaternion(pose_to_list(here)[3:])]
    group.set_pose_target(as_rpy)
    assert group.go()
    first = group.get_current_joint_values()
    group.go("ready")
    group.set_pose_target([*as_rpy[:3], *pose_to_list(here)[3:]])
    assert group.go()
    np.testing.assert_allclose(group.get_current_joint_values(), first, atol=1e-6)
    with pytest.raises(UsageError, match="set_pose_target: pose list .* got 5 numbers"):
        group.set_pose_target([0.1, 0.2, 0.3, 0.0, 1.0])
    with pytest.raises(UsageError, match="not a rotation|nonzero"):
        group.set_pose_target([0.5, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0])


def test_shift_pose_target_moves_along_planning_axes_and_rolls_about_the_tool(
        group: moveit_commander.MoveGroupCommander) -> None:
    group.go("ready")
    start = matrix(group.get_current_pose().pose)
    group.shift_pose_target(2, 0.1)
    assert group.go()
    shifted = matrix(group.get_current_pose().pose)
    np.testing.assert_allclose(shifted[:3, 3], start[:3, 3] + [0, 0, 0.1], atol=1e-4)
    np.testing.assert_allclose(shifted[:3, :3], start[:3, :3], atol=1e-3)
    group.shift_pose_target(3, 0.2)  # roll: about the tool's own x axis (MoveIt's sxyz angles)
    assert group.go()
    rolled = matrix(group.get_current_pose().pose)
    np.testing.assert_allclose(rolled[:3, :3], shifted[:3, :3] @ Rotation.from_euler("x", 0.2).as_matrix(),
                               atol=1e-3)
    with pytest.raises(UsageError, match="an axis value between 0 and 5 expected, got 6"):
        group.shift_pose_target(6, 0.1)


def test_pose_target_in_an_unknown_frame_raises_frame_not_found(group: moveit_commander.MoveGroupCommander) -> None:
    group.set_pose_target(stamped("tol0"))
    with pytest.raises(FrameNotFound, match="frame 'tol0' not found in .*ur10e_workshop_scene.yaml; known: .*object"):
        group.plan()


# Failed plans and executions


def test_failed_plans_return_false_an_empty_trajectory_and_moveits_code(
        robot: moveit_commander.RobotCommander, group: moveit_commander.MoveGroupCommander) -> None:
    scene = moveit_commander.PlanningSceneInterface()
    far = Pose()
    far.position.x = 5.0
    success, trajectory, _, code = group.plan(far)
    assert (success, trajectory.joint_trajectory.points, code.val) == (False, [], MoveItErrorCodes.NO_IK_SOLUTION)
    assert code.message.startswith("no IK solution for link 'tool0'")
    group.go("ready")
    scene.add_box("blocker", group.get_current_pose(), size=(0.1, 0.1, 0.1))
    assert group.plan("home")[3].val == MoveItErrorCodes.START_STATE_IN_COLLISION
    scene.remove_world_object("blocker")
    group.go("home")
    scene.add_box("blocker", stamped("base_link", (0.6914, 0.1741, 0.6768)), size=(0.2, 0.2, 0.2))
    success, _, _, code = group.plan("ready")
    assert not success and code.val == MoveItErrorCodes.GOAL_IN_COLLISION and "touches blocker" in code.message
    before = group.get_current_joint_values()
    assert group.go("ready") is False
    assert group.get_current_joint_values() == before


def test_executing_a_stale_trajectory_is_refused_and_moves_nothing(group: moveit_commander.MoveGroupCommander) -> None:
    _, to_home, _, _ = group.plan("home")
    assert group.go("ready")
    assert group.execute(to_home) is False
    report = group.get_execution_report()
    assert report.result.name == "START_STATE_INVALID" and "start point deviates" in report.result.message
    np.testing.assert_allclose(group.get_current_joint_values(), READY, atol=1e-6)


def test_a_failed_execution_leaves_the_robot_where_it_stopped() -> None:
    moveit_commander.RobotCommander("ur10e", plant="pid", controllers=SAMPLES / "ur10e_mistuned_controllers.yaml")
    group = moveit_commander.MoveGroupCommander("manipulator")
    assert group.go("ready") is False
    report = group.get_execution_report()
    assert report.result.name == "PATH_TOLERANCE_VIOLATED" and report.violations[0].check == "path"
    stopped = group.get_current_joint_values()
    assert 0.05 < abs(stopped[2]) < 1.0  # on the way: neither at the start (0) nor at ready (pi/2)


def test_an_edited_trajectory_executes_as_given(group: moveit_commander.MoveGroupCommander) -> None:
    _, trajectory, _, _ = group.plan("ready")
    for point in trajectory.joint_trajectory.points:  # twice as slow: velocities and accelerations scaled
        seconds = point.time_from_start.to_sec() * 2
        point.time_from_start = rospy.Duration.from_sec(seconds)
        point.velocities = [v / 2 for v in point.velocities]
        point.accelerations = [a / 4 for a in point.accelerations]
    assert group.execute(trajectory)
    planned = trajectory.joint_trajectory.points[-1].time_from_start.to_sec()
    assert group.get_execution_report().duration_s == pytest.approx(planned, abs=0.01)  # the slowed timing ran
    trajectory.joint_trajectory.joint_names[0] = "elbow"
    with pytest.raises(UsageError, match="execute: joint_names .* expected distinct joints of the group"):
        group.execute(trajectory)


def test_tolerances_sent_with_execute_replace_the_controller_s_and_are_saved(cli: Cli, tmp_path: Path) -> None:
    """JTC's get_segment_tolerances (test_tolerances.cpp): > 0 replaces the controller's tolerance, -1 erases it."""
    robot = moveit_commander.RobotCommander("ur10e", plant="lag", plant_params={"tau": 0.05})
    group = moveit_commander.MoveGroupCommander("manipulator")
    target = [0.5, -1.2, -1.8, 0.0, 1.57, 0.0]
    tight = FollowJointTrajectoryGoal(goal_tolerance=[JointTolerance(name="elbow_joint", position=1e-6)],
                                      goal_time_tolerance=rospy.Duration(0.001))
    assert group.execute(group.plan(target)[1], tolerances=tight) is False
    assert group.get_execution_report().result.name == "GOAL_TOLERANCE_VIOLATED"
    assert group.go("home")
    erased = {"goal_tolerance": [{"name": "elbow_joint", "position": -1}]}
    assert group.execute(group.plan(target)[1], tolerances=erased) is True
    out = tmp_path / "session.mcap"
    robot.save(out)
    assert [s.tolerances.goal[0].position if s.tolerances else None for s in read_plan(out).steps] == [1e-6, None, -1.0]
    with pytest.raises(UsageError, match=r"^execute: tolerances\.goal_tolerance\[0\]"):
        group.execute(group.plan("home")[1], tolerances={"goal_tolerance": [{"nme": "elbow_joint"}]})
    with pytest.raises(UsageError, match=r"^execute: tolerances: expected a mapping"):
        group.execute(group.plan("home")[1], tolerances=5)


# Cartesian paths


def test_cartesian_path_is_straight_and_stops_short_of_an_obstacle(group: moveit_commander.MoveGroupCommander) -> None:
    group.go("ready")
    start = group.get_current_pose().pose
    down = copy.deepcopy(start)
    down.position.z -= 0.3
    trajectory, fraction = group.compute_cartesian_path([down], 0.01, 0.0)
    assert fraction == 1.0 and len(trajectory.joint_trajectory.points) > 10
    wall = stamped("base_link", (start.position.x, start.position.y, start.position.z - 0.2))
    moveit_commander.PlanningSceneInterface().add_box("wall", wall, size=(0.3, 0.3, 0.02))
    side = copy.deepcopy(start)
    side.position.y -= 0.1
    _, fraction = group.compute_cartesian_path([side, down], 0.01, 0.0)
    assert 0.5 < fraction < 0.85  # the first leg whole, the second cut before the wall
    with pytest.raises(UsageError, match="avoid_collisions=False is not supported"):
        group.compute_cartesian_path([down], 0.01, 0.0, avoid_collisions=False)
    with pytest.raises(UsageError, match="eef_step must be a positive distance"):
        group.compute_cartesian_path([down], 0.0)


def test_executed_cartesian_path_moves_the_tool_along_the_line(group: moveit_commander.MoveGroupCommander) -> None:
    group.go("ready")
    start = group.get_current_pose().pose
    up = copy.deepcopy(start)
    up.position.z += 0.1
    trajectory, fraction = group.compute_cartesian_path([up], 0.01)
    assert fraction == 1.0 and group.execute(trajectory)
    end = group.get_current_pose().pose
    np.testing.assert_allclose(pose_to_list(end)[:3], pose_to_list(up)[:3], atol=1e-4)


# Planning scene


def test_scene_objects_are_added_listed_attached_and_removed(group: moveit_commander.MoveGroupCommander) -> None:
    scene = moveit_commander.PlanningSceneInterface()
    scene.add_box("cube", stamped("object", (0, 0, 0.05)), size=(0.05, 0.05, 0.05))
    scene.add_sphere("ball", stamped("base_link", (0.3, 0.6, 0.1)), radius=0.05)
    scene.add_cylinder("can", stamped("base_link", (-0.3, 0.6, 0.1)), height=0.2, radius=0.04)
    scene.add_mesh("tray", stamped("base_link", (-0.5, -0.2, 0.0)), SAMPLES / "panda_tray.obj")
    assert scene.get_known_object_names() == ["table", "post", "cube", "ball", "can", "tray"]
    np.testing.assert_allclose(pose_to_list(scene.get_object_poses(["cube"])["cube"])[:3], [0.6, -0.4, 0.15])
    group.go("ready")
    tool = group.get_current_pose()
    scene.attach_box("tool0", "gripper", tool, size=(0.04, 0.04, 0.04), touch_links=["tool0", "wrist_3_link"])
    assert scene.get_attached_objects()["gripper"].link_name == "tool0"
    assert "gripper" not in scene.get_known_object_names()
    assert group.go("home")
    np.testing.assert_allclose(pose_to_list(scene.get_attached_objects()["gripper"].object.pose)[:3], [0, 0, 0],
                               atol=1e-9)  # carried at the tool
    scene.remove_attached_object("tool0", "gripper")
    left = scene.get_object_poses(["gripper"])["gripper"]  # stays in the world, where the tool left it
    np.testing.assert_allclose(pose_to_list(left)[:3], pose_to_list(group.get_current_pose().pose)[:3], atol=1e-6)
    scene.remove_world_object("cube")
    assert "cube" not in scene.get_known_object_names()
    scene.remove_world_object()
    assert scene.get_known_object_names() == []


def test_bad_scene_objects_raise_one_clear_error(robot: moveit_commander.RobotCommander) -> None:
    scene = moveit_commander.PlanningSceneInterface()
    with pytest.raises(UsageError, match=r"add_box\('cube'\): size: expected 3 positive lengths"):
        scene.add_box("cube", stamped("base_link"), size=(0.1, -0.1, 0.1))
    with pytest.raises(ConfigError, match="mesh file not found"):
        scene.add_mesh("part", stamped("base_link"), "no_such_mesh.stl")
    with pytest.raises(FrameNotFound, match="frame 'nowhere' not found"):
        scene.add_sphere("ball", stamped("nowhere"), radius=0.1)
    with pytest.raises(UnknownName, match="object 'ghost' not found in the planning scene"):
        scene.attach_object("ghost", "tool0")
    assert scene.get_known_object_names() == ["table", "post"]


# tf


def test_lookup_transform_between_a_static_frame_and_a_link_at_the_current_state(
        group: moveit_commander.MoveGroupCommander) -> None:
    buffer = tf2_ros.Buffer()
    tf2_ros.TransformListener(buffer)
    target = buffer.lookup_transform("base_link", "target_1", rospy.Time(0))
    assert (target.header.frame_id, target.child_frame_id) == ("base_link", "target_1")
    assert [target.transform.translation.x, target.transform.translation.y, target.transform.translation.z] == \
        pytest.approx([0.6, 0.2, 0.4])
    group.go("ready")
    tool = buffer.lookup_transform("base_link", "tool0")
    np.testing.assert_allclose([tool.transform.translation.x, tool.transform.translation.z],
                               [0.6914, 0.6768], atol=1e-3)
    relative = buffer.lookup_transform("tool0", "target_1")
    expected = np.linalg.inv(matrix(group.get_current_pose().pose)) @ [0.6, 0.2, 0.4, 1.0]
    np.testing.assert_allclose([relative.transform.translation.x, relative.transform.translation.y,
                                relative.transform.translation.z], expected[:3], atol=1e-9)
    with pytest.raises(tf2_ros.LookupException, match="frame 'tol0' not found .* known: .*target_1"):
        buffer.lookup_transform("base_link", "tol0")
    assert buffer.can_transform("tool0", "object") and not buffer.can_transform("tool0", "tol0")


def test_a_broadcast_static_frame_is_a_pose_target(group: moveit_commander.MoveGroupCommander) -> None:
    frame = TransformStamped()
    frame.header.frame_id = "target_1"
    frame.child_frame_id = "above_target"
    frame.transform.translation.z = -0.1  # target_1's z points down
    tf2_ros.StaticTransformBroadcaster().sendTransform(frame)
    group.set_pose_target(stamped("above_target"))
    assert group.go()
    np.testing.assert_allclose(pose_to_list(group.get_current_pose().pose)[:3], [0.6, 0.2, 0.5], atol=1e-4)
    moved = tf2_ros.Buffer().transform(stamped("above_target", (0, 0, 0.05)), "base_link")
    np.testing.assert_allclose(pose_to_list(moved.pose)[:3], [0.6, 0.2, 0.45], atol=1e-6)
    frame.child_frame_id = "tool0"
    with pytest.raises(ConfigError, match="frame 'tool0' has the name of a robot link"):
        tf2_ros.StaticTransformBroadcaster().sendTransform(frame)


def test_set_start_state_plans_from_another_state(group: moveit_commander.MoveGroupCommander) -> None:
    group.set_start_state(RobotState(JointState(name=group.get_active_joints(), position=READY)))
    _, trajectory, _, _ = group.plan("home")
    np.testing.assert_allclose(trajectory.joint_trajectory.points[0].positions, READY, atol=1e-12)
    group.set_start_state_to_current_state()
    _, trajectory, _, _ = group.plan("home")
    np.testing.assert_allclose(trajectory.joint_trajectory.points[0].positions, [0, -1.57, 0, -1.57, 0, 0])


# Saving


def test_save_writes_a_plan_file_the_cli_and_rosbags_read(group: moveit_commander.MoveGroupCommander,
                                                         robot: moveit_commander.RobotCommander,
                                                         cli: Cli, tmp_path: Path) -> None:
    with pytest.raises(UsageError, match="no motion has been executed yet"):
        robot.save(tmp_path / "empty.mcap")
    assert not (tmp_path / "empty.mcap").exists()
    assert group.go("home") and group.go([0.5, -1.2, -1.8, 0.0, 1.57, 0.0]) and group.go("home")
    group.plan("ready")  # planned, never executed: not saved
    out = tmp_path / "session.mcap"
    robot.save(out)
    plan = read_plan(out)
    assert [s.name for s in plan.steps] == ["home", "joints", "home_2"]
    assert [e["result"]["name"] for e in json.loads(plan.metadata["executions"])] == ["SUCCESSFUL"] * 3
    with AnyReader([out]) as reader:
        connections = [c for c in reader.connections if c.topic == "/planned_trajectory"]
        messages = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=connections)]
    np.testing.assert_allclose(messages[0].points[-1].positions, HOME, atol=1e-12)
    np.testing.assert_allclose(messages[1].points[-1].positions, [0.5, -1.2, -1.8, 0.0, 1.57, 0.0], atol=1e-12)
    inspected = cli("inspect", out)
    assert inspected.exit_code == 0 and "joints" in inspected.stdout
    executed = cli("execute", out, "--fake", "-o", tmp_path / "executed.mcap")
    assert executed.exit_code == 0, executed.stderr
    with pytest.raises(UsageError, match="is an input of this session"):
        robot.save(WORKSHOP_SCENE)


def test_the_api_prints_nothing(group: moveit_commander.MoveGroupCommander, capfd: pytest.CaptureFixture[str],
                                tmp_path: Path) -> None:
    group.go("ready")
    far = Pose()
    far.position.x = 5.0
    group.plan(far)
    group.execute(group.plan("home")[1])
    moveit_commander.RobotCommander("ur10e").get_current_state()
    assert capfd.readouterr() == ("", "")


def test_bad_input_is_an_input_or_usage_error_never_a_crash(group: moveit_commander.MoveGroupCommander) -> None:
    with pytest.raises(InputError):
        moveit_commander.RobotCommander("ur10e", scene=SAMPLES / "no_such_scene.yaml")
    with pytest.raises(UsageError, match="set_planner_id: unknown planner 'Foo'"):
        group.set_planner_id("Foo")
    group.set_planner_id("RRTConnectkConfigDefault")
    assert group.get_planner_id() == "RRTConnect"
    with pytest.raises(UsageError, match="set_planning_time: expected a positive number of seconds"):
        group.set_planning_time(0)
    assert group.get_planning_time() == 5.0
