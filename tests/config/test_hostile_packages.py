"""Hostile input on MoveIt config packages, substitutions, SRDF, URDF, limits, start values and MoveIt scenes.

Every case is one clear line naming the file and the problem, exit 3, and no plan file written
(docs/cli.md, Exit codes); the cases that MoveIt itself accepts load, with a warning where a
value is ignored.
"""

from __future__ import annotations

import os
import shutil
import struct
from pathlib import Path

import pytest
import yaml
from conftest import REALWORLD, UR10E, Cli

URDF = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="j3" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="0 0 0.5"/></joint>
  EXTRA
</robot>
"""
SRDF = """<?xml version="1.0"?>
<robot name="arm">
  <virtual_joint name="vj" type="fixed" parent_frame="world" child_link="base"/>
  <group name="arm"><chain base_link="base" tip_link="tip"/></group>
  EXTRA
</robot>
"""
LIMITS = "joint_limits:\n  j1: {has_acceleration_limits: true, max_acceleration: 2.0}\n" \
         "  j2: {has_acceleration_limits: true, max_acceleration: 2.0}\n"
CONTROLLERS = """controller_manager:
  ros__parameters:
    update_rate: 100
    arm_controller:
      type: joint_trajectory_controller/JointTrajectoryController
arm_controller:
  ros__parameters:
    joints: [JOINT, j2]
    command_interfaces: [position]
    state_interfaces: [position, velocity]
"""
MESH_LINK = ('<link name="m"><collision><geometry><mesh filename="package://desc_pkg/meshes/x.stl"/></geometry>'
             '</collision></link><joint name="jm" type="fixed"><parent link="tip"/><child link="m"/></joint>')


def one_line(result) -> str:  # noqa: ANN001 - click's Result
    """Return the error's one line on stderr (asserting it is the only line and no traceback)."""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr and "internal error" not in result.stderr
    return lines[0]


def arm_package(tmp_path: Path, urdf_extra: str = "", srdf_extra: str = "", limits: str = LIMITS) -> Path:
    """A MoveIt config package of a two-joint arm, in a colcon workspace's src/ folder."""
    package = tmp_path / "ws" / "src" / "arm_moveit_config"
    (package / "config").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>arm_moveit_config</name></package>")
    (package / "config" / "arm.urdf").write_text(URDF.replace("EXTRA", urdf_extra))
    (package / "config" / "arm.srdf").write_text(SRDF.replace("EXTRA", srdf_extra))
    (package / "config" / "joint_limits.yaml").write_text(limits)
    return package


def stl(path: Path, triangles: list[tuple[float, ...]], count: int | None = None) -> Path:
    """Write a binary STL of `triangles` (nine vertex coordinates each); `count` overrides the header's count."""
    data = b"\0" * 80 + struct.pack("<I", len(triangles) if count is None else count)
    data += b"".join(struct.pack("<12fH", 0, 0, 1, *t, 0) for t in triangles)
    path.write_bytes(data)
    return path


def description_package(package: Path) -> Path:
    """A description package `desc_pkg` below the workspace's src/, holding meshes/x.stl."""
    folder = package.parent / "deep" / "desc_pkg"
    (folder / "meshes").mkdir(parents=True)
    (folder / "package.xml").write_text("<package><name>desc_pkg</name></package>")
    stl(folder / "meshes" / "x.stl", [(0, 0, 0, 0.1, 0, 0, 0, 0.1, 0)])
    return folder


def plan_arm(cli: Cli, package: Path, *args: object) -> tuple[int, str]:
    """Plan j1 to 0.5 on `package`; return exit code and the one-line message, asserting no file is left."""
    output = package.parent.parent / "out.mcap"
    result = cli("plan", "--robot", package, "--joints", "j1=0.5", "-o", output, *args)
    assert not output.exists()
    return result.exit_code, one_line(result)


def assert_loads(cli: Cli, package: Path, caplog: pytest.LogCaptureFixture | None = None) -> str:
    """Assert `moveplan robot` loads the package; return the warnings it logged."""
    result = cli("robot", package)
    assert result.exit_code == 0, result.stderr
    return caplog.text if caplog is not None else ""


# .setup_assistant


@pytest.mark.parametrize(("text", "problem"), [
    ("moveit_setup_assistant_config: [\n", "malformed YAML"),
    ("- a\n- b\n", "expected a mapping, got list"),
    ("moveit_setup_assistant_config:\n  URDF:\n    package: arm_moveit_config\n    relative_path: config/arm.urdf\n"
     "    xacro_args: foo\n", "'foo': expected name:=value"),
    ("moveit_setup_assistant_config:\n  SRDF:\n    relative_path: /etc/passwd\n", "'/etc/passwd' leaves the package"),
    ("moveit_setup_assistant_config:\n  URDF:\n    package: arm_moveit_config\n"
     "    relative_path: ../../../../etc/hostname\n", "leaves the package"),
    ("moveit_setup_assistant_config:\n  URDF:\n    package: [1, 2]\n", "expected a path"),
])
def test_broken_setup_assistant_is_one_line_naming_it(cli: Cli, tmp_path: Path, text: str, problem: str) -> None:
    package = arm_package(tmp_path)
    (package / ".setup_assistant").write_text(text)
    code, message = plan_arm(cli, package)
    assert code == 3
    assert ".setup_assistant" in message and problem in message


def test_setup_assistant_naming_a_missing_package_says_where_it_looked(cli: Cli, tmp_path: Path) -> None:
    package = arm_package(tmp_path)
    (package / "config" / "arm.urdf").unlink()
    (package / ".setup_assistant").write_text(
        "moveit_setup_assistant_config:\n  URDF:\n    package: nope_description\n    relative_path: urdf/x.urdf\n")
    code, message = plan_arm(cli, package)
    assert code == 3
    assert ".setup_assistant" in message and "package 'nope_description' not found" in message


@pytest.mark.parametrize("kind", ["folder", "symlink loop"])
def test_setup_assistant_that_is_no_file_is_refused(cli: Cli, tmp_path: Path, kind: str) -> None:
    package = arm_package(tmp_path)
    target = package / ".setup_assistant"
    if kind == "folder":
        target.mkdir()
    else:
        os.symlink(target, target)
    code, message = plan_arm(cli, package)
    assert code == 3
    assert ".setup_assistant: not a readable file" in message


# package.xml and the workspace walk


def test_two_packages_of_one_name_in_the_workspace_are_refused_as_colcon_refuses_them(
        cli: Cli, tmp_path: Path) -> None:
    package = arm_package(tmp_path, urdf_extra=MESH_LINK)
    description_package(package)
    other = package.parent / "other" / "desc_pkg"
    other.mkdir(parents=True)
    (other / "package.xml").write_text("<package><name>desc_pkg</name></package>")
    code, message = plan_arm(cli, package)
    assert code == 3
    assert "arm.urdf" in message and "package 'desc_pkg' is defined by 2 folders" in message
    assert "COLCON_IGNORE" in message


def test_a_link_back_into_the_workspace_is_no_duplicate_and_no_endless_walk(cli: Cli, tmp_path: Path) -> None:
    package = arm_package(tmp_path, urdf_extra=MESH_LINK)
    description_package(package)
    os.symlink(package.parent, package.parent / "aaa_loop")
    assert_loads(cli, package)


def test_malformed_package_xml_of_the_package_looked_for_is_named_in_a_warning(
        cli: Cli, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    package = arm_package(tmp_path, urdf_extra=MESH_LINK)
    (description_package(package) / "package.xml").write_text("<package><name>desc_pkg")
    result = cli("plan", "--robot", package, "--joints", "j1=0.5", "-o", tmp_path / "out.mcap")
    assert result.exit_code == 3 and not (tmp_path / "out.mcap").exists()
    assert "desc_pkg/package.xml cannot be read" in caplog.text
    assert "package 'desc_pkg' not found" in one_line(result)


@pytest.mark.parametrize("manifest", ["<package><name>arm_moveit", "<package></package>",
                                      "<package><name>" + "x" * 100_000 + "</name></package>"])
def test_config_package_xml_without_a_usable_name_falls_back_to_the_folder_name(
        cli: Cli, tmp_path: Path, manifest: str) -> None:
    package = arm_package(tmp_path)
    (package / "package.xml").write_text(manifest)
    assert_loads(cli, package)


# launch substitutions in ros2_controllers.yaml


@pytest.mark.parametrize(("joint", "problem"), [
    ("$(var pre", "unterminated substitution"),
    ("$(var " * 5000 + "x" + ")" * 5000, "substitutions nested more than 32 deep"),
    ("$(find arm_moveit_config)", "the 'find' substitution is not supported"),
    ("$(env MOVEPLAN_SURELY_UNSET_VARIABLE)", "environment variable 'MOVEPLAN_SURELY_UNSET_VARIABLE' is not set"),
    ("$(env)", "'env' takes a name and an optional default, got 0 arguments"),
    ("$(var x 'abc)", "unterminated quoted argument"),
])
def test_bad_substitution_names_file_line_and_problem(cli: Cli, tmp_path: Path, joint: str, problem: str) -> None:
    package = arm_package(tmp_path)
    (package / "config" / "ros2_controllers.yaml").write_text(CONTROLLERS.replace("JOINT", joint))
    code, message = plan_arm(cli, package)
    assert code == 3
    assert "ros2_controllers.yaml: line 8:" in message and problem in message
    assert len(message) < 400


def test_substitution_repeated_into_a_huge_file_is_refused(cli: Cli, tmp_path: Path,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MOVEPLAN_BIG", "b" * 100_000)
    package = arm_package(tmp_path)
    controllers = CONTROLLERS.replace("JOINT", "$(env MOVEPLAN_BIG)" * 1000)
    (package / "config" / "ros2_controllers.yaml").write_text(controllers)
    code, message = plan_arm(cli, package)
    assert code == 3
    assert "ros2_controllers.yaml" in message and "grows beyond 67,108,864 characters" in message


# SRDF


@pytest.mark.parametrize(("srdf_extra", "problem"), [
    ('<group name="a"><group name="b"/></group><group name="b"><group name="a"/></group>',
     "groups a, b include each other as subgroups"),
    ('<group name="a"><group name="a"/><joint name="j1"/></group>', "group 'a' includes itself as a subgroup"),
    ('<group name="g"><link name="nope"/></group>', "link 'nope' not found"),
    ('<group name="g"><joint name="nope"/></group>', "joint 'nope' not found"),
    ('<group name="g"><chain base_link="base" tip_link="nope"/></group>', "link 'nope' not found"),
    ('<group_state name="h" group="arm"><joint name="j1" value="nan"/></group_state>', "is not a finite number"),
    ('<group_state name="h" group="arm"><joint name="j1" value="1e999"/></group_state>', "is not a finite number"),
])
def test_broken_srdf_group_is_one_line_naming_the_srdf(cli: Cli, tmp_path: Path, srdf_extra: str,
                                                       problem: str) -> None:
    code, message = plan_arm(cli, arm_package(tmp_path, srdf_extra=srdf_extra))
    assert code == 3
    assert "arm.srdf" in message and problem in message


def test_srdf_virtual_joint_of_unknown_type_is_taken_as_fixed_with_a_warning(
        cli: Cli, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    package = arm_package(tmp_path)
    srdf = package / "config" / "arm.srdf"
    srdf.write_text(srdf.read_text().replace('type="fixed"', 'type="wobbly"'))
    assert "type 'wobbly' is not one of fixed, floating, planar; taken as fixed" in assert_loads(cli, package, caplog)


def test_group_state_value_of_a_joint_outside_the_group_is_dropped_with_a_warning(
        cli: Cli, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    package = arm_package(tmp_path, srdf_extra='<group name="first"><joint name="j1"/></group>'
                          '<group_state name="h" group="first"><joint name="j1" value="0.1"/>'
                          '<joint name="j2" value="0.5"/></group_state>'
                          '<group_state name="h" group="first"><joint name="j1" value="0.2"/></group_state>')
    code, document = cli.json("robot", package)
    assert code == 0
    assert document["named_states"]["first"]["h"] == [0.2]
    stderr = caplog.text
    assert "group_state 'h' gives joints that group 'first' does not have: j2; ignored" in stderr
    assert "group_state 'h' of group 'first' is defined twice; the last one counts" in stderr


# URDF, as urdfdom reads it


@pytest.mark.parametrize(("old", "new", "problem"), [
    ('lower="-2" upper="2" velocity="1"', 'lower="nan" upper="2" velocity="1"', "lower='nan' is not a finite number"),
    (' velocity="1"', ' velocity="inf"', "velocity='inf' is not a finite number"),
    (' velocity="1"', "", "<limit> has no velocity (urdfdom requires it)"),
    ('<limit lower="-2" upper="2" velocity="1" effort="1"/>', "", "is revolute but has no <limit>"),
    ('type="revolute"', 'type="banana"', "joint 'j1' has type 'banana'"),
    ('name="j2"', 'name="j1"', "joint 'j1' is defined twice"),
    ('<link name="l1"/>', '<link name="l1"/><link name="l1"/>', "link 'l1' is defined twice"),
    ('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', "has zero length"),
    ('<link name="tip"/>', '<link name="tip"/><link name="island"/>', "2 root links (base, island)"),
    ('name="j2" ', "", "a <joint> has no name"),
])
def test_urdf_that_urdfdom_refuses_is_one_line_not_its_log(cli: Cli, tmp_path: Path, old: str, new: str,
                                                           problem: str) -> None:
    package = arm_package(tmp_path)
    urdf = package / "config" / "arm.urdf"
    urdf.write_text(urdf.read_text().replace(old, new, 1))
    code, message = plan_arm(cli, package)
    assert code == 3
    assert "arm.urdf" in message and problem in message


@pytest.mark.parametrize(("mimic", "problem"), [
    ('<mimic joint="jm"/>', "in a loop (jm -> jm)"),
    ('<mimic joint="j1" multiplier="nan"/>', "multiplier='nan' is not a finite number"),
])
def test_mimic_joint_of_itself_or_with_nan_factor_is_refused(cli: Cli, tmp_path: Path, mimic: str,
                                                             problem: str) -> None:
    extra = ('<link name="l3"/><joint name="jm" type="revolute"><parent link="tip"/><child link="l3"/>'
             f'<axis xyz="1 0 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/>{mimic}</joint>')
    code, message = plan_arm(cli, arm_package(tmp_path, urdf_extra=extra))
    assert code == 3
    assert "arm.urdf" in message and problem in message


# <ros2_control> initial values and initial_positions.yaml


def ros2_control(value: str, joint: str = "j1") -> str:
    return (f'<ros2_control name="sys" type="system"><joint name="{joint}"><state_interface name="position">'
            f'<param name="initial_value">{value}</param></state_interface></joint></ros2_control>')


@pytest.mark.parametrize(("value", "problem"), [
    ("nan", "initial value 'nan' is not a finite number"),
    ("1e999", "is out of range"),
    ("1e300", "is out of range; values are limited to |value| <= 1,000,000"),
    ("abc", "initial value 'abc' is not a number"),
    ("1_000", "initial value '1_000' is not a number"),
    ("1" * 5000, "(5000 characters)"),
])
def test_bad_ros2_control_initial_value_names_urdf_and_joint(cli: Cli, tmp_path: Path, value: str,
                                                             problem: str) -> None:
    code, message = plan_arm(cli, arm_package(tmp_path, urdf_extra=ros2_control(value)))
    assert code == 3
    assert "arm.urdf" in message and "joint 'j1'" in message and problem in message
    assert len(message) < 400


def test_initial_value_outside_limits_is_a_start_outside_limits(cli: Cli, tmp_path: Path) -> None:
    code, message = plan_arm(cli, arm_package(tmp_path, urdf_extra=ros2_control("5.0")))
    assert code == 4
    assert "start for joint 'j1' is 5 rad, outside its limits [-2, 2]" in message and "arm.urdf" in message


def test_initial_values_of_unknown_and_mimic_joints_are_ignored_with_a_warning(
        cli: Cli, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    mimic = ('<link name="l3"/><joint name="jm" type="revolute"><parent link="tip"/><child link="l3"/>'
             '<axis xyz="1 0 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/><mimic joint="j2"/></joint>')
    stderr = assert_loads(cli, arm_package(tmp_path, urdf_extra=mimic + ros2_control("0.7", "jm")
                                           + ros2_control("0.1", "nope")), caplog)
    assert "initial values of joints the URDF does not have: nope" in stderr
    assert "initial values of mimic joints ignored: jm (0.7, follows as 0)" in stderr


def test_initial_positions_yaml_beyond_the_magnitude_limit_is_refused(cli: Cli, tmp_path: Path) -> None:
    package = arm_package(tmp_path)
    (package / "config" / "initial_positions.yaml").write_text("initial_positions:\n  j1: 1e300\n")
    code, message = plan_arm(cli, package)
    assert code == 3
    assert "initial_positions.yaml: initial_positions.j1" in message and "out of range" in message


# joint_limits.yaml


@pytest.mark.parametrize(("entry", "problem"), [
    ("{has_acceleration_limits: 'true', max_acceleration: 2}", "has_acceleration_limits: expected true or false"),
    ("{has_velocity_limits: true, max_velocity: -1}", "max_velocity: expected a positive number"),
    ("{has_acceleration_limits: true, max_acceleration: 0}", "max_acceleration: expected a positive number"),
    ("{has_acceleration_limits: true, max_acceleration: 1e300}", "max_acceleration: 1e+300 is out of range"),
    ("{has_position_limits: true, min_position: -1e300, max_position: 1}", "min_position: -1e+300 is out of range"),
    ("{has_position_limits: true, min_position: .nan, max_position: 1}", "expected a finite number, got nan"),
])
def test_bad_joint_limit_names_file_and_key(cli: Cli, tmp_path: Path, entry: str, problem: str) -> None:
    code, message = plan_arm(cli, arm_package(tmp_path, limits=f"joint_limits:\n  j1: {entry}\n"))
    assert code == 3
    assert "joint_limits.yaml: joint_limits.j1." in message and problem in message


def test_default_scaling_below_the_flag_limit_is_refused(cli: Cli, tmp_path: Path) -> None:
    package = arm_package(tmp_path, limits="default_velocity_scaling_factor: 1e-9\n" + LIMITS)
    code, message = plan_arm(cli, package)
    assert code == 3
    assert "joint_limits.yaml: default_velocity_scaling_factor: expected a number in [0.001, 1]" in message


# MoveIt PlanningScene: meshes, attached objects, frames


def plan_scene(cli: Cli, tmp_path: Path, scene: dict, *goal: object) -> tuple[int, str, str]:
    """Plan the UR10e in `scene` (a PlanningScene written beside its meshes); return code, one line, stderr."""
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene))
    output = tmp_path / "out.mcap"
    goal = goal or ("--joints", "0.1,-1.5,1.2,-1.2,-1.5,0")
    result = cli("plan", "--robot", UR10E, "--scene", path, "--start-named", "home", *goal, "-o", output)
    if result.exit_code == 0:
        return 0, "", result.stderr
    assert not output.exists()
    return result.exit_code, one_line(result), result.stderr


def mesh_scene(resource: str, dimensions: list | None = None) -> dict:
    mesh: dict = {"resource": resource}
    if dimensions is not None:
        mesh["dimensions"] = dimensions
    return {"world": {"collision_objects": [{"id": "m", "header": {"frame_id": "base_link"}, "meshes": [mesh],
                                             "mesh_poses": [{"position": {"x": 2.0, "y": 2.0, "z": 0.0}}]}]}}


@pytest.mark.parametrize(("make", "problem"), [
    (lambda d: d / "nope.stl", "mesh file not found"),
    (lambda d: (d / "adir.stl").mkdir() or d / "adir.stl", "mesh file not found"),
    (lambda d: (d / "zero.stl").write_bytes(b"") or d / "zero.stl", "empty file, not an STL mesh"),
    (lambda d: stl(d / "cut.stl", [(0, 0, 0, 1, 0, 0, 0, 1, 0)], count=5), "a binary STL of 5 triangles has 334"),
    (lambda d: stl(d / "huge.stl", [(0, 0, 0, 1, 0, 0, 0, 1, 0)], count=4_000_000_000), "4000000000 triangles"),
    (lambda d: stl(d / "nan.stl", [(float("nan"), 0, 0, 1, 0, 0, 0, 1, 0)]),
     "triangle 0 has a vertex that is not finite"),
    (lambda d: (d / "a.stl").write_text("solid x\nfacet normal 0 0 1\nouter loop\nvertex nan 0 0\nvertex 1 0 0\n"
                                        "vertex 0 1 0\nendloop\nendfacet\nendsolid x\n") and d / "a.stl",
     "ASCII STL: vertex 0 is not finite"),
    (lambda d: Path("a" * 100_000 + ".stl"), "is not a file name or package:// URI"),
])
def test_bad_mesh_resource_is_one_line_naming_scene_and_mesh(cli: Cli, tmp_path: Path, make, problem: str) -> None:  # noqa: ANN001
    resource = make(tmp_path)
    code, message, _ = plan_scene(cli, tmp_path, mesh_scene(str(resource)))
    assert code == 3
    assert "scene.yaml: world.collision_objects[0].meshes[0].resource" in message and problem in message
    assert len(message) < 500


@pytest.mark.parametrize(("resource", "dimensions", "problem"), [
    ("package://nope_pkg/x.stl", None, "package 'nope_pkg' not found"),
    ("ok.stl", [0, 1, 1], "dimensions[0]: expected a positive number, got 0"),
    ("ok.stl", [-1, 1, 1], "dimensions[0]: expected a positive number, got -1"),
    ("ok.stl", [float("nan"), 1, 1], "dimensions[0]: expected a finite number, got nan"),
])
def test_mesh_of_unknown_package_or_bad_scale_is_refused(cli: Cli, tmp_path: Path, resource: str,
                                                         dimensions: list | None, problem: str) -> None:
    stl(tmp_path / "ok.stl", [(0, 0, 0, 0.1, 0, 0, 0, 0.1, 0)])
    code, message, _ = plan_scene(cli, tmp_path, mesh_scene(resource, dimensions))
    assert code == 3
    assert "scene.yaml" in message and problem in message


def box(object_id: str, frame: str = "base_link", x: float = 2.0) -> dict:
    return {"id": object_id, "header": {"frame_id": frame}, "primitives": [{"type": 1, "dimensions": [0.1, 0.1, 0.1]}],
            "primitive_poses": [{"position": {"x": x, "y": 2.0, "z": 0.0}}]}


def test_attached_object_on_an_unknown_link_lists_the_links(cli: Cli, tmp_path: Path) -> None:
    scene = {"robot_state": {"attached_collision_objects": [{"link_name": "nope_link", "object": box("b")}]}}
    code, message, _ = plan_scene(cli, tmp_path, scene)
    assert code == 3
    assert "link 'nope_link' not found in" in message and "scene.yaml" in message and "tool0" in message


def test_unknown_touch_link_is_named_in_a_warning(cli: Cli, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    attached = {"link_name": "tool0", "object": box("b", "tool0", 0.05), "touch_links": ["nope_link"]}
    code, _, _ = plan_scene(cli, tmp_path, {"robot_state": {"attached_collision_objects": [attached]}})
    assert code == 0
    assert "touch_links: nope_link name no robot link or object" in caplog.text


def test_world_object_id_twice_and_frame_cycle_are_refused(cli: Cli, tmp_path: Path) -> None:
    code, message, _ = plan_scene(cli, tmp_path, {"world": {"collision_objects": [box("w"), box("w", x=3.0)]}})
    assert code == 3 and "collision object 'w' is defined twice" in message

    def tf(header: str, child: str) -> dict:
        return {"header": {"frame_id": header}, "child_frame_id": child,
                "transform": {"translation": {"x": 1.0}, "rotation": {"w": 1.0}}}

    code, message, _ = plan_scene(cli, tmp_path, {"fixed_frame_transforms": [tf("a", "b"), tf("b", "a")]})
    assert code == 3 and "scene.yaml: frames form a loop" in message


# the real workspace still loads under the stricter checks


@pytest.mark.realworld
@pytest.mark.parametrize("config", ["moveit_resources/panda_moveit_config", "moveit_resources/fanuc_moveit_config"])
def test_real_moveit_configs_still_load(cli: Cli, config: str) -> None:
    result = cli("robot", REALWORLD / config)
    assert result.exit_code == 0, result.stderr


@pytest.mark.realworld
def test_copied_panda_package_with_setup_assistant_still_loads(cli: Cli, tmp_path: Path) -> None:
    src = tmp_path / "src"
    shutil.copytree(REALWORLD / "moveit_resources" / "panda_moveit_config", src / "panda_moveit_config")
    shutil.copytree(REALWORLD / "moveit_resources" / "panda_description", src / "panda_description", symlinks=True)
    assert cli("robot", src / "panda_moveit_config").exit_code == 0
