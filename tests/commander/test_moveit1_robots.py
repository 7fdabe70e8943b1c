"""MoveIt's own Python test cases on the robots they run on: MoveIt 1's moveit_resources fanuc, panda, dual panda.

Each test follows one upstream case, named in it, with the robot loaded as the test's launch file
loads it (MOVEPLAN_ROBOT and ROS_PACKAGE_PATH standing in for test_environment.launch).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import NOETIC

from moveplan import commander as moveit_commander
from moveplan.commander import _world
from moveplan.commander.ros.geometry_msgs.msg import Point, PoseStamped
from moveplan.commander.ros.moveit_msgs.msg import MoveItErrorCodes, RobotState

pytestmark = pytest.mark.realworld


@pytest.fixture()
def launch(monkeypatch: pytest.MonkeyPatch):  # type: ignore[no-untyped-def]
    """Return a function that 'launches' a MoveIt 1 config: the next commander loads it."""
    def launched(config: str) -> None:
        monkeypatch.setattr(_world, "_latest", None)
        monkeypatch.setenv("MOVEPLAN_ROBOT", str(NOETIC / config))
        monkeypatch.setenv("ROS_PACKAGE_PATH", str(NOETIC))
    return launched


def test_fanuc_current_state_is_moveits(launch) -> None:  # type: ignore[no-untyped-def]
    # python_moveit_commander.py test_get_current_state: all zeros (fake_controllers.yaml's all-zeros).
    launch("fanuc_moveit_config")
    group = moveit_commander.RobotCommander("robot_description").get_group("manipulator")
    expected = RobotState()
    expected.joint_state.header.frame_id = "base_link"
    expected.multi_dof_joint_state.header.frame_id = "base_link"
    expected.joint_state.name = [f"joint_{k}" for k in range(1, 7)]
    expected.joint_state.position = [0] * 6
    assert group.get_current_state() == expected


def test_fanuc_jacobian_is_moveits(launch) -> None:  # type: ignore[no-untyped-def]
    # python_move_group.py test_get_jacobian_matrix: the known values at the initial pose.
    launch("fanuc_moveit_config")
    group = moveit_commander.MoveGroupCommander("manipulator")
    current = group.get_current_joint_values()
    np.testing.assert_allclose(group.get_jacobian_matrix(current), [
        [0.0, 0.8, -0.2, 0.0, 0.0, 0.0], [0.89, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, -0.74, 0.74, 0.0, 0.1, 0.0],
        [0.0, 0.0, 0.0, -1.0, 0.0, -1.0], [0.0, 1.0, -1.0, 0.0, -1.0, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]],
        atol=1e-8)
    np.testing.assert_allclose(group.get_jacobian_matrix(current, [1.0, 1.0, 1.0]), [
        [1.0, 1.8, -1.2, 0.0, -1.0, 0.0], [1.89, 0.0, 0.0, 1.0, 0.0, 1.0], [0.0, -1.74, 1.74, 1.0, 1.1, 1.0],
        [0.0, 0.0, 0.0, -1.0, 0.0, -1.0], [0.0, 1.0, -1.0, 0.0, -1.0, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]],
        atol=1e-8)


def test_fanuc_random_targets_execute_and_land(launch) -> None:  # type: ignore[no-untyped-def]
    # robot_state_update.py: a planned and executed target is where the robot is reported.
    launch("fanuc_moveit_config")
    group = moveit_commander.MoveGroupCommander("manipulator")
    current = np.asarray(group.get_current_joint_values())
    rng = np.random.default_rng(0)
    for _ in range(5):
        target = current + rng.uniform(-0.5, 0.5, size=current.shape)
        assert group.go(target)
        np.testing.assert_allclose(group.get_current_joint_values(), target, atol=1e-4)


def test_noetic_panda_starts_ready_with_the_hand_open(launch) -> None:  # type: ignore[no-untyped-def]
    launch("panda_moveit_config")
    values = moveit_commander.RobotCommander().get_current_variable_values()
    assert values["panda_joint4"] == pytest.approx(-2.356) and values["panda_finger_joint2"] == 0.035


@pytest.mark.parametrize(("planner", "obstacle", "carried"), [
    ("LIN", (0.4, 0.1, 0.25), (0.0, 0.0, 0.15)),   # testLINGoalStateCollision
    ("PTP", (0.4, 0.1, 0.25), (0.0, 0.0, 0.15)),   # testPTPGoalStateCollision
    ("PTP", (0.0, 0.0, 0.25), (0.0, 0.0, 0.15)),   # testPTPStartStateCollision
    ("PTP", (0.4, 0.1, 0.25), (-0.3, 0.3, 0.0)),   # testPTPStartStateCollisionAttached
])
def test_pilz_planning_with_an_attached_object(launch, planner: str, obstacle: tuple[float, ...],  # type: ignore[no-untyped-def]
                                               carried: tuple[float, ...]) -> None:
    # pilz_industrial_motion_planner/test/python_move_group_planning.py, as written there.
    launch("panda_moveit_config")
    group = moveit_commander.MoveGroupCommander("panda_arm")
    scene = moveit_commander.PlanningSceneInterface(synchronous=True)
    tcp = group.get_end_effector_link()
    target = group.get_current_pose(tcp)
    target.pose.position.y += 0.1
    group.set_pose_target(target)
    box = PoseStamped()
    box.header.frame_id = "world"
    box.pose.position = Point(*obstacle)
    scene.add_box(name="box1", pose=box, size=(0.1, 0.1, 0.5))
    held = PoseStamped()
    held.header.frame_id = tcp
    held.pose.position = Point(*carried)
    scene.attach_box(link=tcp, name="box2", pose=held, size=(0.1, 0.1, 0.1),
                     touch_links=["panda_rightfinger", "panda_leftfinger"])
    group.set_planning_pipeline_id("pilz_industrial_motion_planner")
    group.set_planner_id(planner)
    _, _, _, error = group.plan()
    assert error.val == MoveItErrorCodes.INVALID_MOTION_PLAN


def test_dual_panda_reaches_both_hands_targets(launch) -> None:  # type: ignore[no-untyped-def]
    # dual_arm_robot_state_update.py: targets for panda_1_link8 and panda_2_link8, one plan of dual_arm.
    launch("dual_panda_moveit_config")
    robot = moveit_commander.RobotCommander()
    dual, first, second = robot.dual_arm, robot.panda_1, robot.panda_2
    one, two = first.get_current_pose("panda_1_link8"), second.get_current_pose("panda_2_link8")
    one.pose.position.z -= 0.05
    one.pose.position.x += 0.05
    two.pose.position.z -= 0.05
    two.pose.position.x -= 0.05
    dual.set_start_state_to_current_state()
    dual.set_pose_target(one, end_effector_link="panda_1_link8")
    dual.set_pose_target(two, end_effector_link="panda_2_link8")
    assert dual.go()
    for stamped, link in ((one, "panda_1_link8"), (two, "panda_2_link8")):
        reached = dual.get_current_pose(link).pose.position
        assert [reached.x, reached.z] == pytest.approx([stamped.pose.position.x, stamped.pose.position.z], abs=1e-4)
