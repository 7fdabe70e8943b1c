"""RobotCommander: the robot, as moveit_commander's, loaded from a moveplan or MoveIt config instead of a ROS graph.

Creating one stands in for launching move_group with the fake controllers: it loads the
robot, sets up the planning scene and the simulated hardware, and becomes the robot that
MoveGroupCommander, PlanningSceneInterface, tf Buffer and StaticTransformBroadcaster use
when they are not given one (as they would talk to the one move_group of a ROS graph).
"""

from __future__ import annotations

import numbers
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..core.config import MAX_SEED, Group
from ..core.errors import UnknownName, UsageError
from ..core.pipeline import ExecutionSettings, RobotSource, check_execution
from ._messages import state_message
from ._targets import finite_number
from ._world import ROBOT_VARIABLE, World, make_current
from .conversions import matrix_to_pose
from .msgs import PoseStamped, RobotState

if TYPE_CHECKING:
    from .move_group import MoveGroupCommander

__all__ = ["Joint", "Link", "RobotCommander"]


# A ROS parameter name ending in robot_description: MoveIt's way of naming the robot a launch file loaded.
_PARAMETER = re.compile(r"[~/]?([A-Za-z_][A-Za-z0-9_]*/)*robot_description")

class Joint:
    """One joint of the robot, as moveit_commander's RobotCommander.Joint: its limits, its value, a move."""

    def __init__(self, robot: RobotCommander, name: str) -> None:
        self._robot, self._name = robot, name

    def name(self) -> str:
        """Return the joint's name."""
        return self._name

    def variable_count(self) -> int:
        """Return how many values the joint has: 1 (moveplan's joints are revolute or prismatic)."""
        return 1

    def bounds(self) -> list[float]:
        """Return [min, max] of the joint's position in [rad] or [m]."""
        limit = self._robot.world.config.limits[self._name]
        return [limit.lower, limit.upper]

    def min_bound(self) -> float:
        """Return the joint's lower limit."""
        return self.bounds()[0]

    def max_bound(self) -> float:
        """Return the joint's upper limit."""
        return self.bounds()[1]

    def value(self) -> float:
        """Return the joint's current position."""
        return self._robot.world.joint_value(self._name)

    def move(self, position: float, wait: bool = True) -> bool:
        """Return True once the smallest group with this joint moved it to `position` (the others stay)."""
        owner = self._robot.get_default_owner_group(self._name)
        if owner is None:
            raise UsageError(f"Joint('{self._name}').move: no group contains the joint; cannot move it")
        group = self._robot.get_group(owner)
        group.set_joint_value_target(group.get_current_joint_values())
        group.set_joint_value_target(self._name, position)
        return group.go(wait=wait)


class Link:
    """One link of the robot, as moveit_commander's RobotCommander.Link: its name and current pose."""

    def __init__(self, robot: RobotCommander, name: str) -> None:
        self._robot, self._name = robot, name

    def name(self) -> str:
        """Return the link's name."""
        return self._name

    def pose(self) -> PoseStamped:
        """Return the link's current pose, stamped in the planning frame."""
        stamped = PoseStamped(pose=matrix_to_pose(self._robot.world.pose(self._name)))
        stamped.header.frame_id = self._robot.get_planning_frame()
        return stamped


class RobotCommander:
    """The robot: its groups, joints and links, its current state, and every motion it executed.

    Args:
        robot_description: What `moveplan --robot` takes: a shipped config's name (`ur10e`), a
            moveplan.yaml or its folder, a MoveIt config package, a URDF or SRDF. MoveIt's
            default, a ROS parameter name ("robot_description", "/ns/robot_description"), or
            None: the robot `$MOVEPLAN_ROBOT` names, as the parameter names the launched robot.
        ns: MoveIt's namespace of the move_group; kept (`get_namespace`), there is one robot here.
        scene: A scene file (moveplan's or a MoveIt PlanningScene YAML): its frames, objects and
            robot state are the planning scene's to start with.
        package_path: Folders searched for `package://` and `$(find)` (`--package-path`), before
            `$ROS_PACKAGE_PATH`.
        urdf, srdf, joint_limits, xacro_args, strict_limits: As `--urdf`, `--srdf`, `--joint-limits`,
            `--xacro-arg`, `--strict-limits`.
        launch, launch_args: As `--launch` and `--launch-arg`: the MoveIt package's launch file to
            read the robot from, and its launch arguments (name -> value).
        plant, plant_params, controllers: The simulated hardware motions execute on, as
            `execute --fake --plant`, `--plant-param` and `--controllers` choose it.
        seed: Seeds every plan (each one anew, as one `moveplan plan` run) and the plant.
    """

    def __init__(
        self,
        robot_description: str | Path | None = "robot_description",
        ns: str = "",
        *,
        scene: str | Path | None = None,
        package_path: str | Path | Sequence[str | Path] | None = None,
        urdf: str | None = None,
        srdf: str | None = None,
        joint_limits: str | None = None,
        xacro_args: Mapping[str, str] | None = None,
        strict_limits: bool = False,
        launch: str | None = None,
        launch_args: Mapping[str, str] | None = None,
        plant: str | None = None,
        plant_params: Mapping[str, float] | None = None,
        controllers: str | Path | None = None,
        seed: int = 0,
    ) -> None:
        robot = robot_description
        if robot is None or (isinstance(robot, str) and _PARAMETER.fullmatch(robot)):
            robot = os.environ.get(ROBOT_VARIABLE) or None
            if robot is None:
                raise UsageError(f"RobotCommander({robot_description!r}): no robot: give a config "
                                 f"(RobotCommander('ur10e')) or set {ROBOT_VARIABLE}, which names the robot the "
                                 "robot_description parameter would hold")
        if not isinstance(ns, str):
            raise UsageError(f"RobotCommander: ns: expected a namespace, got {ns!r}")
        if ns.endswith((".yaml", ".yml")) or (ns and os.path.isfile(ns)):
            # MoveIt's second argument is the namespace; a scene file there would be silently unused.
            raise UsageError(f"RobotCommander: ns: '{ns}' is a file, not a namespace; give a scene as "
                             f"RobotCommander(..., scene='{ns}')")
        where = "RobotCommander"
        paths = [] if package_path is None else [package_path] if isinstance(package_path, str | Path) else package_path
        if not hasattr(paths, "__iter__"):
            raise UsageError(f"{where}: package_path: expected a folder or a list of folders, got {package_path!r}")
        _check_arguments(robot, {"urdf": urdf, "srdf": srdf, "joint_limits": joint_limits, "launch": launch},
                         {"xacro_args": xacro_args, "plant_params": plant_params, "launch_args": launch_args}, seed)
        params = {str(k): finite_number(v, f"{where}: plant_params['{k}']") for k, v in (plant_params or {}).items()}
        source = RobotSource(robot, tuple(_path(p, f"{where}: package_path") for p in paths), dict(xacro_args or {}),
                             urdf, srdf, strict_limits, joint_limits, launch,
                             {str(k): str(v) for k, v in (launch_args or {}).items()})
        controllers_path = _path(controllers, f"{where}: controllers") if controllers else None
        execution = ExecutionSettings(plant, params, controllers_path, int(seed))
        scene_path = _path(scene, f"{where}: scene") if scene is not None else None
        self.world = World(source, scene_path, execution, int(seed))
        check_execution(self.world.config, self.world.robot(None).joint_names, execution)
        self._ns = ns
        self._groups: dict[str, MoveGroupCommander] = {}
        make_current(self.world)

    def get_namespace(self) -> str:
        """Return the namespace given (MoveIt's `ns`)."""
        return self._ns

    def get_planning_frame(self) -> str:
        """Return the frame all planning is done in: the URDF's root link."""
        return self.world.robot(None).root_link

    def get_root_link(self) -> str:
        """Return the URDF's root link."""
        return self.world.robot(None).root_link

    def get_group_names(self) -> list[str]:
        """Return the names of the SRDF's planning groups."""
        return list(self.world.config.srdf.groups)

    def has_group(self, name: str) -> bool:
        """Return True if the SRDF has a planning group `name`."""
        return name in self.world.config.srdf.groups

    def get_joint_names(self, group: str | None = None) -> list[str]:
        """Return the joints of `group` (or of the robot for None), fixed and mimic joints included, as MoveIt does."""
        joints = self.world.config.urdf_joints
        if group is None:
            return list(joints)
        above = {joint.child: name for name, joint in joints.items()}
        return [above[link] for link in self._group(group).links]

    def get_active_joint_names(self, group: str | None = None) -> list[str]:
        """Return the joints of `group` (or of the robot) that are planned: movable and not mimic joints."""
        joints = self.world.config.urdf_joints
        if group is None:
            return [j for j in self.world.joint_names() if not joints[j].mimic]
        return [j for j in self._group(group).joints if not joints[j].mimic]

    def get_link_names(self, group: str | None = None) -> list[str]:
        """Return the robot's links (for None), or the group's: the child link of each of its joints, fixed ones too."""
        if group is None:
            return list(self.world.robot(None).link_names)
        return list(self._group(group).links)

    def get_current_state(self) -> RobotState:
        """Return the robot's current state: every movable joint's position, in the planning frame."""
        return state_message(self.world)

    def get_current_variable_values(self) -> dict[str, float]:
        """Return joint name -> current position in [rad] or [m], for every movable joint."""
        return {j: self.world.joint_value(j) for j in self.world.joint_names()}

    def get_joint(self, name: str) -> Joint:
        """Return the movable joint `name` (its limits, value, a move), else raise UnknownName."""
        movable = self.world.joint_names()
        if name not in movable:
            raise UnknownName("joint", str(name), "the robot's movable joints", movable)
        return Joint(self, name)

    def get_link(self, name: str) -> Link:
        """Return the link `name` (its current pose), else raise UnknownName."""
        links = self.world.robot(None).link_names
        if name not in links:
            raise UnknownName("link", str(name), "the robot's links", links)
        return Link(self, name)

    def get_group(self, name: str) -> MoveGroupCommander:
        """Return the MoveGroupCommander of the group `name` of this robot (one per group, as MoveIt keeps it)."""
        from .move_group import MoveGroupCommander

        self._group(name)
        if name not in self._groups:
            self._groups[name] = MoveGroupCommander(name, self)
        return self._groups[name]

    def get_default_owner_group(self, joint_name: str) -> str | None:
        """Return the smallest group (fewest links) that has joint `joint_name`, None if none has it."""
        owners = [g for g in self.get_group_names() if joint_name in self.get_joint_names(g)]
        return min(owners, key=lambda g: len(self.get_link_names(g)), default=None)

    def __getattr__(self, name: str) -> Any:
        """Return the group, joint or link named `name` (MoveIt's `robot.right_arm`, `robot.elbow_joint`)."""
        world = self.__dict__.get("world")
        if world is not None and name in world.config.srdf.groups:
            return self.get_group(name)
        if world is not None and name in world.joint_names():
            return Joint(self, name)
        if world is not None and name in world.robot(None).link_names:
            return Link(self, name)
        raise AttributeError(f"'RobotCommander' object has no attribute '{name}'")

    def save(self, path: str | Path, distro: str = "jazzy") -> None:
        """Write every motion executed so far, in order, as one plan file (`moveplan inspect`, `execute` read it).

        The file holds the final planning scene, and the result of each execution as the
        "executions" metadata. Motions of one group only.

        Raises:
            UsageError: Nothing was executed yet, several groups moved, or `path` is an input file
                (or cannot be written as one: a folder, a device).
            InputError: `path` cannot be written.
        """
        self.world.save(_path(path, "save"), distro)

    def _group(self, name: str) -> Group:
        """Return the SRDF group `name`, else raise UnknownName."""
        groups = self.world.config.srdf.groups
        if name not in groups:
            raise UnknownName("group", str(name), f"{self.world.config.srdf_path}", groups)
        return groups[name]


def _path(value: Any, where: str) -> Path:
    """Return `value` as a Path if it is a name or a path, else raise UsageError naming `where`."""
    if not isinstance(value, str | os.PathLike) or not str(value):
        raise UsageError(f"{where}: expected a file or folder name, got {value!r}")
    return Path(value)


def _check_arguments(robot: Any, descriptions: Mapping[str, Any], mappings: Mapping[str, Any], seed: Any) -> None:
    """Raise UsageError naming the RobotCommander argument that has the wrong type (or a seed out of range)."""
    _path(robot, "RobotCommander: robot_description")  # kept as given by the caller: a shipped config's name is no path
    for flag, value in descriptions.items():
        if value is not None and not isinstance(value, str):
            raise UsageError(f"RobotCommander: {flag}: expected a file name or package:// URI, got {value!r}")
    for flag, given in mappings.items():
        if given is not None and not isinstance(given, Mapping):
            raise UsageError(f"RobotCommander: {flag}: expected a mapping of names to values, got {given!r}")
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or not 0 <= int(seed) <= MAX_SEED:
        raise UsageError(f"RobotCommander: seed: expected an integer in 0..{MAX_SEED}, got {seed!r}")
