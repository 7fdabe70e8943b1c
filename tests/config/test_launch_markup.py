"""XML and YAML launch files read as ROS 2's launch_xml and launch_yaml frontends read them, nothing run."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from moveplan.core.config._launch_markup import MAX_ENTITIES, evaluate_markup_launch
from moveplan.core.config._launch_values import (
    Condition,
    Declared,
    LaunchContext,
    LaunchRecord,
    NodeRecord,
    Unknown,
    text,
)
from moveplan.core.errors import ConfigError

PACKAGES = {"pkg": "/ws/src/pkg", "acme_moveit_config": "/ws/src/acme_moveit_config"}

ROBOT_XML = """<?xml version="1.0"?>
<launch>
  <arg name="robot" default="ur5e" description="robot model"/>
  <node pkg="robot_state_publisher" exec="robot_state_publisher" name="rsp">
    <param name="robot_description"
           value="$(command 'xacro $(find-pkg-share pkg)/urdf/r.urdf.xacro name:=$(var robot)')"/>
  </node>
</launch>
"""

ROBOT_YAML = """
launch:
- arg: {name: robot, default: ur5e, description: robot model}
- node:
    pkg: robot_state_publisher
    exec: robot_state_publisher
    param:
    - name: robot_description
      value: "$(command 'xacro $(find-pkg-share pkg)/urdf/r.urdf.xacro name:=$(var robot)')"
"""


Include = tuple[Any, Any, Any, int]


def _context(**given: str) -> LaunchContext:
    return LaunchContext(dict(given), PACKAGES.get)


def _evaluate(path: Path, context: LaunchContext | None = None) -> tuple[LaunchRecord, list[Include]]:
    """Return a launch file's record and the includes it called back with (and the nodes recorded by then)."""
    calls: list[Include] = []

    def include(source: Any, arguments: Any, condition: Any, record: LaunchRecord) -> None:
        calls.append((source, arguments, condition, len(record.nodes)))

    record = evaluate_markup_launch(path, context or _context(), include)
    return record, calls


def _write(tmp_path: Path, name: str, content: str) -> Path:
    path = tmp_path / name
    path.write_text(content)
    return path


def _description(node: NodeRecord, context: LaunchContext) -> str | Unknown:
    (parameters,) = [p for p in node.parameters if isinstance(p, dict) and "robot_description" in p]
    return text(parameters["robot_description"], context)


def _nodes(record: LaunchRecord, executable: str) -> list[NodeRecord]:
    return [n for n in record.nodes if n.executable == executable]


# -- XML ----------------------------------------------------------------------------------------------

def test_xml_robot_description_command_resolves_to_the_xacro_command_line(tmp_path: Path) -> None:
    """launch_xml: `$(command '...')` is Command over its quoted text, with find-pkg-share and var inside it."""
    context = _context()
    record, _ = _evaluate(_write(tmp_path, "robot.launch.xml", ROBOT_XML), context)
    (node,) = record.nodes
    assert (node.package, node.executable) == ("robot_state_publisher", "robot_state_publisher")
    assert _description(node, context) == "xacro /ws/src/pkg/urdf/r.urdf.xacro name:=ur5e"


def test_xml_given_argument_keeps_its_value_over_the_default(tmp_path: Path) -> None:
    """DeclareLaunchArgument (<arg>): an argument given on the command line or by an include wins over `default`."""
    context = _context(robot="ur10e")
    record, _ = _evaluate(_write(tmp_path, "robot.launch.xml", ROBOT_XML), context)
    assert context.declared["robot"] == Declared("ur5e", None)
    assert _description(record.nodes[0], context) == "xacro /ws/src/pkg/urdf/r.urdf.xacro name:=ur10e"


def test_xml_arguments_declare_defaults_and_choices(tmp_path: Path) -> None:
    """DeclareLaunchArgument.parse: `default`, `description` and <choice value=...> children; no default: required."""
    path = _write(tmp_path, "args.launch.xml", """<launch>
      <arg name="model" default="$(var family)_arm"/>
      <arg name="family" default="acme"/>
      <arg name="mode" default="sim" description="hardware">
        <choice value="sim"/>
        <choice value="real"/>
      </arg>
      <arg name="robot_ip"/>
      <node pkg="p" exec="driver" args="--model $(var model) --ip $(var robot_ip)"/>
    </launch>""")
    context = _context()
    record, _ = _evaluate(path, context)
    assert context.declared["mode"] == Declared("sim", ("sim", "real"))
    assert context.declared["robot_ip"] == Declared(None, None)
    words = [text(word, context) for word in record.nodes[0].arguments]
    assert words == ["--model", "acme_arm", "--ip", Unknown(frozenset({"robot_ip"}))]
    assert "robot_ip" in context.missing


def test_xml_let_overrides_a_given_argument_within_its_scope(tmp_path: Path) -> None:
    """SetLaunchConfiguration (<let>) replaces a launch configuration, given or not; a scoped <group> pops it."""
    path = _write(tmp_path, "let.launch.xml", """<launch>
      <arg name="robot" default="ur5e"/>
      <group>
        <let name="robot" value="inner_$(var robot)"/>
        <node pkg="p" exec="in_group" args="$(var robot)"/>
      </group>
      <node pkg="p" exec="after_group" args="$(var robot)"/>
      <group scoped="false">
        <let name="robot" value="leaked"/>
      </group>
      <node pkg="p" exec="after_unscoped" args="$(var robot)"/>
    </launch>""")
    context = _context(robot="given")
    record, _ = _evaluate(path, context)
    assert [text(n.arguments[0], context) for n in record.nodes] == ["inner_given", "given", "leaked"]


def test_xml_include_calls_back_with_its_arguments_after_the_file(tmp_path: Path) -> None:
    """IncludeLaunchDescription (<include file=...> with <arg name= value=/>): launch arguments passed in order,
    the included files followed once this one is done."""
    path = _write(tmp_path, "top.launch.xml", """<launch>
      <arg name="robot" default="ur5e"/>
      <include file="$(find-pkg-share acme_moveit_config)/launch/move_group.launch.xml">
        <arg name="robot" value="$(var robot)"/>
        <arg name="use_sim" value="true"/>
      </include>
      <include file="$(dirname)/rviz.launch.py" if="$(var rviz false)"/>
      <node pkg="p" exec="last"/>
    </launch>""")
    context = _context()
    record, calls = _evaluate(path, context)
    assert len(calls) == 2
    (source, arguments, condition, nodes_by_then), second = calls
    assert text(source, context) == "/ws/src/acme_moveit_config/launch/move_group.launch.xml"
    assert [(text(n, context), text(v, context)) for n, v in arguments] == [("robot", "ur5e"), ("use_sim", "true")]
    assert condition is None
    assert nodes_by_then == 1  # the node after the includes was recorded first
    assert text(second[0], context) == str(tmp_path / "rviz.launch.py")
    assert isinstance(second[2], Condition) and not second[2].holds(context)


def test_xml_param_from_files_and_nested_params(tmp_path: Path) -> None:
    """launch_ros Node.parse_nested_parameters: <param from=FILE/> is a parameter file, <param name=> a dict per
    param, nested <param>s a nested dict (moveplan names them with ROS's dotted names)."""
    path = _write(tmp_path, "move_group.launch.xml", """<launch>
      <node pkg="moveit_ros_move_group" exec="move_group">
        <param from="$(find-pkg-share acme_moveit_config)/config/kinematics.yaml"/>
        <param name="robot_description_planning">
          <param name="joint_limits" value="$(find-pkg-share acme_moveit_config)/config/joint_limits.yaml"/>
        </param>
        <param name="use_sim_time" value="false"/>
      </node>
    </launch>""")
    context = _context()
    record, _ = _evaluate(path, context)
    files, nested, flat = record.nodes[0].parameters
    assert text(files, context) == "/ws/src/acme_moveit_config/config/kinematics.yaml"
    assert list(nested) == ["robot_description_planning.joint_limits"]
    assert text(nested["robot_description_planning.joint_limits"], context) == \
        "/ws/src/acme_moveit_config/config/joint_limits.yaml"
    assert flat == {"use_sim_time": "false"}


def test_xml_if_unless_and_group_conditions(tmp_path: Path) -> None:
    """Every action takes `if`/`unless` (IfCondition/UnlessCondition); a <group> whose condition is false runs none
    of its actions, one known only at launch time conditions them."""
    path = _write(tmp_path, "conditions.launch.xml", """<launch>
      <arg name="sim" default="true"/>
      <node pkg="p" exec="fake" if="$(var sim)"/>
      <node pkg="p" exec="real" unless="$(var sim)"/>
      <group if="$(var rviz false)">
        <node pkg="rviz2" exec="rviz2"/>
      </group>
      <group unless="$(var hardware)">
        <node pkg="p" exec="in_unknown_group"/>
      </group>
    </launch>""")
    context = _context()
    record, _ = _evaluate(path, context)
    assert [n.executable for n in record.nodes] == ["fake", "real", "in_unknown_group"]
    fake, real, grouped = record.nodes
    assert fake.condition.holds(context) and not real.condition.holds(context)
    assert grouped.condition.kind == "unless"
    assert text(grouped.condition.parts[0], context) == Unknown(frozenset({"hardware"}))


def test_xml_node_args_and_executable_cmd_split_into_words(tmp_path: Path) -> None:
    """ExecuteProcess._parse_cmdline: `args` and `cmd` are split by shlex, a substitution kept with the text it
    touches; <executable> is recorded as the Python side records ExecuteProcess."""
    path = _write(tmp_path, "spawn.launch.xml", """<launch>
      <node pkg="controller_manager" exec="spawner"
            args="arm_controller -p $(find-pkg-share acme_moveit_config)/config/ros2_controllers.yaml 'a b'"/>
      <executable cmd="ros2 run controller_manager spawner hand_controller --param-file $(dirname)/c.yaml"/>
    </launch>""")
    context = _context()
    record, _ = _evaluate(path, context)
    spawner, process = record.nodes
    assert [text(w, context) for w in spawner.arguments] == [
        "arm_controller", "-p", "/ws/src/acme_moveit_config/config/ros2_controllers.yaml", "a b"]
    assert process.package is None and process.executable == ["ros2", "run", "controller_manager", "spawner"]
    assert [text(w, context) for w in process.arguments] == ["hand_controller", "--param-file",
                                                             str(tmp_path / "c.yaml")]


def test_xml_substitutions_nested_quoted_and_not_followed(tmp_path: Path) -> None:
    """launch's frontend grammar: nested substitutions, quoted arguments, backslash escapes, var's default;
    eval, anon and env without default are not followed (Unknown), and never an error."""
    path = _write(tmp_path, "subst.launch.xml", """<launch>
      <arg name="which" default="model"/>
      <arg name="model" default="ur5e"/>
      <node pkg="p" exec="n" args="$(var $(var which)) $(var absent 'a default') \\$(var model) $(env HOME /home/x)">
        <param name="robot_description"
               value="$(command '$(find-exec xacro) $(var model).urdf.xacro prefix:=&quot;&quot; tf:=\\'x\\'')"/>
        <param name="evaluated" value="$(eval '1 + 1')"/>
        <param name="anonymous" value="$(anon node)"/>
        <param name="environment" value="$(env HOME)"/>
        <param name="broken" value="$(var unclosed"/>
      </node>
      <unknown_action/>
    </launch>""")
    context = _context()
    record, _ = _evaluate(path, context)
    (node,) = record.nodes
    assert [text(w, context) for w in node.arguments] == ["ur5e", "a default", "$(var", "model)", "/home/x"]
    parameters = {k: text(v, context) for item in node.parameters for k, v in item.items()}
    # Command splits its text with shlex: its quotes go, as here.
    assert parameters["robot_description"] == "xacro ur5e.urdf.xacro prefix:= tf:=x"
    assert all(isinstance(parameters[k], Unknown) for k in ("evaluated", "anonymous", "environment", "broken"))


# -- YAML ---------------------------------------------------------------------------------------------

def test_yaml_robot_description_command_resolves(tmp_path: Path) -> None:
    """launch_yaml: the same actions as one-key mappings; a node's `param` list holds name/value mappings."""
    context = _context()
    record, _ = _evaluate(_write(tmp_path, "robot.launch.yaml", ROBOT_YAML), context)
    (node,) = record.nodes
    assert _description(node, context) == "xacro /ws/src/pkg/urdf/r.urdf.xacro name:=ur5e"
    given = _context(robot="ur10e")
    record, _ = _evaluate(_write(tmp_path, "robot.launch.yaml", ROBOT_YAML), given)
    assert _description(record.nodes[0], given) == "xacro /ws/src/pkg/urdf/r.urdf.xacro name:=ur10e"


def test_yaml_include_params_conditions_and_groups(tmp_path: Path) -> None:
    """launch_yaml Entity: a list of mappings under a key is child entities of that kind (`arg`, `param`,
    `choice`), a group's actions are its `children`; `if`/`unless` as in XML."""
    path = _write(tmp_path, "all.launch.yaml", """
launch:
- arg: {name: sim, default: "true"}
- arg:
    name: mode
    default: fake
    choice: [{value: fake}, {value: real}]
- let: {name: config, value: "$(find-pkg-share acme_moveit_config)/config"}
- include:
    file: "$(var config)/../launch/move_group.launch.py"
    arg:
    - {name: mode, value: "$(var mode)"}
- node:
    pkg: controller_manager
    exec: ros2_control_node
    if: "$(var sim)"
    param:
    - from: "$(var config)/ros2_controllers.yaml"
    - name: update_rate
      value: 100
    - name: outer
      param: [{name: inner, value: "x"}]
- group:
    unless: "$(var sim)"
    children:
    - node: {pkg: p, exec: real_driver}
- executable: {cmd: "ros2 run controller_manager spawner arm_controller"}
""")
    context = _context()
    record, calls = _evaluate(path, context)
    assert context.declared["mode"] == Declared("fake", ("fake", "real"))
    ((source, arguments, condition, _),) = calls
    assert text(source, context) == "/ws/src/acme_moveit_config/config/../launch/move_group.launch.py"
    assert [(text(n, context), text(v, context)) for n, v in arguments] == [("mode", "fake")]
    control, spawner = record.nodes
    assert control.condition.holds(context)
    files, rate, nested = control.parameters
    assert text(files, context) == "/ws/src/acme_moveit_config/config/ros2_controllers.yaml"
    assert rate == {"update_rate": 100} and nested == {"outer.inner": "x"}
    assert spawner.executable == ["ros2", "run", "controller_manager", "spawner"]
    assert spawner.arguments == ["arm_controller"]


# -- what is refused, what is bounded -----------------------------------------------------------------

@pytest.mark.parametrize(("name", "content", "problem"), [
    ("broken.launch.xml", "<launch><node pkg='p'></launch>", "malformed XML"),
    ("entities.launch.xml", '<!DOCTYPE launch [<!ENTITY e "x">]>\n<launch><arg name="a" default="&e;"/></launch>',
     "DOCTYPE"),
    ("urdf.launch.xml", "<robot name='r'/>", "not <launch>"),
    ("broken.launch.yaml", "launch:\n- node: {pkg: p\n", "malformed YAML"),
    ("params.launch.yaml", "move_group:\n  ros__parameters: {}\n", "not a ROS 2 YAML launch file"),
])
def test_malformed_files_raise_config_error_naming_the_file(tmp_path: Path, name: str, content: str,
                                                            problem: str) -> None:
    """launch_xml and launch_yaml parsers fail on a file that does not parse or has no launch root; moveplan says
    which file, in one line (and reads no XML document type declaration)."""
    path = _write(tmp_path, name, content)
    with pytest.raises(ConfigError) as error:
        _evaluate(path)
    message = str(error.value)
    assert message.startswith(str(path)) and problem in message and "\n" not in message


def test_a_huge_launch_file_is_followed_only_so_far(tmp_path: Path) -> None:
    """Not a frontend behaviour but moveplan's bound: at most MAX_ENTITIES elements are followed, with a note."""
    nodes = "".join(f'<node pkg="p" exec="n{i}"/>' for i in range(MAX_ENTITIES + 10))
    record, _ = _evaluate(_write(tmp_path, "huge.launch.xml", f"<launch>{nodes}</launch>"))
    assert len(record.nodes) == MAX_ENTITIES
    assert record.notes and "5,000" in record.notes[0]
