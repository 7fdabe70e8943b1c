"""Config files that load but mean nothing ros2_control or MoveIt would run: each is one line naming
the file, the key and the value (exit 3), or a flag contradicting itself (exit 2); none passes silently."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from conftest import SAMPLES, Cli
from test_hostile_packages import CONTROLLERS, arm_package, one_line

from moveplan.core.config.controllers import default_controller
from moveplan.core.pipeline._plan_files import pick_controller

PLAN_ARGS = ("--start-joints", "0,0", "--joints", "0.5,0.5", "--seed", "0")
SECOND = """arm2_controller:
  ros__parameters:
    joints: [j1, j2]
    command_interfaces: [position]
    state_interfaces: [position, velocity]
    constraints: {goal_time: 0.5, j1: {goal: 0.001}}
"""


def with_controllers(tmp_path: Path, text: str) -> Path:
    """Return an arm package whose ros2_controllers.yaml is `text`."""
    package = arm_package(tmp_path)
    (package / "config" / "ros2_controllers.yaml").write_text(text)
    return package


def two_controllers(tmp_path: Path) -> Path:
    """Return an arm package with two JointTrajectoryControllers of different tolerances driving j1 and j2."""
    declared = "    arm2_controller:\n      type: joint_trajectory_controller/JointTrajectoryController\n"
    text = CONTROLLERS.replace("JOINT", "j1").replace("    arm_controller:\n", declared + "    arm_controller:\n", 1)
    text += SECOND
    return with_controllers(tmp_path, text)


@pytest.mark.parametrize(("key", "value", "problem"), [
    ("command_interfaces", "[banana]", "'banana' is not an interface a JointTrajectoryController uses"),
    ("command_interfaces", "[position, position]", "names an interface twice"),
    ("command_interfaces", "[velocity, effort]", "'velocity' is used alone or with 'position'"),
    ("command_interfaces", "[position, velocity, effort]", "'effort' is used alone or with 'position'"),
    ("command_interfaces", "[acceleration]", "'acceleration' needs 'velocity' or 'position'"),
    ("command_interfaces", "[]", "expected a non-empty list of interface names"),
    ("state_interfaces", "[velocity]", "'position' is required"),
    ("state_interfaces", "[kiwi]", "'kiwi' is not an interface"),
    ("state_interfaces", "[position, acceleration]", "'acceleration' needs 'position' and 'velocity'"),
])
def test_controller_interfaces_ros2_controllers_refuses_are_refused_naming_the_key(
    cli: Cli, tmp_path: Path, key: str, value: str, problem: str
) -> None:
    """ros2_controllers' validate_jtc_parameters.hpp and joint_trajectory_controller_parameters.yaml
    (subset_of, unique) refuse these when the controller is configured."""
    default = {"command_interfaces": "[position]", "state_interfaces": "[position, velocity]"}[key]
    text = CONTROLLERS.replace("JOINT", "j1").replace(f"{key}: {default}", f"{key}: {value}")
    package = with_controllers(tmp_path, text)
    result = cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    line = one_line(result)
    assert f"ros2_controllers.yaml: arm_controller.ros__parameters.{key}" in line and problem in line
    assert not (tmp_path / "p.mcap").exists()


@pytest.mark.parametrize("commands", ["[position, velocity, acceleration]", "[position, effort]", "[velocity]"])
def test_controller_interfaces_ros2_controllers_accepts_still_load(cli: Cli, tmp_path: Path, commands: str) -> None:
    """[position, effort] is Jazzy's (validate_jtc_parameters.hpp, feed-forward effort); Humble refused it."""
    text = CONTROLLERS.replace("JOINT", "j1").replace(
        "command_interfaces: [position]", f"command_interfaces: {commands}").replace(
        "state_interfaces: [position, velocity]", "state_interfaces: [position, velocity, acceleration]")
    package = with_controllers(tmp_path, text)
    assert cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap", "-q").exit_code == 0


@pytest.mark.parametrize("commands", ["[velocity]", "[effort]", "[position, effort]"])
def test_velocity_or_effort_commands_without_velocity_states_are_refused(
    cli: Cli, tmp_path: Path, commands: str
) -> None:
    """ros2_controllers' joint_trajectory_controller.cpp (on_configure) refuses these across the two lists."""
    text = CONTROLLERS.replace("JOINT", "j1").replace(
        "command_interfaces: [position]", f"command_interfaces: {commands}").replace(
        "state_interfaces: [position, velocity]", "state_interfaces: [position]")
    package = with_controllers(tmp_path, text)
    result = cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    line = one_line(result)
    assert "ros2_controllers.yaml: arm_controller.ros__parameters.state_interfaces: ['position']" in line
    assert "need 'position' and 'velocity' state interfaces" in line


def test_two_different_controllers_for_the_same_joints_are_an_error_not_a_silent_choice(
    cli: Cli, tmp_path: Path
) -> None:
    package = two_controllers(tmp_path)
    assert cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap", "-q").exit_code == 0
    result = cli("execute", tmp_path / "p.mcap", "--fake", "-o", tmp_path / "e.mcap")
    assert result.exit_code == 3
    line = one_line(result)
    assert "controllers 'arm2_controller', 'arm_controller' all drive j1, j2 with different settings" in line
    assert "default: true" in line
    assert not (tmp_path / "e.mcap").exists()


def test_of_two_controllers_for_the_same_joints_moveits_default_one_executes(cli: Cli, tmp_path: Path) -> None:
    """MoveIt's TrajectoryExecutionManager prefers the controller moveit_controllers.yaml marks default
    (UR's ur_moveit_config marks scaled_joint_trajectory_controller so)."""
    package = two_controllers(tmp_path)
    (package / "config" / "moveit_controllers.yaml").write_text(
        "moveit_simple_controller_manager:\n  controller_names: [arm_controller, arm2_controller]\n"
        "  arm_controller: {default: false}\n  arm2_controller: {default: true}\n")
    assert cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap", "-q").exit_code == 0
    code, document = cli.json("execute", tmp_path / "p.mcap", "--fake", "-o", tmp_path / "e.mcap")
    assert code == 0 and document["controller"] == "arm2_controller"


def test_moveits_default_controller_is_chosen_even_when_another_drives_fewer_joints() -> None:
    """MoveIt's TrajectoryExecutionManager ranks controllers by `default` first, then by fewest joints
    (OrderPotentialControllerCombination in trajectory_execution_manager.cpp)."""
    arm = replace(default_controller(["j1", "j2"]), name="arm_controller")
    whole = replace(default_controller(["j1", "j2", "j4"]), name="whole_controller")
    controllers = {"arm_controller": arm, "whole_controller": whole}
    assert pick_controller(controllers, ["j1", "j2"], "x").name == "arm_controller"
    assert pick_controller(controllers, ["j1", "j2"], "x", ("whole_controller",)).name == "whole_controller"


def test_two_identical_controllers_for_the_same_joints_execute_with_the_first(cli: Cli, tmp_path: Path) -> None:
    declared = "    arm2_controller:\n      type: joint_trajectory_controller/JointTrajectoryController\n"
    text = CONTROLLERS.replace("JOINT", "j1").replace("    arm_controller:\n", declared + "    arm_controller:\n", 1)
    text += "arm2_controller:\n  ros__parameters:\n    joints: [j2, j1]\n    command_interfaces: [position]\n" \
            "    state_interfaces: [position, velocity]\n"
    package = with_controllers(tmp_path, text)
    assert cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap", "-q").exit_code == 0
    code, document = cli.json("execute", tmp_path / "p.mcap", "--fake", "-o", tmp_path / "e.mcap")
    assert code == 0 and document["controller"] == "arm2_controller"


def test_an_srdf_chain_given_tip_to_base_is_refused_naming_both_links(cli: Cli, tmp_path: Path) -> None:
    package = arm_package(tmp_path)
    srdf = package / "config" / "arm.srdf"
    srdf.write_text(srdf.read_text().replace('base_link="base" tip_link="tip"', 'base_link="tip" tip_link="base"'))
    result = cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    line = one_line(result)
    assert "arm.srdf group 'arm': chain base_link 'tip' is below tip_link 'base'" in line and "swap" in line


@pytest.mark.parametrize("flag", ["--joints", "--start-joints"])
def test_a_joint_named_twice_in_a_flag_is_a_usage_error(cli: Cli, tmp_path: Path, flag: str) -> None:
    package = arm_package(tmp_path)
    other = "--start-joints" if flag == "--joints" else "--joints"
    result = cli("plan", "--robot", package, flag, "j1=0.1,j2=0,j1=0.2", other, "0.5,0.5", "-o", tmp_path / "p.mcap")
    assert result.exit_code == 2
    assert one_line(result) == f"moveplan: error: {flag}: joint 'j1' is given twice"


def test_execute_start_joints_named_twice_is_a_usage_error(cli: Cli, tmp_path: Path) -> None:
    plan = SAMPLES / "recordings" / "tool_up_plan.mcap"
    result = cli("execute", plan, "--fake", "--start-joints", "elbow_joint=1,elbow_joint=1", "-o", tmp_path / "e.mcap")
    assert result.exit_code == 2
    assert one_line(result) == "moveplan: error: --start-joints: joint 'elbow_joint' is given twice"


@pytest.mark.parametrize(("flag", "value", "message"), [
    ("--disturb", "t=1,joint=elbow_joint,delta=0.1,delta=0.2", "--disturb: expected 't=SECONDS,joint=NAME,delta=RAD'"),
    ("--plant-param", "tau=0.1", "--plant-param: 'tau' is given twice"),
])
def test_execute_flag_pairs_named_twice_are_a_usage_error(
    cli: Cli, tmp_path: Path, flag: str, value: str, message: str
) -> None:
    plan = SAMPLES / "recordings" / "tool_up_plan.mcap"
    twice = (flag, value, flag, value) if flag == "--plant-param" else (flag, value)
    result = cli("execute", plan, "--fake", "--plant", "lag", *twice, "-o", tmp_path / "e.mcap")
    assert result.exit_code == 2
    assert one_line(result).startswith(f"moveplan: error: {message}")
    assert not (tmp_path / "e.mcap").exists()


def test_a_shift_axis_named_twice_is_a_usage_error(cli: Cli, tmp_path: Path) -> None:
    result = cli("plan", "--robot", arm_package(tmp_path), "--start-joints", "0,0", "--shift", "z=0.1,z=0.2",
                 "-o", tmp_path / "p.mcap")
    assert result.exit_code == 2
    assert one_line(result) == "moveplan: error: --shift: axis 'z' is given twice"


@pytest.mark.parametrize(("old", "new", "problem"), [
    ("joints: [j1, j2]", "joints: .nan", "ros__parameters.joints: expected a list of joint names, got nan"),
    ("joints: [j1, j2]", "joints: [j1, [j2]]", "expected a list of joint names, got ['j1', ['j2']]"),
])
def test_controller_joints_that_are_no_list_of_names_are_refused(
    cli: Cli, tmp_path: Path, old: str, new: str, problem: str
) -> None:
    package = with_controllers(tmp_path, CONTROLLERS.replace("JOINT", "j1").replace(old, new))
    result = cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    assert problem in one_line(result)


def test_moveit_controller_names_that_are_no_names_are_refused(cli: Cli, tmp_path: Path) -> None:
    package = two_controllers(tmp_path)
    (package / "config" / "moveit_controllers.yaml").write_text(
        "moveit_simple_controller_manager:\n  controller_names: [[arm_controller]]\n")
    result = cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    assert "moveit_controllers.yaml: moveit_simple_controller_manager.controller_names: expected a list of " \
           "controller names, got [['arm_controller']]" in one_line(result)
