"""Limits and the start state as MoveIt and mock hardware have them.

joint_limits.yaml entries for joints the URDF lacks are ignored; a joint without an
acceleration limit plans with the documented default (an error with strict limits); with
no start given a plan starts where mock hardware starts (the URDF's <ros2_control> initial
values, else initial_positions.yaml, else MoveIt's default state), checked against the
limits before anything else.
"""

from __future__ import annotations

import json
import logging
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import REALWORLD, ROOT, Cli, run_process

from moveplan.core.bag.plan_file import read_plan
from moveplan.core.config._urdf import parse_urdf
from moveplan.core.config.limits import DEFAULT_ACCELERATION, merge_limits, parse_joint_limits
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.errors import ConfigError

DATA = ROOT / "tests" / "data" / "limits_start"
PANDA = ROOT / "configs" / "panda"
GROUP = ("j1", "j2", "j3", "j4")


def arm(folder: Path, ros2_control: str | None = None, initial: str | None = None) -> Path:
    """Write the test arm into `folder`: its URDF (plus a <ros2_control> block), SRDF, limits, initial positions."""
    folder.mkdir(parents=True, exist_ok=True)
    urdf = (DATA / "arm.urdf").read_text()
    if ros2_control is not None:
        urdf = urdf.replace("</robot>", ros2_control + "</robot>")
    (folder / "arm.urdf").write_text(urdf)
    shutil.copy(DATA / "arm.srdf", folder)
    shutil.copy(DATA / "joint_limits.yaml", folder)
    manifest = "urdf: arm.urdf\nsrdf: arm.srdf\njoint_limits: joint_limits.yaml\n"
    if initial is not None:
        (folder / "initial_positions.yaml").write_text(initial)
        manifest += "initial_positions: initial_positions.yaml\n"
    (folder / "moveplan.yaml").write_text(manifest)
    return folder


def mock_hardware(**changes: str) -> str:
    """Return the test <ros2_control> block, with initial values replaced (old text -> new text)."""
    text = (DATA / "ros2_control.xml").read_text()
    for old, new in changes.items():
        text = text.replace(old, new)
    return text


def first_point(plan: Path) -> dict[str, float]:
    """Return where a plan file's first step starts, joint -> value."""
    trajectory = read_plan(plan).steps[0].trajectory
    return dict(zip(trajectory.joint_names, trajectory.positions[0].tolist(), strict=True))


@pytest.fixture(scope="module")
def realworld() -> Path:
    return REALWORLD


# --- joint_limits.yaml ------------------------------------------------------------------------


def test_limits_for_a_joint_the_urdf_lacks_are_ignored_and_logged_at_debug(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.DEBUG, logger="moveplan.core.config.limits"):
        config = load_robot_config(arm(tmp_path / "arm"))
    assert "j7" not in config.limits and config.limits["j1"].max_acceleration == 2.0
    [record] = [r for r in caplog.records if "j7" in r.getMessage()]
    assert record.levelno == logging.DEBUG and "joint_limits.yaml: joint_limits.j7" in record.getMessage()


def test_a_joint_without_acceleration_limit_takes_the_default_with_default_as_its_source(tmp_path: Path) -> None:
    config = load_robot_config(arm(tmp_path / "arm"))
    for joint in ("j3", "j4"):  # has_acceleration_limits: false, and not listed at all
        assert config.limits[joint].max_acceleration == DEFAULT_ACCELERATION == 1.0
        assert config.limits[joint].source["acceleration"] == "default"
    assert config.limits["j1"].source["acceleration"] == "joint_limits.yaml"
    assert config.missing_acceleration_limits() == ("j3", "j4")


def test_strict_limits_refuse_a_missing_acceleration_limit_naming_joints_and_file(tmp_path: Path) -> None:
    folder = arm(tmp_path / "arm")
    path = folder / "joint_limits.yaml"
    overrides, _, _ = parse_joint_limits(path)
    joints = parse_urdf((folder / "arm.urdf").read_text(), folder / "arm.urdf")
    # finger_b_joint mimics finger_a_joint: MoveIt times the leader only, so it needs no limit.
    with pytest.raises(ConfigError, match=r"joint_limits.yaml: no acceleration limit for joints j3, j4 \("):
        merge_limits(folder / "arm.urdf", joints, path, overrides, strict=True)
    with pytest.raises(ConfigError, match=r"no acceleration limit for joints j3, j4"):
        load_robot_config(folder, strict_limits=True)
    assert merge_limits(folder / "arm.urdf", joints, path, overrides)["j3"].max_acceleration == 1.0


def test_plan_warns_about_default_acceleration_and_records_it_in_the_plan_file(tmp_path: Path) -> None:
    out = tmp_path / "out.mcap"
    result = run_process("plan", "--robot", arm(tmp_path / "arm"), "--joints", "j1=0.5,j3=0.08,j4=1", "-o", out)
    assert result.returncode == 0, result.stderr
    assert "joint_limits.yaml: no acceleration limit for joints j3, j4; planning with the default 1 rad/s^2" \
        in result.stderr
    plan = read_plan(out)
    sources = json.loads(plan.metadata["limit_sources"])
    assert sources["j3"]["acceleration"] == "default" and sources["j1"]["acceleration"] == "joint_limits.yaml"
    assert plan.limits["j3"]["max_acceleration"] == 1.0


def test_robot_command_shows_the_default_acceleration_and_its_source(cli: Cli, tmp_path: Path) -> None:
    code, document = cli.json("robot", arm(tmp_path / "arm"))
    assert code == 0, document
    assert document["joints"]["j3"]["max_acceleration"] == 1.0
    assert document["joints"]["j3"]["source"]["acceleration"] == "default"
    assert document["missing_acceleration"] == ["j3", "j4"]


# --- where the robot starts --------------------------------------------------------------------


def test_without_urdf_or_file_values_joints_start_at_moveit_default_state(tmp_path: Path) -> None:
    config = load_robot_config(arm(tmp_path / "arm"))
    # j2's limits [0.5, 2.5] exclude 0: MoveIt's default state puts it in the middle.
    assert config.initial_positions == {"j1": 0.0, "j2": 1.5, "j3": 0.0, "j4": 0.0,
                                        "finger_a_joint": 0.0, "finger_b_joint": 0.0}
    assert config.initial_sources["j2"].startswith("MoveIt's default state")


def test_ros2_control_initial_values_are_where_the_robot_starts(cli: Cli, tmp_path: Path) -> None:
    folder = arm(tmp_path / "arm", ros2_control=mock_hardware())
    config = load_robot_config(folder)
    expected = {"j1": 0.3, "j2": 1.2, "j3": 0.04, "j4": 0.0, "finger_a_joint": 0.01, "finger_b_joint": -0.01}
    assert config.initial_positions == pytest.approx(expected)  # j3: the older `initial_position` parameter
    assert config.initial_sources["j1"] == f"the <ros2_control> initial_value in {folder / 'arm.urdf'}"
    assert config.initial_sources["finger_b_joint"] == "joint 'finger_a_joint', which it mimics"
    out = tmp_path / "out.mcap"
    code, document = cli.json("plan", "--robot", folder, "--joints", "j1=1", "-o", out)
    assert code == 0, document
    np.testing.assert_allclose([first_point(out)[j] for j in GROUP], [0.3, 1.2, 0.04, 0.0], atol=1e-12)


def test_urdf_initial_values_win_over_initial_positions_yaml_with_a_warning(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    initial = "initial_positions: {j1: 0.3, j2: 2.0, j4: 0.7}\n"
    with caplog.at_level(logging.WARNING):
        config = load_robot_config(arm(tmp_path / "arm", ros2_control=mock_hardware(), initial=initial))
    assert config.initial_positions["j2"] == 1.2  # the URDF's, where mock hardware starts
    assert config.initial_positions["j4"] == 0.7  # the URDF gives none: initial_positions.yaml
    assert config.initial_sources["j4"].endswith("initial_positions.yaml")
    [warning] = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert "<ros2_control> initial values differ from" in warning and "j2 (1.2, not 2)" in warning
    assert "j1" not in warning  # they agree on j1


def test_a_malformed_initial_value_names_the_urdf_and_the_joint(tmp_path: Path) -> None:
    hardware = mock_hardware(**{">0.3<": ">zero<"})
    with pytest.raises(ConfigError, match=r"arm.urdf: <ros2_control name=\"ArmMockSystem\"> joint 'j1': "
                                          r"initial value 'zero' is not a number"):
        load_robot_config(arm(tmp_path / "arm", ros2_control=hardware))


def test_initial_positions_outside_limits_name_joint_and_file_before_collisions(cli: Cli, tmp_path: Path) -> None:
    folder = arm(tmp_path / "arm", initial="initial_positions: {j2: 0.1}\n")
    code, document = cli.json("plan", "--robot", folder, "--joints", "j1=1", "-o", tmp_path / "out.mcap")
    assert code == 4 and document["error"]["kind"] == "StartOutsideLimits"
    assert document["error"]["message"] == (
        f"start for joint 'j2' is 0.1 rad, outside its limits [0.5, 2.5]; the value comes from "
        f"{folder / 'initial_positions.yaml'}")
    assert not (tmp_path / "out.mcap").exists()


def test_urdf_initial_value_outside_limits_names_the_urdf(cli: Cli, tmp_path: Path) -> None:
    folder = arm(tmp_path / "arm", ros2_control=mock_hardware(**{">1.2<": ">3.0<"}))
    code, document = cli.json("plan", "--robot", folder, "--joints", "j1=1", "-o", tmp_path / "out.mcap")
    assert code == 4, document
    assert document["error"]["message"].endswith(
        f"the value comes from the <ros2_control> initial_value in {folder / 'arm.urdf'}")


def test_a_partial_start_flag_replaces_its_joints_and_the_others_are_checked(cli: Cli, tmp_path: Path) -> None:
    folder = arm(tmp_path / "arm", initial="initial_positions: {j2: 0.1}\n")
    out = tmp_path / "out.mcap"
    code, document = cli.json("plan", "--robot", folder, "--start-joints", "j2=1.0", "--joints", "j1=1", "-o", out)
    assert code == 0, document
    assert first_point(out)["j2"] == 1.0
    code, document = cli.json("plan", "--robot", folder, "--start-joints", "j1=0.5", "--joints", "j1=1", "-o", out)
    assert code == 4 and document["error"]["message"].endswith("initial_positions.yaml")
    code, document = cli.json("plan", "--robot", folder, "--start-joints", "j2=3", "--joints", "j1=1", "-o", out)
    assert code == 4 and document["error"]["message"].endswith("; the value comes from --start-joints")


def test_panda_without_initial_positions_starts_at_moveit_default_state(cli: Cli, tmp_path: Path) -> None:
    folder = tmp_path / "panda"
    shutil.copytree(PANDA, folder)
    (folder / "initial_positions.yaml").unlink()
    manifest = folder / "moveplan.yaml"
    manifest.write_text("".join(line for line in manifest.read_text().splitlines(keepends=True)
                                if not line.startswith("initial_positions:")))
    out = tmp_path / "out.mcap"
    code, document = cli.json("plan", "--robot", folder, "--named", "ready", "-o", out)
    assert code == 0, document  # all zeros would put joint 4 outside [-3.0718, -0.0698]
    start = first_point(out)
    np.testing.assert_allclose([start[f"panda_joint{i}"] for i in range(1, 8)], [0, 0, 0, -1.5708, 0, 0, 0],
                               atol=1e-12)


# --- real MoveIt config packages ---------------------------------------------------------------


@pytest.mark.realworld
def test_dual_arm_panda_starts_where_its_mock_hardware_starts(
    cli: Cli, tmp_path: Path, realworld: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(realworld))
    config = realworld / "moveit_resources" / "dual_arm_panda_moveit_config"
    out = tmp_path / "out.mcap"
    # No initial_positions.yaml: all zeros would fold link 7 into link 5.
    code, document = cli.json("plan", "--robot", config, "--group", "left_panda_arm",
                              "--joints", "left_panda_joint1=0.5", "-o", out)
    assert code == 0, document
    start = first_point(out)
    np.testing.assert_allclose([start[f"left_panda_joint{i}"] for i in range(1, 8)],
                               [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785], atol=1e-12)


@pytest.mark.realworld
def test_kinova_gripper_starts_closed_as_its_urdf_says_not_as_initial_positions_yaml(
    realworld: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(realworld))
    with caplog.at_level(logging.WARNING):
        config = load_robot_config(realworld / "ros2_kortex" / "kortex_moveit_config" /
                                   "kinova_gen3_7dof_robotiq_2f_85_moveit_config")
    # robotiq_description's 2f_85.ros2_control.xacro starts the gripper closed; the yaml says 0.
    assert config.initial_positions["robotiq_85_left_knuckle_joint"] == pytest.approx(0.7929)
    assert any("robotiq_85_left_knuckle_joint (0.7929, not 0)" in r.getMessage() for r in caplog.records)


@pytest.mark.realworld
def test_abb_irb1200_plans_with_the_default_acceleration_and_strict_limits_refuse(
    tmp_path: Path, realworld: Path
) -> None:
    config = realworld / "abb_ros2" / "robot_specific_config" / "abb_irb1200_5_90_moveit_config"
    out = tmp_path / "out.mcap"
    result = run_process("plan", "--robot", config, "--package-path", realworld, "--joints", "joint_1=0.5",
                         "-o", out)
    assert result.returncode == 0, result.stderr
    assert "joint_limits.yaml: no acceleration limit for joints joint_1, joint_2, joint_3, joint_4, joint_5, " \
           "joint_6; planning with the default 1 rad/s^2" in result.stderr
    assert json.loads(read_plan(out).metadata["limit_sources"])["joint_1"]["acceleration"] == "default"
    strict = run_process("plan", "--robot", config, "--package-path", realworld, "--joints", "joint_1=0.5",
                         "--strict-limits", "-o", tmp_path / "strict.mcap")
    assert strict.returncode == 3
    assert "joint_limits.yaml: no acceleration limit for joints joint_1" in strict.stderr
