"""A vendor's MoveIt package whose launch files name the robot, read without running them.

The workspace is built from the shipped UR10e test packages, with a MoveIt package laid out the
way vendors publish theirs (Franka's, KUKA's, Interbotix's, PAL's): the URDF and SRDF named by
a launch file through `Command(xacro ...)` or a MoveItConfigsBuilder chain, launch arguments with
and without defaults, one SRDF per robot in config/srdf/, limits and controllers named where
the launch file loads them, an SRDF a CMakeLists.txt generates, a helper from another package.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import ROOT, Cli

from moveplan.core.config.launch_files import launch_arguments, read_launch
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.config.sources import search_path
from moveplan.core.config.xacro import PackagePath
from moveplan.core.errors import ConfigError, UsageError

DATA = ROOT / "tests" / "data"
PACKAGE_XML = """<?xml version="1.0"?>
<package format="3"><name>{name}</name><version>0.1.0</version><description>test</description>
<maintainer email="a@b.c">a</maintainer><license>BSD</license></package>
"""

# Franka's moveit.launch.py, cut down: xacro by Command, an argument without default passed to
# xacro (robot_ip), one with a default (mount_height), load_yaml for the limits, ros2_control_node's
# parameter file, and a ParameterValue wrapper.
FRANKA_LIKE = '''
import os
import yaml
from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import Command, FindExecutable, LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue


def load_yaml(package_name, file_path):
    package_path = get_package_share_directory(package_name)
    absolute_file_path = os.path.join(package_path, file_path)
    try:
        with open(absolute_file_path, 'r') as file:
            return yaml.safe_load(file)
    except EnvironmentError:
        return None


def generate_launch_description():
    robot_ip = LaunchConfiguration('robot_ip')
    mount = LaunchConfiguration('mount_height')
    xacro_file = os.path.join(get_package_share_directory('ur10e_moveit_config'), 'config', 'ur10e.urdf.xacro')
    robot_description = {'robot_description': ParameterValue(Command(
        [FindExecutable(name='xacro'), ' ', xacro_file, ' mount_height:=', mount, ' robot_ip:=', robot_ip]),
        value_type=str)}
    srdf = os.path.join(get_package_share_directory('acme_moveit_config'), 'config', 'srdf', 'ur10e.srdf')
    robot_description_semantic = {'robot_description_semantic': Command(['cat ', srdf])}
    joint_limits = {'robot_description_planning': load_yaml('acme_moveit_config', 'config/limits/ur10e.yaml')}
    move_group = Node(package='moveit_ros_move_group', executable='move_group',
                      parameters=[robot_description, robot_description_semantic, joint_limits])
    controllers = os.path.join(get_package_share_directory('acme_moveit_config'), 'config', 'acme_control.yaml')
    control = Node(package='controller_manager', executable='ros2_control_node',
                   parameters=[robot_description, controllers])
    return LaunchDescription([
        DeclareLaunchArgument('robot_ip', description='Hostname or IP address of the robot.'),
        DeclareLaunchArgument('mount_height', default_value='0.5'),
        move_group, control,
    ])
'''

# Interbotix's and KUKA's: one package for a family, the model a launch argument with choices,
# files named in an OpaqueFunction with perform(context), a MoveItConfigsBuilder chain.
FAMILY_LIKE = '''
from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from moveit_configs_utils import MoveItConfigsBuilder


def launch_setup(context, *args, **kwargs):
    model = LaunchConfiguration('robot_model')
    moveit_config = (
        MoveItConfigsBuilder('acme', package_name='acme_moveit_config')
        .robot_description(file_path=get_package_share_directory('ur10e_moveit_config') + '/config/ur10e.urdf.xacro',
                           mappings={'mount_height': '0.25'})
        .robot_description_semantic(f'config/srdf/{model.perform(context)}.srdf')
        .joint_limits(file_path=f'config/limits/{model.perform(context)}.yaml')
        .to_moveit_configs()
    )
    return [Node(package='moveit_ros_move_group', executable='move_group', parameters=[moveit_config.to_dict()])]


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('robot_model', choices=['ur10e', 'ur10e_tool'], description='model'),
        OpaqueFunction(function=launch_setup),
    ])
'''


def write(folder: Path, files: dict[str, str]) -> Path:
    """Write files (relative path -> text) below `folder`; return it."""
    for name, text in files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    return folder


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    """Return a workspace's src/ with the UR10e description packages and a vendor-style MoveIt package."""
    src = tmp_path / "src"
    shutil.copytree(DATA / "ur10e_description", src / "ur10e_description")
    shutil.copytree(DATA / "ur10e_moveit_config", src / "ur10e_moveit_config")
    config = src / "ur10e_moveit_config" / "config"
    srdf = (config / "ur10e.srdf").read_text()
    write(src / "acme_moveit_config", {
        "package.xml": PACKAGE_XML.format(name="acme_moveit_config"),
        "config/srdf/ur10e.srdf": srdf,
        "config/srdf/ur10e_tool.srdf": srdf.replace('<group_state name="home"', '<group_state name="tool_home"'),
        # The vendor's limits: slower than the shipped ones, so that a plan shows which it used.
        "config/limits/ur10e.yaml": _slow_limits(config / "joint_limits.yaml"),
        "config/limits/ur10e_tool.yaml": _slow_limits(config / "joint_limits.yaml"),
        "config/acme_control.yaml": (config / "ros2_controllers.yaml").read_text(),
        "launch/moveit.launch.py": FRANKA_LIKE,
    })
    return src


def _slow_limits(path: Path) -> str:
    """Return joint_limits.yaml with every velocity limit 0.5 rad/s."""
    import yaml

    top = yaml.safe_load(path.read_text())
    for limits in top["joint_limits"].values():
        limits["has_velocity_limits"], limits["max_velocity"] = True, 0.5
    return yaml.safe_dump(top)


def test_a_launch_file_names_the_urdf_srdf_limits_and_controllers_as_ros2_launch_would(workspace: Path) -> None:
    """moveit.launch.py as Franka's: xacro by Command, ParameterValue, load_yaml, ros2_control_node's file."""
    package = workspace / "acme_moveit_config"
    config = load_robot_config(package)
    assert config.sources["urdf"] == workspace / "ur10e_moveit_config" / "config" / "ur10e.urdf.xacro"
    assert config.sources["srdf"] == package / "config" / "srdf" / "ur10e.srdf"
    assert config.sources["joint_limits"] == package / "config" / "limits" / "ur10e.yaml"
    assert config.sources["controllers"] == package / "config" / "acme_control.yaml"
    assert config.sources["launch"] == package / "launch" / "moveit.launch.py"
    assert {limit.max_velocity for limit in config.limits.values()} == {0.5}
    # robot_ip has no value: its xacro arg keeps xacro's default, as xacro run without it would.
    assert config.xacro_args == {"mount_height": "0.5"}
    assert "robot_ip" not in config.urdf


def test_launch_arguments_given_reach_the_xacro_args_they_feed(workspace: Path) -> None:
    package = workspace / "acme_moveit_config"
    config = load_robot_config(package, launch_args={"mount_height": "1.25", "robot_ip": "10.0.0.2"})
    assert config.xacro_args["mount_height"] == "1.25"
    assert '<origin rpy="0 0 0" xyz="0 0 1.25"/>' in config.urdf or 'xyz="0 0 1.25"' in config.urdf


def test_a_family_package_asks_for_its_model_with_the_choices_and_srdfs(workspace: Path) -> None:
    """A launch argument declared with choices and no default: ros2 launch refuses to start without it."""
    package = workspace / "acme_moveit_config"
    (package / "launch" / "moveit.launch.py").unlink()
    write(package, {"launch/family.launch.py": FAMILY_LIKE})
    with pytest.raises(ConfigError) as error:
        load_robot_config(package)
    message = str(error.value)
    assert "launch argument 'robot_model' has no value" in message
    assert "choices: ur10e, ur10e_tool" in message and "SRDFs in the package: ur10e, ur10e_tool" in message
    assert "pass --launch-arg robot_model:=VALUE" in message
    config = load_robot_config(package, launch_args={"robot_model": "ur10e_tool"})
    assert config.sources["srdf"] == package / "config" / "srdf" / "ur10e_tool.srdf"
    assert config.sources["joint_limits"] == package / "config" / "limits" / "ur10e_tool.yaml"
    assert "tool_home" in config.srdf.group_states["ur_manipulator"]
    assert config.xacro_args["mount_height"] == "0.25"  # the builder's mappings


def test_launch_files_naming_different_robots_need_launch_to_choose(workspace: Path) -> None:
    package = workspace / "acme_moveit_config"
    write(package, {"launch/tool.launch.py": FRANKA_LIKE.replace("'ur10e.srdf'", "'ur10e_tool.srdf'")})
    with pytest.raises(ConfigError, match=r"its launch files name 2 different srdf files \(moveit.launch.py: "
                                          r"ur10e.srdf; tool.launch.py: ur10e_tool.srdf\); pass --launch FILE"):
        load_robot_config(package)
    config = load_robot_config(package, launch="tool.launch.py")
    assert config.sources["srdf"] == package / "config" / "srdf" / "ur10e_tool.srdf"
    with pytest.raises(ConfigError, match=r"--launch other.launch.py: file not found \(launch files of .*: "
                                          r"moveit.launch.py, tool.launch.py\)"):
        load_robot_config(package, launch="other.launch.py")


def test_an_srdf_the_cmake_build_generates_is_read_from_its_xacro(workspace: Path) -> None:
    """KUKA's: xacro_add_files(... REMAP robot_name:=${model} OUTPUT ${model}.srdf INSTALL DESTINATION urdf)."""
    package = workspace / "acme_moveit_config"
    srdf = (package / "config" / "srdf" / "ur10e.srdf").read_text()
    write(package, {
        "srdf/arm.srdf.xacro": srdf.replace('name="ur10e"', 'xmlns:xacro="http://www.ros.org/wiki/xacro" '
                                                           'name="$(arg robot_name)"', 1),
        "CMakeLists.txt": "set(supported_robots\n  ur10e  # the arm\n  ur5e\n)\n"
                          "foreach(model IN LISTS supported_robots)\n"
                          "  xacro_add_files(TARGET ${model} srdf/arm.srdf.xacro REMAP robot_name:=${model} "
                          "OUTPUT ${model}.srdf INSTALL DESTINATION urdf)\nendforeach()\n",
    })
    launch = package / "launch" / "moveit.launch.py"
    launch.write_text(launch.read_text().replace("'config', 'srdf', 'ur10e.srdf'", "'urdf', 'ur10e.srdf'"))
    config = load_robot_config(package)
    assert config.sources["srdf"] == package / "srdf" / "arm.srdf.xacro"
    assert config.srdf.name == "ur10e" and config.xacro_args["robot_name"] == "ur10e"


def test_a_helper_of_another_workspace_package_is_followed(workspace: Path) -> None:
    """PAL's: `from tiago_description.tiago_launch_utils import get_tiago_hw_suffix` builds the SRDF's name."""
    write(workspace / "acme_utils", {
        "package.xml": PACKAGE_XML.format(name="acme_utils"),
        "acme_utils/__init__.py": "",
        "acme_utils/naming.py": "def suffix(tool):\n    if tool in ['none']:\n        return ''\n"
                                "    return '_' + tool\n",
    })
    package = workspace / "acme_moveit_config"
    launch = package / "launch" / "moveit.launch.py"
    text = launch.read_text().replace("import yaml\n", "import yaml\nfrom acme_utils.naming import suffix\n")
    launch.write_text(text.replace("'ur10e.srdf')", "'ur10e' + suffix(tool='tool') + '.srdf')"))
    assert load_robot_config(package).sources["srdf"] == package / "config" / "srdf" / "ur10e_tool.srdf"


UNDECLARED = '''
import os
from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.substitutions import Command, LaunchConfiguration
from launch_pal.robot_utils import get_mount
from launch_ros.actions import Node


def generate_launch_description():
    share = get_package_share_directory('acme_moveit_config')
    xacro_file = os.path.join(get_package_share_directory('ur10e_moveit_config'), 'config', 'ur10e.urdf.xacro')
    srdf = [share, '/config/srdf/ur10e_', LaunchConfiguration('mount_height'), '.srdf']
    node = Node(package='moveit_ros_move_group', executable='move_group', parameters=[
        {'robot_description': Command(['xacro ', xacro_file]), 'robot_description_semantic': Command(['cat ', srdf])}])
    return LaunchDescription([get_mount('acme'), node])
'''


def test_an_argument_no_launch_file_declares_takes_the_default_the_urdf_gives_it(
        workspace: Path, caplog: pytest.LogCaptureFixture) -> None:
    """PAL's launch_pal declares arm and end_effector outside the workspace; tiago.urdf.xacro gives their defaults."""
    package = workspace / "acme_moveit_config"
    srdf = package / "config" / "srdf"
    shutil.copy(srdf / "ur10e_tool.srdf", srdf / "ur10e_0.0.srdf")
    shutil.copy(srdf / "ur10e.srdf", srdf / "ur10e_1.5.srdf")
    (package / "launch" / "moveit.launch.py").write_text(UNDECLARED)
    config = load_robot_config(package)
    assert config.sources["srdf"] == srdf / "ur10e_0.0.srdf"
    assert "launch arguments mount_height:=0.0 have no value" in caplog.text
    assert "the defaults ur10e.urdf.xacro gives its xacro args" in caplog.text
    config = load_robot_config(package, launch_args={"mount_height": "1.5"})
    assert config.sources["srdf"] == srdf / "ur10e_1.5.srdf" and config.xacro_args["mount_height"] == "1.5"


def test_a_launch_file_is_read_never_run(workspace: Path, tmp_path: Path) -> None:
    """Reading a package must not start processes or write files, whatever its launch files say."""
    marker = tmp_path / "ran"
    package = workspace / "acme_moveit_config"
    launch = package / "launch" / "moveit.launch.py"
    launch.write_text("import os, subprocess\n"
                      f"subprocess.run(['touch', '{marker}'])\n"
                      f"os.system('touch {marker}')\n"
                      f"open('{marker}', 'w').write('x')\n"
                      f"__import__('os').system('touch {marker}')\n"
                      "while True:\n    pass\n" + launch.read_text())
    config = load_robot_config(package)
    assert not marker.exists()
    assert config.sources["srdf"] == package / "config" / "srdf" / "ur10e.srdf"


def test_a_launch_file_that_loops_forever_or_recurses_stops_within_its_budget(workspace: Path) -> None:
    package = workspace / "acme_moveit_config"
    launch = package / "launch" / "moveit.launch.py"
    launch.write_text(launch.read_text() + "\ndef f(n):\n    return f(n + 1)\n\n\nf(0)\n"
                      "for i in range(10 ** 12):\n    pass\n"
                      "x = ['a']\nfor i in x:\n    x.append(i)\n")
    found = read_launch(package, PackagePath(search_path(package)), {})
    assert found.srdf is not None and found.srdf.path.name == "ur10e.srdf"


def test_a_launch_file_python_cannot_parse_names_the_file_with_launch(workspace: Path) -> None:
    package = workspace / "acme_moveit_config"
    (package / "launch" / "broken.launch.py").write_text("def generate_launch_description(:\n")
    assert load_robot_config(package).sources["srdf"].name == "ur10e.srdf"  # the others still serve
    with pytest.raises(ConfigError, match=r"broken.launch.py: not a Python launch file moveplan can read \(line 1"):
        load_robot_config(package, launch="broken.launch.py")


def test_launch_arguments_are_name_value_pairs_as_ros2_launch_takes_them() -> None:
    assert launch_arguments(["robot_model:=wx250s", "a.b:="]) == {"robot_model": "wx250s", "a.b": ""}
    with pytest.raises(UsageError, match=r"--launch-arg 'robot_model=wx250s': expected name:=value"):
        launch_arguments(["robot_model=wx250s"])
    with pytest.raises(UsageError, match=r"--launch-arg robot_model: given twice"):
        launch_arguments(["robot_model:=a", "robot_model:=b"])


def test_launch_on_a_lone_urdf_is_a_usage_error(workspace: Path) -> None:
    urdf = workspace / "ur10e_moveit_config" / "config" / "ur10e.urdf.xacro"
    with pytest.raises(UsageError, match=r"--launch and --launch-arg read a MoveIt package's launch files"):
        load_robot_config(urdf, launch_args={"a": "b"})


def test_plan_and_robot_take_launch_and_launch_arg(workspace: Path, cli: Cli, tmp_path: Path) -> None:
    package = workspace / "acme_moveit_config"
    (package / "launch" / "moveit.launch.py").unlink()
    write(package, {"launch/family.launch.py": FAMILY_LIKE})
    result = cli("robot", package)
    assert result.exit_code == 3 and result.stderr.count("\n") == 1, result.stderr
    assert "launch argument 'robot_model' has no value" in result.stderr
    code, document = cli.json("robot", package, "--launch", "family.launch.py", "--launch-arg", "robot_model:=ur10e")
    assert code == 0, document
    assert document["sources"]["joint_limits"] == str(package / "config" / "limits" / "ur10e.yaml")
    code, report = cli.json("plan", "--robot", package, "--launch-arg", "robot_model:=ur10e", "--named", "home",
                            "--seed", 0, "-o", tmp_path / "plan.mcap")
    assert code == 0, report
    result = cli("plan", "--robot", package, "--launch-arg", "robot_model", "--named", "home",
                 "-o", tmp_path / "bad.mcap")
    assert result.exit_code == 2 and "expected name:=value" in result.stderr
    assert not (tmp_path / "bad.mcap").exists()


# Denso's: the MoveIt launch file lives in a bringup package, the model is a launch argument without
# default or choices, and the limits are per model (robots/<model>/config/joint_limits.yaml).
BRINGUP_LIKE = '''
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import Command, FindExecutable, LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    model = LaunchConfiguration('model')
    moveit_config_package = LaunchConfiguration('moveit_config_package')
    prefix = LaunchConfiguration('prefix')
    robot_description = {'robot_description': Command([
        PathJoinSubstitution([FindExecutable(name='xacro')]), ' ',
        PathJoinSubstitution([FindPackageShare('ur10e_moveit_config'), 'config', 'ur10e.urdf.xacro']), ' ',
        'mount_height:=', prefix, ' ', 'model:=', model])}
    semantic = {'robot_description_semantic': Command(['cat ', PathJoinSubstitution(
        [FindPackageShare(moveit_config_package), 'config', 'srdf', 'ur10e.srdf'])])}
    limits = PathJoinSubstitution([FindPackageShare(moveit_config_package), 'robots', model,
                                   'config/joint_limits.yaml'])
    return LaunchDescription([
        DeclareLaunchArgument('model', description='Type of the robot.'),
        DeclareLaunchArgument('moveit_config_package', default_value='acme_moveit_config'),
        DeclareLaunchArgument('prefix', default_value='""'),
        Node(package='moveit_ros_move_group', executable='move_group',
             parameters=[robot_description, semantic, limits]),
    ])
'''


def test_a_moveit_launch_file_in_a_bringup_package_names_the_robot_and_asks_for_its_model(workspace: Path) -> None:
    """Denso's denso_robot_bringup.launch.py names denso_robot_moveit_config, which has no launch/ folder."""
    package = workspace / "acme_moveit_config"
    shutil.rmtree(package / "launch")
    for model in ("alpha", "beta"):
        write(package, {f"robots/{model}/config/joint_limits.yaml": (package / "config/limits/ur10e.yaml").read_text()})
    write(workspace / "acme_bringup", {"package.xml": PACKAGE_XML.format(name="acme_bringup"),
                                       "launch/acme_bringup.launch.py": BRINGUP_LIKE})
    with pytest.raises(ConfigError, match=r"launch argument 'model' has no value \(acme_bringup.launch.py: "
                                          r"declared without a default; choices: alpha, beta\).*; "
                                          r"pass --launch-arg model:=VALUE"):
        load_robot_config(package)
    config = load_robot_config(package, launch_args={"model": "beta"})
    assert config.sources["launch"] == workspace / "acme_bringup" / "launch" / "acme_bringup.launch.py"
    assert config.sources["joint_limits"] == package / "robots" / "beta" / "config" / "joint_limits.yaml"
    # `prefix:=""` is an empty value, as launch's Command splits it with shlex: xacro's 0.0 would be "".
    assert config.xacro_args.get("mount_height", "") == ""


def test_the_urdf_of_the_srdfs_robot_is_found_one_folder_down_or_in_xacro(workspace: Path) -> None:
    """ROBOTIS keeps urdf/<robot>/<robot>.urdf.xacro, TM and Doosan xacro/<robot>.urdf.xacro."""
    package = workspace / "acme_moveit_config"
    launch = package / "launch" / "moveit.launch.py"
    launch.write_text(launch.read_text().replace("robot_description, robot_description_semantic, joint_limits",
                                                 "robot_description_semantic, joint_limits").replace(
        "parameters=[robot_description, controllers]", "parameters=[controllers]"))
    description = workspace / "ur10e_moveit_config" / "config" / "ur10e.urdf.xacro"
    for where in ("urdf/ur10e/ur10e.urdf.xacro", "xacro/ur10e.urdf.xacro"):
        target = workspace / "ur10e_description" / where
        target.parent.mkdir(parents=True, exist_ok=True)
        control = "$(find ur10e_moveit_config)/config/ur10e.ros2_control.xacro"
        target.write_text(description.read_text().replace("ur10e.ros2_control.xacro", control))
        assert load_robot_config(package).sources["urdf"] == target
        target.unlink()


# xArm's: the launch file builds the config with its own MoveItConfigsBuilder class, from a workspace
# package (uf_ros_lib), whose methods name the files; the result reaches move_group through yaml.dump.
CLASS_BUILDER = '''
from pathlib import Path
from launch.substitutions import LaunchConfiguration
from launch_param_builder import ParameterBuilder, load_xacro, load_yaml


class AcmeConfigsBuilder(ParameterBuilder):
    __urdf_args = None

    def __init__(self, context=None, **kwargs):
        super().__init__('acme_moveit_config')
        def get_param_str(name, default_val):
            val = kwargs.get(name, default_val)
            return val if isinstance(val, str) else 'false' if val == False else \\
                (val.perform(context) if context is not None else val) if isinstance(val, LaunchConfiguration) \\
                else str(val)
        self.__model = get_param_str('model', 'ur10e')
        self.__urdf_args = {'mount_height': get_param_str('mount', 0.0)}
        self.__configs = {}

    def robot_description(self):
        path = Path(self._package_path).parent / 'ur10e_moveit_config' / 'config' / 'ur10e.urdf.xacro'
        self.__configs['robot_description'] = {'robot_description': load_xacro(path, mappings=self.__urdf_args)}
        return self

    def robot_description_semantic(self):
        path = self._package_path / 'config' / 'srdf' / '{}.srdf'.format(self.__model)
        self.__configs['semantic'] = {'robot_description_semantic': load_xacro(path)}
        return self

    def joint_limits(self):
        limits = load_yaml(self._package_path / 'config' / 'limits' / (self.__model + '.yaml'))
        self.__configs['limits'] = {'robot_description_planning': limits if limits else {}}
        return self

    def to_moveit_configs(self):
        return self.robot_description().robot_description_semantic().joint_limits()

    def to_dict(self):
        return self.__configs
'''

CLASS_LAUNCH = '''
import yaml
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription, OpaqueFunction
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration
from acme_lib.builder import AcmeConfigsBuilder


def launch_setup(context, *args, **kwargs):
    config = AcmeConfigsBuilder(context=context, model=LaunchConfiguration('model'), mount='0.75')
    config = config.to_moveit_configs()
    return [IncludeLaunchDescription(PythonLaunchDescriptionSource(['common.launch.py']),
                                     launch_arguments={'moveit_config_dump': yaml.dump(config.to_dict())}.items())]


def generate_launch_description():
    return LaunchDescription([DeclareLaunchArgument('model', default_value='ur10e_tool'),
                              OpaqueFunction(function=launch_setup)])
'''


def test_a_builder_class_of_a_workspace_package_names_the_files_its_methods_load(workspace: Path) -> None:
    """xArm's xarm6_moveit_fake.launch.py: uf_ros_lib's MoveItConfigsBuilder(context=..., dof=..., ...), a
    launch_param_builder.ParameterBuilder whose methods load_xacro and load_yaml the robot's files."""
    write(workspace / "acme_lib", {"package.xml": PACKAGE_XML.format(name="acme_lib"),
                                   "acme_lib/__init__.py": "", "acme_lib/builder.py": CLASS_BUILDER})
    package = workspace / "acme_moveit_config"
    (package / "launch" / "moveit.launch.py").write_text(CLASS_LAUNCH)
    config = load_robot_config(package)
    assert config.sources["srdf"] == package / "config" / "srdf" / "ur10e_tool.srdf"
    assert config.sources["joint_limits"] == package / "config" / "limits" / "ur10e_tool.yaml"
    assert config.sources["urdf"] == workspace / "ur10e_moveit_config" / "config" / "ur10e.urdf.xacro"
    assert config.xacro_args["mount_height"] == "0.75"
    assert load_robot_config(package, launch_args={"model": "ur10e"}).sources["srdf"].name == "ur10e.srdf"
