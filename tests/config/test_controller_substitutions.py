"""Launch substitutions in controller files, made as ParameterFile(allow_substs=True) makes them."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import REALWORLD, ROOT, Cli

from moveplan.core.config._substitutions import substitute
from moveplan.core.config.controllers import parse_controllers, parse_execution
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.errors import ConfigError

PREFIXED_ARM = Path(__file__).parents[1] / "data" / "controller_substitutions" / "prefixed_arm"
UR_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
             "wrist_3_joint")
PLAN = ROOT / "samples" / "recordings" / "tool_up_plan.mcap"  # a UR10e plan


@pytest.fixture(scope="module")
def ur_controllers() -> Path:
    """ur_robot_driver's ur_controllers.yaml in the real-world workspace."""
    return REALWORLD / "Universal_Robots_ROS2_Driver" / "ur_robot_driver" / "config" / "ur_controllers.yaml"


def one_line(result) -> str:  # noqa: ANN001 - click's Result
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    return lines[0]


def controllers_file(folder: Path, joint_line: str = "$(var tf_prefix)j1", rate: str = "100") -> Path:
    path = folder / "ros2_controllers.yaml"
    path.write_text(f"""controller_manager:
  ros__parameters:
    update_rate: {rate}
    arm_controller:
      type: joint_trajectory_controller/JointTrajectoryController
arm_controller:
  ros__parameters:
    joints:
      - {joint_line}
""")
    return path


# --- ur_robot_driver's file ---------------------------------------------------------------------------


@pytest.mark.realworld
def test_ur_driver_controllers_load_with_tf_prefix_empty_by_default(ur_controllers: Path) -> None:
    controller = parse_controllers(ur_controllers)["joint_trajectory_controller"]
    assert controller.joints == UR_JOINTS
    assert controller.trajectory_tolerance["elbow_joint"] == 0.2
    assert controller.goal_tolerance["wrist_3_joint"] == 0.1


@pytest.mark.realworld
def test_ur_driver_controllers_take_tf_prefix_from_the_launch_args(ur_controllers: Path) -> None:
    controller = parse_controllers(ur_controllers, {"tf_prefix": "ur_"})["joint_trajectory_controller"]
    assert controller.joints == tuple(f"ur_{j}" for j in UR_JOINTS)
    assert controller.trajectory_tolerance["ur_elbow_joint"] == 0.2


@pytest.mark.realworld
def test_execute_with_the_ur_driver_controllers_file_succeeds(cli: Cli, ur_controllers: Path) -> None:
    code, document = cli.json("execute", PLAN, "--fake", "--controllers", ur_controllers)
    assert code == 0, document
    assert document["result"]["name"] == "SUCCESSFUL"
    assert set(document["margins"]) == set(UR_JOINTS)


# --- a robot config: the xacro args in force ------------------------------------------------------


def test_a_config_substitutes_its_moveplan_yaml_xacro_args(cli: Cli) -> None:
    code, document = cli.json("robot", PREFIXED_ARM)
    assert code == 0, document
    controller = document["controllers"]["arm_controller"]
    assert controller["joints"] == ["left_shoulder_joint", "left_elbow_joint"]
    assert document["groups"]["arm"]["joints"] == controller["joints"]


def test_a_xacro_arg_flag_reaches_the_controller_files(cli: Cli) -> None:
    code, document = cli.json("robot", PREFIXED_ARM, "--xacro-arg", "tf_prefix:=right_")
    assert code == 0, document
    assert document["controllers"]["arm_controller"]["joints"] == ["right_shoulder_joint", "right_elbow_joint"]


def test_a_substituted_default_is_read_as_yaml_reads_it() -> None:
    config = load_robot_config(PREFIXED_ARM)
    assert config.controllers["arm_controller"].goal_time_s == 0.5  # $(var goal_time 0.5): a number
    assert config.execution.allowed_start_tolerance == 0.02  # $(var start_tolerance 0.02)


def test_parse_execution_substitutes_too() -> None:
    execution = parse_execution(PREFIXED_ARM / "moveit_controllers.yaml", {"start_tolerance": "0.05"})
    assert execution.allowed_start_tolerance == 0.05


# --- environment variables --------------------------------------------------------------------------


def test_env_takes_the_variable_else_its_default(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = controllers_file(tmp_path, rate="$(env MOVEPLAN_TEST_RATE 250)")
    monkeypatch.delenv("MOVEPLAN_TEST_RATE", raising=False)
    assert parse_controllers(path)["arm_controller"].update_rate_hz == 250
    monkeypatch.setenv("MOVEPLAN_TEST_RATE", "125")
    assert parse_controllers(path)["arm_controller"].update_rate_hz == 125


def test_an_unset_environment_variable_without_default_is_an_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("MOVEPLAN_TEST_UNSET", raising=False)
    path = controllers_file(tmp_path, rate="$(env MOVEPLAN_TEST_UNSET)")
    with pytest.raises(ConfigError) as error:
        parse_controllers(path)
    assert str(error.value) == (f"{path}: line 3: $(env MOVEPLAN_TEST_UNSET): environment variable "
                                "'MOVEPLAN_TEST_UNSET' is not set, and no default is given")


# --- errors name the user's file, the line and the substitution ---------------------------------------


def test_an_unsupported_substitution_exits_3_naming_the_users_file_and_line(cli: Cli, tmp_path: Path) -> None:
    path = controllers_file(tmp_path, joint_line="$(find-pkg-share ur_description)/j1")
    result = cli("execute", PLAN, "--fake", "--controllers", path)
    assert result.exit_code == 3
    assert one_line(result) == (
        f"moveplan: error: {path}: line 9: $(find-pkg-share ur_description): the 'find-pkg-share' substitution "
        "is not supported; moveplan makes $(var NAME [DEFAULT]) and $(env NAME [DEFAULT]) only")


def test_yaml_broken_by_a_substitution_names_the_users_file_and_line(tmp_path: Path) -> None:
    path = controllers_file(tmp_path)
    with pytest.raises(ConfigError, match=rf"^{path}: line 10 malformed YAML once its launch substitutions are made"):
        parse_controllers(path, {"tf_prefix": "[unclosed "})


@pytest.mark.parametrize(("text", "problem"), [
    ("a: 1\nb: $(var tf_prefix\n", "line 2: $(var tf_prefix: unterminated substitution: expected ')'"),
    ("a: $(var)\n", "line 1: $(var): 'var' takes a name and an optional default, got 0 arguments"),
    ("a: $(var a b c)\n", "line 1: $(var a b c): 'var' takes a name and an optional default, got 3 arguments"),
    ("a: $( var a)\n", "line 1: $( var a): expected a substitution name after '$('"),
    ("a: $(var 'a b)\n", "line 1: $(var 'a b): unterminated quoted argument: expected '"),
])
def test_a_malformed_substitution_is_one_line_naming_the_line(text: str, problem: str) -> None:
    with pytest.raises(ConfigError) as error:
        substitute(text, "params.yaml", {})
    assert str(error.value) == f"params.yaml: {problem}"


# --- the grammar -------------------------------------------------------------------------------------


@pytest.mark.parametrize(("text", "expected"), [
    ("j: $(var tf_prefix)elbow_joint", "j: ur_elbow_joint"),
    ("j: $(var missing)elbow_joint", "j: elbow_joint"),
    ("j: $(var missing left_)elbow_joint", "j: left_elbow_joint"),
    ("j: \"$(var missing 'a b')\"", 'j: "a b"'),
    ("j: $(var missing $(var tf_prefix))", "j: ur_"),
    ("j: \\$(var tf_prefix)", "j: $(var tf_prefix)"),
    ("# $(var tf_prefix) in a comment", "# ur_ in a comment"),
    ("price: $5", "price: $5"),
])
def test_var_substitutions_follow_the_launch_grammar(text: str, expected: str) -> None:
    assert substitute(text, "params.yaml", {"tf_prefix": "ur_"}) == expected
