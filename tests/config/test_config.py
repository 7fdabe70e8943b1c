"""Loading rules of robot configs: which files a folder supplies, package lookup, xacro, embedding."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import yaml
from conftest import ROOT, UR10E, Cli

from moveplan.core import bag as recording
from moveplan.core.collision.checker import CollisionChecker
from moveplan.core.config.robot_config import RobotConfig, load_robot_config
from moveplan.core.config.sources import resolve_config_path, search_path
from moveplan.core.config.xacro import PackagePath, parse_xacro_args
from moveplan.core.errors import ConfigError, UnknownName, UsageError
from moveplan.core.model.robot import Robot

PANDA = ROOT / "configs" / "panda"
MBM_PANDA = ROOT / "tests" / "data" / "mbm" / "panda_robot"

URDF = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/><link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="tip"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
</robot>
"""
SRDF = """<?xml version="1.0"?>
<robot name="arm">
  <group name="{group}"><joint name="j1"/></group>
  <group name="other"><joint name="j1"/></group>
  <group_state name="zero" group="{group}"><joint name="j1" value="0"/></group_state>
</robot>
"""
LIMITS = "joint_limits:\n  j1: {has_acceleration_limits: true, max_acceleration: 3.0}\n"


def write(folder: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    return folder


def plain(folder: Path, **extra: str) -> Path:
    return write(folder, {"arm.urdf": URDF, "arm.srdf": SRDF.format(group="arm"), **extra})


@pytest.fixture(scope="module")
def panda_config() -> RobotConfig:
    return load_robot_config(PANDA)


# --- moveplan.yaml configs --------------------------------------------------------------------


def test_shipped_config_embeds_its_own_files_under_the_names_it_gives() -> None:
    config = load_robot_config(UR10E)
    assert config.files["moveplan.yaml"] == (UR10E / "moveplan.yaml").read_bytes()
    assert set(config.files) == {"moveplan.yaml", "ur10e.urdf", "ur10e.srdf", "joint_limits.yaml",
                                 "ros2_controllers.yaml", "moveit_controllers.yaml", "initial_positions.yaml"}


def test_sources_name_the_file_of_each_setting() -> None:
    config = load_robot_config(UR10E)
    assert {k: v.name for k, v in config.sources.items()} == {
        "moveplan": "moveplan.yaml", "urdf": "ur10e.urdf", "srdf": "ur10e.srdf",
        "joint_limits": "joint_limits.yaml", "controllers": "ros2_controllers.yaml",
        "moveit_controllers": "moveit_controllers.yaml", "initial_positions": "initial_positions.yaml",
        "planning": "moveplan.yaml",
    }
    assert config.urdf_includes == (UR10E / "ur10e.urdf",)


def test_moveplan_yaml_may_name_a_xacro_with_args_that_a_flag_overrides(tmp_path: Path) -> None:
    xacro = URDF.replace('<robot name="arm">', '<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                         '<xacro:arg name="reach" default="1"/>').replace('upper="1"', 'upper="$(arg reach)"')
    folder = write(tmp_path, {"arm.urdf.xacro": xacro, "arm.srdf": SRDF.format(group="arm"),
                              "moveplan.yaml": "urdf: arm.urdf.xacro\nsrdf: arm.srdf\nxacro_args: {reach: 2}\n"})
    assert load_robot_config(folder).limits["j1"].upper == 2.0
    flagged = load_robot_config(folder, xacro_args={"reach": "0.5"})
    assert flagged.limits["j1"].upper == 0.5 and flagged.xacro_args == {"reach": "0.5"}
    embedded = yaml.safe_load(flagged.files["moveplan.yaml"])
    assert embedded["urdf"] == "arm.urdf" and b"upper=\"0.5\"" in flagged.files["arm.urdf"]


def test_unknown_xacro_arg_in_moveplan_yaml_is_a_config_error(tmp_path: Path) -> None:
    folder = plain(tmp_path, **{"moveplan.yaml": "urdf: arm.urdf\nsrdf: arm.srdf\nxacro_args: {reach: 2}\n"})
    with pytest.raises(ConfigError, match=r"xacro_args: xacro arg 'reach' given, but .*arm.urdf and .*are not"):
        load_robot_config(folder)


def test_unknown_xacro_arg_flag_is_a_usage_error(tmp_path: Path) -> None:
    with pytest.raises(UsageError, match=r"--xacro-arg reach: xacro arg 'reach' given, but .*arm.urdf and .*are not"):
        load_robot_config(plain(tmp_path), xacro_args={"reach": "2"})


def test_xacro_arg_flags_parse_as_ros2_launch_writes_them() -> None:
    assert parse_xacro_args(["a:=1", "b:=x:=y", "c:="]) == {"a": "1", "b": "x:=y", "c": ""}
    with pytest.raises(UsageError, match="name:=value"):
        parse_xacro_args(["a=1"])


# --- folders without moveplan.yaml ------------------------------------------------------------


def test_plain_folder_with_urdf_srdf_and_joint_limits_loads(tmp_path: Path) -> None:
    config = load_robot_config(plain(tmp_path, **{"joint_limits.yaml": LIMITS}))
    assert config.name == "arm"
    assert config.planning == {"group": "arm", "planner": "RRTConnect", "planning_time": 1.0, "collision": "exact"}
    assert config.limits["j1"].max_acceleration == 3.0
    assert config.sources["planning"] == tmp_path / "arm.srdf"
    assert "moveplan" not in config.sources and "controllers" not in config.sources


def test_a_folder_without_any_srdf_names_what_it_looked_for(tmp_path: Path) -> None:
    write(tmp_path, {"arm.urdf": URDF})
    with pytest.raises(ConfigError, match=r"no moveplan.yaml, and no \*.srdf in config/, srdf/"):
        resolve_config_path(tmp_path)


def test_files_in_config_win_over_files_beside_it(tmp_path: Path) -> None:
    plain(tmp_path, **{"joint_limits.yaml": LIMITS, "config/joint_limits.yaml": LIMITS.replace("3.0", "4.0"),
                       "config/arm.srdf": SRDF.format(group="arm")})
    config = load_robot_config(tmp_path)
    assert config.sources["srdf"] == tmp_path / "config" / "arm.srdf"
    assert config.limits["j1"].max_acceleration == 4.0


def test_several_urdfs_pick_the_one_named_like_the_srdf(tmp_path: Path) -> None:
    plain(tmp_path, **{"other.urdf": URDF})
    assert load_robot_config(tmp_path).sources["urdf"] == tmp_path / "arm.urdf"


def test_several_urdfs_none_named_like_the_srdf_ask_for_a_moveplan_yaml(tmp_path: Path) -> None:
    write(tmp_path, {"a.urdf": URDF, "b.urdf": URDF, "arm.srdf": SRDF.format(group="arm")})
    with pytest.raises(ConfigError, match=r"several URDF files \(a.urdf, b.urdf\); write a moveplan.yaml"):
        load_robot_config(tmp_path)


def test_ompl_planning_chooses_group_and_default_planner(tmp_path: Path) -> None:
    ompl = ("planner_configs:\n  PRMkConfigDefault: {type: geometric::PRM}\n"
            "other:\n  default_planner_config: PRMkConfigDefault\n")
    config = load_robot_config(plain(tmp_path, **{"config/ompl_planning.yaml": ompl}))
    assert config.planning["group"] == "other" and config.planning["planner"] == "PRM"
    assert config.sources["planning"] == tmp_path / "config" / "ompl_planning.yaml"


def test_ompl_group_without_default_planner_gets_rrtconnect_as_in_moveit(tmp_path: Path) -> None:
    config = load_robot_config(plain(tmp_path, **{"ompl_planning.yaml": "other:\n  planner_configs: []\n"}))
    assert config.planning["group"] == "other" and config.planning["planner"] == "RRTConnect"


def test_kinematics_yaml_is_read_and_its_groups_checked(tmp_path: Path) -> None:
    solver = "arm:\n  kinematics_solver: kdl_kinematics_plugin/KDLKinematicsPlugin\n"
    config = load_robot_config(plain(tmp_path, **{"kinematics.yaml": solver}))
    assert config.kinematics["arm"]["kinematics_solver"].startswith("kdl")
    (tmp_path / "kinematics.yaml").write_text(solver.replace("arm:", "amr:"))
    with pytest.raises(UnknownName, match=r"group 'amr' not found in .*kinematics.yaml"):
        load_robot_config(tmp_path)


def test_missing_acceleration_limits_are_listed_by_joint_and_take_the_default(tmp_path: Path) -> None:
    config = load_robot_config(plain(tmp_path))
    assert config.missing_acceleration_limits() == ("j1",)
    assert config.limits["j1"].source["acceleration"] == "default" and config.limits["j1"].max_acceleration == 1.0


# --- packages ---------------------------------------------------------------------------------


def test_a_package_is_found_by_the_name_its_package_xml_gives(tmp_path: Path) -> None:
    write(tmp_path, {"src/repo/Description_Repo/package.xml": "<package><name>arm_description</name></package>"})
    found = PackagePath((tmp_path / "src",)).find("arm_description", "test")
    assert found == (tmp_path / "src" / "repo" / "Description_Repo").resolve()


def test_the_first_search_folder_holding_the_package_wins(tmp_path: Path) -> None:
    (tmp_path / "a" / "pkg").mkdir(parents=True)
    (tmp_path / "b" / "pkg").mkdir(parents=True)
    packages = PackagePath((tmp_path / "b", tmp_path / "a"))
    assert packages.find("pkg", "test") == (tmp_path / "b" / "pkg").resolve()


def test_a_missing_package_names_the_source_package_and_search_path(tmp_path: Path) -> None:
    packages = PackagePath((tmp_path / "one", tmp_path / "two"))
    with pytest.raises(ConfigError, match=rf"robot.xacro: package 'nope' not found; searched in order: "
                                          rf"{tmp_path}/one, {tmp_path}/two"):
        packages.find("nope", "robot.xacro")


def test_ros_package_path_comes_after_package_path_flags(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"{tmp_path / 'env1'}:{tmp_path / 'env2'}")
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    folders = search_path(tmp_path / "config", (tmp_path / "flag",), (tmp_path / "yaml",))
    assert folders[:5] == (tmp_path / "config", tmp_path / "yaml", tmp_path / "flag", tmp_path / "env1",
                           tmp_path / "env2")


def test_xacro_find_resolves_packages_on_the_package_path(tmp_path: Path) -> None:
    include = ('<robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
               '<xacro:macro name="arm">' + URDF.split('<robot name="arm">')[1].split("</robot>")[0] +
               "</xacro:macro></robot>")
    write(tmp_path, {"lib/arm_description/urdf/arm.xacro": include,
                     "cfg/config/arm.urdf.xacro": '<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                     '<xacro:include filename="$(find arm_description)/urdf/arm.xacro"/><xacro:arm/></robot>',
                     "cfg/config/arm.srdf": SRDF.format(group="arm")})
    with pytest.raises(ConfigError, match=r"arm.urdf.xacro: \$\(find arm_description\): package 'arm_description' "
                                          r"not found; searched in order: "):
        load_robot_config(tmp_path / "cfg")
    config = load_robot_config(tmp_path / "cfg", (tmp_path / "lib",))
    assert list(config.urdf_joints) == ["j1"]
    assert config.urdf_includes[1] == (tmp_path / "lib/arm_description/urdf/arm.xacro").resolve()


# --- the mbm Panda folder and configs/panda ---------------------------------------------------


def test_the_motionbenchmaker_panda_folder_loads_without_moveplan_yaml() -> None:
    config = load_robot_config(MBM_PANDA)
    assert config.planning["group"] == "panda_arm" and config.missing_acceleration_limits() == ()
    assert config.sources["joint_limits"] == MBM_PANDA / "joint_limits.yaml"
    # Mesh paths come resolved (symlinks followed), as pinocchio is given them.
    assert config.collision_meshes()[0].path == (MBM_PANDA / "meshes" / "collision" / "link0.obj").resolve()


def test_panda_urdf_and_meshes_come_from_example_robot_data(panda_config: RobotConfig) -> None:
    assert panda_config.sources["urdf"].parts[-5:] == ("example-robot-data", "robots", "panda_description",
                                                       "urdf", "panda.urdf")
    meshes = panda_config.collision_meshes()
    assert {m.link for m in meshes} >= {f"panda_link{i}" for i in range(8)} | {"panda_hand"}
    assert all(m.package == "example-robot-data" and m.path.suffix == ".stl" and m.path.is_file() for m in meshes)


def test_panda_limits_are_franka_published_ones(panda_config: RobotConfig) -> None:
    acceleration = [panda_config.limits[f"panda_joint{i}"].max_acceleration for i in range(1, 8)]
    assert acceleration == [3.75, 1.875, 2.5, 3.125, 3.75, 5.0, 5.0]
    assert panda_config.limits["panda_joint4"].upper == pytest.approx(-0.0698)
    assert panda_config.missing_acceleration_limits("hand") == ("panda_finger_joint1",)


def test_panda_named_states_are_free_of_self_collision_with_meshes(panda_config: RobotConfig) -> None:
    robot = Robot(panda_config)
    checker = CollisionChecker(robot)
    assert len(checker.geometry.geometryObjects) == 9 + 8  # link0-7 and hand meshes, four boxes per finger
    for name in ("ready", "extended", "transport"):
        values = [panda_config.srdf.group_states["panda_arm"][name][j] for j in robot.joint_names]
        assert checker.colliding_pair(robot.configuration(values)) is None, name
    wrist_on_shoulder = robot.configuration([-0.29, 1.04, -1.56, -2.92, -0.55, 0.73, -2.37])
    assert checker.colliding_pair(wrist_on_shoulder) == ("panda_link1", "panda_link7")


def test_panda_srdf_disables_example_robot_data_pairs(panda_config: RobotConfig) -> None:
    pairs = panda_config.srdf.disabled_pairs
    assert len(pairs) == 35 and frozenset(("panda_hand", "panda_link5")) in pairs


def test_panda_plan_embeds_the_urdf_and_a_generated_moveplan_yaml(panda_config: RobotConfig, tmp_path: Path) -> None:
    for name, data in panda_config.files.items():
        (tmp_path / name).write_bytes(data)
    generated = yaml.safe_load(panda_config.files["moveplan.yaml"])
    assert generated["urdf"] == "panda.urdf" and generated["planning"]["group"] == "panda_arm"
    again = load_robot_config(tmp_path)
    assert again.urdf == panda_config.urdf and again.limits == panda_config.limits
    assert again.srdf == panda_config.srdf


def test_a_config_copied_elsewhere_loads_the_same(tmp_path: Path) -> None:
    shutil.copytree(PANDA, tmp_path / "panda")
    assert load_robot_config(tmp_path / "panda").urdf == load_robot_config(PANDA).urdf


def test_robot_command_shows_the_panda_by_name(cli: Cli) -> None:
    code, document = cli.json("robot", "panda")
    assert code == 0, document
    assert list(document["groups"]) == ["panda_arm", "hand", "panda_arm_hand"]
    finger = document["joints"]["panda_finger_joint1"]
    assert finger["max_acceleration"] == 1.0 and finger["source"]["acceleration"] == "default"
    assert document["named_states"]["panda_arm"]["ready"][3] == -2.356


def test_plan_on_the_panda_reaches_a_named_state_around_its_meshes(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "p.mcap"
    code, document = cli.json("plan", "--robot", PANDA, "--start-named", "transport", "--named", "ready",
                              "--seed", 1, "-o", out)
    assert code == 0, document
    assert document["group"] == "panda_arm" and document["steps"][0]["duration_s"] > 0
    assert "panda.urdf" in recording.read_plan(out).attachments


# --- the simulated hardware a config carries (moveplan.yaml `plant`) ----------------------------

def _excavator(tmp_path: Path, plant: str) -> Path:
    folder = tmp_path / "excavator"
    shutil.copytree(ROOT / "configs" / "excavator", folder)
    manifest = folder / "moveplan.yaml"
    text = "\n".join(line for line in manifest.read_text().splitlines() if not line.startswith("plant:"))
    manifest.write_text(f"{text}\n{plant}\n")
    return folder


def test_a_configs_plant_is_read_and_embedded_with_the_plan(tmp_path: Path) -> None:
    config = load_robot_config(ROOT / "configs" / "excavator")
    assert config.plant is not None and config.plant.model == "pid"
    assert config.plant.params == {"drive_tau": 0.06, "load": 0.03, "noise": 0.0002}
    assert b"plant:" in config.files["moveplan.yaml"]


@pytest.mark.parametrize(("plant", "message"), [
    ("plant: {model: hydraulic}", r"plant.model: unknown plant 'hydraulic'; known: lag, mirror, pid"),
    ("plant: {model: pid, drive_tau: fast}", r"plant.drive_tau: expected a finite number"),
    ("plant: [pid]", r"plant: expected a mapping"),
])
def test_a_malformed_plant_is_a_config_error_naming_the_key(tmp_path: Path, plant: str, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        load_robot_config(_excavator(tmp_path, plant))


def test_a_plant_parameter_its_model_does_not_take_names_the_config(tmp_path: Path, cli: Cli) -> None:
    folder = _excavator(tmp_path, "plant: {model: pid, drive_lag: 0.1}")
    plan = tmp_path / "plan.mcap"
    assert cli("plan", "--robot", folder, "--named", "ready", "-o", plan, "-q").exit_code == 0
    result = cli("execute", plan, "--fake")
    assert result.exit_code == 3 and result.stderr.count("\n") == 1, result.stderr
    assert "moveplan.yaml: plant: plant 'pid' has no parameter 'drive_lag'" in result.stderr
    assert cli("execute", plan, "--fake", "--plant", "mirror").exit_code == 0  # another model: its params only
