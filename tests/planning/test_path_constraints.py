"""Path constraints (moveit_msgs/Constraints) hold every state of a motion, from a task file, a request or a script.

MoveIt's semantics (moveit_core kinematic_constraints: JointConstraint, OrientationConstraint with
XYZ_EULER_ANGLES or ROTATION_VECTOR, PositionConstraint): a joint within [position - below,
position + above]; a link's orientation within per-axis tolerances of a target; a link point
inside a region. A start or goal outside them is refused with MoveIt's error.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import Cli

from moveplan import commander as moveit_commander
from moveplan.commander.ros.moveit_msgs.msg import (
    BoundingVolume,
    Constraints,
    JointConstraint,
    MoveItErrorCodes,
    OrientationConstraint,
    PositionConstraint,
)
from moveplan.commander.ros.shape_msgs.msg import SolidPrimitive
from moveplan.core.bag import read_plan
from moveplan.core.rotations import matrix_from_quaternion, rotation_angle


def _task(tmp_path: Path, tolerance: float) -> Path:
    path = tmp_path / "task.yaml"
    path.write_text(yaml.safe_dump({"robot": "ur10e", "start": {"named": "ready"}, "steps": [{
        "name": "within", "joints": [0.25, -1.2, 1.4, -1.6, -1.5, 0.0],
        "path_constraints": {"joint_constraints": [{"joint_name": "shoulder_pan_joint", "position": 0.0,
                                                    "tolerance_above": tolerance, "tolerance_below": tolerance}]}}]}))
    return path


def test_a_task_steps_joint_constraint_holds_the_whole_motion(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "plan.mcap"
    result = cli("plan", _task(tmp_path, 0.3), "-o", out)
    assert result.exit_code == 0, result.stderr
    pan = read_plan(out).steps[0].trajectory.positions[:, 0]
    assert pan.min() >= -0.3 and pan.max() <= 0.3


def test_a_goal_outside_the_constraints_is_refused_naming_the_joint(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "plan.mcap"
    result = cli("plan", _task(tmp_path, 0.1), "-o", out)
    assert result.exit_code == 4 and not out.exists()
    assert "goal state violates the path constraints: joint 'shoulder_pan_joint' at 0.25 outside [-0.1, 0.1]" \
        in result.stderr


def test_a_script_keeps_the_tool_upright_while_it_moves() -> None:
    robot = moveit_commander.RobotCommander("ur10e")
    group = robot.manipulator
    group.go("ready")
    start = group.get_current_pose()
    upright = OrientationConstraint(link_name="tool0", orientation=start.pose.orientation,
                                    absolute_x_axis_tolerance=0.1, absolute_y_axis_tolerance=0.1,
                                    absolute_z_axis_tolerance=0.1)
    upright.header.frame_id = "base_link"
    group.set_path_constraints(Constraints(orientation_constraints=[upright]))
    target = group.get_current_pose()
    target.pose.position.x += 0.15
    target.pose.position.z -= 0.1
    success, plan, _, _ = group.plan(target)
    assert success
    q = start.pose.orientation
    wanted = matrix_from_quaternion([q.x, q.y, q.z, q.w])
    model = group._robot
    for point in plan.joint_trajectory.points:
        rotation = model.frame_pose(model.configuration(np.array(point.positions)), "tool0")[:3, :3]
        assert rotation_angle(wanted.T @ rotation) <= 0.1 * np.sqrt(3) + 1e-6


def test_a_start_outside_the_constraints_is_moveits_start_state_error() -> None:
    group = moveit_commander.RobotCommander("ur10e").manipulator
    group.go("ready")
    region = BoundingVolume(primitives=[SolidPrimitive(SolidPrimitive.SPHERE, [0.05])],
                            primitive_poses=[moveit_commander.msgs.Pose()])
    far = PositionConstraint(link_name="tool0", constraint_region=region)  # a sphere about the base: not reached
    group.set_path_constraints(Constraints(position_constraints=[far]))
    success, _, _, error = group.plan("home")
    assert not success and error.val == MoveItErrorCodes.START_STATE_VIOLATES_PATH_CONSTRAINTS
    group.clear_path_constraints()
    group.set_path_constraints(Constraints(joint_constraints=[JointConstraint("wrist_3_joint", 0.0, 0.2, 0.2)]))
    assert group.go([0.0, -1.2, 1.4, -1.6, -1.5, 0.1])
    with pytest.raises(moveit_commander.MoveItCommanderException, match="no constraints database|warehouse"):
        group.set_path_constraints("upright")


def test_a_task_step_plans_pilz_circ_about_a_center(cli: Cli, tmp_path: Path) -> None:
    # The ready pose's tool0 is at [0.6914, 0.17415, 0.67685]: a quarter circle up and across, 10 cm about a center.
    center = np.array([0.6914, 0.27415, 0.67685])
    path = tmp_path / "circ.yaml"
    path.write_text(yaml.safe_dump({"robot": "ur10e", "start": {"named": "ready"}, "steps": [{
        "name": "quarter", "pose": {"xyz": [0.6914, 0.27415, 0.77685], "rpy": ["pi", 0, "-pi/2"]},
        "planner": "CIRC", "arc": {"center": center.tolist()}}]}))
    out = tmp_path / "circ.mcap"
    result = cli("plan", path, "-o", out, "--json")
    assert result.exit_code == 0, result.stderr
    assert json.loads(result.stdout)["steps"][0]["planner"] == "CIRC"
    step = read_plan(out).steps[0]
    robot = moveit_commander.RobotCommander("ur10e").manipulator._robot
    radii = [np.linalg.norm(robot.frame_pose(robot.configuration(p), "tool0")[:3, 3] - center)
             for p in step.trajectory.positions]
    assert max(radii) == pytest.approx(0.1, abs=1e-6)


def test_circ_without_its_point_is_a_usage_error(cli: Cli, tmp_path: Path) -> None:
    path = tmp_path / "circ.yaml"
    path.write_text(yaml.safe_dump({"robot": "ur10e", "steps": [{"name": "s", "named": "home", "planner": "CIRC"}]}))
    out = tmp_path / "x.mcap"
    result = cli("plan", path, "-o", out)
    assert result.exit_code == 2 and "CIRC needs the point its arc passes through" in result.stderr
    assert not out.exists() and len(result.stderr.strip().splitlines()) == 1
