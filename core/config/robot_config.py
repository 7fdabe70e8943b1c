"""A robot config, loaded: moveplan.yaml or a MoveIt config package, and every file they name.

Loading runs in stages, each in its own module: locate the files (sources.py), read the
URDF and SRDF through xacro (descriptions.py) and parse them (urdf.py, srdf.py), merge the
limits as MoveIt does: URDF limits, overridden by joint_limits.yaml (limits.py), read the
controllers (controllers.py) and the other settings (settings.py), and collect the files
a plan embeds (embed.py). Every error names the file and key path.

A config a plan file carries (`embedded=True`) is data only: no xacro runs, no `$(...)`
substitution is made, no package is searched for, and its moveplan.yaml may name only files
beside it, which are the plan's attachments.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError, UnknownName, UsageError
from ._descriptions import check_xacro_args, expand, file_xacro_args
from ._initial_state import fake_controllers_initial, initial_state
from ._settings import parse_kinematics, planning_defaults
from ._substitutions import read_substituted
from ._urdf import CollisionMesh, UrdfJoint, parse_urdf, resolve_collision_meshes
from .controllers import ControllerConfig, ExecutionConfig, parse_controllers, parse_execution
from .embed import carried_paths, embedded_files
from .fields import load_yaml, read_input
from .launch_files import LaunchFiles, RobotFile, read_launch
from .limits import DEFAULT_SOURCE, JointLimit, is_moveit_joint_limits, merge_limits, parse_joint_limits
from .motion import Resolved
from .plant import PlantSettings, parse_plant
from .sources import (
    CONFIG_FILE,
    discover,
    discover_beside,
    flag_file,
    manifest_files,
    read_manifest,
    resolve_config_path,
    robot_file_kind,
    search_path,
)
from .srdf import Group, Srdf, parse_srdf
from .xacro import PackagePath

__all__ = ["RobotConfig", "load_robot_config"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class RobotConfig:
    """A robot config folder, parsed: file paths, texts and typed settings.

    Attributes:
        name: Robot name.
        root: The config folder.
        urdf_path: URDF file; `urdf` its text.
        urdf_joints: URDF joints by name, in file order.
        srdf: Parsed SRDF; `srdf_path` its file.
        limits: Merged limits of every movable URDF joint; an acceleration limit the config
            does not give is limits.DEFAULT_ACCELERATION, its source limits.DEFAULT_SOURCE.
        motion: What a motion is planned with where nothing else says: `planning`'s planner and
            planning time, joint_limits.yaml's default scalings (MoveIt: 0.1).
        controllers: JointTrajectoryControllers from ros2_controllers.yaml.
        execution: MoveIt's trajectory_execution settings.
        initial_positions: Where every movable joint starts when no start is given (joint ->
            value): the URDF's <ros2_control> initial values (where mock hardware starts), else
            initial_positions.yaml, else MoveIt's default state (initial_state.py).
        planning: moveplan.yaml `planning` defaults: group, planner, planning_time, and
            collision (`exact`: the URDF's meshes; `convex`: their convex hulls), as a
            generated moveplan.yaml writes them; a motion's settings are read from `motion`.
        files: File name -> bytes of every config file, to embed in plan files; laid out in
            one folder they load again as this config (expanded URDF, generated moveplan.yaml).
        package_paths: Folders searched for `$(find pkg)` and `package://` URIs, in order.
        sources: Setting -> the file it came from: urdf, srdf, joint_limits, kinematics,
            controllers, moveit_controllers, initial_positions, ompl_planning, moveplan (the
            moveplan.yaml), planning (the file that chose the default group). Absent: not given.
        urdf_includes: Every file the URDF was made of (the .urdf, or the xacro and its includes).
        kinematics: kinematics.yaml's settings per group (reported; moveplan solves IK itself).
        xacro_args: The xacro args the URDF and SRDF were expanded with.
        initial_sources: Joint -> where its initial position comes from (initial_state.py).
        srdf_text: The SRDF as read (xacro expanded): what MoveIt holds as robot_description_semantic.
        plant: moveplan.yaml's `plant`, the simulated hardware (core/config/plant.py); None: mirror.
    """

    name: str
    root: Path
    urdf_path: Path
    urdf: str
    urdf_joints: dict[str, UrdfJoint]
    srdf_path: Path
    srdf: Srdf
    limits: dict[str, JointLimit]
    motion: Resolved
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
    initial_sources: dict[str, str] = field(default_factory=dict)
    srdf_text: str = ""
    plant: PlantSettings | None = None

    def group(self, name: str | None = None) -> Group:
        """Return the named planning group, or the config's default one."""
        name = name or self.planning["group"]
        if name not in self.srdf.groups:
            raise UnknownName("group", name, str(self.srdf_path), self.srdf.groups)
        return self.srdf.groups[name]

    def missing_acceleration_limits(self, group: str | None = None) -> tuple[str, ...]:
        """Return the group's joints the config gives no acceleration limit (they plan with the default).

        Mimic joints are left out: MoveIt times the joint they follow.
        """
        return tuple(j for j in self.group(group).joints
                     if self.limits[j].source["acceleration"] == DEFAULT_SOURCE and not self.urdf_joints[j].mimic)

    def collision_meshes(self) -> tuple[CollisionMesh, ...]:
        """Return every collision mesh of the URDF with the file it resolves to.

        Raises:
            ConfigError: A mesh whose package cannot be found or whose file does not exist;
                names the URDF, the link, the URI, the package and the search path.
        """
        return resolve_collision_meshes(self.urdf, self.urdf_path, self.package_paths)[1]

    def collision_urdf(self) -> str:
        """Return the URDF with every collision mesh's filename replaced by its absolute path."""
        return resolve_collision_meshes(self.urdf, self.urdf_path, self.package_paths)[0]


@dataclass(frozen=True)
class _Located:
    """Where a config's files are: its moveplan.yaml (None: a folder without one) and setting -> file."""

    manifest: Path | None
    root: Path
    top: dict[str, Any]
    packages: PackagePath
    paths: dict[str, Path]
    xacro_args: dict[str, str] = field(default_factory=dict)  # from moveplan.yaml or .setup_assistant
    xacro_source: Path | None = None  # the file that gave them
    launch: LaunchFiles = field(default_factory=LaunchFiles)  # what the package's launch files name


@dataclass(frozen=True)
class _Model:
    """The URDF and SRDF, as text and parsed, and the xacro args they were expanded with."""

    urdf_text: str
    urdf_includes: tuple[Path, ...]
    urdf_joints: dict[str, UrdfJoint]
    srdf_text: str
    srdf: Srdf
    xacro_args: dict[str, str]


def load_robot_config(
    robot: str | Path,
    package_paths: Sequence[Path] = (),
    xacro_args: Mapping[str, str] | None = None,
    urdf: str | None = None,
    srdf: str | None = None,
    strict_limits: bool = False,
    embedded: bool = False,
    joint_limits: str | None = None,
    launch: str | None = None,
    launch_args: Mapping[str, str] | None = None,
    strict: bool = False,
) -> RobotConfig:
    """Return the parsed robot config at `robot`.

    Args:
        robot: A moveplan.yaml, a folder holding one, a MoveIt config package folder, a plain
            folder with a URDF and an SRDF, a URDF or SRDF file (the other one found beside
            it), or the name of a shipped config (core/config/sources.py has the rules).
        package_paths: --package-path folders, searched for `$(find pkg)` and `package://`
            after the config folder and before the enclosing workspace and ROS_PACKAGE_PATH.
        xacro_args: --xacro-arg values; they override moveplan.yaml's or .setup_assistant's `xacro_args`.
        urdf: --urdf, a file or `package://pkg/path`: the URDF, whatever the config names.
        srdf: --srdf, likewise the SRDF.
        joint_limits: --joint-limits, likewise MoveIt's joint_limits.yaml (a vendor keeps it
            where a launch file names it).
        launch: --launch, the one launch file of a MoveIt package to read (default: all of its
            launch/ folder; core/config/launch_files.py).
        launch_args: --launch-arg values, as `ros2 launch` takes them; a launch argument also
            sets the URDF's and SRDF's xacro arg of the same name where they declare one.
        strict: --strict: a parameter a controller does not declare is an error, not a warning.
        strict_limits: --strict-limits: a joint without an acceleration limit is an error
            instead of planning with the documented default.
        embedded: `robot` is the folder a plan file's attachments were written to: read as
            data only (module docstring); its moveplan.yaml's package_paths and xacro_args
            are not read.

    Raises:
        ConfigError: A file is missing or malformed, or the files are ambiguous; the message
            names file and key, or the files and the flag that settles it.
        UsageError: A --xacro-arg the xacro files do not declare.
    """
    found = _carried(Path(robot)) if embedded else _locate(robot, package_paths, urdf, srdf, joint_limits, launch,
                                                             launch_args or {})
    paths = found.paths
    model = _read_model(found, xacro_args or {})
    limit_overrides, v_scale, a_scale = parse_joint_limits(paths.get("joint_limits"))
    limits = merge_limits(paths["urdf"], model.urdf_joints, paths.get("joint_limits"), limit_overrides,
                          strict=strict_limits)
    substitute = not embedded
    controllers = (parse_controllers(paths["controllers"], model.xacro_args, substitute=substitute, strict=strict)
                   if "controllers" in paths else {})
    _check_controller_joints(controllers, model.urdf_joints, paths.get("controllers"))
    execution = (parse_execution(paths["moveit_controllers"], model.xacro_args, substitute=substitute)
                 if "moveit_controllers" in paths else ExecutionConfig())
    fake = paths.get("fake_controllers")
    named = (fake_controllers_initial(fake, model.srdf.group_states, limits), fake) if fake else None
    initial = initial_state(model.urdf_text, paths["urdf"], model.urdf_joints, limits, paths.get("initial_positions"),
                            named)
    kinematics = _kinematics(paths.get("kinematics"), model.srdf, named=found.manifest is not None)
    if "kinematics" in paths and kinematics is None:
        del paths["kinematics"]
    planning, planning_source = planning_defaults(
        found.manifest, found.top, paths.get("ompl_planning"), model.srdf, paths["srdf"]
    )
    name = str(found.top.get("name") or model.srdf.name)
    plant = parse_plant(found.top.get("plant"), f"{found.manifest}: plant")
    texts = {"urdf": model.urdf_text, "srdf": model.srdf_text}
    # A plan carries controller files with their launch substitutions made: execute reads them without args.
    texts.update({key: read_substituted(paths[key], model.xacro_args) for key in ("controllers", "moveit_controllers")
                  if substitute and key in paths and b"$(" in read_input(paths[key])})
    config = RobotConfig(
        name=name,
        root=found.root,
        urdf_path=paths["urdf"],
        urdf=model.urdf_text,
        urdf_joints=model.urdf_joints,
        srdf_path=paths["srdf"],
        srdf=model.srdf,
        limits=limits,
        motion=Resolved(planning["planner"], planning["planning_time"], v_scale, a_scale),
        controllers=controllers,
        execution=execution,
        initial_positions=initial.positions,
        planning=planning,
        files=embedded_files(found.manifest, found.top, found.root, paths, texts, name, planning,
                             plant.as_dict() if plant else None),
        package_paths=found.packages.folders,
        sources=_sources(found, planning_source),
        urdf_includes=model.urdf_includes,
        kinematics=kinematics or {},
        xacro_args=model.xacro_args,
        initial_sources=initial.sources,
        srdf_text=model.srdf_text,
        plant=plant,
    )
    config.group()  # an unknown default group is a config error, found at load time
    return config


def _locate(
    robot: str | Path, package_paths: Sequence[Path], urdf: str | None, srdf: str | None, joint_limits: str | None,
    launch: str | None = None, launch_args: Mapping[str, str] | None = None,
) -> _Located:
    """Return where the config's files are: named by its moveplan.yaml, or found in its folder or beside a file."""
    # Absolute: files found in the folder and files found through packages print the same way.
    path = resolve_config_path(robot, srdf_given=srdf is not None).absolute()
    manifest = path if robot_file_kind(path) == "moveplan" else None
    root = path if path.is_dir() else path.parent
    top: dict[str, Any] = {}
    extra: tuple[Path, ...] = ()
    if manifest is not None:
        top, extra = read_manifest(manifest)
    packages = PackagePath(search_path(root, tuple(package_paths), extra))
    given = {key: flag_file(value, key, packages)
             for key, value in (("urdf", urdf), ("srdf", srdf), ("joint_limits", joint_limits)) if value}
    if (launch or launch_args) and not path.is_dir():
        raise UsageError(f"--launch and --launch-arg read a MoveIt package's launch files; {robot} is not a package "
                         "folder")
    if manifest is not None:
        paths = manifest_files(manifest, top, packages, given)
        # A flag's file replaces moveplan.yaml's, named by URI: a plan then embeds the files as loaded.
        top = {**top, **{key: file.resolve().as_uri() for key, file in given.items()}}
        return _Located(manifest, root, top, packages, paths, file_xacro_args(manifest, top.get("xacro_args")),
                        manifest)
    launched = read_launch(root, packages, launch_args or {}, launch) if path.is_dir() else LaunchFiles()
    found = discover(root, packages, given, launched) if path.is_dir() else discover_beside(path, given)
    if found.root != root:
        packages = PackagePath(search_path(found.root, tuple(package_paths)))
    paths = {**found.paths, **{key: file for key, file in given.items() if key not in ("urdf", "srdf")}}
    if "joint_limits" in paths and "joint_limits" not in given and not is_moveit_joint_limits(paths["joint_limits"]):
        # Found by name only: a description package's own limits (Franka's) beside its URDF, not MoveIt's.
        logger.warning("%s: not MoveIt's joint_limits.yaml (no joint_limits key); not read: pass --joint-limits "
                       "FILE to name MoveIt's", paths.pop("joint_limits"))
    return _Located(None, found.root, top, packages, paths, found.xacro_args, found.xacro_source, launched)


def _carried(folder: Path) -> _Located:
    """Return the files of a config a plan carries, written to `folder`: those its moveplan.yaml names beside it."""
    manifest = folder / CONFIG_FILE
    if not manifest.is_file():
        raise ConfigError(f"{folder}: no {CONFIG_FILE}")
    top, _ = read_manifest(manifest)
    return _Located(manifest, folder, top, PackagePath(()), carried_paths(manifest, top))


def _read_model(found: _Located, flags: Mapping[str, str]) -> _Model:
    """Return the URDF and SRDF read (through xacro) and parsed.

    xacro args, later ones winning: the launch file's for that file, moveplan.yaml's or
    .setup_assistant's, --launch-arg, --xacro-arg. Only the last three are checked against what
    the files declare: a launch file may pass args a xacro does not use, as xacro allows.
    """
    args = {**found.xacro_args, **flags}
    launch = found.launch
    urdf_path, srdf_path = found.paths["urdf"], found.paths["srdf"]
    urdf_args = {**_launched(launch.urdf, urdf_path), **found.xacro_args, **launch.given, **flags}
    srdf_args = {**_launched(launch.srdf, srdf_path), **found.xacro_args, **launch.given, **flags}
    try:
        urdf_text, urdf_includes, declared = expand(urdf_path, found.root, urdf_args, found.packages)
    except ConfigError as exc:
        named = launch.urdf is not None and launch.urdf.path.resolve() == urdf_path.resolve()
        if not named or launch.source is None:
            raise
        where = launch.source.relative_to(found.root) if launch.source.is_relative_to(found.root) else launch.source
        raise ConfigError(f"{exc} (the URDF {where} names; pass --urdf FILE for another)") from None
    srdf_text, _, srdf_declared = expand(srdf_path, found.root, srdf_args, found.packages)
    check_xacro_args(args, frozenset(flags), declared | srdf_declared, (urdf_path, srdf_path), found.xacro_source)
    urdf_joints = parse_urdf(urdf_text, urdf_path)
    srdf = parse_srdf(srdf_text, srdf_path, urdf_joints)
    used = {name: value for name, value in {**srdf_args, **urdf_args}.items() if name in declared | srdf_declared}
    return _Model(urdf_text, urdf_includes, urdf_joints, srdf_text, srdf, {**used, **args})


def _launched(named: RobotFile | None, path: Path) -> dict[str, str]:
    """Return the xacro args a launch file gives `path`, {} if it names another file."""
    return dict(named.args) if named is not None and named.path.resolve() == path.resolve() else {}


def _kinematics(path: Path | None, srdf: Srdf, named: bool) -> dict[str, dict[str, Any]] | None:
    """Return kinematics.yaml's settings ({} without one); None for a file found by name that is not MoveIt's."""
    if path is None:
        return {}
    top = load_yaml(path)
    moveit = any(key in ("/**", "robot_description_kinematics") or (isinstance(entry, dict) and any(
        str(k).startswith("kinematics_solver") for k in entry)) for key, entry in top.items()) \
        if isinstance(top, dict) else True
    if not named and top and not moveit:
        # A description package's own kinematics.yaml (Franka's DH parameters) lies where a lone URDF is.
        logger.warning("%s: not MoveIt's kinematics.yaml (no group names a kinematics_solver); not read", path)
        return None
    return parse_kinematics(path, srdf)


def _sources(found: _Located, planning_source: Path) -> dict[str, Path]:
    """Return setting -> the file it came from (see RobotConfig.sources)."""
    sources = dict(found.paths)
    if found.manifest is not None:
        sources["moveplan"] = found.manifest
    if found.launch.source is not None:
        sources["launch"] = found.launch.source
    sources["planning"] = planning_source
    return sources


def _check_controller_joints(
    controllers: Mapping[str, ControllerConfig], joints: Mapping[str, UrdfJoint], source: Path | None
) -> None:
    """Raise for a controller joint the URDF lacks: ros2_control refuses to configure such a controller."""
    for name, controller in controllers.items():
        for joint in controller.joints:
            if joint not in joints:
                raise UnknownName("joint", joint, f"{source}: {name}.ros__parameters.joints", joints)

