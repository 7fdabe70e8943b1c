"""Robot configuration: reads moveplan.yaml and the MoveIt / ros2_control files it names.

This is the one place that parses YAML and XML into typed values; every error
names the file and key path. Limits are merged as MoveIt does: URDF limits,
overridden by joint_limits.yaml.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from importlib import resources
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from moveplan.core.errors import ConfigError, UnknownName, known

__all__ = [
    "ControllerConfig",
    "ExecutionConfig",
    "Group",
    "JointLimit",
    "RobotConfig",
    "Srdf",
    "UrdfJoint",
    "check_keys",
    "load_robot_config",
    "load_yaml",
    "parse_controllers",
    "number",
    "resolve_config_path",
    "shipped_configs",
]

CONFIG_FILE = "moveplan.yaml"


# --- small validation helpers, shared with scene and task parsing -----------------------


def load_yaml(path: Path) -> Any:
    """Return the parsed content of a YAML file; ConfigError names the file and line."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read: {exc}") from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"{path}:{where} malformed YAML: {problem}") from None


def mapping(value: Any, where: str) -> dict[str, Any]:
    """Return `value` if it is a mapping with string keys, else raise ConfigError at `where`."""
    if value is None:
        return {}
    if not isinstance(value, Mapping) or not all(isinstance(k, str) for k in value):
        raise ConfigError(f"{where}: expected a mapping, got {type(value).__name__}")
    return dict(value)


def check_keys(value: Mapping[str, Any], allowed: set[str], where: str) -> None:
    """Raise ConfigError for the first key of `value` not in `allowed` (typos must not pass)."""
    for key in value:
        if key not in allowed:
            raise ConfigError(f"{where}: unknown key '{key}'; expected one of: {known(allowed)}")


def number(value: Any, where: str, positive: bool = False) -> float:
    """Return `value` as a finite float, else raise ConfigError at `where`."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ConfigError(f"{where}: expected a finite number, got {value!r}")
    if positive and value <= 0:
        raise ConfigError(f"{where}: expected a positive number, got {value!r}")
    return float(value)


# --- typed configuration ------------------------------------------------------------------


@dataclass(frozen=True)
class UrdfJoint:
    """A joint as written in the URDF: type, parent and child links, limits (NaN when absent)."""

    name: str
    type: str
    parent: str
    child: str
    lower: float = math.nan
    upper: float = math.nan
    velocity: float = math.nan


@dataclass(frozen=True)
class JointLimit:
    """Merged limits of one joint in [rad] (or [m]), [rad]/[s], [rad]/[s]^2, with their sources."""

    lower: float
    upper: float
    max_velocity: float
    max_acceleration: float
    continuous: bool
    source: dict[str, str]


@dataclass(frozen=True)
class Group:
    """A planning group: its active joints in order, base and tip links."""

    name: str
    joints: tuple[str, ...]
    base: str
    tip: str


@dataclass(frozen=True)
class Srdf:
    """What moveplan uses of an SRDF: groups, named states and disabled collision pairs."""

    name: str
    groups: dict[str, Group]
    group_states: dict[str, dict[str, dict[str, float]]]
    disabled_pairs: frozenset[frozenset[str]]


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


@dataclass(frozen=True)
class ExecutionConfig:
    """MoveIt's trajectory_execution parameters from moveit_controllers.yaml (MoveIt defaults)."""

    allowed_start_tolerance: float = 0.01
    allowed_execution_duration_scaling: float = 1.1
    allowed_goal_duration_margin: float = 0.5
    execution_duration_monitoring: bool = True


@dataclass(frozen=True)
class RobotConfig:
    """A robot config folder, parsed: file paths, texts and typed settings.

    Attributes:
        name: Robot name.
        root: The config folder.
        urdf_path: URDF file; `urdf` its text.
        urdf_joints: URDF joints by name, in file order.
        srdf: Parsed SRDF; `srdf_path` its file.
        limits: Merged limits of every movable URDF joint.
        default_velocity_scaling, default_acceleration_scaling: From joint_limits.yaml (MoveIt: 0.1).
        controllers: JointTrajectoryControllers from ros2_controllers.yaml.
        execution: MoveIt's trajectory_execution settings.
        initial_positions: Where the fake hardware starts (joint -> value).
        planning: moveplan.yaml `planning` defaults: group, planner, planning_time.
        files: File name -> bytes of every config file, to embed in plan files.
        package_paths: Folders searched for `package://` URIs.
    """

    name: str
    root: Path
    urdf_path: Path
    urdf: str
    urdf_joints: dict[str, UrdfJoint]
    srdf_path: Path
    srdf: Srdf
    limits: dict[str, JointLimit]
    default_velocity_scaling: float
    default_acceleration_scaling: float
    controllers: dict[str, ControllerConfig]
    execution: ExecutionConfig
    initial_positions: dict[str, float]
    planning: dict[str, Any]
    files: dict[str, bytes] = field(default_factory=dict)
    package_paths: tuple[Path, ...] = ()

    def group(self, name: str | None = None) -> Group:
        """Return the named planning group, or the config's default one."""
        name = name or self.planning["group"]
        if name not in self.srdf.groups:
            raise UnknownName("group", name, str(self.srdf_path), self.srdf.groups)
        return self.srdf.groups[name]


# --- loading --------------------------------------------------------------------------------

_MOVEPLAN_KEYS = {
    "name", "urdf", "srdf", "joint_limits", "controllers", "moveit_controllers",
    "initial_positions", "planning", "package_paths",
}
_PLANNING_KEYS = {"group", "planner", "planning_time"}
_LIMIT_KEYS = {
    "has_position_limits", "min_position", "max_position", "has_velocity_limits", "max_velocity",
    "has_acceleration_limits", "max_acceleration", "has_deceleration_limits", "max_deceleration",
    "has_jerk_limits", "max_jerk", "has_effort_limits", "max_effort", "angle_wraparound",
}


def resolve_config_path(robot: str | Path) -> Path:
    """Return the moveplan.yaml a --robot argument names (the file, or a folder holding one)."""
    path = Path(robot)
    shipped = Path(str(resources.files("moveplan.configs"))) / str(robot)
    if not path.exists() and path.name == str(robot) and (shipped / CONFIG_FILE).is_file():
        path = shipped  # a bare name like "ur10e" names a config shipped with moveplan
    if path.is_dir():
        path = path / CONFIG_FILE
    if not path.is_file():
        raise ConfigError(f"{robot}: robot config not found (expected a {CONFIG_FILE} or a folder holding one, "
                          f"or a shipped config: {known(shipped_configs())})")
    return path


def shipped_configs() -> list[str]:
    """Return the names of the robot configs shipped with moveplan."""
    folder = Path(str(resources.files("moveplan.configs")))
    return sorted(p.name for p in folder.iterdir() if (p / CONFIG_FILE).is_file())


def load_robot_config(robot: str | Path, package_paths: tuple[Path, ...] = ()) -> RobotConfig:
    """Return the parsed robot config at `robot` (a moveplan.yaml or its folder)."""
    path = resolve_config_path(robot)
    root = path.parent
    top = mapping(load_yaml(path), str(path))
    check_keys(top, _MOVEPLAN_KEYS, str(path))
    files: dict[str, bytes] = {CONFIG_FILE: path.read_bytes()}

    def named_file(key: str, required: bool = True) -> Path | None:
        if key not in top:
            if required:
                raise ConfigError(f"{path}: missing key '{key}'")
            return None
        if not isinstance(top[key], str):
            raise ConfigError(f"{path}: {key}: expected a file name, got {top[key]!r}")
        file = root / top[key]
        if not file.is_file():
            raise ConfigError(f"{path}: {key}: file not found: {file}")
        # Keyed by the path moveplan.yaml names, so the files can be laid out again as a config.
        files[top[key]] = file.read_bytes()
        return file

    urdf_path = named_file("urdf")
    srdf_path = named_file("srdf")
    assert urdf_path is not None and srdf_path is not None
    urdf_text, urdf_joints = _parse_urdf(urdf_path)
    srdf = _parse_srdf(srdf_path, urdf_joints)

    limits_path = named_file("joint_limits", required=False)
    limit_overrides, v_scale, a_scale = _parse_joint_limits(limits_path)
    limits = _merge_limits(urdf_path, urdf_joints, limits_path, limit_overrides)

    controllers_path = named_file("controllers", required=False)
    controllers = parse_controllers(controllers_path) if controllers_path else {}
    moveit_path = named_file("moveit_controllers", required=False)
    execution = _parse_execution(moveit_path) if moveit_path else ExecutionConfig()
    initial_path = named_file("initial_positions", required=False)
    initial = _parse_initial_positions(initial_path, limits) if initial_path else {}

    planning = mapping(top.get("planning"), f"{path}: planning")
    check_keys(planning, _PLANNING_KEYS, f"{path}: planning")
    planning.setdefault("group", next(iter(srdf.groups), ""))
    planning.setdefault("planner", "RRTConnect")
    planning["planning_time"] = number(
        planning.get("planning_time", 1.0), f"{path}: planning.planning_time", positive=True
    )
    extra_paths = tuple(root / p for p in top.get("package_paths", []) or [])
    config = RobotConfig(
        name=str(top.get("name") or srdf.name),
        root=root,
        urdf_path=urdf_path,
        urdf=urdf_text,
        urdf_joints=urdf_joints,
        srdf_path=srdf_path,
        srdf=srdf,
        limits=limits,
        default_velocity_scaling=v_scale,
        default_acceleration_scaling=a_scale,
        controllers=controllers,
        execution=execution,
        initial_positions=initial,
        planning=planning,
        files=files,
        package_paths=(root, *extra_paths, *package_paths),
    )
    config.group()  # an unknown default group is a config error, found at load time
    return config


def _xml_root(path: Path) -> ET.Element:
    try:
        return ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise ConfigError(f"{path}: malformed XML: {exc}") from None


def _float_attr(element: ET.Element, name: str, path: Path, default: float = math.nan) -> float:
    text = element.get(name)
    if text is None:
        return default
    try:
        return float(text)
    except ValueError:
        raise ConfigError(f"{path}: <{element.tag}> {name}='{text}' is not a number") from None


def _parse_urdf(path: Path) -> tuple[str, dict[str, UrdfJoint]]:
    root = _xml_root(path)
    if root.tag != "robot":
        raise ConfigError(f"{path}: not a URDF (root element is <{root.tag}>, expected <robot>)")
    links = {link.get("name", "") for link in root.findall("link")}
    joints: dict[str, UrdfJoint] = {}
    for element in root.findall("joint"):
        name = element.get("name", "")
        parent, child = element.find("parent"), element.find("child")
        if parent is None or child is None:
            raise ConfigError(f"{path}: joint '{name}' needs <parent> and <child>")
        for link in (parent.get("link", ""), child.get("link", "")):
            if link not in links:
                raise ConfigError(f"{path}: joint '{name}' names link '{link}', which is not defined")
        limit = element.find("limit")
        lower = upper = velocity = math.nan
        if limit is not None:
            lower = _float_attr(limit, "lower", path, 0.0)
            upper = _float_attr(limit, "upper", path, 0.0)
            velocity = _float_attr(limit, "velocity", path)
        joints[name] = UrdfJoint(
            name, element.get("type", ""), parent.get("link", ""), child.get("link", ""),
            lower, upper, velocity,
        )
    return path.read_text(encoding="utf-8"), joints


def _chain(path: Path, joints: dict[str, UrdfJoint], base: str, tip: str) -> list[str]:
    """Return the joints from `base` to `tip`, in order."""
    parent_joint = {j.child: j for j in joints.values()}
    links = {j.child for j in joints.values()} | {j.parent for j in joints.values()}
    for link in (base, tip):
        if link not in links:
            raise UnknownName("link", link, str(path), links)
    chain: list[str] = []
    link = tip
    while link != base:
        if link not in parent_joint:
            raise ConfigError(f"{path}: chain: '{tip}' does not descend from '{base}'")
        joint = parent_joint[link]
        chain.append(joint.name)
        link = joint.parent
    return chain[::-1]


def _parse_srdf(path: Path, joints: dict[str, UrdfJoint]) -> Srdf:
    root = _xml_root(path)
    if root.tag != "robot":
        raise ConfigError(f"{path}: not an SRDF (root element is <{root.tag}>, expected <robot>)")
    movable = [j.name for j in joints.values() if j.type in ("revolute", "continuous", "prismatic")]
    groups: dict[str, Group] = {}
    for element in root.findall("group"):
        name = element.get("name", "")
        names: list[str] = []
        base = tip = ""
        for chain in element.findall("chain"):
            base, tip = chain.get("base_link", ""), chain.get("tip_link", "")
            names += _chain(path, joints, base, tip)
        for joint in element.findall("joint"):
            jname = joint.get("name", "")
            if jname not in joints:
                raise UnknownName("joint", jname, f"{path} group '{name}'", joints)
            names.append(jname)
        for sub in element.findall("group"):
            sub_name = sub.get("name", "")
            if sub_name not in groups:
                raise UnknownName("group", sub_name, f"{path} group '{name}'", groups)
            names += groups[sub_name].joints
        active = tuple(n for n in dict.fromkeys(names) if n in movable)
        if not base and active:
            base, tip = joints[active[0]].parent, joints[active[-1]].child
        groups[name] = Group(name, active, base, tip)
    if not groups:
        raise ConfigError(f"{path}: defines no <group>")

    states: dict[str, dict[str, dict[str, float]]] = {g: {} for g in groups}
    for element in root.findall("group_state"):
        group, name = element.get("group", ""), element.get("name", "")
        if group not in groups:
            raise UnknownName("group", group, f"{path} group_state '{name}'", groups)
        values: dict[str, float] = {}
        for joint in element.findall("joint"):
            jname = joint.get("name", "")
            if jname not in joints:
                raise UnknownName("joint", jname, f"{path} group_state '{name}'", joints)
            values[jname] = _float_attr(joint, "value", path, 0.0)
        states[group][name] = values

    disabled = frozenset(
        frozenset((e.get("link1", ""), e.get("link2", ""))) for e in root.findall("disable_collisions")
    )
    return Srdf(root.get("name", ""), groups, states, disabled)


def _parse_joint_limits(path: Path | None) -> tuple[dict[str, dict[str, Any]], float, float]:
    if path is None:
        return {}, 0.1, 0.1
    top = mapping(load_yaml(path), str(path))
    # MoveIt loads this file under robot_description_planning; accept it written either way.
    if "robot_description_planning" in top:
        top = mapping(top["robot_description_planning"], f"{path}: robot_description_planning")
    check_keys(
        top,
        {"joint_limits", "default_velocity_scaling_factor", "default_acceleration_scaling_factor",
         "cartesian_limits"},
        str(path),
    )
    scales = []
    for key in ("default_velocity_scaling_factor", "default_acceleration_scaling_factor"):
        value = number(top.get(key, 0.1), f"{path}: {key}", positive=True)
        if value > 1.0:
            raise ConfigError(f"{path}: {key}: expected a number in (0, 1], got {value}")
        scales.append(value)
    entries = mapping(top.get("joint_limits"), f"{path}: joint_limits")
    overrides: dict[str, dict[str, Any]] = {}
    for joint, entry in entries.items():
        where = f"{path}: joint_limits.{joint}"
        entry = mapping(entry, where)
        check_keys(entry, _LIMIT_KEYS, where)
        overrides[joint] = entry
    return overrides, scales[0], scales[1]


def _merge_limits(
    urdf_path: Path,
    joints: dict[str, UrdfJoint],
    limits_path: Path | None,
    overrides: dict[str, dict[str, Any]],
) -> dict[str, JointLimit]:
    for joint in overrides:
        if joint not in joints:
            raise UnknownName("joint", joint, f"{limits_path}: joint_limits", joints)
    limits: dict[str, JointLimit] = {}
    for joint in joints.values():
        if joint.type not in ("revolute", "continuous", "prismatic"):
            continue
        continuous = joint.type == "continuous"
        lower, upper = (-math.pi, math.pi) if continuous else (joint.lower, joint.upper)
        velocity, acceleration = joint.velocity, math.nan
        urdf_name, file_name = urdf_path.name, limits_path.name if limits_path else ""
        source = {"position": urdf_name, "velocity": urdf_name, "acceleration": ""}
        entry = overrides.get(joint.name, {})
        where = f"{limits_path}: joint_limits.{joint.name}"
        if entry.get("has_position_limits") and not continuous:
            lower = number(entry.get("min_position", lower), f"{where}.min_position")
            upper = number(entry.get("max_position", upper), f"{where}.max_position")
            source["position"] = file_name
        if entry.get("has_velocity_limits"):
            velocity = number(entry.get("max_velocity"), f"{where}.max_velocity", positive=True)
            source["velocity"] = file_name
        if entry.get("has_acceleration_limits"):
            acceleration = number(entry.get("max_acceleration"), f"{where}.max_acceleration", positive=True)
            source["acceleration"] = file_name
        if not lower <= upper:
            raise ConfigError(f"{urdf_path}: joint '{joint.name}': lower limit {lower} above upper {upper}")
        limits[joint.name] = JointLimit(lower, upper, velocity, acceleration, continuous, source)
    return limits


def _ros_parameters(top: dict[str, Any], node: str, path: Path) -> dict[str, Any]:
    section = mapping(top.get(node), f"{path}: {node}")
    return mapping(section.get("ros__parameters"), f"{path}: {node}.ros__parameters")


def parse_controllers(path: Path) -> dict[str, ControllerConfig]:
    """Return the JointTrajectoryControllers configured in a ros2_controllers.yaml."""
    top = mapping(load_yaml(path), str(path))
    manager = _ros_parameters(top, "controller_manager", path)
    rate = number(manager.get("update_rate", 100), f"{path}: controller_manager.ros__parameters.update_rate",
                  positive=True)
    controllers: dict[str, ControllerConfig] = {}
    for name, entry in manager.items():
        if not (isinstance(entry, dict) and "JointTrajectoryController" in str(entry.get("type", ""))):
            continue
        params = _ros_parameters(top, name, path)
        where = f"{path}: {name}.ros__parameters"
        joints = tuple(params.get("joints") or ())
        if not joints:
            raise ConfigError(f"{where}.joints: a JointTrajectoryController needs joints")
        constraints = mapping(params.get("constraints"), f"{where}.constraints")
        trajectory, goal = {}, {}
        for joint in joints:
            entry_j = mapping(constraints.get(joint), f"{where}.constraints.{joint}")
            trajectory[joint] = number(entry_j.get("trajectory", 0.0), f"{where}.constraints.{joint}.trajectory")
            goal[joint] = number(entry_j.get("goal", 0.0), f"{where}.constraints.{joint}.goal")
        gains = {
            joint: {k: number(v, f"{where}.gains.{joint}.{k}") for k, v in mapping(g, f"{where}.gains.{joint}").items()
                    if not isinstance(v, bool)}
            for joint, g in mapping(params.get("gains"), f"{where}.gains").items()
        }
        controllers[name] = ControllerConfig(
            name=name,
            joints=joints,
            update_rate_hz=rate,
            command_interfaces=tuple(params.get("command_interfaces") or ("position",)),
            state_interfaces=tuple(params.get("state_interfaces") or ("position",)),
            goal_time_s=number(constraints.get("goal_time", 0.0), f"{where}.constraints.goal_time"),
            stopped_velocity_tolerance=number(
                constraints.get("stopped_velocity_tolerance", 0.01),
                f"{where}.constraints.stopped_velocity_tolerance",
            ),
            trajectory_tolerance=trajectory,
            goal_tolerance=goal,
            gains=gains,
        )
    return controllers


def _parse_execution(path: Path) -> ExecutionConfig:
    top = mapping(load_yaml(path), str(path))
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
        execution_duration_monitoring=bool(section.get("execution_duration_monitoring", True)),
    )


def _parse_initial_positions(path: Path, limits: dict[str, JointLimit]) -> dict[str, float]:
    top = mapping(load_yaml(path), str(path))
    values = mapping(top.get("initial_positions", top), f"{path}: initial_positions")
    result = {}
    for joint, value in values.items():
        if joint not in limits:
            raise UnknownName("joint", joint, f"{path}: initial_positions", limits)
        result[joint] = number(value, f"{path}: initial_positions.{joint}")
    return result
