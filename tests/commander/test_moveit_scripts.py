"""What MoveIt's own Python scripts do, on moveplan.commander: each case names the upstream test or script it follows.

Upstream (read there, not copied): moveit/moveit moveit_commander/test/python_moveit_commander.py,
python_moveit_commander_ns.py, python_time_parameterization.py; moveit_ros/planning_interface/test/
python_move_group.py, robot_state_update.py, dual_arm_robot_state_update.py;
pilz_industrial_motion_planner/test/python_move_group_planning.py; moveit_commander/demos; and
moveit_tutorials' move_group_python_interface_tutorial.py and collision_scene_example.py. They run on
MoveIt 1's fanuc, panda and dual panda; here on the shipped UR10e and Panda and a PR2-like robot.
"""

from __future__ import annotations

import io
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

from moveplan import commander as moveit_commander
from moveplan.commander import _world
from moveplan.commander.ros import genpy, rospy
from moveplan.commander.ros.geometry_msgs.msg import Pose, PoseStamped
from moveplan.commander.ros.moveit_msgs.msg import (
    CollisionObject,
    Constraints,
    DisplayTrajectory,
    MoveItErrorCodes,
    PlanningScene,
    PlanningSceneComponents,
    RobotState,
    RobotTrajectory,
)
from moveplan.commander.ros.moveit_ros_planning_interface._moveit_move_group_interface import MoveGroupInterface
from moveplan.commander.ros.sensor_msgs.msg import JointState
from moveplan.commander.ros.shape_msgs.msg import SolidPrimitive
from moveplan.commander.ros.tf import transformations
from moveplan.core.errors import UnknownName, UsageError

PR2_LIKE = ROOT / "tests" / "data" / "srdf_groups" / "pr2_like"


@pytest.fixture()
def fresh(monkeypatch: pytest.MonkeyPatch) -> pytest.MonkeyPatch:
    """No RobotCommander made yet in this process, as when a script starts."""
    monkeypatch.setattr(_world, "_latest", None)
    return monkeypatch


# Loading the robot -----------------------------------------------------------------------------------


def test_robot_description_names_the_robot_of_the_environment(fresh: pytest.MonkeyPatch) -> None:
    # python_moveit_commander.py: RobotCommander("robot_description"); _ns: ("test_ns/robot_description", "test_ns/").
    fresh.setenv("MOVEPLAN_ROBOT", "ur10e")
    assert moveit_commander.RobotCommander("robot_description").get_root_link() == "base_link"
    robot = moveit_commander.RobotCommander("test_ns/robot_description", "test_ns/")
    assert robot.get_namespace() == "test_ns/" and robot.get_group("manipulator").get_variable_count() == 6
    assert moveit_commander.RobotCommander(robot_description="robot_description", ns="").get_group_names()


def test_a_group_made_before_any_robot_loads_the_environments(fresh: pytest.MonkeyPatch) -> None:
    # python_move_group_planning.py makes MoveGroupCommander("panda_arm") and PlanningSceneInterface first.
    fresh.setenv("MOVEPLAN_ROBOT", "panda")
    group = moveit_commander.MoveGroupCommander("panda_arm", robot_description="robot_description")
    scene = moveit_commander.PlanningSceneInterface(ns="", synchronous=True)
    assert group.get_end_effector_link() == "panda_link8" and scene.get_known_object_names() == []


def test_without_a_robot_the_error_says_how_to_name_one(fresh: pytest.MonkeyPatch) -> None:
    fresh.delenv("MOVEPLAN_ROBOT", raising=False)
    with pytest.raises(UsageError, match="set MOVEPLAN_ROBOT"):
        moveit_commander.RobotCommander()
    with pytest.raises(UsageError, match="MoveGroupCommander\\('arm'\\): no robot: .* or set MOVEPLAN_ROBOT"):
        moveit_commander.MoveGroupCommander("arm")
    with pytest.raises(UsageError, match="set MOVEPLAN_ROBOT"):
        rospy.search_param("robot_description_semantic")  # collision_scene_example.py would wait for ever


def test_a_group_is_an_attribute_of_the_robot() -> None:
    # moveit_commander demos plan.py and pick.py: robot.right_arm.
    robot = moveit_commander.RobotCommander(str(PR2_LIKE))
    assert robot.right_arm is robot.get_group("right_arm")
    assert robot.right_arm.get_end_effector_link() == "r_wrist_roll_link"
    with pytest.raises(AttributeError, match="no attribute 'left_leg'"):
        _ = robot.left_leg


# Grippers: mimic joints ---------------------------------------------------------------------------------


def test_a_gripper_group_names_its_links_and_plans_its_named_states() -> None:
    # move_group_python_interface_tutorial.py: touch_links = robot.get_link_names(group=grasping_group).
    robot = moveit_commander.RobotCommander("panda")
    assert robot.get_link_names(group="hand") == ["panda_hand", "panda_leftfinger", "panda_rightfinger"]
    assert robot.get_joint_names("hand") == ["panda_hand_joint", "panda_finger_joint1", "panda_finger_joint2"]
    assert robot.get_active_joint_names("hand") == ["panda_finger_joint1"]
    hand = robot.hand
    assert hand.get_variable_count() == 2 and hand.get_active_joints() == ["panda_finger_joint1"]
    assert hand.go("open")
    assert hand.get_current_joint_values() == pytest.approx([0.035, 0.035], abs=1e-5)
    assert hand.go([0.01, 0.01])  # every variable, as MoveIt takes them; the mimic follows its leader
    assert hand.get_current_joint_values() == pytest.approx([0.01, 0.01], abs=1e-5)
    with pytest.raises(moveit_commander.MoveItCommanderException, match="'panda_finger_joint2' mimics"):
        hand.set_joint_value_target([0.01, 0.03])


# rospy ---------------------------------------------------------------------------------------------------


def test_time_moves_only_when_the_script_sleeps() -> None:
    # The tutorial's wait_for_state_update loops on get_time() and sleep(0.1) until a timeout.
    start = rospy.get_time()
    rospy.sleep(0.1)
    rospy.Rate(10).sleep()
    rospy.sleep(rospy.Duration(0.5))
    assert rospy.get_time() - start == pytest.approx(0.7)
    assert rospy.Time(1.5) == rospy.Time(1, 500_000_000) and rospy.Duration(0.25).to_sec() == 0.25
    assert not rospy.is_shutdown() and rospy.Time.now().to_sec() == pytest.approx(rospy.get_time())
    with pytest.raises(rospy.ROSInterruptException):
        raise rospy.ROSInterruptException("interrupted")


def test_the_robot_description_parameters_are_the_robots_files() -> None:
    robot = moveit_commander.RobotCommander("ur10e")
    assert rospy.get_param("/robot_description") == robot.world.config.urdf
    assert "<group name=\"manipulator\">" in rospy.get_param("robot_description_semantic")
    assert rospy.search_param("robot_description_semantic") == "/robot_description_semantic"
    assert rospy.get_param("/no_such_param", 3) == 3
    with pytest.raises(KeyError):
        rospy.get_param("/no_such_param")


def test_a_state_published_to_the_fake_controllers_moves_the_robot() -> None:
    # MoveIt's workshop publishes the home state to /move_group/fake_controller_joint_states.
    robot = moveit_commander.RobotCommander("ur10e")
    publisher = rospy.Publisher("/move_group/fake_controller_joint_states", JointState, queue_size=1)
    publisher.publish(JointState(name=["elbow_joint"], position=[1.2]))
    assert robot.get_current_variable_values()["elbow_joint"] == 1.2
    display = rospy.Publisher("/move_group/display_planned_path", DisplayTrajectory, queue_size=20)
    display.publish(DisplayTrajectory(trajectory=[RobotTrajectory()]))
    assert len(display.published) == 1 and robot.get_current_variable_values()["elbow_joint"] == 1.2
    with pytest.raises(UnknownName, match="joint 'elbow'"):
        publisher.publish(JointState(name=["elbow"], position=[1.0]))


# Messages ---------------------------------------------------------------------------------------------------


def test_messages_round_trip_through_bytes_and_print_as_yaml() -> None:
    # python_move_group.py reads plan()'s serialized error code with MoveItErrorCodes().deserialize(...).
    message = RobotTrajectory()
    message.joint_trajectory.joint_names = ["a"]
    buffer = io.BytesIO()
    message.serialize(buffer)
    assert RobotTrajectory().deserialize(buffer.getvalue()) == message
    assert "joint_names: ['a']" in str(message)
    with pytest.raises(genpy.DeserializationError):
        MoveItErrorCodes().deserialize(b"not a message")


def test_the_current_state_is_in_the_planning_frame() -> None:
    # python_moveit_commander.py test_get_current_state: both headers name the planning frame.
    state = moveit_commander.RobotCommander("ur10e").get_current_state()
    assert state.joint_state.header.frame_id == state.multi_dof_joint_state.header.frame_id == "base_link"
    assert state.joint_state.velocity == [] and state.attached_collision_objects == []


# MoveGroupCommander ----------------------------------------------------------------------------------------------


def test_enforce_bounds_clamps_and_an_empty_state_is_refused() -> None:
    # python_moveit_commander.py test_enforce_bounds, test_enforce_bounds_empty_state.
    group = moveit_commander.RobotCommander("ur10e").get_group("manipulator")
    with pytest.raises(genpy.DeserializationError):
        group.enforce_bounds(RobotState())
    state = RobotState()
    state.joint_state.name = group.get_active_joints()
    state.joint_state.position = [1000.0, 0, 0, 0, 0, 0]
    bounded = group.enforce_bounds(state)
    assert state.joint_state.position[0] == 1000 and bounded.joint_state.position[0] == pytest.approx(2 * math.pi)


def test_retiming_scales_a_path_and_an_unknown_algorithm_returns_nothing() -> None:
    # python_time_parameterization.py: three algorithms time the path; "" returns an empty trajectory.
    robot = moveit_commander.RobotCommander("ur10e")
    group = robot.get_group("manipulator")
    group.go("ready")
    goal = group.get_current_pose().pose
    goal.position.z -= 0.1
    plan, fraction = group.compute_cartesian_path([goal], 0.005)
    assert fraction == 1.0
    limits = np.array([robot.world.config.limits[j].max_velocity for j in group.get_active_joints()])
    for algorithm in ("iterative_time_parameterization", "iterative_spline_parameterization",
                      "time_optimal_trajectory_generation"):
        slow = group.retime_trajectory(robot.get_current_state(), plan, 0.1, 0.1, algorithm).joint_trajectory
        fast = group.retime_trajectory(robot.get_current_state(), plan, 1.0, 1.0, algorithm).joint_trajectory
        assert (np.abs([p.velocities for p in slow.points]).max(axis=0) <= 0.1 * limits + 1e-9).all()
        assert slow.points[-1].time_from_start.to_sec() > 2 * fast.points[-1].time_from_start.to_sec()
    assert group.retime_trajectory(robot.get_current_state(), plan, algorithm="").joint_trajectory.points == []


def test_the_jacobian_moves_the_end_effector_and_a_point_fixed_to_it() -> None:
    # python_move_group.py test_get_jacobian_matrix: rows are the velocity of the reference point, then omega.
    group = moveit_commander.RobotCommander("ur10e").get_group("manipulator")
    values = [0.3, -1.2, 1.4, -0.9, -1.5, 0.2]
    point = [0.1, 0.0, 0.05]
    jacobian = group.get_jacobian_matrix(values, point)
    robot = group._robot
    tip = group.get_end_effector_link()

    def where(v: np.ndarray) -> np.ndarray:
        pose = robot.frame_pose(robot.configuration(v), tip)
        return pose[:3, 3] + pose[:3, :3] @ point

    step = 1e-7
    numeric = np.array([(where(np.add(values, step * e)) - where(np.subtract(values, step * e))) / (2 * step)
                        for e in np.eye(6)]).T
    np.testing.assert_allclose(jacobian[:3], numeric, atol=1e-6)


def test_random_targets_lie_within_the_limits_and_repeat_run_after_run() -> None:
    # demos/plan.py: plan to get_random_joint_values().
    def values() -> list[float]:
        return moveit_commander.RobotCommander("ur10e", seed=3).manipulator.get_random_joint_values()

    first = values()
    assert first == values()
    limits = moveit_commander.RobotCommander("ur10e").world.config.limits
    assert all(limits[j].lower <= v <= limits[j].upper for j, v in zip(limits, first, strict=False))


def test_pilz_ptp_moves_straight_in_joint_space_and_lin_the_tool_straight() -> None:
    # MoveIt 2 users: set_planning_pipeline_id("pilz_industrial_motion_planner"), set_planner_id("PTP"/"LIN").
    group = moveit_commander.RobotCommander("ur10e").get_group("manipulator")
    group.go("ready")
    group.set_planning_pipeline_id("pilz_industrial_motion_planner")
    assert group.get_planner_id() == "PTP"
    success, plan, _, _ = group.plan([0.4, -1.0, 1.2, -1.6, -1.5, 0.3])
    assert success
    points = np.array([p.positions for p in plan.joint_trajectory.points])
    direction = (points[-1] - points[0]) / np.linalg.norm(points[-1] - points[0])
    off_line = (points - points[0]) - np.outer((points - points[0]) @ direction, direction)
    assert np.abs(off_line).max() < 1e-9
    group.set_planner_id("LIN")
    goal = group.get_current_pose().pose
    goal.position.x += 0.1
    assert group.go(goal)


def test_pilz_reports_a_colliding_goal_as_an_invalid_motion_plan() -> None:
    # python_move_group_planning.py testPTPGoalStateCollision and testLINGoalStateCollision.
    robot = moveit_commander.RobotCommander("panda")
    group, scene = robot.panda_arm, moveit_commander.PlanningSceneInterface(robot)
    target = group.get_current_pose()
    scene.add_box("box1", [target.pose.position.x, target.pose.position.y + 0.1, target.pose.position.z],
                  (0.1, 0.1, 0.1))
    target.pose.position.y += 0.1
    group.set_pose_target(target)
    group.set_planning_pipeline_id("pilz_industrial_motion_planner")
    for planner in ("PTP", "LIN"):
        group.set_planner_id(planner)
        success, _, _, error = group.plan()
        assert not success and error.val == MoveItErrorCodes.INVALID_MOTION_PLAN


def test_pose_targets_of_two_end_effectors_are_reached_together() -> None:
    # dual_arm_robot_state_update.py: set_pose_target for panda_1_link8, then for panda_2_link8, one plan.
    robot = moveit_commander.RobotCommander(str(PR2_LIKE))
    arms = robot.arms
    start = arms.get_current_joint_values()
    arms.go([0.3, 0.2, 0.1, -0.3, 0.2, -0.1])
    right, left = arms.get_current_pose("r_wrist_roll_link"), arms.get_current_pose("l_wrist_roll_link")
    arms.go(start)
    arms.set_pose_target(right, end_effector_link="r_wrist_roll_link")
    arms.set_pose_target(left, end_effector_link="l_wrist_roll_link")
    assert arms.go()
    for stamped, link in ((right, "r_wrist_roll_link"), (left, "l_wrist_roll_link")):
        reached = arms.get_current_pose(link).pose.position
        assert [reached.x, reached.y, reached.z] == pytest.approx(
            [stamped.pose.position.x, stamped.pose.position.y, stamped.pose.position.z], abs=1e-4)


def test_cartesian_paths_take_both_of_moveits_signatures() -> None:
    # MoveIt >= 1.1.15: (waypoints, eef_step, avoid_collisions, path_constraints); before: jump_threshold third.
    group = moveit_commander.RobotCommander("ur10e").get_group("manipulator")
    group.go("ready")
    pose = group.get_current_pose().pose
    pose.position.z += 0.05
    for call in (lambda: group.compute_cartesian_path([pose], 0.01, True, path_constraints=Constraints()),
                 lambda: group.compute_cartesian_path([pose], 0.01, 0.0, True),
                 lambda: group.compute_cartesian_path([pose], 0.01, jump_threshold=0.0)):
        assert call()[1] == 1.0
    with pytest.raises(UsageError, match="jump_threshold must be a number >= 0"):
        group.compute_cartesian_path([pose], 0.01, -1.0)


def test_move_group_interface_speaks_serialized_messages() -> None:
    # python_move_group.py test_validation: plan() returns serialized messages; a stale plan is refused.
    moveit_commander.RobotCommander("ur10e")
    group = MoveGroupInterface("manipulator", "robot_description", "/")
    current = np.asarray(group.get_current_joint_values())
    group.set_joint_value_target(current + 0.2)
    error1, plan1, _ = group.plan()
    group.set_joint_value_target(current + 0.2)
    _, plan2, _ = group.plan()
    assert MoveItErrorCodes().deserialize(error1).val == MoveItErrorCodes.SUCCESS
    assert group.execute(plan1) and not group.execute(plan2)


# PlanningSceneInterface ---------------------------------------------------------------------------------------


def test_the_allowed_collision_matrix_round_trips_through_the_scene() -> None:
    # python_moveit_commander.py PythonPSITest.test_acm.
    moveit_commander.RobotCommander("ur10e")
    psi = moveit_commander.PlanningSceneInterface()
    acm = psi.get_planning_scene(PlanningSceneComponents.ALLOWED_COLLISION_MATRIX).allowed_collision_matrix
    assert "obj" not in acm.entry_names and "obj" not in acm.default_entry_names
    acm.set_allowed("obj")
    scene = PlanningScene(allowed_collision_matrix=acm, is_diff=True)
    psi.apply_planning_scene(scene)
    acm = psi.get_planning_scene(PlanningSceneComponents.ALLOWED_COLLISION_MATRIX).allowed_collision_matrix
    assert "obj" in acm.default_entry_names


def test_an_allowed_object_may_touch_the_robot() -> None:
    robot = moveit_commander.RobotCommander("ur10e")
    group, psi = robot.manipulator, moveit_commander.PlanningSceneInterface(robot)
    group.go("ready")
    tool = group.get_current_pose()
    psi.add_box("touching", tool, (0.05, 0.05, 0.05))
    assert not group.go("home")
    acm = psi.get_planning_scene(PlanningSceneComponents.ALLOWED_COLLISION_MATRIX).allowed_collision_matrix
    acm.set_allowed("touching")
    psi.apply_planning_scene(PlanningScene(allowed_collision_matrix=acm, is_diff=True))
    assert group.go("home")


def test_a_collision_object_of_two_shapes_is_added_moved_and_removed() -> None:
    # add_object(CollisionObject) with shape_msgs SolidPrimitives, as pick-and-place scripts build them.
    robot = moveit_commander.RobotCommander("ur10e")
    psi = moveit_commander.PlanningSceneInterface(robot)
    table = CollisionObject(id="table", primitives=[SolidPrimitive(SolidPrimitive.BOX, [1.0, 1.0, 0.05]),
                                                   SolidPrimitive(SolidPrimitive.CYLINDER, [0.5, 0.05])],
                            primitive_poses=[Pose(), Pose()])
    table.header.frame_id = "base_link"
    table.pose.position.x, table.primitive_poses[1].position.z = 0.8, -0.25
    psi.add_object(table)
    assert psi.get_known_object_names() == ["table"]
    assert psi.get_known_object_names_in_roi(0.5, -1, -1, 1.0, 1, 1) == ["table"]
    assert psi.get_known_object_names_in_roi(-1, -1, -1, 0.5, 1, 1) == []
    shapes = psi.get_objects(["table"])["table"]
    assert [p.type for p in shapes.primitives] == [SolidPrimitive.BOX, SolidPrimitive.CYLINDER]
    assert shapes.primitives[1].dimensions == pytest.approx([0.5, 0.05])
    assert shapes.primitive_poses[1].position.z == pytest.approx(-0.25) and shapes.pose.position.x == 0.8
    table.operation, table.pose.position.x = CollisionObject.MOVE, 0.9
    psi.add_object(table)
    assert psi.get_object_poses(["table"])["table"].position.x == pytest.approx(0.9)
    assert psi.get_objects()["table"].primitive_poses[1].position.z == pytest.approx(-0.25)
    psi.add_object(CollisionObject(id="table", operation=CollisionObject.REMOVE))
    assert psi.get_known_object_names() == []


def test_an_attached_object_is_reported_in_its_links_frame() -> None:
    # The tutorial attaches a box to the end effector with the hand's links as touch links.
    robot = moveit_commander.RobotCommander("panda")
    psi = moveit_commander.PlanningSceneInterface(robot)
    box = PoseStamped()
    box.header.frame_id = "panda_hand"
    box.pose.position.z = 0.11
    psi.add_box("box", box, size=(0.075, 0.075, 0.075))
    psi.attach_box("panda_link8", "box", touch_links=robot.get_link_names(group="hand"))
    attached = psi.get_attached_objects(["box"])["box"]
    assert attached.link_name == "panda_link8" and attached.object.header.frame_id == "panda_link8"
    assert "box" not in psi.get_known_object_names()
    assert robot.get_current_state().attached_collision_objects[0].object.id == "box"


# tf.transformations ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("axes", ["sxyz", "rzyx", "szxz", "rxyz"])
def test_euler_angles_of_every_convention_match_a_rotation_library(axes: str) -> None:
    from scipy.spatial.transform import Rotation

    angles = (0.3, -0.7, 1.1)
    order = axes[1:].upper() if axes[0] == "r" else axes[1:]  # scipy: upper case rotates about moving axes
    expected = Rotation.from_euler(order, angles).as_quat()
    got = transformations.quaternion_from_euler(*angles, axes=axes)
    assert np.allclose(got, expected) or np.allclose(got, -expected)
    back = transformations.quaternion_from_euler(*transformations.euler_from_quaternion(got, axes), axes=axes)
    assert np.allclose(back, got) or np.allclose(back, -got)  # proper Euler angles have two triples a rotation
    assert transformations.translation_from_matrix(transformations.translation_matrix([1, 2, 3])).tolist() == [1, 2, 3]
    with pytest.raises(UsageError, match="axes 'xyz'"):
        transformations.euler_matrix(*angles, axes="xyz")


# Failures are seen -----------------------------------------------------------------------------------------------


def test_a_failed_go_says_why_on_stderr_without_any_logging_set_up(tmp_path: Path) -> None:
    script = tmp_path / "script.py"
    script.write_text("from moveplan import commander as moveit_commander\n"
                      "group = moveit_commander.RobotCommander('ur10e').get_group('manipulator')\n"
                      "print(group.go([0.0, -1.5, 3.0, 0.0, 0.0, 0.0]))\n")
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, check=True)
    assert run.stdout.strip() == "False"
    assert "plan: " in run.stderr and "collision" in run.stderr


def _circ_point(group: moveit_commander.MoveGroupCommander, kind: str, point: np.ndarray) -> Constraints:
    """Return Pilz's CIRC point as MoveIt 2 users send it: constraints named "center" or "interim"."""
    region = moveit_commander.msgs.BoundingVolume(primitive_poses=[Pose()])
    position = region.primitive_poses[0].position
    position.x, position.y, position.z = (float(v) for v in point)
    constraint = moveit_commander.msgs.PositionConstraint(link_name=group.get_end_effector_link(),
                                                          constraint_region=region)
    constraint.header.frame_id = "base_link"
    return Constraints(name=kind, position_constraints=[constraint])


@pytest.mark.parametrize("kind", ["center", "interim"])
def test_pilz_circ_moves_the_tool_on_a_circle(kind: str) -> None:
    # pilz_industrial_motion_planner's CIRC: the point comes from path constraints named "center" or "interim".
    group = moveit_commander.RobotCommander("ur10e").get_group("manipulator")
    group.go("ready")
    start = group.get_current_pose()
    origin = np.array([start.pose.position.x, start.pose.position.y, start.pose.position.z])
    center = origin + [0.0, 0.1, 0.0]
    goal = group.get_current_pose()
    goal.pose.position.y += 0.1
    goal.pose.position.z += 0.1
    point = center if kind == "center" else center + 0.1 * np.array([0.0, -np.sqrt(0.5), np.sqrt(0.5)])
    group.set_path_constraints(_circ_point(group, kind, point))
    group.set_planning_pipeline_id("pilz_industrial_motion_planner")
    group.set_planner_id("CIRC")
    success, plan, _, _ = group.plan(goal)
    assert success
    model = group._robot
    radii = [np.linalg.norm(model.frame_pose(model.configuration(np.array(p.positions)), "tool0")[:3, 3] - center)
             for p in plan.joint_trajectory.points]
    assert min(radii) == pytest.approx(0.1, abs=1e-3) and max(radii) == pytest.approx(0.1, abs=1e-6)
    across = group.get_current_pose()
    across.pose.position.y += 0.2  # start, center and goal on one line: no plane for the circle
    group.set_path_constraints(_circ_point(group, "center", center))
    success, _, _, error = group.plan(across)
    assert not success and "on one line" in error.message


def test_a_cartesian_path_cut_short_says_what_it_ran_into(caplog: pytest.LogCaptureFixture) -> None:
    robot = moveit_commander.RobotCommander("ur10e")
    group, psi = robot.manipulator, moveit_commander.PlanningSceneInterface(robot)
    group.go("ready")
    below = group.get_current_pose()
    below.pose.position.z -= 0.2
    psi.add_box("block", below, (0.2, 0.2, 0.05))
    goal = group.get_current_pose().pose
    goal.position.z -= 0.3
    with caplog.at_level("INFO", logger="moveplan"):
        _, fraction = group.compute_cartesian_path([goal], 0.01)
    assert 0.0 < fraction < 1.0
    assert any("straight line stops" in r.message and "touches block" in r.message for r in caplog.records)


def test_joints_and_links_are_robot_attributes_too() -> None:
    # moveit_commander robot.py: robot.get_joint(name).move(...), robot.<link>.pose().
    robot = moveit_commander.RobotCommander("ur10e")
    elbow = robot.get_joint("elbow_joint")
    assert elbow.bounds() == [elbow.min_bound(), elbow.max_bound()] and elbow.variable_count() == 1
    assert elbow.move(1.0) and robot.elbow_joint.value() == pytest.approx(1.0, abs=1e-6)
    assert robot.tool0.pose().header.frame_id == "base_link"
    assert robot.get_link("tool0").pose() == robot.manipulator.get_current_pose()
    with pytest.raises(UnknownName, match="joint 'elbow'"):
        robot.get_joint("elbow")


def test_times_subtract_to_durations_as_genpys_do() -> None:
    # Scripts wait with `while (rospy.Time.now() - start).to_sec() < timeout:`.
    start = rospy.Time.now()
    rospy.sleep(1.5)
    elapsed = rospy.Time.now() - start
    assert isinstance(elapsed, rospy.Duration) and elapsed.to_sec() == pytest.approx(1.5)
    assert start + elapsed == rospy.Time.now() and elapsed < rospy.Duration(2) and (elapsed * 2).to_sec() == 3.0


def test_tf1_listener_and_broadcaster_work_on_the_robot_and_scene() -> None:
    # MoveIt 1 scripts: listener.waitForTransform(...); (trans, rot) = listener.lookupTransform(...).
    from moveplan.commander.ros import tf

    robot = moveit_commander.RobotCommander("ur10e")
    listener = tf.TransformListener()
    listener.waitForTransform("/base_link", "/tool0", rospy.Time(0), rospy.Duration(4.0))
    trans, rot = listener.lookupTransform("/base_link", "/tool0", rospy.Time(0))
    tool = robot.manipulator.get_current_pose().pose
    assert trans == pytest.approx([tool.position.x, tool.position.y, tool.position.z])
    tf.TransformBroadcaster().sendTransform((0.5, 0.0, 0.3), (0.0, 0.0, 0.0, 1.0), rospy.Time.now(), "bin",
                                            "base_link")
    assert listener.lookupTransform("base_link", "bin", rospy.Time(0)) == ([0.5, 0.0, 0.3], [0.0, 0.0, 0.0, 1.0])
    with pytest.raises(tf.LookupException, match="frame 'nowhere'"):
        listener.lookupTransform("base_link", "nowhere", rospy.Time(0))
    with pytest.raises(rospy.ROSException, match="no ROS graph"):
        rospy.ServiceProxy("/compute_ik", None)()


def test_scene_messages_published_to_move_groups_topics_change_the_scene() -> None:
    # MoveIt 1 scripts publish CollisionObjects to /collision_object and PlanningScene diffs to /planning_scene.
    robot = moveit_commander.RobotCommander("ur10e")
    psi = moveit_commander.PlanningSceneInterface(robot)
    box = CollisionObject(id="box", primitives=[SolidPrimitive(type=SolidPrimitive.BOX, dimensions=[0.1, 0.1, 0.1])],
                          primitive_poses=[Pose()], operation=CollisionObject.ADD)
    box.header.frame_id = "base_link"
    box.primitive_poses[0].position.x = 0.8
    rospy.Publisher("/collision_object", CollisionObject, queue_size=10).publish(box)
    assert psi.get_known_object_names() == ["box"]
    diff = PlanningScene(is_diff=True)
    diff.world.collision_objects.append(CollisionObject(id="box", operation=CollisionObject.REMOVE))
    rospy.Publisher("planning_scene", PlanningScene, queue_size=1).publish(diff)
    assert psi.get_known_object_names() == []
