"""Robot configuration: reads moveplan.yaml or a MoveIt config package, and the files they name.

This is the one place that parses YAML and XML into typed values; every error
names the file and key path. Limits are merged as MoveIt does: URDF limits,
overridden by joint_limits.yaml.

Where a config's files come from (`RobotConfig.sources` records each):

- A moveplan.yaml names them (relative to itself, or `package://pkg/...`); a URDF or
  SRDF ending in .xacro is expanded with its `xacro_args`, overridden by --xacro-arg.
- A folder without moveplan.yaml is a MoveIt config package (or a plain folder): the
  SRDF is the one *.srdf(.xacro) in the first of config/, srdf/, the folder that has
  any; the URDF the one *.urdf(.xacro) in the first of config/, urdf/, the folder
  (several: the one named like the SRDF); joint_limits.yaml, kinematics.yaml,
  ros2_controllers.yaml, moveit_controllers.yaml, initial_positions.yaml and
  ompl_planning.yaml by name, in config/ before the folder. More than one candidate
  is an error that asks for a moveplan.yaml.
- Planning defaults: moveplan.yaml `planning` > ompl_planning.yaml's first group
  and its default planner > the SRDF's first group and RRTConnect.
- `$(find pkg)` and `package://pkg` search, in order: the config folder,
  moveplan.yaml `package_paths`, --package-path, ROS_PACKAGE_PATH, AMENT_PREFIX_PATH
  shares, and Python-installed (cmeel) package shares (core/config/xacro.py finds them).
"""

from __future__ import annotations

import math
import os
import sys
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import yaml

from ..errors import ConfigError, UnknownName, UsageError, known
from .xacro import PackagePath, process_xacro

__all__ = [
    "COLLISION_MODES",
    "CollisionMesh",
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
    "search_path",
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
        # libyaml's loader, where PyYAML has it, reads a MotionBenchMaker scene 10x faster.
        return yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))  # noqa: S506 - a safe loader
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
class CollisionMesh:
    """A collision mesh of a link: the URI the URDF gives and the file it resolves to."""

    link: str
    uri: str
    path: Path
    package: str = ""


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
        planning: moveplan.yaml `planning` defaults: group, planner, planning_time, and
            collision (`exact`: the URDF's meshes; `convex`: their convex hulls).
        files: File name -> bytes of every config file, to embed in plan files; laid out in
            one folder they load again as this config (expanded URDF, generated moveplan.yaml).
        package_paths: Folders searched for `$(find pkg)` and `package://` URIs, in order.
        sources: Setting -> the file it came from: urdf, srdf, joint_limits, kinematics,
            controllers, moveit_controllers, initial_positions, ompl_planning, moveplan (the
            moveplan.yaml), planning (the file that chose the default group). Absent: not given.
        urdf_includes: Every file the URDF was made of (the .urdf, or the xacro and its includes).
        kinematics: kinematics.yaml's settings per group (reported; moveplan solves IK itself).
        xacro_args: The xacro args the URDF and SRDF were expanded with.
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
    sources: dict[str, Path] = field(default_factory=dict)
    urdf_includes: tuple[Path, ...] = ()
    kinematics: dict[str, dict[str, Any]] = field(default_factory=dict)
    xacro_args: dict[str, str] = field(default_factory=dict)

    def group(self, name: str | None = None) -> Group:
        """Return the named planning group, or the config's default one."""
        name = name or self.planning["group"]
        if name not in self.srdf.groups:
            raise UnknownName("group", name, str(self.srdf_path), self.srdf.groups)
        return self.srdf.groups[name]

    def missing_acceleration_limits(self, group: str | None = None) -> tuple[str, ...]:
        """Return the group's joints without an acceleration limit (planning needs one for each)."""
        return tuple(j for j in self.group(group).joints if math.isnan(self.limits[j].max_acceleration))

    def collision_meshes(self) -> tuple[CollisionMesh, ...]:
        """Return every collision mesh of the URDF with the file it resolves to.

        Raises:
            ConfigError: A mesh whose package cannot be found or whose file does not exist;
                names the URDF, the link, the URI, the package and the search path.
        """
        return _collision_meshes(self)[1]

    def collision_urdf(self) -> str:
        """Return the URDF with every collision mesh's filename replaced by its absolute path."""
        return _collision_meshes(self)[0]


# --- loading --------------------------------------------------------------------------------

_MOVEPLAN_KEYS = {
    "name", "urdf", "srdf", "joint_limits", "kinematics", "controllers", "moveit_controllers",
    "initial_positions", "planning", "package_paths", "xacro_args",
}
_FILE_KEYS = ("urdf", "srdf", "joint_limits", "kinematics", "controllers", "moveit_controllers", "initial_positions")
_PLANNING_KEYS = {"group", "planner", "planning_time", "collision"}
COLLISION_MODES = ("exact", "convex")  # robot meshes as triangle BVHs, or as their convex hulls
_LIMIT_KEYS = {
    "has_position_limits", "min_position", "max_position", "has_velocity_limits", "max_velocity",
    "has_acceleration_limits", "max_acceleration", "has_deceleration_limits", "max_deceleration",
    "has_jerk_limits", "max_jerk", "has_effort_limits", "max_effort", "angle_wraparound",
}
# A folder without moveplan.yaml: a MoveIt config package keeps these in config/, a plain folder
# beside the URDF; config/ is searched first.
_PACKAGE_FILES = {
    "joint_limits": "joint_limits.yaml",
    "kinematics": "kinematics.yaml",
    "controllers": "ros2_controllers.yaml",
    "moveit_controllers": "moveit_controllers.yaml",
    "initial_positions": "initial_positions.yaml",
    "ompl_planning": "ompl_planning.yaml",
}
_SRDF_FOLDERS = ("config", "srdf", ".")
_URDF_FOLDERS = ("config", "urdf", ".")


def resolve_config_path(robot: str | Path) -> Path:
    """Return what a --robot argument names: a moveplan.yaml, or a folder to read without one.

    A bare name such as `ur10e` names a config shipped with moveplan. A folder holding a
    moveplan.yaml means that file; a folder without one is read as a MoveIt config package
    (or a plain folder holding a URDF and an SRDF) if it holds an SRDF.
    """
    path = Path(robot)
    shipped = Path(str(resources.files("moveplan.configs"))) / str(robot)
    if not path.exists() and path.name == str(robot) and (shipped / CONFIG_FILE).is_file():
        path = shipped
    if path.is_dir():
        if (path / CONFIG_FILE).is_file():
            return path / CONFIG_FILE
        if any(_candidates(path / sub, (".srdf", ".srdf.xacro")) for sub in _SRDF_FOLDERS):
            return path
        raise ConfigError(f"{robot}: no robot config: no {CONFIG_FILE}, and no *.srdf in config/, srdf/ "
                          "or the folder itself (a MoveIt config package)")
    if not path.is_file():
        raise ConfigError(f"{robot}: robot config not found (expected a {CONFIG_FILE}, a folder holding one, "
                          f"a MoveIt config package, or a shipped config: {known(shipped_configs())})")
    return path


def shipped_configs() -> list[str]:
    """Return the names of the robot configs shipped with moveplan."""
    folder = Path(str(resources.files("moveplan.configs")))
    return sorted(p.name for p in folder.iterdir() if (p / CONFIG_FILE).is_file())


def search_path(root: Path, package_paths: Sequence[Path] = (), extra: Sequence[Path] = ()) -> tuple[Path, ...]:
    """Return the folders searched for ROS packages, in order (first match wins).

    The config folder, moveplan.yaml's `package_paths` (`extra`), --package-path, then
    ROS_PACKAGE_PATH, then the `share` folder of each AMENT_PREFIX_PATH entry (a sourced
    ROS 2 workspace), then the share folders of Python-installed (cmeel) packages such as
    example-robot-data.
    """
    env = [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    ament = [Path(p) / "share" for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    cmeel = [Path(p) / "cmeel.prefix" / "share" for p in sys.path if p]
    cmeel = [p for p in cmeel if p.is_dir()]
    return tuple(dict.fromkeys((root, *extra, *package_paths, *env, *ament, *cmeel)))


def load_robot_config(
    robot: str | Path,
    package_paths: Sequence[Path] = (),
    xacro_args: Mapping[str, str] | None = None,
) -> RobotConfig:
    """Return the parsed robot config at `robot`.

    Args:
        robot: A moveplan.yaml, a folder holding one, a MoveIt config package folder, a plain
            folder with a URDF and an SRDF, or the name of a shipped config.
        package_paths: --package-path folders, searched for `$(find pkg)` and `package://`
            after the config folder and before ROS_PACKAGE_PATH.
        xacro_args: --xacro-arg values; they override moveplan.yaml's `xacro_args`.

    Raises:
        ConfigError: A file is missing or malformed; the message names file and key.
        UsageError: A --xacro-arg the xacro files do not declare.
    """
    path = resolve_config_path(robot)
    manifest = path if path.is_file() else None
    root = path.parent if manifest else path
    top: dict[str, Any] = {}
    extra: tuple[Path, ...] = ()
    if manifest is not None:
        top = mapping(load_yaml(manifest), str(manifest))
        check_keys(top, _MOVEPLAN_KEYS, str(manifest))
        extra = tuple(root / p for p in _strings(top.get("package_paths"), f"{manifest}: package_paths"))
    packages = PackagePath(search_path(root, tuple(package_paths), extra))
    paths = _manifest_files(manifest, top, packages) if manifest else _discover(root)
    args, flag_args = _xacro_args(manifest, top, xacro_args or {})

    urdf_path, srdf_path = paths["urdf"], paths["srdf"]
    urdf_text, urdf_includes, declared = _expand(urdf_path, root, args, packages)
    srdf_text, _, srdf_declared = _expand(srdf_path, root, args, packages)
    _check_xacro_args(args, flag_args, declared | srdf_declared, urdf_path, manifest)
    urdf_joints = _parse_urdf(urdf_text, urdf_path)
    srdf = _parse_srdf(srdf_text, srdf_path, urdf_joints)

    limits_path = paths.get("joint_limits")
    limit_overrides, v_scale, a_scale = _parse_joint_limits(limits_path)
    limits = _merge_limits(urdf_path, urdf_joints, limits_path, limit_overrides)
    controllers = parse_controllers(paths["controllers"]) if "controllers" in paths else {}
    execution = _parse_execution(paths["moveit_controllers"]) if "moveit_controllers" in paths else ExecutionConfig()
    initial = _parse_initial_positions(paths["initial_positions"], limits) if "initial_positions" in paths else {}
    kinematics = _parse_kinematics(paths["kinematics"], srdf) if "kinematics" in paths else {}
    planning, planning_source = _planning(manifest, top, paths.get("ompl_planning"), srdf, srdf_path)

    sources = dict(paths)
    if manifest is not None:
        sources["moveplan"] = manifest
    sources["planning"] = planning_source
    name = str(top.get("name") or srdf.name)
    texts = {"urdf": urdf_text, "srdf": srdf_text}
    config = RobotConfig(
        name=name,
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
        files=_embedded(manifest, top, root, paths, texts, name, planning),
        package_paths=packages.folders,
        sources=sources,
        urdf_includes=urdf_includes,
        kinematics=kinematics,
        xacro_args=dict(args),
    )
    config.group()  # an unknown default group is a config error, found at load time
    return config


def _strings(value: Any, where: str) -> list[str]:
    if value is None:
        return []
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ConfigError(f"{where}: expected a list of folder names, got {value!r}")
    return value


def _manifest_files(manifest: Path, top: dict[str, Any], packages: PackagePath) -> dict[str, Path]:
    """Return setting -> file for the files moveplan.yaml names (relative to it, or package://)."""
    root = manifest.parent
    paths: dict[str, Path] = {}
    for key in _FILE_KEYS:
        if key not in top:
            if key in ("urdf", "srdf"):
                raise ConfigError(f"{manifest}: missing key '{key}'")
            continue
        value = top[key]
        if not isinstance(value, str):
            raise ConfigError(f"{manifest}: {key}: expected a file name, got {value!r}")
        file = packages.resolve_uri(value, root, f"{manifest}: {key}")[0] if "://" in value else root / value
        if not file.is_file():
            raise ConfigError(f"{manifest}: {key}: file not found: {file}")
        paths[key] = file
    return paths


def _candidates(folder: Path, suffixes: tuple[str, ...]) -> list[Path]:
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir() if p.is_file() and p.name.endswith(suffixes))


def _stem(path: Path) -> str:
    """Return a robot file's name without .xacro and its format suffix: panda.urdf.xacro -> panda."""
    name = path.name.removesuffix(".xacro")
    return name.rsplit(".", 1)[0]


def _one(root: Path, folders: tuple[str, ...], suffixes: tuple[str, str], kind: str, prefer: str = "") -> Path:
    """Return the one `kind` file in the first of `folders` that has any; `prefer` breaks ties by stem."""
    for sub in folders:
        found = _candidates(root / sub, suffixes)
        if len(found) > 1:
            found = [p for p in found if _stem(p) == prefer] or found
        if len(found) == 1:
            return found[0]
        if found:
            raise ConfigError(f"{root / sub}: several {kind} files ({', '.join(p.name for p in found)}); "
                              f"write a {CONFIG_FILE} that names one")
    where = ", ".join(f"{s}/" for s in folders if s != ".")
    raise ConfigError(f"{root}: no {kind} file (*{suffixes[0]} or *{suffixes[1]}) in {where} or the folder "
                      f"itself; write a {CONFIG_FILE} that names one (urdf: package://pkg/urdf/robot.urdf.xacro)")


def _discover(root: Path) -> dict[str, Path]:
    """Return setting -> file for a folder without moveplan.yaml (see the module's loading rules)."""
    paths = {"srdf": _one(root, _SRDF_FOLDERS, (".srdf", ".srdf.xacro"), "SRDF")}
    paths["urdf"] = _one(root, _URDF_FOLDERS, (".urdf", ".urdf.xacro"), "URDF", prefer=_stem(paths["srdf"]))
    for setting, name in _PACKAGE_FILES.items():
        for sub in ("config", "."):
            if (root / sub / name).is_file():
                paths[setting] = root / sub / name
                break
    return paths


def _xacro_args(
    manifest: Path | None, top: dict[str, Any], flags: Mapping[str, str]
) -> tuple[dict[str, str], frozenset[str]]:
    """Return the xacro args in force (flag > moveplan.yaml) and the names set by flag."""
    args: dict[str, str] = {}
    for key, value in mapping(top.get("xacro_args"), f"{manifest}: xacro_args").items():
        if isinstance(value, bool):
            value = "true" if value else "false"
        if not isinstance(value, str | int | float):
            raise ConfigError(f"{manifest}: xacro_args.{key}: expected a string or number, got {value!r}")
        args[key] = str(value)
    args.update(flags)
    return args, frozenset(flags)


def _expand(
    path: Path, root: Path, args: Mapping[str, str], packages: PackagePath
) -> tuple[str, tuple[Path, ...], frozenset[str]]:
    """Return a URDF or SRDF file's XML text (through xacro for *.xacro), the files it read, its args."""
    if path.name.endswith(".xacro"):
        shown = path.relative_to(root) if path.is_relative_to(root) else Path(path.name)
        result = process_xacro(path, args, packages, str(shown))
        return result.text, (path, *(p for p in result.includes if p != path)), result.declared
    try:
        return path.read_text(encoding="utf-8"), (path,), frozenset()
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read: {exc}") from None


def _check_xacro_args(
    args: Mapping[str, str], flags: frozenset[str], declared: frozenset[str], urdf: Path, manifest: Path | None
) -> None:
    """Raise for a xacro arg no xacro file declares (a typo must not pass silently)."""
    for name in args:
        if name in declared:
            continue
        what = f"xacro arg '{name}' is not declared by {urdf} or the files it includes; declared: {known(declared)}"
        if not urdf.name.endswith(".xacro"):
            what = f"xacro arg '{name}' given, but {urdf} is not a .xacro file"
        if name in flags:
            raise UsageError(f"--xacro-arg {name}: {what}")
        raise ConfigError(f"{manifest}: xacro_args: {what}")


def _embedded(
    manifest: Path | None,
    top: dict[str, Any],
    root: Path,
    paths: dict[str, Path],
    texts: dict[str, str],
    name: str,
    planning: dict[str, Any],
) -> dict[str, bytes]:
    """Return the config files to embed in plan files, laid out so they load again as a config.

    A moveplan.yaml whose files all lie in its folder is embedded as it is, with the files
    under the names it gives them. Otherwise (a MoveIt package, xacro, package:// files) the
    expanded URDF and SRDF and the other files are embedded side by side, with a generated
    moveplan.yaml naming them.
    """
    embed = [k for k in _FILE_KEYS if k in paths]
    if manifest is not None and not any(paths[k].name.endswith(".xacro") for k in ("urdf", "srdf")):
        written = {k: str(top[k]) for k in embed}
        if all("://" not in v and (root / v).resolve().is_relative_to(root.resolve()) for v in written.values()):
            files = {CONFIG_FILE: manifest.read_bytes()}
            files.update({written[k]: paths[k].read_bytes() for k in embed})
            return files
    files = {}
    generated: dict[str, Any] = {"name": name}
    for key in embed:
        path = paths[key]
        file_name = f"{_stem(path)}.{key}" if key in ("urdf", "srdf") else path.name
        if file_name in files or file_name == CONFIG_FILE:
            file_name = f"{key}_{file_name}"
        files[file_name] = texts[key].encode("utf-8") if key in texts else path.read_bytes()
        generated[key] = file_name
    generated["planning"] = dict(planning)
    origin = f"{root.name}/{CONFIG_FILE}" if manifest is not None else f"the config folder {root.name}"
    header = f"# Generated by moveplan from {origin}: names the files embedded beside it, as loaded.\n"
    files[CONFIG_FILE] = (header + yaml.safe_dump(generated, sort_keys=False)).encode("utf-8")
    return files


def _planning(
    manifest: Path | None, top: dict[str, Any], ompl: Path | None, srdf: Srdf, srdf_path: Path
) -> tuple[dict[str, Any], Path]:
    """Return the planning defaults and the file that chose the group.

    Precedence: moveplan.yaml `planning` > ompl_planning.yaml (its first group section, and
    that group's `default_planner_config`) > the SRDF's first group, RRTConnect, 1 s, and
    `exact` collision geometry.
    """
    planning = mapping(top.get("planning"), f"{manifest}: planning")
    check_keys(planning, _PLANNING_KEYS, f"{manifest}: planning")
    source = manifest if manifest is not None and "group" in planning else srdf_path
    if ompl is not None:
        group, planner = _ompl_defaults(ompl, srdf)
        if group and "group" not in planning:
            planning["group"], source = group, ompl
        if planner and "planner" not in planning and planning.get("group") == group:
            planning["planner"] = planner
    planning.setdefault("group", next(iter(srdf.groups), ""))
    planning.setdefault("planner", "RRTConnect")
    planning["planning_time"] = number(
        planning.get("planning_time", 1.0), f"{manifest}: planning.planning_time", positive=True
    )
    planning.setdefault("collision", "exact")
    if planning["collision"] not in COLLISION_MODES:
        raise ConfigError(f"{manifest}: planning.collision: expected one of {', '.join(COLLISION_MODES)}, "
                          f"got {planning['collision']!r}")
    return planning, source


def _ompl_defaults(path: Path, srdf: Srdf) -> tuple[str | None, str | None]:
    """Return the first SRDF group ompl_planning.yaml configures and its default planner (or None).

    MoveIt gives a group without a (known) `default_planner_config` RRTConnect; so does this.
    """
    top = mapping(load_yaml(path), str(path))
    group = next((key for key in top if key in srdf.groups), None)
    if group is None:
        return None, None
    section = mapping(top[group], f"{path}: {group}")
    default = section.get("default_planner_config")
    configs = mapping(top.get("planner_configs"), f"{path}: planner_configs")
    if not isinstance(default, str) or default not in configs:
        return group, None
    kind = mapping(configs[default], f"{path}: planner_configs.{default}").get("type", "")
    if not isinstance(kind, str) or not kind.startswith("geometric::"):
        raise ConfigError(f"{path}: planner_configs.{default}.type: expected geometric::<Planner>, got {kind!r}")
    return group, kind.removeprefix("geometric::")


def _parse_kinematics(path: Path, srdf: Srdf) -> dict[str, dict[str, Any]]:
    """Return kinematics.yaml's settings per group (moveplan solves IK itself; they are reported)."""
    top = mapping(load_yaml(path), str(path))
    if "/**" in top:  # written as ROS 2 parameters: /**: ros__parameters: robot_description_kinematics:
        top = mapping(mapping(top["/**"], f"{path}: /**").get("ros__parameters"), f"{path}: /**.ros__parameters")
    if "robot_description_kinematics" in top:
        top = mapping(top["robot_description_kinematics"], f"{path}: robot_description_kinematics")
    result = {}
    for group, entry in top.items():
        if group not in srdf.groups:
            raise UnknownName("group", group, f"{path} (groups of {srdf.name})", srdf.groups)
        result[group] = mapping(entry, f"{path}: {group}")
    return result


def _collision_meshes(config: RobotConfig) -> tuple[str, tuple[CollisionMesh, ...]]:
    """Return the URDF with collision mesh files resolved to absolute paths, and the meshes."""
    root = _xml_root(config.urdf, config.urdf_path)
    packages = PackagePath(config.package_paths)
    meshes = []
    for link in root.findall("link"):
        for mesh in link.findall("collision/geometry/mesh"):
            uri = mesh.get("filename", "")
            where = f"{config.urdf_path}: link '{link.get('name', '')}': collision mesh {uri}"
            path, package = packages.resolve_uri(uri, config.urdf_path.parent, where)
            if not path.is_file():
                inside = f" (package '{package}' is {packages.find(package, where)})" if package else ""
                raise ConfigError(f"{where}: file not found: {path}{inside}; search path: {packages.describe()}")
            mesh.set("filename", str(path.resolve()))
            meshes.append(CollisionMesh(link.get("name", ""), uri, path, package))
    return ET.tostring(root, encoding="unicode"), tuple(meshes)


def _xml_root(text: str, path: Path) -> ET.Element:
    try:
        return ET.fromstring(text)
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


def _parse_urdf(text: str, path: Path) -> dict[str, UrdfJoint]:
    root = _xml_root(text, path)
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
    return joints


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


def _parse_srdf(text: str, path: Path, joints: dict[str, UrdfJoint]) -> Srdf:
    root = _xml_root(text, path)
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
