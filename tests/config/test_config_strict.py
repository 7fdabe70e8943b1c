"""Strict config files: unknown controller keys and non-boolean flags are errors naming file and key."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import yaml
from conftest import ROOT, Cli

from moveplan.core.config.controllers import parse_controllers, parse_execution
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.errors import ConfigError

# Controller files of real MoveIt config packages, unchanged (sources in the folder's README).
REALWORLD = Path(__file__).parents[1] / "data" / "realworld_controllers"

URDF = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/><link name="mid"/><link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="mid"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="mid"/><child link="tip"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
</robot>
"""
SRDF = """<?xml version="1.0"?>
<robot name="arm"><group name="arm"><joint name="j1"/><joint name="j2"/></group></robot>
"""


def controllers_yaml(params: dict[str, object], kind: str = "joint_trajectory_controller/JointTrajectoryController",
                     **others: dict[str, object]) -> str:
    manager: dict[str, object] = {"update_rate": 100, "arm_controller": {"type": kind}}
    manager.update({name: {"type": f"some_package/{name}"} for name in others})
    document: dict[str, object] = {
        "controller_manager": {"ros__parameters": manager},
        "arm_controller": {"ros__parameters": {"joints": ["j1", "j2"], **params}},
    }
    document.update({name: {"ros__parameters": p} for name, p in others.items()})
    return yaml.safe_dump(document)


def write_controllers(folder: Path, params: dict[str, object], **others: dict[str, object]) -> Path:
    path = folder / "ros2_controllers.yaml"
    path.write_text(controllers_yaml(params, **others))
    return path


def robot_folder(folder: Path, controllers: str = "", **files: str) -> Path:
    (folder / "arm.urdf").write_text(URDF)
    (folder / "arm.srdf").write_text(SRDF)
    if controllers:
        (folder / "ros2_controllers.yaml").write_text(controllers)
    for name, text in files.items():
        (folder / name).write_text(text)
    return folder


# --- unknown keys in a JointTrajectoryController ----------------------------------------------


def test_a_typo_in_a_joint_constraint_names_file_and_key_path(tmp_path: Path) -> None:
    path = write_controllers(tmp_path, {"constraints": {"j1": {"trajectroy": 0.1, "goal": 0.05}}})
    with pytest.raises(ConfigError, match=r"ros2_controllers.yaml: arm_controller.ros__parameters.constraints.j1: "
                                          r"unknown key 'trajectroy'; expected one of: .*trajectory"):
        parse_controllers(path)


def test_constraints_for_a_joint_the_controller_does_not_have_are_an_error(tmp_path: Path) -> None:
    path = write_controllers(tmp_path, {"constraints": {"j3": {"trajectory": 0.1}, "goal_time": 1.0}})
    with pytest.raises(ConfigError, match=r"arm_controller.ros__parameters.constraints: unknown key 'j3'; "
                                          r"expected one of: .*j1, j2"):
        parse_controllers(path)


def test_a_typo_in_a_constraint_setting_is_an_error(tmp_path: Path) -> None:
    path = write_controllers(tmp_path, {"constraints": {"stopped_velocity_tolerence": 0.1}})
    with pytest.raises(ConfigError, match=r"constraints: unknown key 'stopped_velocity_tolerence'"):
        parse_controllers(path)


def test_a_typo_in_gains_names_file_and_key_path(tmp_path: Path) -> None:
    path = write_controllers(tmp_path, {"gains": {"j1": {"p": 10.0, "ff_velocity_scal": 1.0}}})
    with pytest.raises(ConfigError, match=r"ros2_controllers.yaml: arm_controller.ros__parameters.gains.j1: "
                                          r"unknown key 'ff_velocity_scal'"):
        parse_controllers(path)


def test_gains_for_a_joint_the_controller_does_not_have_are_an_error(tmp_path: Path) -> None:
    path = write_controllers(tmp_path, {"gains": {"j_1": {"p": 10.0}}})
    with pytest.raises(ConfigError, match=r"arm_controller.ros__parameters.gains: unknown key 'j_1'"):
        parse_controllers(path)


def test_a_parameter_the_controller_does_not_declare_is_ignored_with_a_warning_naming_the_nearest(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    # ros2_control ignores an override a controller does not declare (rclcpp's undeclared parameters);
    # Interbotix's files still carry Foxy's interface_name.
    path = write_controllers(tmp_path, {"allow_partial_joint_goal": True, "interface_name": "position"})
    assert set(parse_controllers(path)) == {"arm_controller"}
    messages = [r.getMessage() for r in caplog.records]
    assert any("arm_controller.ros__parameters: unknown parameter 'allow_partial_joint_goal' ignored" in m
               and "did you mean 'allow_partial_joints_goal'" in m for m in messages)
    assert any("interface_name is ignored" in m for m in messages)


def test_strict_refuses_a_parameter_the_controller_does_not_declare(tmp_path: Path, cli: Cli) -> None:
    path = write_controllers(tmp_path, {"allow_partial_joint_goal": True})
    with pytest.raises(ConfigError, match=r"unknown parameter 'allow_partial_joint_goal' \(did you mean "
                                          r"'allow_partial_joints_goal'\?\): the controller does not declare it; "
                                          r"--strict refuses it"):
        parse_controllers(path, strict=True)
    (tmp_path / "robot").mkdir()
    folder = robot_folder(tmp_path / "robot", path.read_text())
    assert cli("robot", folder).exit_code == 0
    result = cli("robot", folder, "--strict")
    assert result.exit_code == 3 and result.stderr.count("\n") == 1, result.stderr
    assert "--strict refuses it" in result.stderr


def test_several_wildcard_blocks_and_a_namespace_merge_as_rcl_reads_them(tmp_path: Path) -> None:
    # Franka's fr3_ros_controllers.yaml repeats `/**:`; Interbotix's wraps everything in `/wx250s:`.
    path = tmp_path / "ros2_controllers.yaml"
    path.write_text("/**:\n  controller_manager:\n    ros__parameters:\n      update_rate: 500\n"
                    "      arm_controller: {type: joint_trajectory_controller/JointTrajectoryController}\n"
                    "/**:\n  arm_controller:\n    ros__parameters:\n      joints: [j1, j2]\n"
                    "      command_interfaces: [position]\n      state_interfaces: [position]\n")
    controller = parse_controllers(path)["arm_controller"]
    assert controller.joints == ("j1", "j2") and controller.update_rate_hz == 500.0
    path.write_text("/robot:\n  controller_manager:\n    ros__parameters:\n"
                    "      arm_controller: {type: joint_trajectory_controller/JointTrajectoryController}\n"
                    "  arm_controller:\n    ros__parameters:\n      joints: [j1]\n"
                    "      command_interfaces: [position]\n      state_interfaces: [position]\n")
    assert parse_controllers(path)["arm_controller"].joints == ("j1",)


def test_a_typo_under_speed_scaling_is_an_error(tmp_path: Path) -> None:
    path = write_controllers(tmp_path, {"speed_scaling": {"state_interfaces": "speed_scaling/factor"}})
    with pytest.raises(ConfigError, match=r"ros__parameters.speed_scaling: unknown key 'state_interfaces'"):
        parse_controllers(path)


def test_a_controller_typo_exits_3_naming_file_and_key(cli: Cli, tmp_path: Path) -> None:
    folder = robot_folder(tmp_path, controllers_yaml({"constraints": {"j2": {"trajectroy": 0.1}}}))
    result = cli("robot", folder)
    assert result.exit_code == 3
    assert "ros2_controllers.yaml" in result.stderr and "constraints.j2: unknown key 'trajectroy'" in result.stderr


# --- what a JointTrajectoryController accepts --------------------------------------------------


def test_every_parameter_of_some_jtc_release_loads(tmp_path: Path) -> None:
    params = {
        "command_joints": ["j1", "j2"], "command_interfaces": ["velocity"],
        "state_interfaces": ["position", "velocity"], "allow_partial_joints_goal": False,
        "open_loop_control": False, "interpolate_from_desired_state": False,
        "allow_integration_in_goal_trajectories": False,
        "set_last_command_interface_value_as_state_on_activation": True,
        "state_publish_rate": 50.0, "action_monitor_rate": 20.0, "interpolation_method": "splines",
        "allow_nonzero_velocity_at_trajectory_end": True, "cmd_timeout": 0.0, "start_with_holding": True,
        "speed_scaling": {"initial_scaling_factor": 1.0, "state_interface": "", "command_interface": ""},
        "update_rate": 100, "is_async": False, "use_sim_time": False,
        "type": "joint_trajectory_controller/JointTrajectoryController",
        "constraints": {"stopped_velocity_tolerance": 0.05, "goal_time": 0.5, "decelerate_on_cancel": False,
                        "j1": {"trajectory": 0.2, "goal": 0.1, "max_deceleration_on_cancel": 1.0}},
        "gains": {
            "j1": {"p": 5.0, "i": 0.1, "d": 0.2, "i_clamp": 0.3, "ff_velocity_scale": 1.0, "angle_wraparound": False,
                   "normalize_error": False, "antiwindup": True},
            "j2": {"p": 5.0, "i_clamp_max": 1.0, "i_clamp_min": -1.0, "u_clamp_max": 2.0, "u_clamp_min": -2.0,
                   "antiwindup_strategy": "back_calculation", "tracking_time_constant": 0.0, "error_deadband": 0.0},
        },
    }
    controller = parse_controllers(write_controllers(tmp_path, params))["arm_controller"]
    assert controller.trajectory_tolerance == {"j1": 0.2, "j2": 0.0}
    assert controller.goal_time_s == 0.5 and controller.stopped_velocity_tolerance == 0.05
    assert controller.gains["j1"] == {"p": 5.0, "i": 0.1, "d": 0.2, "i_clamp": 0.3, "ff_velocity_scale": 1.0}
    assert set(controller.gains["j2"]) == {"p", "i_clamp_max", "i_clamp_min", "u_clamp_max", "u_clamp_min",
                                           "tracking_time_constant", "error_deadband"}


def test_a_gain_flag_must_be_a_yaml_boolean(tmp_path: Path) -> None:
    path = write_controllers(tmp_path, {"gains": {"j1": {"p": 1.0, "angle_wraparound": "true"}}})
    with pytest.raises(ConfigError, match=r"gains.j1.angle_wraparound: expected true or false, got 'true'"):
        parse_controllers(path)


def test_the_scaled_jtc_accepts_its_own_parameters_and_the_plain_one_ignores_them(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    params = {"speed_scaling_interface_name": "speed_scaling/speed_scaling_factor"}
    path = tmp_path / "ros2_controllers.yaml"
    path.write_text(controllers_yaml(params, kind="ur_controllers/ScaledJointTrajectoryController"))
    assert set(parse_controllers(path)) == {"arm_controller"}
    with caplog.at_level("WARNING"):
        parse_controllers(write_controllers(tmp_path, params))
    assert "unknown parameter 'speed_scaling_interface_name' ignored" in caplog.text


def test_other_controllers_keep_their_own_keys(tmp_path: Path) -> None:
    path = write_controllers(
        tmp_path, {},
        gripper_controller={"joint": "finger", "allow_stalling": True, "stall_timeout": 0.05, "goal_tolerance": 0.02},
        joint_state_broadcaster={"interfaces": ["position"], "anything": {"nested": 1}},
    )
    assert set(parse_controllers(path)) == {"arm_controller"}


SHIPPED = sorted(
    [*ROOT.glob("configs/*/ros2_controllers.yaml"), *ROOT.glob("samples/**/*controllers.yaml"),
     *ROOT.glob("tests/data/**/ros2_controllers.yaml")],
)
SHIPPED = [p for p in SHIPPED if "moveit_controllers" not in p.name]


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: str(p.relative_to(ROOT)))
def test_the_repository_controller_files_load(path: Path) -> None:
    assert parse_controllers(path)


REALWORLD_FILES = [
    "Universal_Robots_ROS2_Driver/ur_robot_driver/config/ur_controllers.yaml",
    "moveit_resources/panda_moveit_config/config/ros2_controllers.yaml",
    "moveit_resources/fanuc_moveit_config/config/ros2_controllers.yaml",
    "moveit_resources/dual_arm_panda_moveit_config/config/ros2_controllers.yaml",
    "ros2_kortex/kortex_description/arms/gen3/7dof/config/ros2_controllers.yaml",
    "ros2_kortex/kortex_description/arms/gen3_lite/6dof/config/ros2_controllers.yaml",
    "ros2_kortex/kortex_moveit_config/kinova_gen3_7dof_robotiq_2f_85_moveit_config/config/ros2_controllers.yaml",
    "ros2_kortex/kortex_moveit_config/kinova_gen3_lite_moveit_config/config/ros2_controllers.yaml",
    "ros2_robotiq_gripper/robotiq_description/config/robotiq_controllers.yaml",
]


@pytest.mark.parametrize("name", REALWORLD_FILES)
def test_real_world_controller_files_load(name: str) -> None:
    controllers = parse_controllers(REALWORLD / name)
    assert all(c.joints for c in controllers.values())


def test_ur_driver_controllers_substitute_the_tf_prefix_in_joint_names() -> None:
    path = REALWORLD / "Universal_Robots_ROS2_Driver/ur_robot_driver/config/ur_controllers.yaml"
    controller = parse_controllers(path)["joint_trajectory_controller"]
    assert controller.trajectory_tolerance["elbow_joint"] == 0.2


# --- YAML booleans --------------------------------------------------------------------------------


def write_execution(folder: Path, value: str) -> Path:
    path = folder / "moveit_controllers.yaml"
    path.write_text(f"trajectory_execution:\n  execution_duration_monitoring: {value}\n")
    return path


def test_unquoted_false_turns_execution_duration_monitoring_off(tmp_path: Path) -> None:
    assert parse_execution(write_execution(tmp_path, "false")).execution_duration_monitoring is False
    assert parse_execution(write_execution(tmp_path, "true")).execution_duration_monitoring is True


@pytest.mark.parametrize("value", ['"false"', "0", "off-ish"])
def test_a_non_boolean_execution_duration_monitoring_is_an_error(tmp_path: Path, value: str) -> None:
    path = write_execution(tmp_path, value)
    with pytest.raises(ConfigError, match=r"moveit_controllers.yaml: trajectory_execution."
                                          r"execution_duration_monitoring: expected true or false"):
        parse_execution(path)


def test_a_quoted_false_in_joint_limits_is_an_error_not_true(tmp_path: Path) -> None:
    limits = 'joint_limits:\n  j1: {has_velocity_limits: "false", max_velocity: 9.0}\n'
    folder = robot_folder(tmp_path, **{"joint_limits.yaml": limits})
    with pytest.raises(ConfigError, match=r"joint_limits.yaml: joint_limits.j1.has_velocity_limits: "
                                          r"expected true or false, got 'false'"):
        load_robot_config(folder)


def test_unquoted_false_in_joint_limits_keeps_the_urdf_limit(tmp_path: Path) -> None:
    limits = "joint_limits:\n  j1: {has_velocity_limits: false, max_velocity: 9.0}\n"
    config = load_robot_config(robot_folder(tmp_path, **{"joint_limits.yaml": limits}))
    assert config.limits["j1"].max_velocity == 2.0 and config.limits["j1"].source["velocity"] == "arm.urdf"


def test_a_quoted_false_in_moveit_controllers_exits_3(cli: Cli, tmp_path: Path) -> None:
    text = 'trajectory_execution:\n  execution_duration_monitoring: "false"\n'
    result = cli("robot", robot_folder(tmp_path, **{"moveit_controllers.yaml": text}))
    assert result.exit_code == 3
    assert "moveit_controllers.yaml: trajectory_execution.execution_duration_monitoring" in result.stderr


@pytest.mark.parametrize(("manager_key", "controller_key"), [
    ("/robot/controller_manager", "/robot/arm_controller"),  # launched in a namespace
    ("/**/controller_manager", "/**/arm_controller"),
    ("/**", "arm_controller"),  # one wildcard section for every node
])
def test_namespaced_and_wildcard_parameter_sections_configure_the_controllers(
    tmp_path: Path, manager_key: str, controller_key: str
) -> None:
    manager = {"update_rate": 250, "arm_controller": {"type": "joint_trajectory_controller/JointTrajectoryController"}}
    arm = {"joints": ["j1", "j2"], "command_interfaces": ["position"], "state_interfaces": ["position"],
           "constraints": {"j1": {"goal": 0.02}}}
    sections = {manager_key: {"ros__parameters": manager}}
    if controller_key == manager_key:
        manager.update(arm)
    else:
        sections[controller_key] = {"ros__parameters": arm}
    if manager_key == "/**":
        sections = {"/**": {"ros__parameters": manager}, "arm_controller": {"ros__parameters": arm}}
    path = tmp_path / "ros2_controllers.yaml"
    path.write_text(yaml.safe_dump(sections))
    controller = parse_controllers(path)["arm_controller"]
    assert controller.update_rate_hz == 250 and controller.joints == ("j1", "j2")
    assert controller.goal_tolerance["j1"] == 0.02


def test_a_controller_joint_the_urdf_lacks_exits_3_naming_the_file_controller_and_joint(
    cli: Cli, tmp_path: Path
) -> None:
    shutil.copytree(ROOT / "configs" / "ur10e", tmp_path / "ur10e")
    path = tmp_path / "ur10e" / "ros2_controllers.yaml"
    path.write_text(path.read_text().replace("- shoulder_pan_joint", "- shoulder_pan_jiont", 1)
                    .replace("      shoulder_pan_joint: {", "      shoulder_pan_jiont: {"))
    result = cli("plan", "--robot", tmp_path / "ur10e", "--named", "home", "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3, result.stderr
    line = result.stderr.strip()
    assert "\n" not in line and "joint 'shoulder_pan_jiont' not found" in line and "ros2_controllers.yaml" in line
    assert not (tmp_path / "p.mcap").exists()


def test_a_controller_file_without_a_manager_takes_its_types_from_the_launch_file_that_spawns_it(
        tmp_path: Path) -> None:
    # PAL's TIAGo: config/arm_controller.yaml holds one controller; launch/arm_controller.launch.py hands the
    # spawner its type. The launch file is parsed, never run.
    package = tmp_path / "robot_controller_configuration"
    (package / "config").mkdir(parents=True)
    (package / "launch").mkdir()
    (package / "package.xml").write_text("<package><name>robot_controller_configuration</name></package>")
    params = package / "config" / "arm_controller.yaml"
    params.write_text("arm_controller:\n  ros__parameters:\n    joints: [j1, j2]\n    command_interfaces: [position]\n"
                      "    state_interfaces: [position]\n    constraints: {goal_time: 0.6, j1: {goal: 0.02}}\n")
    (package / "launch" / "arm_controller.launch.py").write_text(
        "import os\nraise SystemExit('a launch file is parsed, never run')\n"
        "def generate_launch_description():\n"
        "    return generate_load_controller_launch_description(controller_name='arm_controller',\n"
        "        controller_type='joint_trajectory_controller/JointTrajectoryController',\n"
        "        controller_params_file=os.path.join(pkg, 'config', 'arm_controller.yaml'))\n")
    controller = parse_controllers(params)["arm_controller"]
    assert controller.joints == ("j1", "j2") and controller.goal_time_s == 0.6
    assert controller.goal_tolerance["j1"] == 0.02
    (package / "launch" / "arm_controller.launch.py").write_text("def broken(:\n")
    assert parse_controllers(params) == {}
