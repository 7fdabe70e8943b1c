"""Angles: radians, pi expressions or degrees (`90deg`); degrees written without their unit are refused."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import ROOT, UR10E, Cli
from rosbags.highlevel import AnyReader

from moveplan.cli.parsing import parse_joint_values, parse_joints, parse_number, parse_pose, parse_shift
from moveplan.core.config import JointGoal, load_task
from moveplan.core.config.fields import angle, pose_angle
from moveplan.core.errors import ConfigError, UsageError

ARM = ROOT / "tests" / "data" / "limits_start" / "arm.urdf"  # j3 prismatic [0, 0.1] m, j4 continuous
TURN = "more than a full turn (2*pi)"
HINT = "angles are in radians (pi, -pi/2) or, with a unit, in degrees"


def one_line(result: Any) -> str:
    """Return the error's one line on stderr (asserting it is one line)."""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    return lines[0]


def refused_plan(cli: Cli, tmp_path: Path, *args: Any) -> tuple[int, str]:
    """Run `moveplan plan` that must fail; return exit code and its one line, asserting no file is left."""
    output = tmp_path / "out.mcap"
    result = cli("plan", *args, "-o", output)
    assert not output.exists()
    return result.exit_code, one_line(result)


def task(tmp_path: Path, steps: list[dict[str, Any]], robot: Path = UR10E, **top: Any) -> Path:
    path = tmp_path / "task.yaml"
    path.write_text(yaml.safe_dump({"robot": str(robot), "steps": steps, **top}))
    return path


def last_point(path: Path) -> list[float]:
    """Return the plan's last trajectory point, read back with rosbags."""
    with AnyReader([path]) as reader:
        connections = [c for c in reader.connections if c.topic == "/planned_trajectory"]
        messages = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=connections)]
    return list(messages[-1].points[-1].positions)


# The cases: degrees in a pose, from a flag (exit 2) and from a task file (exit 3).


def test_pose_flag_in_degrees_without_unit_exits_2(cli: Cli, tmp_path: Path) -> None:
    code, message = refused_plan(cli, tmp_path, "--robot", UR10E, "--pose", "0.6,0,0.4,180,0,0")
    assert code == 2
    assert message == f"moveplan: error: --pose roll: 180 rad is {TURN}: {HINT} (180deg)"


def test_task_rpy_in_degrees_without_unit_exits_3_naming_the_file(cli: Cli, tmp_path: Path) -> None:
    path = task(tmp_path, [{"name": "down", "pose": {"xyz": [0.6, 0, 0.4], "rpy": [180, 0, 0]}}])
    code, message = refused_plan(cli, tmp_path, path)
    assert code == 3
    assert message == f"moveplan: error: {path}: steps[0].pose.rpy[0]: 180 rad is {TURN}: {HINT} (180deg)"


def test_scene_frame_rpy_in_degrees_without_unit_exits_3_and_with_deg_plans(cli: Cli, tmp_path: Path) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text("frames:\n  - {name: target, parent: base_link, xyz: [0.5, 0, 0.2], rpy: [180, 0, 0]}\n")
    goal = ("--robot", UR10E, "--scene", str(scene), "--pose", "0,0,0.1,0,0,0", "--frame", "target")
    code, message = refused_plan(cli, tmp_path, *goal)
    assert code == 3
    assert message == f"moveplan: error: {scene}: frames[0].rpy[0]: 180 rad is {TURN}: {HINT} (180deg)"
    scene.write_text("frames:\n  - {name: target, parent: base_link, xyz: [0.5, 0, 0.2], rpy: [180deg, 0, 0]}\n")
    assert cli("plan", *goal, "-o", str(tmp_path / "plan.mcap"), "-q").exit_code == 0


@pytest.mark.parametrize(("args", "message"), [
    (["--joints", "elbow_joint=90"], f"--joints elbow_joint: 90 rad is {TURN} and outside its limits [-3.14159, "
                                     f"3.14159]: {HINT} (90deg)"),
    (["--joints", "0,-90,0,0,0,0"], "--joints shoulder_lift_joint: -90 rad is"),
    (["--start-joints", "wrist_1_joint=-90", "--named", "home"], "--start-joints wrist_1_joint: -90 rad is"),
    (["--start-named", "home", "--shift", "yaw=45"], f"--shift yaw: 45 rad is {TURN}: {HINT} (45deg)"),
    (["--start-named", "home", "--shift", "z=5deg"], "--shift z: '5deg': a 'deg' suffix is for angles"),
    (["--pose", "0.6deg,0,0.4"], "--pose: '0.6deg': a 'deg' suffix is for angles"),
    (["--pose", "0.6,0,0.4,0,0,0,1deg"], "--pose: '1deg': a 'deg' suffix is for angles"),
    (["--joints", "elbow_joint=1", "--planning-time", "1deg"], "--planning-time: '1deg': a 'deg' suffix"),
    (["--joints", "elbow_joint=ninety"], "--joints elbow_joint: expected a number in radians (1.57, pi/2) or "
                                         "degrees (90deg), got 'ninety'"),
    (["--joints", "elbow_joint=deg"], "expected a number in radians (1.57, pi/2) or degrees (90deg), got 'deg'"),
])
def test_flags_refuse_unitless_degrees_and_misplaced_units_with_exit_2(
    cli: Cli, tmp_path: Path, args: list[str], message: str
) -> None:
    code, line = refused_plan(cli, tmp_path, "--robot", UR10E, *args)
    assert code == 2
    assert message in line


@pytest.mark.parametrize(("step", "message"), [
    ({"joints": {"elbow_joint": 90}}, f"steps[0].joints.elbow_joint: 90 rad is {TURN} and outside its limits"),
    ({"joints": [0, -90, 0, 0, 0, 0]}, f"steps[0].joints[1] (shoulder_lift_joint): -90 rad is {TURN}"),
    ({"shift": {"roll": -200}}, f"steps[0].shift.roll: -200 rad is {TURN}: {HINT} (-200deg)"),
    ({"shift": {"x": "5deg"}}, "steps[0].shift.x: expected a finite number, got '5deg'"),
    ({"pose": {"rpy": [0, "ninety", 0]}}, "steps[0].pose.rpy[1]: expected a number in radians (1.57, pi/2)"),
])
def test_task_files_refuse_unitless_degrees_with_exit_3(
    cli: Cli, tmp_path: Path, step: dict[str, Any], message: str
) -> None:
    path = task(tmp_path, [{"name": "go", **step}], start={"named": "home"})
    code, line = refused_plan(cli, tmp_path, path)
    assert code == 3
    assert line.startswith(f"moveplan: error: {path}: ") and message in line


def test_task_start_joints_are_checked_too(cli: Cli, tmp_path: Path) -> None:
    path = task(tmp_path, [{"name": "go", "named": "home"}], start={"joints": {"elbow_joint": 120}})
    code, line = refused_plan(cli, tmp_path, path)
    assert code == 3
    assert f"{path}: start.joints.elbow_joint: 120 rad is {TURN}" in line


def test_prismatic_joint_in_degrees_names_the_joint(cli: Cli, tmp_path: Path) -> None:
    code, line = refused_plan(cli, tmp_path, "--robot", ARM, "--joints", "j3=2deg")
    assert code == 2
    assert line == "moveplan: error: --joints j3: 'j3' is a prismatic joint, in [m]; 'deg' is for revolute joints"
    path = task(tmp_path, [{"name": "slide", "joints": {"j3": "2deg"}}], robot=ARM)
    code, line = refused_plan(cli, tmp_path, path)
    assert code == 3
    assert line.endswith(f"{path}: steps[0].joints.j3: 'j3' is a prismatic joint, in [m]; 'deg' is for "
                         "revolute joints")


def test_execute_start_joints_refuse_degrees_on_a_prismatic_joint(cli: Cli, tmp_path: Path) -> None:
    plan = tmp_path / "slide.mcap"
    assert cli("plan", "--robot", ARM, "--joints", "j3=0.05", "-o", plan, "-q").exit_code == 0
    result = cli("execute", plan, "--fake", "--start-joints", "j3=2deg")
    assert result.exit_code == 2
    assert one_line(result) == ("moveplan: error: --start-joints j3: 'j3' is a prismatic joint, in [m]; 'deg' is "
                                "for revolute joints")
    assert cli("execute", plan, "--fake", "--start-joints", "j3=0.01", "-q").exit_code in (0, 5)


def test_continuous_joint_beyond_a_turn_is_refused_but_degrees_are_not(cli: Cli, tmp_path: Path) -> None:
    code, line = refused_plan(cli, tmp_path, "--robot", ARM, "--joints", "j4=7")
    assert code == 2
    assert line.endswith(f"--joints j4: 7 rad is {TURN}: {HINT} (7deg)")


# What passes: values within a turn, values within wider limits, and degrees with their unit.


def test_wrist_at_5_rad_within_its_limits_still_plans(cli: Cli, tmp_path: Path) -> None:
    output = tmp_path / "wrist.mcap"
    result = cli("plan", "--robot", UR10E, "--joints", "wrist_3_joint=5", "-o", output)
    assert result.exit_code == 0, result.stderr
    assert last_point(output)[5] == pytest.approx(5.0)


def test_joints_in_degrees_plan_to_radians(cli: Cli, tmp_path: Path) -> None:
    output = tmp_path / "deg.mcap"
    result = cli("plan", "--robot", UR10E, "--start-joints", "0,-90deg,-pi/2,0,0,0",
                 "--joints", "elbow_joint=-60deg,wrist_1_joint=10deg", "-o", output)
    assert result.exit_code == 0, result.stderr
    end = last_point(output)
    assert end[1] == pytest.approx(-math.pi / 2) and end[2] == pytest.approx(-math.pi / 3)
    assert end[3] == pytest.approx(math.radians(10))


def test_task_angles_take_degrees_and_pi_expressions(tmp_path: Path) -> None:
    path = task(tmp_path, [
        {"name": "down", "pose": {"xyz": [0.6, 0, 0.4], "rpy": ["180deg", "-pi/4", 0.5]}},
        {"name": "turn", "shift": {"yaw": "-90 deg", "z": 0.1}},
        {"name": "joints", "joints": ["0deg", "-pi/2", -1.2, 0, "90deg", 0]},
    ])
    steps = load_task(path).steps
    assert steps[0].goal.rpy == pytest.approx((math.pi, -math.pi / 4, 0.5))
    assert steps[1].goal.yaw == pytest.approx(-math.pi / 2) and steps[1].goal.z == 0.1
    goal = steps[2].goal
    assert isinstance(goal, JointGoal)
    assert goal.values == pytest.approx((0.0, -math.pi / 2, -1.2, 0.0, math.pi / 2, 0.0))
    assert goal.degrees == (True, False, False, False, True, False)
    assert goal == JointGoal((0.0, -math.pi / 2, -1.2, 0.0, math.pi / 2, 0.0))  # units do not change the goal


# The one helper both flags and files use.


def test_angle_reads_numbers_expressions_and_degrees() -> None:
    assert angle(1.5, "x") == (1.5, False)
    assert angle("pi/2", "x") == (math.pi / 2, False)
    assert angle(" -90deg ", "x") == (pytest.approx(-math.pi / 2), True)
    assert angle("45 deg", "x") == (pytest.approx(math.pi / 4), True)
    assert pose_angle("400deg", "x") == pytest.approx(math.radians(400))  # a unit given is taken at its word
    assert pose_angle(6.2832, "x") == 6.2832  # 2*pi rounded by hand is still a turn
    with pytest.raises(ConfigError, match=r"^x: 6.3 rad is more than a full turn"):
        pose_angle(6.3, "x")
    with pytest.raises(UsageError, match=r"^--pose yaw: 7 rad"):
        pose_angle("7", "--pose yaw", UsageError)
    with pytest.raises(ConfigError, match="expected a finite number, got True"):
        angle(True, "x")


def test_flag_parsers_keep_units_apart() -> None:
    assert parse_number("-pi/2", "--x") == -math.pi / 2
    goal = parse_joints("elbow_joint=-90deg,wrist_1_joint=1", "--joints")
    assert goal.named_values == {"elbow_joint": pytest.approx(-math.pi / 2), "wrist_1_joint": 1.0}
    assert goal.degrees == (True, False) and goal.source == "--joints"
    assert parse_joint_values("elbow_joint=30deg", "--start-joints").named_values == {
        "elbow_joint": pytest.approx(math.pi / 6)}
    assert parse_pose("0.6,0,0.4,180deg,0,-90deg", "--pose").rpy == pytest.approx((math.pi, 0.0, -math.pi / 2))
    assert parse_pose("0.6,0,0.4,pi,0,0", "--pose").rpy == (math.pi, 0.0, 0.0)
    assert parse_shift("yaw=30deg,z=0.1", "--shift").yaw == pytest.approx(math.pi / 6)
    with pytest.raises(UsageError, match="got 2 values"):
        parse_pose("0.6,0", "--pose")
    with pytest.raises(UsageError, match="--pose pitch: 90 rad"):
        parse_pose("0.6,0,0.4,0,90,0", "--pose")
