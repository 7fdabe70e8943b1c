"""Controller settings: ros2_controllers.yaml's JointTrajectoryControllers, moveit_controllers.yaml's execution.

Only the controllers moveplan interprets are read, and their keys checked: a
JointTrajectoryController's parameters, `constraints` and `gains` accept what some
ROS 2 release of it declares, so a typo (`trajectroy`, read by ROS as an undeclared
parameter and ignored) is an error rather than a tolerance of 0, "not checked". The
other controllers of the file (broadcasters, grippers, ...) are not looked at.

Both files may use ROS 2 launch substitutions, as ur_robot_driver's ur_controllers.yaml does
(`$(var tf_prefix)shoulder_pan_joint`): they are made first, with the launch arguments given
(substitutions.py), and errors name the file as the user wrote it.
"""

from __future__ import annotations

import difflib
import logging
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ._launch_types import spawned_types
from ._substitutions import load_substituted_yaml
from .fields import boolean, check_keys, load_yaml, mapping, number, string_list

__all__ = [
    "MAX_UPDATE_RATE_HZ", "ControllerConfig", "ExecutionConfig", "default_controller", "parse_controllers",
    "parse_execution",
]

logger = logging.getLogger(__name__)

# What a JointTrajectoryController declares, in any release from Humble to master: ros2_controllers'
# joint_trajectory_controller/src/joint_trajectory_controller_parameters.yaml (@9c53e68, Humble-era
# versions, @02aa372 master) and its release notes (start_with_holding, removed in Jazzy).
_JTC_KEYS = frozenset({
    "joints", "command_joints", "command_interfaces", "state_interfaces", "allow_partial_joints_goal",
    "open_loop_control", "interpolate_from_desired_state", "allow_integration_in_goal_trajectories",
    "set_last_command_interface_value_as_state_on_activation", "state_publish_rate", "action_monitor_rate",
    "interpolation_method", "allow_nonzero_velocity_at_trajectory_end", "cmd_timeout", "start_with_holding",
    "speed_scaling", "gains", "constraints",
})
# Every controller's node also takes these: controller_interface's update_rate, is_async and
# async_parameters (ControllerInterfaceBase), the spawner's `type`, rclcpp's use_sim_time.
MAX_UPDATE_RATE_HZ = 10_000.0
_NODE_KEYS = frozenset({"update_rate", "is_async", "async_parameters", "type", "use_sim_time"})
# gripper_controllers' and parallel_gripper_controller's GripperActionController parameters.
_GRIPPER_KEYS = frozenset({"joint", "action_monitor_rate", "goal_tolerance", "max_effort", "max_velocity",
                           "allow_stalling", "stall_velocity_threshold", "stall_timeout", "state_interfaces"})
# ur_controllers' ScaledJointTrajectoryController adds scaled_joint_trajectory_controller_parameters.yaml.
_SCALED_JTC_KEYS = frozenset({
    "speed_scaling_interface_name", "use_speed_scaling_topic_instead", "speed_scaling_topic_name",
    "speed_scaling_sim_mode",
})
_SPEED_SCALING_KEYS = frozenset({"initial_scaling_factor", "state_interface", "command_interface"})
_COMMAND_INTERFACES = ("position", "velocity", "acceleration", "effort")
_STATE_INTERFACES = ("position", "velocity", "acceleration")
_CONSTRAINT_KEYS = frozenset({"stopped_velocity_tolerance", "goal_time", "decelerate_on_cancel"})
_JOINT_CONSTRAINT_KEYS = frozenset({"trajectory", "goal", "max_deceleration_on_cancel"})
# gains.<joint>: numbers (kept in ControllerConfig.gains), flags, and the anti-windup strategy's name.
_GAIN_NUMBERS = frozenset({
    "p", "i", "d", "i_clamp", "i_clamp_max", "i_clamp_min", "u_clamp_max", "u_clamp_min", "ff_velocity_scale",
    "tracking_time_constant", "error_deadband",
})
_GAIN_FLAGS = frozenset({"angle_wraparound", "normalize_error", "antiwindup"})
_GAIN_STRINGS = frozenset({"antiwindup_strategy"})


@dataclass(frozen=True)
class ControllerConfig:
    """A JointTrajectoryController's parameters from ros2_controllers.yaml."""

    name: str
    joints: tuple[str, ...]
    update_rate_hz: float
    command_interfaces: tuple[str, ...]
    state_interfaces: tuple[str, ...]
    goal_time_s: float
    stopped_velocity_tolerance: float
    trajectory_tolerance: dict[str, float]
    goal_tolerance: dict[str, float]
    gains: dict[str, dict[str, float]]
    allow_nonzero_velocity_at_trajectory_end: bool = False
    """Jazzy's default (false): JTC refuses a goal whose last point still moves."""
    allow_partial_joints_goal: bool = False
    """JTC's default (false): a goal must name every joint; true: the joints it leaves out hold where they are."""


@dataclass(frozen=True)
class ExecutionConfig:
    """MoveIt's trajectory_execution parameters from moveit_controllers.yaml (MoveIt defaults)."""

    allowed_start_tolerance: float = 0.01
    allowed_execution_duration_scaling: float = 1.1
    allowed_goal_duration_margin: float = 0.5
    execution_duration_monitoring: bool = True
    default_controllers: tuple[str, ...] = ()
    """moveit_simple_controller_manager's controllers marked `default: true`: MoveIt prefers them."""


def parse_controllers(
    path: Path, launch_args: Mapping[str, str] | None = None, substitute: bool = True, strict: bool = False
) -> dict[str, ControllerConfig]:
    """Return the JointTrajectoryControllers (and GripperActionControllers) of a ros2_controllers.yaml, by name.

    A GripperActionController is kept as a JointTrajectoryController of its one joint with
    nothing checked on the way: MoveIt's GripperCommand sends the last point, the gripper goes there.
    A file without a controller_manager section (one controller a file, as PAL writes them) takes
    each controller's type from the package's launch files that spawn it with this file.

    Args:
        path: The file.
        launch_args: Values of its `$(var NAME)` substitutions (the xacro args in force).
        substitute: False for a file a plan carries: its substitutions were made when the plan
            was, and a `$(` left in it is text (no environment variable is read for a plan).
        strict: --strict: a parameter the controller does not declare is an error, not a warning.

    Raises:
        ConfigError: A malformed value, or an unknown key in a JointTrajectoryController's
            parameters, `constraints` or `gains`; names the file and the key path. An
            unsupported or malformed substitution; names the file, line and substitution.
    """
    top = mapping(load_substituted_yaml(path, launch_args, merge=True) if substitute else load_yaml(path, merge=True),
                  str(path))
    manager = _ros_parameters(top, "controller_manager", path)
    where = f"{path}: controller_manager.ros__parameters.update_rate"
    rate = number(manager.get("update_rate", 100), where, positive=True)
    if rate < 1.0:  # controller_manager's update_rate is a whole number of Hz; 5e-324 made the period infinite
        raise ConfigError(f"{where}: {rate:g} Hz is below 1 Hz (controller_manager runs at a whole number of Hz)")
    if rate > MAX_UPDATE_RATE_HZ:
        # Each simulated second costs `rate` control cycles of state: 1e9 Hz asked for 24 GB.
        raise ConfigError(f"{where}: {rate:g} Hz is beyond moveplan's limit of {MAX_UPDATE_RATE_HZ:g} Hz "
                          "(ros2_control loops run at up to a few kHz)")
    controllers: dict[str, ControllerConfig] = {}
    kinds = {name: str(entry.get("type", "")) for name, entry in manager.items() if isinstance(entry, dict)}
    if not kinds and substitute:  # no controller_manager section: the launch file that spawns each gives its type
        kinds = {name: kind for name, kind in spawned_types(path).items() if _ros_parameters(top, name, path)}
    for name, kind in kinds.items():
        if "JointTrajectoryController" in kind:
            declared = _JTC_KEYS | _NODE_KEYS | (_SCALED_JTC_KEYS if "Scaled" in kind else frozenset())
            params = _ros_parameters(top, name, path, declared)
            where = f"{path}: {name}.ros__parameters"
            controllers[name] = _joint_trajectory_controller(name, kind, params, rate, where, strict)
        elif "GripperActionController" in kind:
            params = _ros_parameters(top, name, path, _GRIPPER_KEYS | _NODE_KEYS)
            joint = params.get("joint")
            if not isinstance(joint, str) or not joint:
                raise ConfigError(f"{path}: {name}.ros__parameters.joint: expected the gripper's joint, got {joint!r}")
            # MoveIt's GripperCommand sends the trajectory's last position; the gripper goes there. Executed as
            # a trajectory of that joint with nothing checked on the way (the action has no path tolerance).
            controllers[name] = replace(default_controller((joint,)), name=name, update_rate_hz=rate)
    return controllers


def default_controller(joints: Sequence[str]) -> ControllerConfig:
    """Return a JointTrajectoryController over `joints` with ros2_controllers' and controller_manager's defaults."""
    return ControllerConfig(
        name="joint_trajectory_controller", joints=tuple(joints), update_rate_hz=100.0,
        command_interfaces=("position",), state_interfaces=("position",), goal_time_s=0.0,
        stopped_velocity_tolerance=0.01, trajectory_tolerance=dict.fromkeys(joints, 0.0),
        goal_tolerance=dict.fromkeys(joints, 0.0), gains={},
    )


def parse_execution(
    path: Path, launch_args: Mapping[str, str] | None = None, substitute: bool = True
) -> ExecutionConfig:
    """Return moveit_controllers.yaml's trajectory_execution settings, MoveIt's defaults where absent.

    `launch_args` are the values of its `$(var NAME)` substitutions and `substitute` whether to
    make them, as for parse_controllers.
    """
    top = mapping(load_substituted_yaml(path, launch_args) if substitute else load_yaml(path), str(path))
    section = mapping(top.get("trajectory_execution"), f"{path}: trajectory_execution")
    defaults = ExecutionConfig()
    where = f"{path}: trajectory_execution"
    return ExecutionConfig(
        allowed_start_tolerance=number(
            section.get("allowed_start_tolerance", defaults.allowed_start_tolerance),
            f"{where}.allowed_start_tolerance",
        ),
        allowed_execution_duration_scaling=number(
            section.get("allowed_execution_duration_scaling", defaults.allowed_execution_duration_scaling),
            f"{where}.allowed_execution_duration_scaling",
        ),
        allowed_goal_duration_margin=number(
            section.get("allowed_goal_duration_margin", defaults.allowed_goal_duration_margin),
            f"{where}.allowed_goal_duration_margin",
        ),
        execution_duration_monitoring=boolean(
            section.get("execution_duration_monitoring", defaults.execution_duration_monitoring),
            f"{where}.execution_duration_monitoring",
        ),
        default_controllers=_default_controllers(top.get("moveit_simple_controller_manager"), path),
    )


def _default_controllers(value: Any, path: Path) -> tuple[str, ...]:
    """Return the controllers moveit_simple_controller_manager lists with `default: true`."""
    where = f"{path}: moveit_simple_controller_manager"
    manager = mapping(value, where)
    names = string_list(manager.get("controller_names"), f"{where}.controller_names", "controller names")
    return tuple(name for name in names if isinstance(manager.get(name), dict)
                 and boolean(manager[name].get("default", False), f"{where}.{name}.default"))


def _warn_unknown(params: Mapping[str, Any], allowed: frozenset[str], where: str, strict: bool) -> None:
    """Warn about parameters the controller does not declare: ros2_control ignores them, and so does moveplan.

    A node ignores an override it does not declare; the legacy `interface_name` (Foxy's) among them.
    A typo inside `constraints` or `gains` changes what is checked, and stays an error there.
    With `strict` (--strict), each is a ConfigError instead.
    """
    for key in params:
        if key in allowed:
            continue
        if key == "interface_name":
            if strict:
                raise ConfigError(f"{where}: interface_name: today's JointTrajectoryController does not declare it "
                                  "(command_interfaces name the interface); --strict refuses it")
            logger.warning("%s: interface_name is ignored, as today's JointTrajectoryController ignores it "
                           "(command_interfaces name the interface)", where)
            continue
        near = difflib.get_close_matches(str(key), sorted(allowed), n=1)
        hint = f" (did you mean '{near[0]}'?)" if near else ""
        if strict:
            raise ConfigError(f"{where}: unknown parameter '{key}'{hint}: the controller does not declare it; "
                              "--strict refuses it")
        logger.warning("%s: unknown parameter '%s' ignored, as the controller ignores parameters it does not "
                       "declare%s", where, key, hint)


def _ros_parameters(
    top: dict[str, Any], node: str, path: Path, declared: frozenset[str] | None = None
) -> dict[str, Any]:
    """Return the parameters a ROS 2 parameter file gives `node`, merged in file order as rclcpp does.

    A section applies to the node when its key names it in any namespace (`controller_manager`,
    `/robot/controller_manager`, or nested: `/robot:` holding `controller_manager:`) or matches it
    by wildcard (`/**`, `/**/controller_manager`, `*`). A section whose node name is a wildcard
    serves every node: of its parameters, only those in `declared` are the node's (a node ignores
    overrides it does not declare); a section naming the node is kept whole.
    """
    merged: dict[str, Any] = {}
    for key, params in _sections(top, "", path):
        if _names_node(key, node):
            if "*" in key.rstrip("/").rsplit("/", 1)[-1] and declared is not None:
                params = {k: v for k, v in params.items() if k in declared}
            merged.update(params)
    return merged


def _sections(entries: dict[str, Any], prefix: str, path: Path) -> list[tuple[str, dict[str, Any]]]:
    """Return (node key, parameters) of each `ros__parameters` block, in file order, namespaces joined."""
    found: list[tuple[str, dict[str, Any]]] = []
    for key, section in entries.items():
        if not isinstance(key, str) or not isinstance(section, dict):
            continue
        name = f"{prefix}/{key.strip('/')}" if prefix else key
        where = f"{path}: {name}"
        if "ros__parameters" in section:
            found.append((name, mapping(section.get("ros__parameters"), f"{where}.ros__parameters")))
        found.extend(_sections({k: v for k, v in section.items() if k != "ros__parameters"}, name, path))
    return found


def _names_node(key: str, node: str) -> bool:
    """Return whether a parameter file's top-level key applies to a node named `node` (in some namespace)."""
    # The namespace is the launch file's choice, unknown here: only the key's last name is compared.
    last = key.strip("/").rsplit("/", 1)[-1]
    return last == "**" or re.fullmatch(re.escape(last).replace(r"\*", "[^/]*"), node) is not None


def _joint_trajectory_controller(
    name: str, kind: str, params: dict[str, Any], rate: float, where: str, strict: bool = False
) -> ControllerConfig:
    """Return one JointTrajectoryController's settings from its checked `ros__parameters` (at `where`)."""
    scaled = _SCALED_JTC_KEYS if "ScaledJointTrajectoryController" in kind else frozenset()
    _warn_unknown(params, _JTC_KEYS | _NODE_KEYS | scaled, where, strict)
    check_keys(mapping(params.get("speed_scaling"), f"{where}.speed_scaling"), _SPEED_SCALING_KEYS,
               f"{where}.speed_scaling")
    joints = tuple(string_list(params.get("joints"), f"{where}.joints", "joint names"))
    if not joints:
        raise ConfigError(f"{where}.joints: a JointTrajectoryController needs joints")
    constraints = mapping(params.get("constraints"), f"{where}.constraints")
    check_keys(constraints, _CONSTRAINT_KEYS | set(joints), f"{where}.constraints")
    trajectory, goal = {}, {}
    for joint in joints:
        entry = mapping(constraints.get(joint), f"{where}.constraints.{joint}")
        check_keys(entry, _JOINT_CONSTRAINT_KEYS, f"{where}.constraints.{joint}")
        trajectory[joint] = number(entry.get("trajectory", 0.0), f"{where}.constraints.{joint}.trajectory")
        goal[joint] = number(entry.get("goal", 0.0), f"{where}.constraints.{joint}.goal")
    commands = _interfaces(params.get("command_interfaces"), _COMMAND_INTERFACES, f"{where}.command_interfaces")
    states = _interfaces(params.get("state_interfaces"), _STATE_INTERFACES, f"{where}.state_interfaces")
    if (commands == ("velocity",) or "effort" in commands) and "velocity" not in states:
        # JTC's on_configure checks this, across the two lists its parameter validators see one at a time.
        raise ConfigError(f"{where}.state_interfaces: {list(states)}: command_interfaces {list(commands)} need "
                          "'position' and 'velocity' state interfaces (ros2_controllers' joint_trajectory_controller"
                          ".cpp, on_configure)")
    return ControllerConfig(
        name=name,
        joints=joints,
        update_rate_hz=rate,
        command_interfaces=commands,
        state_interfaces=states,
        goal_time_s=number(constraints.get("goal_time", 0.0), f"{where}.constraints.goal_time"),
        stopped_velocity_tolerance=number(
            constraints.get("stopped_velocity_tolerance", 0.01), f"{where}.constraints.stopped_velocity_tolerance"
        ),
        trajectory_tolerance=trajectory,
        goal_tolerance=goal,
        gains=_gains(params.get("gains"), joints, f"{where}.gains"),
        allow_nonzero_velocity_at_trajectory_end=boolean(
            params.get("allow_nonzero_velocity_at_trajectory_end", False),
            f"{where}.allow_nonzero_velocity_at_trajectory_end"),
        allow_partial_joints_goal=boolean(params.get("allow_partial_joints_goal", False),
                                          f"{where}.allow_partial_joints_goal"),
    )


def _interfaces(value: Any, allowed: tuple[str, ...], where: str) -> tuple[str, ...]:
    """Return a JointTrajectoryController's command or state interfaces, checked as it checks them when configured.

    ros2_controllers' joint_trajectory_controller_parameters.yaml declares both lists `unique`, not
    empty and a subset of `allowed`; validate_jtc_parameters.hpp refuses the combinations below, as
    of Jazzy (which added `[position, effort]`). A list left out is position, moveplan's default.
    """
    if value is None:
        return ("position",)
    if not isinstance(value, list) or not value or not all(isinstance(v, str) for v in value):
        raise ConfigError(f"{where}: expected a non-empty list of interface names, got {str(value)[:60]}")
    unknown = [v for v in value if v not in allowed]
    if unknown:
        raise ConfigError(f"{where}: {unknown[0][:40]!r} is not an interface a JointTrajectoryController uses; "
                          f"expected some of {', '.join(allowed)}")
    if len(set(value)) < len(value):
        raise ConfigError(f"{where}: {value} names an interface twice")
    has = set(value)
    if allowed is _COMMAND_INTERFACES:
        problem = ("'velocity' is used alone or with 'position'" if "velocity" in has and len(has) > 1
                   and "position" not in has else
                   "'acceleration' needs 'velocity' or 'position'" if "acceleration" in has
                   and not has & {"velocity", "position"} else
                   "'effort' is used alone or with 'position'" if "effort" in has and has - {"effort", "position"}
                   else "")
    else:
        # The controller reads the joints' positions: without them it has no state to follow from.
        problem = ("'position' is required" if "position" not in has else
                   "'acceleration' needs 'position' and 'velocity'" if "acceleration" in has
                   and "velocity" not in has else "")
    if problem:
        raise ConfigError(f"{where}: {value}: {problem} (ros2_controllers' validate_jtc_parameters.hpp)")
    return tuple(value)


def _gains(value: Any, joints: tuple[str, ...], where: str) -> dict[str, dict[str, float]]:
    """Return the numeric gains by joint; flags and the anti-windup strategy are checked, not kept."""
    section = mapping(value, where)
    check_keys(section, set(joints), where)
    gains: dict[str, dict[str, float]] = {}
    for joint, entry in section.items():
        at = f"{where}.{joint}"
        entry = mapping(entry, at)
        check_keys(entry, _GAIN_NUMBERS | _GAIN_FLAGS | _GAIN_STRINGS, at)
        for key in _GAIN_FLAGS & entry.keys():
            boolean(entry[key], f"{at}.{key}")
        for key in _GAIN_STRINGS & entry.keys():
            if not isinstance(entry[key], str):
                raise ConfigError(f"{at}.{key}: expected a string, got {entry[key]!r}")
        gains[joint] = {k: number(v, f"{at}.{k}") for k, v in entry.items() if k in _GAIN_NUMBERS}
    return gains
