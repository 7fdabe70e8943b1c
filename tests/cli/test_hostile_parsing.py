"""Hostile input: every parsed value has a bound that comes from the problem, and breaking it is one clear line.

Flags are usage errors (exit 2), files input errors (exit 3); neither writes an output file.
"""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import ROOT, UR10E, Cli
from rosbags.highlevel import AnyReader

from moveplan.cli.parsing import parse_disturbance, parse_number, parse_seeds
from moveplan.core.config.controllers import parse_controllers
from moveplan.core.config.fields import MAX_ALIAS_EXPANSION, load_yaml
from moveplan.core.errors import ConfigError, UsageError


def one_line(result) -> str:  # noqa: ANN001 - click's Result
    """Return the error's one line on stderr (asserting it is one line)."""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    return lines[0]


def plan(cli: Cli, tmp_path: Path, *args: object) -> tuple[int, str]:
    """Run `moveplan plan` on the UR10e with `args`; return exit code and the message, asserting no file is left."""
    output = tmp_path / "out.mcap"
    result = cli("plan", "--robot", UR10E, "-o", output, *args)
    assert not output.exists()
    assert result.exit_code in (2, 3), result.stderr
    return result.exit_code, one_line(result)


@pytest.fixture()
def ur10e_copy(tmp_path: Path) -> Path:
    """A copy of the shipped UR10e config to damage."""
    folder = tmp_path / "ur10e"
    shutil.copytree(UR10E, folder)
    return folder


def _bomb(key: str) -> str:
    lines = ['a: &a ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for i in range(1, 9):
        prev, cur = chr(ord("a") + i - 1), chr(ord("a") + i)
        lines.append(f"{cur}: &{cur} [{', '.join([f'*{prev}'] * 9)}]")
    # The anchors sit inside the one key a PlanningScene or MotionPlanRequest accepts.
    body = "\n".join("  " + line.replace(": &", "_: &", 1) for line in lines)
    return f"{key}:\n{body}\n  all: *i\n"


# 1. YAML alias bombs


def test_alias_bomb_in_scene_is_an_input_error_naming_the_limit(cli: Cli, tmp_path: Path) -> None:
    scene = tmp_path / "bomb_scene.yaml"
    scene.write_text(_bomb("robot_model_name"))
    started = time.perf_counter()
    code, message = plan(cli, tmp_path, "--scene", scene, "--joints", "0,-1,0,0,0,0")
    assert code == 3
    assert "bomb_scene.yaml" in message and f"{MAX_ALIAS_EXPANSION}" in message and "alias" in message
    assert time.perf_counter() - started < 30


def test_alias_bomb_in_motion_plan_request_is_an_input_error(cli: Cli, tmp_path: Path) -> None:
    request = tmp_path / "bomb_request.yaml"
    request.write_text(_bomb("group_name"))
    code, message = plan(cli, tmp_path, "--request", request)
    assert code == 3
    assert "bomb_request.yaml" in message and f"{MAX_ALIAS_EXPANSION}" in message


def test_recursive_alias_is_an_input_error(tmp_path: Path) -> None:
    path = tmp_path / "loop.yaml"
    path.write_text("a: &a [1, *a]\n")
    with pytest.raises(ConfigError, match=r"loop.yaml: a YAML alias refers to a node that contains it"):
        load_yaml(path)


def test_a_few_aliases_as_ros_files_use_them_still_read(tmp_path: Path) -> None:
    path = tmp_path / "ok.yaml"
    path.write_text("joints: &joints [a, b, c]\nother: {joints: *joints}\n")
    assert load_yaml(path)["other"]["joints"] == ["a", "b", "c"]


def test_robot_model_name_that_is_not_a_name_is_an_input_error(cli: Cli, tmp_path: Path) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text("robot_model_name: [1, 2, 3]\n")
    code, message = plan(cli, tmp_path, "--scene", scene, "--joints", "0,-1,0,0,0,0")
    assert code == 3
    assert message.endswith("scene.yaml: robot_model_name: expected a robot name, got a list")


def test_a_date_the_calendar_refuses_is_an_input_error(cli: Cli, tmp_path: Path) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text("robot_model_name: ur10e\nname: 2002-13-45\n")  # YAML 1.1 reads a timestamp there
    code, message = plan(cli, tmp_path, "--scene", scene, "--joints", "0,-1,0,0,0,0")
    assert code == 3
    assert message.endswith("scene.yaml: malformed YAML: month must be in 1..12")


def test_a_list_as_a_parameter_files_key_is_an_input_error(tmp_path: Path) -> None:
    path = tmp_path / "controllers.yaml"
    path.write_text("controller_manager:\n  ros__parameters:\n    [a, b]: 1\n")
    with pytest.raises(ConfigError, match=r"controllers.yaml: line 3 malformed YAML: found unhashable key"):
        parse_controllers(path)


# 2. numbers, expressions and seeds in flags and task files


def test_400_digit_number_in_joints_is_a_usage_error(cli: Cli, tmp_path: Path) -> None:
    code, message = plan(cli, tmp_path, "--joints", "1" + "0" * 400 + ",0,0,0,0,0")
    assert code == 2
    assert "--joints" in message and "longer than 100 characters" in message and len(message) < 200


def test_joint_beyond_a_million_radians_is_a_usage_error(cli: Cli, tmp_path: Path) -> None:
    code, message = plan(cli, tmp_path, "--joints", "1" + "0" * 30 + ",0,0,0,0,0")
    assert code == 2
    assert message.endswith("is out of range; values are limited to |value| <= 1,000,000 (rad, m or s)")


def test_100000_nested_minus_signs_are_a_usage_error(cli: Cli, tmp_path: Path) -> None:
    code, message = plan(cli, tmp_path, "--joints", "-" * 100_000 + "1,0,0,0,0,0")
    assert code == 2
    assert "(100001 characters) is longer than 100 characters" in message and len(message) < 200


def test_nested_minus_signs_within_the_length_still_parse() -> None:
    assert parse_number("-" * 90 + "1", "--joints") == 1.0


def test_seed_beyond_32_bits_is_a_usage_error(cli: Cli, tmp_path: Path) -> None:
    output = tmp_path / "out.mcap"
    result = cli("plan", "--robot", UR10E, "-o", output, "--joints", "0,-1,0,0,0,0", "--seed", "99999999999999999999")
    assert result.exit_code == 2
    assert "4294967295" in result.stderr and "--seed" in result.stderr
    assert not output.exists()


def test_benchmark_seeds_are_bounded() -> None:
    with pytest.raises(UsageError, match=r"seeds in 0\.\.4294967295"):
        parse_seeds("0-99999999999")
    with pytest.raises(UsageError, match="more than 10000 seeds"):
        parse_seeds("0-20000")


def test_pose_at_1e308_is_a_usage_error_without_numpy_warnings(cli: Cli, tmp_path: Path) -> None:
    code, message = plan(cli, tmp_path, "--pose", "1e308,0,0")
    assert code == 2
    assert message == ("moveplan: error: --pose: '1e308' is out of range; values are limited to "
                       "|value| <= 1,000,000 (rad, m or s)")


def test_expression_overflowing_midway_is_a_usage_error() -> None:
    with pytest.raises(UsageError, match="out of range"):
        parse_number("1e5*1e5/1e5", "--pose")


def test_disturbance_time_is_bounded() -> None:
    with pytest.raises(UsageError, match=r"--disturb t: '1e308' is out of range"):
        parse_disturbance("t=1e308,joint=elbow_joint,delta=0.05")
    with pytest.raises(UsageError, match=r"--disturb t: a time must lie in \[0, 1,000,000\] s"):
        parse_disturbance("t=-1,joint=elbow_joint,delta=0.05")


@pytest.mark.parametrize(("start", "expected"), [
    ("1e308", "'1e308' is out of range"),
    ("-5", "a time must lie in [0, 1,000,000] s, got '-5'"),
])
def test_check_tolerances_start_is_a_time_in_range(cli: Cli, tmp_path: Path, start: str, expected: str) -> None:
    result = cli("check-tolerances", tmp_path / "plan.mcap", tmp_path / "rec.mcap", "--start", start)
    assert result.exit_code == 2
    assert expected in one_line(result)


def _task(tmp_path: Path, **top: object) -> Path:
    task = tmp_path / "task.yaml"
    content = {"robot": str(UR10E), "steps": [{"name": "go", "joints": [0, -1, 0, 0, 0, 0]}], **top}
    task.write_text(yaml.safe_dump(content))
    return task


def test_400_digit_number_in_a_task_is_an_input_error(cli: Cli, tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(f"robot: {UR10E}\nsteps:\n  - {{name: go, joints: [1{'0' * 400}, 0, 0, 0, 0, 0]}}\n")
    code, message = plan(cli, tmp_path, task)
    assert code == 3
    assert "task.yaml: steps[0].joints[0]: expected a finite number" in message and len(message) < 200


def test_task_pose_beyond_the_bound_is_an_input_error(cli: Cli, tmp_path: Path) -> None:
    task = _task(tmp_path, steps=[{"name": "far", "pose": {"xyz": [1e308, 0, 0]}}])
    code, message = plan(cli, tmp_path, task)
    assert code == 3
    assert message.endswith("steps[0].pose.xyz[0]: 1e+308 is out of range; values are limited to |value| <= 1,000,000")


def test_task_seed_beyond_32_bits_is_an_input_error(cli: Cli, tmp_path: Path) -> None:
    code, message = plan(cli, tmp_path, _task(tmp_path, seed=99999999999999999999))
    assert code == 3
    assert "seed: expected an integer in 0..4294967295" in message


# 3. numbers as ROS reads them


def test_exponent_without_sign_or_dot_is_a_number_as_in_ros(tmp_path: Path) -> None:
    path = tmp_path / "ros2_controllers.yaml"
    path.write_text(
        "controller_manager:\n  ros__parameters:\n    update_rate: 1.0e3\n"
        "    arm: {type: joint_trajectory_controller/JointTrajectoryController}\n"
        "arm:\n  ros__parameters:\n    joints: [j1]\n    constraints:\n      goal_time: 1e0\n"
        "      j1: {trajectory: 1e-1, goal: 5E-2}\n")
    arm = parse_controllers(path)["arm"]
    assert (arm.update_rate_hz, arm.goal_time_s) == (1000.0, 1.0)
    assert (arm.trajectory_tolerance["j1"], arm.goal_tolerance["j1"]) == (0.1, 0.05)


def test_quoted_exponent_stays_a_string(tmp_path: Path) -> None:
    path = tmp_path / "x.yaml"
    path.write_text("a: '1e9'\nb: 1.0e9\n")
    assert load_yaml(path) == {"a": "1e9", "b": 1e9}


# 4. SRDF, URDF and xacro


def test_nan_in_a_group_state_is_an_input_error(cli: Cli, ur10e_copy: Path) -> None:
    srdf = ur10e_copy / "ur10e.srdf"
    srdf.write_text(srdf.read_text().replace('<joint name="shoulder_pan_joint" value="0"/>',
                                             '<joint name="shoulder_pan_joint" value="nan"/>', 1))
    result = cli("robot", ur10e_copy)
    assert result.exit_code == 3
    assert one_line(result).endswith(
        "ur10e.srdf: group_state 'home' joint 'shoulder_pan_joint': value='nan' is not a finite number")


def _replace_in_urdf(folder: Path, old: str, new: str) -> None:
    urdf = folder / "ur10e.urdf"
    text = urdf.read_text()
    assert old in text
    urdf.write_text(text.replace(old, new, 1))


def test_link_with_two_parents_is_reported_as_a_urdf_problem(cli: Cli, ur10e_copy: Path) -> None:
    _replace_in_urdf(ur10e_copy, '<child link="forearm_link"/>', '<child link="upper_arm_link"/>')
    result = cli("robot", ur10e_copy)
    assert result.exit_code == 3
    assert one_line(result).endswith("ur10e.urdf: link 'upper_arm_link' is the child of two joints, "
                                     "'shoulder_lift_joint' and 'elbow_joint'; a URDF is a tree")


def test_link_that_is_its_own_ancestor_is_reported_as_a_urdf_problem(cli: Cli, tmp_path: Path) -> None:
    folder = tmp_path / "loop"
    folder.mkdir()
    (folder / "arm.urdf").write_text("""<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/><link name="a"/><link name="b"/>
  <joint name="j1" type="revolute"><parent link="b"/><child link="a"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
</robot>
""")
    (folder / "arm.srdf").write_text('<robot name="arm"><group name="arm"><chain base_link="base" tip_link="b"/>'
                                     "</group></robot>")
    (folder / "moveplan.yaml").write_text("name: arm\nurdf: arm.urdf\nsrdf: arm.srdf\n")
    result = cli("robot", folder)
    assert result.exit_code == 3
    assert one_line(result).endswith("arm.urdf: link 'a' is its own ancestor (a -> b -> a); a URDF is a tree")


def test_recursive_xacro_macro_is_one_short_line(cli: Cli, ur10e_copy: Path) -> None:
    (ur10e_copy / "loop.urdf.xacro").write_text("""<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="ur10e">
  <xacro:macro name="again" params="n"><xacro:again n="${n}"/></xacro:macro>
  <xacro:again n="1"/>
</robot>
""")
    config = ur10e_copy / "moveplan.yaml"
    config.write_text(config.read_text().replace("urdf: ur10e.urdf", "urdf: loop.urdf.xacro"))
    result = cli("robot", config)
    assert result.exit_code == 3
    message = one_line(result)
    assert "loop.urdf.xacro: in macro 'again' (recursive:" in message
    assert message.endswith("xacro error: a macro expands itself without end")
    assert len(message.replace(str(ur10e_copy), "")) < 200  # was 2.4 KB of "<- 'again'"


# 5. a joint that cannot move


def test_joint_with_equal_limits_is_refused_clearly(cli: Cli, ur10e_copy: Path, tmp_path: Path) -> None:
    _replace_in_urdf(ur10e_copy, '<limit lower="-3.141592653589793" upper="3.141592653589793" effort="150.0"',
                     '<limit lower="0.5" upper="0.5" effort="150.0"')
    output = tmp_path / "out.mcap"
    result = cli("plan", "--robot", ur10e_copy, "--joints", "wrist_1_joint=0.3", "-o", output)
    assert result.exit_code == 3
    assert not output.exists()
    assert one_line(result).endswith("group 'manipulator': joint 'elbow_joint' has lower limit = upper limit (0.5), "
                                     "so it cannot move; make it a fixed joint in the URDF, or widen its limits")


# 6. scene objects


def test_scene_object_with_more_shapes_than_poses_is_an_input_error(cli: Cli, tmp_path: Path) -> None:
    scene = tmp_path / "scene.yaml"
    box = {"type": "box", "dimensions": [0.1, 0.1, 0.1]}
    scene.write_text(yaml.safe_dump({"world": {"collision_objects": [
        {"id": "boxes", "primitives": [box, box], "primitive_poses": [{"position": [2, 0, 0]}]}]}}))
    code, message = plan(cli, tmp_path, "--scene", scene, "--joints", "0,-1,0,0,0,0")
    assert code == 3
    assert message.endswith("world.collision_objects[0].primitive_poses: object 'boxes' has 2 primitives and "
                            "1 primitive_poses; give one pose per shape")


@pytest.mark.parametrize("moveit", [False, True])
def test_scene_with_too_many_shapes_is_refused_quickly(cli: Cli, tmp_path: Path, moveit: bool) -> None:
    scene = tmp_path / "big.yaml"
    count = 10_001
    if moveit:
        objects = [{"id": f"o{k}", "primitives": [{"type": 2, "dimensions": [0.01]}],
                    "primitive_poses": [{"position": [3, 0, 0]}]} for k in range(count)]
        scene.write_text(yaml.safe_dump({"world": {"collision_objects": objects}}))
    else:
        scene.write_text(yaml.safe_dump({"objects": [{"name": f"o{k}", "sphere": 0.01, "xyz": [3, 0, 0]}
                                                     for k in range(count)]}))
    started = time.perf_counter()
    code, message = plan(cli, tmp_path, "--scene", scene, "--joints", "0,-1,0,0,0,0")
    assert code == 3
    assert message.endswith("big.yaml: 10001 collision shapes; moveplan checks at most 10000 per scene "
                            "(merge small ones into boxes or meshes)")
    assert time.perf_counter() - started < 30


# 7. mimic joints


def test_a_goal_for_a_mimic_joint_that_disagrees_with_its_leader_is_a_usage_error(
        cli: Cli, ur10e_copy: Path, tmp_path: Path) -> None:
    # MoveIt overwrites a mimic joint's value with its leader's (RobotState::updateMimicJoints):
    # a goal asking for another value cannot be met, and is said so rather than dropped.
    _replace_in_urdf(ur10e_copy, '<child link="forearm_link"/>',
                     '<child link="forearm_link"/><mimic joint="shoulder_pan_joint" multiplier="1"/>')
    output = tmp_path / "out.mcap"
    result = cli("plan", "--robot", ur10e_copy, "--joints", "elbow_joint=0.3", "-o", output)
    assert result.exit_code == 2
    assert not output.exists()
    assert one_line(result).endswith("joint 'elbow_joint' mimics 'shoulder_pan_joint', so it is at 0 there, "
                                     "not 0.3: set 'shoulder_pan_joint' only")


def test_a_joint_mimicking_a_group_joint_follows_it_in_the_plan(cli: Cli, ur10e_copy: Path, tmp_path: Path) -> None:
    urdf = ur10e_copy / "ur10e.urdf"
    urdf.write_text(urdf.read_text().replace("</robot>", """
  <link name="follower_link"/>
  <joint name="follower_joint" type="revolute"><parent link="tool0"/><child link="follower_link"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/><mimic joint="elbow_joint" multiplier="0.5"/></joint>
</robot>"""))
    output = tmp_path / "out.mcap"
    result = cli("plan", "--robot", ur10e_copy, "--joints", "elbow_joint=-0.6", "-o", output, "--json")
    assert result.exit_code == 0, result.stderr
    with AnyReader([output]) as reader:
        tf = [c for c in reader.connections if c.topic == "/tf"]
        transforms = [t for c, _, raw in reader.messages(connections=tf) for t in reader.deserialize(raw, c.msgtype)
                      .transforms if t.child_frame_id == "follower_link"]
    z, w = transforms[-1].transform.rotation.z, transforms[-1].transform.rotation.w
    assert 2 * np.arctan2(z, w) == pytest.approx(0.5 * -0.6, abs=1e-9)


def test_a_scaling_below_a_thousandth_is_a_usage_error(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "plan.mcap"
    run = cli("plan", "--robot", "ur10e", "--joints", "elbow_joint=-1", "--velocity-scaling", "1e-9", "-o", out)
    assert run.exit_code == 2 and "--velocity-scaling: expected a factor in [0.001, 1], got 1e-09" in run.stderr
    assert not out.exists()


def test_an_update_rate_beyond_ten_kilohertz_is_an_input_error_naming_the_limit(cli: Cli, tmp_path: Path) -> None:
    controllers = tmp_path / "ros2_controllers.yaml"
    text = (ROOT / "configs" / "ur10e" / "ros2_controllers.yaml").read_text()
    controllers.write_text(text.replace("update_rate: 500", "update_rate: 1.0e+9"))
    assert "update_rate: 1.0e+9" in controllers.read_text()
    plan, out = tmp_path / "plan.mcap", tmp_path / "executed.mcap"
    assert cli("plan", "--robot", "ur10e", "--joints", "elbow_joint=-1", "-o", plan).exit_code == 0
    run = cli("execute", plan, "--fake", "--controllers", controllers, "-o", out)
    assert run.exit_code == 3 and "1e+09 Hz is beyond moveplan's limit of 10000 Hz" in run.stderr
    assert not out.exists()


def test_a_start_outside_the_limits_is_called_a_start(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "plan.mcap"
    run = cli("plan", "--robot", "ur10e", "--start-joints", "elbow_joint=4", "--named", "home", "-o", out)
    assert run.exit_code == 4
    assert "start for joint 'elbow_joint' is 4 rad, outside its limits" in run.stderr and "goal" not in run.stderr
    assert not out.exists()
