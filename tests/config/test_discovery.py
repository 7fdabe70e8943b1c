"""MoveIt config packages loaded as they are: the workspace's packages, .setup_assistant, --urdf/--srdf, lone files."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import yaml
from conftest import REALWORLD, ROOT, UR10E, Cli

from moveplan.core import bag as recording
from moveplan.core.config._setup_assistant import read_setup_assistant
from moveplan.core.config._workspace import packages_under, workspace_src
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.config.sources import discover, search_path
from moveplan.core.config.xacro import PackagePath
from moveplan.core.errors import ConfigError, UsageError

FANUC = "moveit_resources/fanuc_moveit_config"
PANDA = "moveit_resources/panda_moveit_config"
GEN3_LITE = "ros2_kortex/kortex_moveit_config/kinova_gen3_lite_moveit_config"
GEN3 = "ros2_kortex/kortex_moveit_config/kinova_gen3_7dof_robotiq_2f_85_moveit_config"
ABB = "abb_ros2/robot_specific_config/abb_irb1200_5_90_moveit_config"
UR = "Universal_Robots_ROS2_Driver/ur_moveit_config"
UR_ARGS = ("--urdf", "package://ur_description/urdf/ur.urdf.xacro", "--xacro-arg", "ur_type:=ur5e",
           "--xacro-arg", "name:=ur")
MBM = ROOT / "tests" / "data" / "mbm"

URDF = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/><link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="tip"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
</robot>
"""
SRDF = '<?xml version="1.0"?>\n<robot name="arm"><group name="arm"><joint name="j1"/></group></robot>\n'
XACRO_SRDF = ('<?xml version="1.0"?>\n<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
              '<xacro:include filename="{include}"/><group name="arm"><joint name="j1"/></group></robot>\n')
LIMITS = "joint_limits:\n  j1: {has_acceleration_limits: true, max_acceleration: 3.0}\n"


def real(package: str) -> Path:
    """Return a package folder of the real workspace."""
    return REALWORLD / package


def write(folder: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    return folder


@pytest.fixture(autouse=True)
def no_ros_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)


# --- the real workspace, no environment variables -------------------------------------------------


@pytest.mark.realworld
def test_fanuc_config_finds_its_description_package_in_the_workspace(cli: Cli) -> None:
    code, document = cli.json("robot", real(FANUC))
    assert code == 0, document
    assert document["sources"]["urdf"] == str(real(FANUC) / "config" / "fanuc.urdf.xacro")
    assert document["sources"]["srdf"] == str(real(FANUC) / "config" / "fanuc.srdf")
    assert list(document["groups"]) == ["manipulator"]


@pytest.mark.realworld
def test_panda_config_with_three_srdfs_loads_the_one_its_demo_launch_names(cli: Cli) -> None:
    """demo.launch.py: MoveItConfigsBuilder(...).robot_description_semantic(file_path="config/panda.srdf")."""
    code, document = cli.json("robot", real(PANDA))
    assert code == 0, document
    assert document["sources"]["srdf"] == str(real(PANDA) / "config" / "panda.srdf")
    assert document["sources"]["launch"] == str(real(PANDA) / "launch" / "demo.launch.py")
    # MoveItConfigsBuilder prefers the package's config/<robot name>.urdf.xacro (the folder names the robot).
    assert document["sources"]["urdf"] == str(real(PANDA) / "config" / "panda.urdf.xacro")
    assert list(document["groups"]) == ["panda_arm", "hand", "panda_arm_hand"]


@pytest.mark.realworld
def test_gen3_urdf_comes_from_kortex_description_with_the_setup_assistant_xacro_args(cli: Cli) -> None:
    code, document = cli.json("robot", real(GEN3))
    assert code == 0, document
    assert document["sources"]["urdf"] == str(real("ros2_kortex/kortex_description/robots/gen3.xacro"))
    assert document["xacro_args"] == {"gripper": "robotiq_2f_85", "dof": "7"}
    assert document["groups"]["manipulator"]["joints"] == [f"joint_{i}" for i in range(1, 8)]


@pytest.mark.realworld
def test_a_xacro_arg_flag_overrides_one_setup_assistant_arg_and_keeps_the_others() -> None:
    config = load_robot_config(real(GEN3), xacro_args={"robot_ip": "10.0.0.2"})
    assert config.xacro_args == {"gripper": "robotiq_2f_85", "dof": "7", "robot_ip": "10.0.0.2"}


@pytest.mark.realworld
def test_gen3_lite_launch_files_name_a_urdf_xacro_refuses_and_the_error_says_so(cli: Cli) -> None:
    """Its launch files build gen3_lite_gen3_lite_2f.urdf.xacro, whose macro call xacro refuses (as ROS's would)."""
    result = cli("robot", real(GEN3_LITE))
    assert result.exit_code == 3 and result.stderr.count("\n") == 1, result.stderr
    assert 'Invalid parameter "gripper"' in result.stderr
    assert "the URDF launch/demo.launch.py names; pass --urdf FILE for another" in result.stderr
    code, document = cli.json("robot", real(GEN3_LITE), "--urdf", real(GEN3_LITE) / "config" / "gen3_lite.urdf.xacro")
    assert code == 0, document
    assert document["sources"]["urdf"] == str(real(GEN3_LITE) / "config" / "gen3_lite.urdf.xacro")
    assert list(document["groups"]) == ["arm", "gripper"]


@pytest.mark.realworld
def test_abb_srdf_the_setup_assistant_names_without_xacro_is_found_with_it() -> None:
    root = real(ABB)
    found = discover(root, PackagePath(search_path(root)), {})
    assert found.paths["srdf"] == root / "config" / "abb_irb1200_5_90.srdf.xacro"
    assert found.paths["urdf"] == real("abb_ros2/robot_specific_config/abb_irb1200_support/urdf/irb1200_5_90.xacro")


@pytest.mark.realworld
def test_ur_config_asks_for_the_ur_type_its_launch_file_declares_with_choices(cli: Cli) -> None:
    """ur_moveit.launch.py: DeclareLaunchArgument("ur_type", choices=[...]) without a default."""
    result = cli("robot", real(UR))
    assert result.exit_code == 3, result.stderr
    assert result.stderr.count("\n") == 1
    assert f"{real(UR)}: launch argument 'ur_type' has no value" in result.stderr
    assert "choices: ur3, ur5, ur10, ur3e, ur5e" in result.stderr
    assert "pass --launch-arg ur_type:=VALUE" in result.stderr
    code, document = cli.json("robot", real(UR), "--launch-arg", "ur_type:=ur10e", "--xacro-arg", "name:=ur")
    assert code == 0, document
    assert document["sources"]["urdf"] == str(real("Universal_Robots_ROS2_Description/urdf/ur.urdf.xacro"))
    assert document["xacro_args"]["ur_type"] == "ur10e"


@pytest.mark.realworld
def test_ur_config_with_urdf_from_its_description_package_picks_the_top_srdf_and_plans(
    cli: Cli, tmp_path: Path
) -> None:
    code, document = cli.json("robot", real(UR), *UR_ARGS)
    assert code == 0, document
    assert document["sources"]["srdf"] == str(real(UR) / "srdf" / "ur.srdf.xacro")  # not ur_macro.srdf.xacro
    assert document["sources"]["urdf"] == str(real("Universal_Robots_ROS2_Description/urdf/ur.urdf.xacro"))
    out = tmp_path / "up.mcap"
    code, document = cli.json("plan", "--robot", real(UR), *UR_ARGS, "--named", "up", "-o", out)
    assert code == 0, document
    assert document["group"] == "ur_manipulator" and out.is_file()


@pytest.mark.realworld
def test_a_xacro_arg_without_default_names_the_flag_to_pass(cli: Cli) -> None:
    result = cli("robot", real(UR), "--urdf", "package://ur_description/urdf/ur.urdf.xacro")
    assert result.exit_code == 3
    assert "Undefined substitution argument name" in result.stderr
    assert "pass --xacro-arg name:=VALUE" in result.stderr


@pytest.mark.realworld
def test_a_lone_urdf_without_an_srdf_beside_it_says_to_pass_srdf(cli: Cli) -> None:
    urdf = real("moveit_resources/panda_description/urdf/panda.urdf")
    result = cli("robot", urdf)
    assert result.exit_code == 3, result.stderr
    assert result.stderr.count("\n") == 1
    assert f"{urdf}: no SRDF beside it" in result.stderr and "pass --srdf FILE" in result.stderr


@pytest.mark.realworld
def test_a_lone_urdf_with_srdf_by_package_uri_loads(cli: Cli) -> None:
    urdf = real("moveit_resources/panda_description/urdf/panda.urdf")
    code, document = cli.json("robot", urdf, "--srdf", "package://moveit_resources_panda_moveit_config/config/panda.srdf")
    assert code == 0, document
    assert document["sources"]["srdf"] == str(real(PANDA) / "config" / "panda.srdf")
    assert "panda_arm" in document["groups"]


@pytest.mark.realworld
def test_a_lone_srdf_goes_with_the_urdf_of_the_same_name(cli: Cli) -> None:
    code, document = cli.json("robot", real(FANUC) / "config" / "fanuc.srdf")
    assert code == 0, document
    assert document["sources"]["urdf"] == str(real(FANUC) / "config" / "fanuc.urdf.xacro")
    assert document["sources"]["joint_limits"] == str(real(FANUC) / "config" / "joint_limits.yaml")


@pytest.mark.realworld
def test_a_file_that_is_no_robot_config_says_what_robot_takes(cli: Cli) -> None:
    result = cli("robot", real(FANUC) / "package.xml")
    assert result.exit_code == 3
    assert "package.xml: not a robot config; expected a moveplan.yaml" in result.stderr
    assert "URDF (.urdf, .urdf.xacro, .xacro) or SRDF (.srdf, .srdf.xacro) file" in result.stderr
    assert "malformed YAML" not in result.stderr


@pytest.mark.realworld
def test_urdf_flag_naming_an_srdf_is_a_usage_error(cli: Cli) -> None:
    result = cli("robot", real(UR), "--urdf", real(UR) / "srdf" / "ur.srdf.xacro")
    assert result.exit_code == 2
    assert "an SRDF file; pass it with --srdf" in result.stderr


# --- --urdf, --srdf, --strict-limits on every command that loads a robot ---------------------------


def test_urdf_flag_wins_over_moveplan_yaml_and_the_plan_embeds_that_urdf(cli: Cli, tmp_path: Path) -> None:
    urdf = tmp_path / "slow.urdf"
    text = (UR10E / "ur10e.urdf").read_text()
    assert 'velocity="2.094"' in text
    urdf.write_text(text.replace('velocity="2.094"', 'velocity="1.5"'))
    code, document = cli.json("robot", UR10E, "--urdf", urdf)
    assert code == 0, document
    assert document["sources"]["urdf"] == str(urdf)
    out = tmp_path / "home.mcap"
    result = cli("plan", "--robot", UR10E, "--urdf", urdf, "--named", "home", "-o", out)
    assert result.exit_code == 0, result.stderr
    attachments = recording.read_plan(out).attachments
    embedded = yaml.safe_load(attachments["moveplan.yaml"])
    assert 'velocity="1.5"' in attachments[embedded["urdf"]].decode()


def test_urdf_and_srdf_flags_are_inputs_an_output_may_not_replace(cli: Cli, tmp_path: Path) -> None:
    urdf = tmp_path / "arm.urdf"
    shutil.copy(UR10E / "ur10e.urdf", urdf)
    result = cli("plan", "--robot", UR10E, "--urdf", urdf, "--named", "home", "-o", urdf)
    assert result.exit_code == 2
    assert "is also --urdf" in result.stderr
    assert urdf.read_text() == (UR10E / "ur10e.urdf").read_text()


def test_a_missing_urdf_flag_file_exits_3_naming_it(cli: Cli, tmp_path: Path) -> None:
    result = cli("robot", UR10E, "--srdf", tmp_path / "nowhere.srdf")
    assert result.exit_code == 3
    assert f"--srdf {tmp_path / 'nowhere.srdf'}: file not found" in result.stderr


def test_strict_limits_makes_a_missing_acceleration_limit_an_error(cli: Cli, tmp_path: Path) -> None:
    folder = write(tmp_path, {"arm.urdf": URDF, "arm.srdf": SRDF})
    assert cli("robot", folder).exit_code == 0
    result = cli("robot", folder, "--strict-limits")
    assert result.exit_code == 3, result.stderr
    assert "no acceleration limit for joints j1" in result.stderr
    plan = cli("plan", "--robot", folder, "--strict-limits", "--joints", "0.5", "-o", tmp_path / "p.mcap")
    assert plan.exit_code == 3 and not (tmp_path / "p.mcap").exists()


def test_benchmark_loads_the_robot_with_the_flags_in_its_workers(cli: Cli, tmp_path: Path) -> None:
    robot = MBM / "panda_robot"
    for name in ("panda.srdf", "joint_limits.yaml"):
        shutil.copy(robot / name, tmp_path / name)
    # A lone SRDF without a URDF beside it: a worker loading --robot alone would fail.
    code, document = cli.json("benchmark", MBM / "problems" / "table_pick_panda", "--robot", tmp_path / "panda.srdf",
                              "--urdf", robot / "panda.urdf", "--package-path", robot, "--count", 1, "--quiet")
    assert code == 0, document
    assert document["runs"][0]["ok"]
    result = cli("benchmark", MBM / "problems", "--robot", robot, "--srdf", tmp_path / "none.srdf", "--count", 1)
    assert result.exit_code == 3 and "--srdf" in result.stderr


# --- folders without moveplan.yaml: the candidates ------------------------------------------------


def test_macro_and_included_srdfs_are_parts_not_robots(tmp_path: Path) -> None:
    write(tmp_path, {"arm.urdf": URDF, "srdf/robot.srdf.xacro": XACRO_SRDF.format(include="parts.srdf.xacro"),
                     "srdf/parts.srdf.xacro": '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"/>\n',
                     "srdf/robot_macro.srdf.xacro": '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"/>\n'})
    assert load_robot_config(tmp_path).sources["srdf"] == tmp_path / "srdf" / "robot.srdf.xacro"


def test_several_srdfs_name_the_files_and_the_flag(tmp_path: Path) -> None:
    write(tmp_path, {"arm.urdf": URDF, "config/a.srdf": SRDF, "config/b.srdf": SRDF})
    with pytest.raises(ConfigError, match=r"config: several SRDF files \(a.srdf, b.srdf\); .* or pass --srdf FILE"):
        load_robot_config(tmp_path)
    assert load_robot_config(tmp_path, srdf=str(tmp_path / "config" / "b.srdf")).srdf_path.name == "b.srdf"


def test_a_urdf_in_robots_is_found_and_its_macro_ignored(tmp_path: Path) -> None:
    write(tmp_path, {"robots/arm.xacro": URDF, "robots/arm_macro.xacro": "<robot/>", "config/arm.srdf": SRDF})
    assert load_robot_config(tmp_path).sources["urdf"] == tmp_path / "robots" / "arm.xacro"


def test_a_folder_with_only_a_urdf_loads_with_srdf_flag(tmp_path: Path) -> None:
    write(tmp_path, {"cfg/arm.urdf": URDF, "elsewhere/semantic.srdf": SRDF})
    config = load_robot_config(tmp_path / "cfg", srdf=str(tmp_path / "elsewhere" / "semantic.srdf"))
    assert config.sources["urdf"] == tmp_path / "cfg" / "arm.urdf"


# --- .setup_assistant ---------------------------------------------------------------------------


def setup_package(folder: Path, assistant: str) -> Path:
    """Write a description package and a config package naming its URDF in .setup_assistant, in a src/ folder."""
    urdf = URDF.replace('<robot name="arm">', '<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                        '<xacro:arg name="tool" default="none"/><xacro:arg name="mount" default="0"/>')
    write(folder / "src", {
        "arm_description/package.xml": "<package><name>acme_arm_description</name></package>",
        "arm_description/urdf/arm.urdf.xacro": urdf,
        "arm_moveit_config/package.xml": "<package><name>arm_moveit_config</name></package>",
        "arm_moveit_config/config/semantic.srdf.xacro": SRDF,
        "arm_moveit_config/config/joint_limits.yaml": LIMITS,
        "arm_moveit_config/.setup_assistant": assistant,
    })
    return folder / "src" / "arm_moveit_config"


ASSISTANT = """moveit_setup_assistant_config:
  URDF:
    package: acme_arm_description
    relative_path: urdf/arm.urdf.xacro
    xacro_args:
      tool:=gripper
      mount:=1
  SRDF:
    relative_path: config/semantic.srdf
  CONFIG:
    author_name: someone
"""


def test_setup_assistant_xacro_args_folded_over_lines_are_read_as_moveit_reads_them(tmp_path: Path) -> None:
    package = setup_package(tmp_path, ASSISTANT)
    assistant = read_setup_assistant(package)
    assert assistant is not None
    assert (assistant.urdf_package, assistant.urdf_path) == ("acme_arm_description", "urdf/arm.urdf.xacro")
    assert assistant.xacro_args == {"tool": "gripper", "mount": "1"}
    config = load_robot_config(package, xacro_args={"mount": "2"})
    assert config.sources["urdf"] == (tmp_path / "src/arm_description/urdf/arm.urdf.xacro").resolve()
    assert config.sources["srdf"] == package / "config" / "semantic.srdf.xacro"  # named without .xacro
    assert config.xacro_args == {"tool": "gripper", "mount": "2"}


def test_a_setup_assistant_arg_no_xacro_declares_names_the_setup_assistant(tmp_path: Path) -> None:
    package = setup_package(tmp_path, ASSISTANT.replace("mount:=1", "mounting:=1"))
    with pytest.raises(ConfigError, match=r"\.setup_assistant: xacro_args: xacro arg 'mounting' is not declared"):
        load_robot_config(package)
    urdf = tmp_path / "src" / "arm_description" / "urdf" / "arm.urdf.xacro"
    assert load_robot_config(package, urdf=str(urdf)).xacro_args == {}  # its args are for its own URDF


def test_a_malformed_setup_assistant_arg_is_a_config_error_naming_the_file(tmp_path: Path) -> None:
    package = setup_package(tmp_path, ASSISTANT.replace("tool:=gripper", "tool=gripper"))
    with pytest.raises(ConfigError, match=r"\.setup_assistant: moveit_setup_assistant_config.urdf.xacro_args: "
                                          r"'tool=gripper': expected name:=value"):
        load_robot_config(package)


def test_a_setup_assistant_package_not_found_names_the_file_and_the_search_path(tmp_path: Path) -> None:
    package = setup_package(tmp_path, ASSISTANT.replace("package: acme_arm_description", "package: acme_arm"))
    with pytest.raises(ConfigError, match=r"\.setup_assistant: moveit_setup_assistant_config.urdf.package: "
                                          r"package 'acme_arm' not found; searched in order: "):
        load_robot_config(package)


# --- packages: the workspace around the config --------------------------------------------------


def test_a_config_outside_a_src_folder_does_not_search_beside_itself(tmp_path: Path) -> None:
    package = setup_package(tmp_path, ASSISTANT)
    shutil.move(tmp_path / "src", tmp_path / "source")
    with pytest.raises(ConfigError, match=r"package 'acme_arm_description' not found"):
        load_robot_config(tmp_path / "source" / package.name)


def test_the_workspace_comes_after_package_path_flags_and_before_ros_package_path(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "env"))
    config = tmp_path / "ws" / "src" / "repo" / "cfg"
    config.mkdir(parents=True)
    folders = search_path(config, (tmp_path / "flag",), (tmp_path / "yaml",))
    assert folders[:5] == (config, tmp_path / "yaml", tmp_path / "flag", (tmp_path / "ws" / "src").resolve(),
                           tmp_path / "env")
    assert workspace_src(tmp_path / "ws") is None


@pytest.mark.parametrize("layout", ["isolated", "merged"])
def test_a_config_in_an_unsourced_install_folder_finds_its_sibling_packages(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, layout: str
) -> None:
    """`colcon build` without `source install/setup.bash`: the packages lie beside each other in install/."""
    for name in ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH"):
        monkeypatch.delenv(name, raising=False)
    install = tmp_path / "ws" / "install"
    for package in ("ur10e_moveit_config", "ur10e_description"):
        share = install / package / "share" if layout == "isolated" else install / "share"
        shutil.copytree(ROOT / "tests" / "data" / package, share / package)
    (install / "local_setup.sh").write_text("# written by colcon\n")
    config = (install / "ur10e_moveit_config" / "share" if layout == "isolated" else install / "share")
    result = cli("plan", "--robot", config / "ur10e_moveit_config", "--named", "home", "-o", tmp_path / "p.mcap")
    assert result.exit_code == 0, result.stderr


def test_packages_are_found_as_colcon_finds_them(tmp_path: Path) -> None:
    def package(path: str, name: str) -> dict[str, str]:
        return {f"{path}/package.xml": f"<package><name>{name}</name></package>"}

    write(tmp_path / "src", {
        **package("a/b/c/deep", "deep_pkg"), **package("outer", "outer_pkg"), **package("outer/inner", "inner_pkg"),
        **package("build/built", "built_pkg"), **package(".hidden/pkg", "hidden_pkg"),
        **package("ignored/pkg", "ignored_pkg"), "ignored/COLCON_IGNORE": "",
    })
    found = packages_under(tmp_path / "src")
    assert dict(found) == {"deep_pkg": tmp_path / "src/a/b/c/deep", "outer_pkg": tmp_path / "src/outer"}


def test_usage_error_for_urdf_flag_names_the_flag(tmp_path: Path) -> None:
    write(tmp_path, {"arm.urdf": URDF, "arm.srdf": SRDF})
    with pytest.raises(UsageError, match=r"--srdf .*arm.urdf: a URDF file; pass it with --urdf"):
        load_robot_config(tmp_path, srdf=str(tmp_path / "arm.urdf"))


def test_an_arg_only_the_srdf_substitutes_is_taken_and_a_typo_still_refused(tmp_path: Path) -> None:
    # KUKA's kr_arm.srdf.xacro names its robot $(arg robot_name) without <xacro:arg>: CMake passes it, as xacro allows.
    srdf = ('<?xml version="1.0"?>\n<robot name="$(arg robot_name)" xmlns:xacro="http://www.ros.org/wiki/xacro">'
            '<group name="arm"><joint name="j1"/></group></robot>\n')
    folder = write(tmp_path / "arm", {"arm.urdf": URDF, "arm.srdf.xacro": srdf, "joint_limits.yaml": LIMITS})
    with pytest.raises(ConfigError, match="pass --xacro-arg robot_name:=VALUE"):
        load_robot_config(folder)
    assert load_robot_config(folder, xacro_args={"robot_name": "kr6"}).srdf.name == "kr6"
    with pytest.raises(UsageError, match="--xacro-arg robot_nam: .* not declared or used by .*srdf"):
        load_robot_config(folder, xacro_args={"robot_name": "kr6", "robot_nam": "kr6"})


def test_joint_limits_a_vendor_keeps_elsewhere_come_by_flag_path_or_package_uri(cli: Cli, tmp_path: Path) -> None:
    # Interbotix keeps config/joint_limits/<robot>_joint_limits.yaml, KUKA <support>/config/<robot>_joint_limits.yaml:
    # launch files name them; --joint-limits does here.
    folder = write(tmp_path / "arm", {"arm.urdf": URDF, "arm.srdf": SRDF, "joint_limits.yaml": LIMITS,
                                      "package.xml": "<package><name>acme_arm</name></package>",
                                      "config/joint_limits/arm_joint_limits.yaml":
                                          LIMITS.replace("max_acceleration: 3.0", "max_acceleration: 7.5")})
    assert load_robot_config(folder).limits["j1"].max_acceleration == 3.0
    for given in (str(folder / "config/joint_limits/arm_joint_limits.yaml"),
                  "package://acme_arm/config/joint_limits/arm_joint_limits.yaml"):
        code, document = cli.json("robot", folder, "--joint-limits", given, "--package-path", tmp_path)
        assert code == 0, document
        assert document["joints"]["j1"]["max_acceleration"] == 7.5
        assert document["joints"]["j1"]["source"]["acceleration"] == "arm_joint_limits.yaml"
    result = cli("robot", folder, "--joint-limits", str(folder / "no_such.yaml"))
    assert result.exit_code == 3 and "--joint-limits" in result.stderr and "file not found" in result.stderr


def test_a_description_packages_own_limits_and_kinematics_beside_a_lone_urdf_are_skipped_with_a_warning(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    # franka_description/robots/fr3 holds joint_limits.yaml and kinematics.yaml in Franka's own formats.
    folder = write(tmp_path / "fr3", {"arm.urdf": URDF, "arm.srdf": SRDF,
                                      "joint_limits.yaml": "j1:\n  limit: {lower: -1, upper: 1, velocity: 2}\n",
                                      "kinematics.yaml": "j1: {a: 0.0, d: 0.333}\n"})
    with caplog.at_level("WARNING"):
        config = load_robot_config(folder / "arm.urdf")
    assert config.limits["j1"].max_velocity == 2.0 and "joint_limits" not in config.sources
    assert "not MoveIt's joint_limits.yaml" in caplog.text and "not MoveIt's kinematics.yaml" in caplog.text
    with pytest.raises(ConfigError, match="joint_limits.yaml: unknown key 'j1'"):
        load_robot_config(folder / "arm.urdf", joint_limits=str(folder / "joint_limits.yaml"))


def test_joint_limits_written_as_move_group_node_parameters_are_read(tmp_path: Path) -> None:
    limits = ("move_group:\n  ros__parameters:\n    robot_description_planning:\n      joint_limits:\n"
              "        j1: {has_acceleration_limits: true, max_acceleration: 4.5}\n")
    folder = write(tmp_path / "arm", {"arm.urdf": URDF, "arm.srdf": SRDF, "joint_limits.yaml": limits})
    assert load_robot_config(folder).limits["j1"].max_acceleration == 4.5


def test_a_switch_moveit_does_not_read_is_ignored_with_a_warning_but_an_unknown_number_refused(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    # KUKA's kr6_r700_sixx_joint_limits.yaml writes `has_jerk: false`, which MoveIt ignores.
    limits = LIMITS.replace("max_acceleration: 3.0", "max_acceleration: 3.0, has_jerk: false")
    folder = write(tmp_path / "arm", {"arm.urdf": URDF, "arm.srdf": SRDF, "joint_limits.yaml": limits})
    with caplog.at_level("WARNING"):
        assert load_robot_config(folder).limits["j1"].max_acceleration == 3.0
    assert "unknown switch 'has_jerk' ignored" in caplog.text and "has_jerk_limits" in caplog.text
    (folder / "joint_limits.yaml").write_text(limits.replace("has_jerk: false", "max_jerkk: 5"))
    with pytest.raises(ConfigError, match="unknown key 'max_jerkk'"):
        load_robot_config(folder)


# --- vendors' packages: the robot their launch files name -----------------------------------------

FRANKA = "franka_ros2/franka_fr3_moveit_config"
KUKA = "kuka_robot_descriptions/kuka_kr_moveit_config"
INTERBOTIX = "interbotix_ros_manipulators/interbotix_ros_xsarms/interbotix_xsarm_moveit"
TIAGO = "tiago_moveit_config"


@pytest.mark.realworld
def test_franka_loads_as_given_from_the_xacro_commands_of_its_launch_file(cli: Cli) -> None:
    """moveit.launch.py: Command([xacro, fr3.urdf.xacro, ' hand:=true', ' robot_ip:=', robot_ip, ...])."""
    code, document = cli.json("robot", real(FRANKA))
    assert code == 0, document
    assert document["sources"]["urdf"] == str(real("franka_description/robots/fr3/fr3.urdf.xacro"))
    assert document["sources"]["srdf"] == str(real("franka_description/robots/fr3/fr3.srdf.xacro"))
    assert document["sources"]["controllers"] == str(real(FRANKA) / "config" / "fr3_ros_controllers.yaml")
    assert document["xacro_args"]["hand"] == "true"
    assert {"fr3_arm", "fr3_hand"} <= set(document["groups"])


@pytest.mark.realworld
def test_kuka_loads_as_given_with_the_limits_and_srdf_its_launch_and_cmake_name(cli: Cli) -> None:
    """moveit_server_template.launch.py names <support>/config/<model>_joint_limits.yaml and urdf/<model>.srdf,
    which CMakeLists.txt's xacro_add_files makes from srdf/kr_arm.srdf.xacro with robot_name:=<model>."""
    code, document = cli.json("robot", real(KUKA))
    assert code == 0, document
    limits = real("kuka_robot_descriptions/kuka_agilus_support/config/kr6_r700_sixx_joint_limits.yaml")
    assert document["sources"]["joint_limits"] == str(limits)
    assert document["sources"]["srdf"] == str(real(KUKA) / "srdf" / "kr_arm.srdf.xacro")
    assert document["xacro_args"]["robot_name"] == "kr6_r700_sixx"
    joint = document["joints"]["joint_1"]
    assert joint["max_acceleration"] == pytest.approx(41.67291) and joint["source"]["acceleration"].endswith(
        "kr6_r700_sixx_joint_limits.yaml")


@pytest.mark.realworld
def test_interbotix_asks_for_its_robot_model_and_lists_its_srdfs(cli: Cli) -> None:
    result = cli("robot", real(INTERBOTIX))
    assert result.exit_code == 3 and result.stderr.count("\n") == 1, result.stderr
    assert "launch argument 'robot_model' has no value" in result.stderr
    assert "SRDFs in the package: mobile_px100," in result.stderr and ", wx250s;" in result.stderr
    code, document = cli.json("robot", real(INTERBOTIX), "--launch-arg", "robot_model:=wx250s")
    assert code == 0, document
    assert document["sources"]["joint_limits"] == str(real(INTERBOTIX) / "config/joint_limits/wx250s_joint_limits.yaml")
    assert document["sources"]["srdf"] == str(real(INTERBOTIX) / "config/srdf/wx250s.srdf.xacro")


@pytest.mark.realworld
def test_tiago_loads_as_given_with_the_hardware_its_urdf_defaults_to(
        cli: Cli, caplog: pytest.LogCaptureFixture) -> None:
    """move_group.launch.py: 'config/srdf/tiago' + get_tiago_hw_suffix(arm, end_effector, ft_sensor) + '.srdf',
    the arguments declared by launch_pal (not in the workspace): tiago.urdf.xacro's defaults stand in."""
    code, document = cli.json("robot", real(TIAGO))
    assert code == 0, document
    assert document["sources"]["srdf"] == str(real(TIAGO) / "config/srdf/tiago_pal-hey5_schunk-ft.srdf")
    assert "using the defaults tiago.urdf.xacro gives its xacro args" in caplog.text
    assert "arm:=tiago-arm, end_effector:=pal-hey5, ft_sensor:=schunk-ft" in caplog.text
    # The gripper variant's meshes are not in the workspace: its files are checked, not its geometry.
    config = load_robot_config(real(TIAGO), launch_args={"end_effector": "pal-gripper"})
    assert config.sources["srdf"] == real(TIAGO) / "config/srdf/tiago_pal-gripper_schunk-ft.srdf"
    assert config.xacro_args["end_effector"] == "pal-gripper"  # the URDF of the same hardware
