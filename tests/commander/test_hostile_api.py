"""moveplan.commander misused: a setter given NaN, infinity or the wrong type raises the commander's
error naming the method and the value at once, never a ValueError or AttributeError from deep inside."""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from conftest import UR10E

from moveplan import commander as moveit_commander
from moveplan.commander.msgs import JointState, PoseStamped, RobotState, RobotTrajectory, TransformStamped
from moveplan.commander.ros import tf2_ros
from moveplan.core.errors import MoveplanError, UnknownName, UsageError

Group = moveit_commander.MoveGroupCommander
Robot = moveit_commander.RobotCommander
Scene = moveit_commander.PlanningSceneInterface


@pytest.fixture(scope="module")
def robot() -> Robot:
    return moveit_commander.RobotCommander(str(UR10E))


@pytest.fixture(scope="module")
def group(robot: Robot) -> Group:
    return moveit_commander.MoveGroupCommander("manipulator", robot)


@pytest.fixture()
def scene(robot: Robot) -> Scene:
    scene = moveit_commander.PlanningSceneInterface(robot)
    scene.clear()
    return scene


def at(frame: Any = "base_link", x: float = 0.6) -> PoseStamped:
    """A PoseStamped at `x` [m] along `frame`'s x axis."""
    pose = PoseStamped()
    pose.header.frame_id = frame
    pose.pose.position.x = x
    return pose


def raises_naming(call: Callable[[], Any], message: str, kind: type[MoveplanError] = UsageError) -> None:
    """Assert `call` raises the commander's error of `kind`, one line starting with `message`."""
    with pytest.raises(kind) as raised:
        call()
    text = str(raised.value)
    assert text.startswith(message), text
    assert "\n" not in text and len(text) < 400, text
    assert isinstance(raised.value, moveit_commander.MoveItCommanderException)


@pytest.mark.parametrize(("call", "message"), [
    (lambda g: g.set_planning_time(math.nan), "set_planning_time: expected a finite number, got nan"),
    (lambda g: g.set_planning_time(math.inf), "set_planning_time: expected a finite number, got inf"),
    (lambda g: g.set_planning_time("5"), "set_planning_time: expected a finite number, got '5'"),
    (lambda g: g.set_planning_time(10**400), "set_planning_time: expected a finite number, got 1000"),
    (lambda g: g.set_planning_time(1e9), "set_planning_time: expected a positive number of seconds up to 1e+06"),
    (lambda g: g.set_goal_tolerance(math.nan), "set_goal_tolerance: expected a finite number, got nan"),
    (lambda g: g.set_goal_position_tolerance(math.inf), "set_goal_position_tolerance: expected a finite number"),
    (lambda g: g.set_goal_joint_tolerance(-0.1), "set_goal_joint_tolerance: expected a tolerance >= 0, got -0.1"),
    (lambda g: g.set_max_velocity_scaling_factor(math.nan),
     "set_max_velocity_scaling_factor: expected a value in the range from 0.001 to 1 for scaling factor, got nan"),
    (lambda g: g.set_max_acceleration_scaling_factor("0.5"),
     "set_max_acceleration_scaling_factor: expected a value in the range from 0.001 to 1"),
    (lambda g: g.set_num_planning_attempts(1.5), "set_num_planning_attempts: expected an integer >= 0, got 1.5"),
    (lambda g: g.set_num_planning_attempts(math.inf), "set_num_planning_attempts: expected an integer >= 0, got inf"),
    (lambda g: g.set_planner_id(3), "set_planner_id: expected a planner's name, got 3"),
    (lambda g: g.execute(None), "execute: expected a RobotTrajectory or a trajectory_msgs JointTrajectory, got "
                                "NoneType"),
    (lambda g: g.set_pose_target(None), "set_pose_target: expected a Pose, a PoseStamped or a list"),
    (lambda g: g.set_pose_target(at(frame=3)), "set_pose_target: header.frame_id: expected a frame name, got 3"),
    (lambda g: g.set_pose_target([10**400] * 6), "set_pose_target: pose list: expected numbers, got [1000"),
    (lambda g: g.set_joint_value_target({"elbow_joint": "a"}), "set_joint_value_target: elbow_joint: expected a "
                                                               "number, got 'a'"),
    (lambda g: g.set_joint_value_target([math.nan] * 6), "set_joint_value_target: expected a finite number, got nan"),
    (lambda g: g.set_position_target(None), "set_position_target: expected [x, y, z], got None"),
    (lambda g: g.shift_pose_target(0, math.nan), "shift_pose_target: expected a finite number, got nan"),
    (lambda g: g.set_start_state(None), "set_start_state: expected a RobotState, got NoneType"),
    (lambda g: g.set_start_state(RobotState(JointState(name=["elbow_joint"], position=[math.nan]))),
     "set_start_state: elbow_joint: expected a finite number, got nan"),
    (lambda g: g.set_start_state(RobotState(JointState(name=["elbow_joint"], position=["a"]))),
     "set_start_state: elbow_joint: expected a number, got 'a'"),
    (lambda g: g.compute_cartesian_path(3, 0.01), "compute_cartesian_path: waypoints: expected a list of poses, got 3"),
    (lambda g: g.compute_cartesian_path([at()], math.nan),
     "compute_cartesian_path: eef_step must be a positive distance in [m], got nan"),
])
def test_a_setter_given_nan_infinity_or_the_wrong_type_names_the_method_and_value(
    group: Group, call: Callable[[Group], Any], message: str
) -> None:
    raises_naming(lambda: call(group), message)


def test_a_refused_planning_time_leaves_the_one_set_before(group: Group) -> None:
    group.set_planning_time(2.0)
    with pytest.raises(UsageError):
        group.set_planning_time(math.nan)
    assert group.get_planning_time() == 2.0


def test_numbers_a_script_computed_with_numpy_are_numbers(group: Group) -> None:
    group.set_planning_time(np.float32(2.0))
    group.set_max_velocity_scaling_factor(np.float64(0.5))
    group.set_num_planning_attempts(np.int64(3))
    group.shift_pose_target(np.int64(2), np.float32(0.01))
    assert group.get_planning_time() == 2.0
    group.clear_pose_targets()


@pytest.mark.parametrize(("call", "message", "kind"), [
    (lambda g: g.get_current_pose("nope"), "link 'nope' not found in get_current_pose (the robot's links); known:",
     UnknownName),
    (lambda g: moveit_commander.MoveGroupCommander("arm"), "group 'arm' not found in ", UnknownName),
    (lambda g: g.attach_object("nothing", "tool0"), "object 'nothing' not found in the planning scene", UnknownName),
])
def test_an_unknown_link_group_or_object_is_named_with_the_known_ones(
    group: Group, call: Callable[[Group], Any], message: str, kind: type[MoveplanError]
) -> None:
    raises_naming(lambda: call(group), message, kind)


def edited(group: Group, change: Callable[[Any], None]) -> RobotTrajectory:
    """A trajectory planned to "up", its joint_trajectory changed by `change`."""
    group.set_start_state_to_current_state()
    ok, trajectory, _, _ = group.plan("up")
    assert ok
    copied = copy.deepcopy(trajectory)
    change(copied.joint_trajectory)
    return copied


@pytest.mark.parametrize(("change", "message"), [
    (lambda t: setattr(t, "points", None), "execute: points: expected a list, got None"),
    (lambda t: setattr(t, "joint_names", None), "execute: joint_names: expected a list, got None"),
    (lambda t: setattr(t.points[1], "time_from_start", None),
     "execute: points[1]: expected a JointTrajectoryPoint with a Duration time_from_start, got "),
    (lambda t: setattr(t, "points", [3]), "execute: points[0]: expected a JointTrajectoryPoint"),
    (lambda t: setattr(t.points[1], "positions", None), "execute: points hold positions that are not lists of numbers"),
])
def test_a_trajectory_edited_into_something_else_is_refused_naming_the_field(
    group: Group, change: Callable[[Any], None], message: str
) -> None:
    before = group.get_current_joint_values()
    raises_naming(lambda: group.execute(edited(group, change)), message)
    assert group.get_current_joint_values() == before


@pytest.mark.parametrize(("call", "message"), [
    (lambda s: s.add_box("box", None), "add_box('box'): expected a PoseStamped, a Pose or a list [x, y, z(, "
                                       "orientation)] in the planning frame, got NoneType"),
    (lambda s: s.add_box("box", [0.6, 0]), "add_box('box'): expected a PoseStamped"),
    (lambda s: s.add_box("box", [0.6, 0, math.nan]), "add_box('box'): pose: pose list: expected finite numbers"),
    (lambda s: s.add_box("box", at(x=1e18)), "add_box('box'): pose: position [1e+18, 0.0, 0.0] is out of range; "
                                             "coordinates are limited to |value| <= 1,000,000 m"),
    (lambda s: s.add_box("box", at(), (1e18, 1, 1)), "add_box('box'): size: expected 3 positive lengths in [m] up "
                                                     "to 1,000,000, got (1e+18, 1, 1)"),
    (lambda s: s.add_sphere("ball", at(), math.nan), "add_sphere('ball'): radius: expected 1 positive lengths"),
    (lambda s: s.add_box("box", at(frame=None)), "add_box('box'): header.frame_id: expected a frame name, got None"),
    (lambda s: s.add_mesh("part", at(), None), "add_mesh('part'): filename: expected a mesh file's path, got None"),
    (lambda s: s.attach_box("nolink", "box", at(), (0.1, 0.1, 0.1)),
     "link 'nolink' not found in attach_box('nolink', 'box') (the robot's links); known: "),
    (lambda s: s.attach_box("tool0", "box", at(), (0.1, 0.1, 0.1), touch_links=3),
     "attach_box('tool0', 'box'): touch_links: expected a list of link names, got 3"),
    (lambda s: s.attach_box("tool0", "box", at(), (0.1, 0.1, 0.1), touch_links="tool0"),
     "attach_box('tool0', 'box'): touch_links: expected a list of link names, got 'tool0'"),
    (lambda s: s.get_object_poses(None), "get_object_poses: expected a list of object names, got None"),
    (lambda s: s.get_objects(3), "get_objects: expected a list of object names, got 3"),
    (lambda s: s.get_attached_objects("box"), "get_attached_objects: expected a list of object names, got 'box'"),
])
def test_a_scene_call_given_the_wrong_type_or_an_unknown_link_names_the_call_and_changes_nothing(
    scene: Scene, call: Callable[[Scene], Any], message: str
) -> None:
    kind = UnknownName if "not found" in message else UsageError
    raises_naming(lambda: call(scene), message, kind)
    assert scene.get_known_object_names() == [] and scene.get_attached_objects() == {}


@pytest.mark.parametrize(("call", "message"), [
    (lambda b: b.lookup_transform(3, "tool0"), "lookup_transform: target_frame: expected a frame name, got 3"),
    (lambda b: b.lookup_transform("base_link", None),
     "lookup_transform: source_frame: expected a frame name, got None"),
    (lambda b: tf2_ros.StaticTransformBroadcaster(b).sendTransform(None),
     "sendTransform: expected a TransformStamped or a list of them, got None"),
    (lambda b: tf2_ros.StaticTransformBroadcaster(b).sendTransform(TransformStamped(child_frame_id=3)),
     "sendTransform: child_frame_id: expected a frame name, got 3"),
])
def test_a_tf_call_given_the_wrong_type_names_the_call(
    robot: Robot, call: Callable[[tf2_ros.Buffer], Any], message: str
) -> None:
    raises_naming(lambda: call(tf2_ros.Buffer(robot)), message)


def test_a_static_frame_beyond_the_coordinate_bound_is_refused(robot: Robot) -> None:
    far = TransformStamped(child_frame_id="far")
    far.header.frame_id = "base_link"
    far.transform.translation.x = 1e18
    raises_naming(lambda: tf2_ros.StaticTransformBroadcaster(robot).sendTransform(far),
                  "sendTransform('far'): transform: position [1e+18, 0.0, 0.0] is out of range")
    assert not tf2_ros.Buffer(robot).can_transform("base_link", "far")


@pytest.mark.parametrize(("arguments", "message"), [
    ({"robot_description": 3}, "RobotCommander: robot_description: expected a file or folder name, got 3"),
    ({"scene": 3}, "RobotCommander: scene: expected a file or folder name, got 3"),
    ({"package_path": 3}, "RobotCommander: package_path: expected a folder or a list of folders, got 3"),
    ({"urdf": 3}, "RobotCommander: urdf: expected a file name or package:// URI, got 3"),
    ({"xacro_args": 3}, "RobotCommander: xacro_args: expected a mapping of names to values, got 3"),
    ({"plant": "lag", "plant_params": {"tau": "a"}}, "RobotCommander: plant_params['tau']: expected a number, got 'a'"),
    ({"plant": "lag", "plant_params": {"tau": math.nan}},
     "RobotCommander: plant_params['tau']: expected a finite number, got nan"),
    ({"seed": -1}, "RobotCommander: seed: expected an integer in 0..4294967295, got -1"),
    ({"seed": "a"}, "RobotCommander: seed: expected an integer in 0..4294967295, got 'a'"),
])
def test_a_robot_commander_given_the_wrong_type_names_the_argument(arguments: dict[str, Any], message: str) -> None:
    raises_naming(lambda: moveit_commander.RobotCommander(**{"robot_description": str(UR10E), **arguments}), message)


def test_saving_to_no_path_names_the_call(robot: Robot) -> None:
    raises_naming(lambda: robot.save(None), "save: expected a file or folder name, got None")
