"""What a running move_group holds, here in memory: the robot, where it is, the planning scene, what it executed.

One World per RobotCommander; its MoveGroupCommanders, PlanningSceneInterface, tf Buffer and
broadcaster all read and change it. Planning and execution go through
moveplan.core.pipeline.session, the same pipeline the CLI runs.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.config import AllowedCollisions
from ..core.control import ExecutionSummary
from ..core.errors import UnknownName, UsageError
from ..core.model import Robot, Scene, empty_scene, load_scene
from ..core.pipeline import (
    ExecutionSettings,
    Problem,
    RobotSource,
    check_execution,
    compose_scene,
    frame_in_root,
    motion_problem,
    session_plan,
    start_configuration,
    write_session,
)
from ..core.types import CollisionObject, Frame, StepResult
from ._targets import finite_number

__all__ = ["ROBOT_VARIABLE", "Executed", "World", "current_world", "latest_world", "make_current"]

ROBOT_VARIABLE = "MOVEPLAN_ROBOT"
"""Environment variable naming the robot when RobotCommander() is given none (what robot_description is to ROS)."""

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Executed:
    """One executed motion: its group, the step as sent, and what the simulated controller made of it."""

    group: str
    step: StepResult
    summary: ExecutionSummary
    plant: str


class World:
    """The robot config, its current configuration `q` (all joints), the planning scene and the executed motions."""

    def __init__(self, source: RobotSource, scene: Path | None, execution: ExecutionSettings, seed: int) -> None:
        self.config = source.load()
        self.execution = execution
        self.seed = seed
        self._robots: dict[str, Robot] = {}
        robot = self.robot(None)
        base = load_scene(scene, robot) if scene is not None else empty_scene()
        self.scene_file = scene
        self.source = str(scene) if scene is not None else "the planning scene"
        self._frames = {f.name: f for f in base.frames}
        self._objects = {o.name: o for o in base.objects}
        self._parts = dict(base.parts)
        self._allowed = base.allowed
        self.acm = AllowedCollisions({}, {})  # what apply_planning_scene's matrix allows, on top of the file's
        self.shape_offsets: dict[str, NDArray[np.float64]] = {}  # scene object -> object_T_shape, if not identity
        self._robot_state = dict(base.robot_state)
        self._scene: Scene = compose_scene(self.source, base.frames, base.objects, robot, self._allowed,
                                           self._robot_state)
        self.q = start_configuration(robot, self._scene)
        self.start_q = self.q.copy()
        self._problems: dict[tuple[str, bytes], Problem] = {}
        self.executed: list[Executed] = []
        self.rng = np.random.default_rng(seed)  # random targets: the same every run of a script

    def robot(self, group: str | None) -> Robot:
        """Return the robot model seen through `group` (None: the config's planning group)."""
        name = group or self.config.planning["group"]
        if name not in self._robots:
            self._robots[name] = Robot(self.config, name)
        return self._robots[name]

    @property
    def scene(self) -> Scene:
        """Return the planning scene as it is now."""
        return self._scene

    @property
    def frames(self) -> dict[str, Frame]:
        """Return the scene's static frames by name (a copy)."""
        return dict(self._frames)

    @property
    def objects(self) -> dict[str, CollisionObject]:
        """Return the scene's world and attached objects by name (a copy)."""
        return dict(self._objects)

    def parts(self, name: str) -> tuple[str, ...]:
        """Return the object names a scene file's object id became (a PlanningScene object's shapes), else (name,)."""
        return self._parts.get(name, (name,))

    def change(self, frames: Mapping[str, Frame] | None = None, objects: Mapping[str, CollisionObject] | None = None,
               acm: AllowedCollisions | None = None, parts: Mapping[str, tuple[str, ...]] | None = None) -> None:
        """Replace the scene's frames, objects, allowed collisions and object parts; on error nothing changes.

        Checked as a scene file's are. `parts` maps an object id to the scene objects its shapes are.
        """
        new_frames = dict(self._frames if frames is None else frames)
        new_objects = dict(self._objects if objects is None else objects)
        new_acm = self.acm if acm is None else acm
        names = [*self.robot(None).link_names, *new_objects]
        allowed = self._allowed | frozenset(new_acm.pairs(names))
        self._scene = compose_scene(self.source, list(new_frames.values()), list(new_objects.values()),
                                    self.robot(None), allowed, self._robot_state)
        self._frames, self._objects, self.acm = new_frames, new_objects, new_acm
        if parts is not None:
            self._parts = dict(parts)
        self._parts = {k: v for k, v in self._parts.items() if any(n in new_objects for n in v)}
        self.shape_offsets = {k: v for k, v in self.shape_offsets.items() if k in new_objects}
        if objects is not None or acm is not None:
            self._problems.clear()

    @property
    def allowed(self) -> frozenset[frozenset[str]]:
        """Return the pairs of links and objects allowed to touch now."""
        return self._scene.allowed

    @property
    def object_parts(self) -> dict[str, tuple[str, ...]]:
        """Return object id -> the scene objects its shapes are, for ids of several shapes (a copy)."""
        return dict(self._parts)

    def object_id(self, name: str) -> str:
        """Return the object id a scene object belongs to (`box/1` -> `box` when `box` has shapes), else `name`."""
        return next((oid for oid, names in self._parts.items() if name in names), name)

    def object_ids(self, attached: bool) -> list[str]:
        """Return the ids of the world objects (or of the attached ones), each once, in scene order."""
        ids = [self.object_id(n) for n, o in self._objects.items() if bool(o.link) == attached]
        return list(dict.fromkeys(ids))

    def object_pose(self, oid: str) -> NDArray[np.float64]:
        """Return an object's frame: `root_T_object` in the world, `link_T_object` attached."""
        first = self.parts(oid)[0]
        offset = self.shape_offsets.get(first)
        transform = self._objects[first].transform
        return transform if offset is None else transform @ np.linalg.inv(offset)

    def problem(self, robot: Robot, q: NDArray[np.float64]) -> Problem:
        """Return the problem of `robot`'s group in the scene, the other joints as in `q` (built once)."""
        others = robot.configuration(np.zeros(robot.dof), q)
        key = (robot.group.name, others.tobytes())
        if key not in self._problems:
            self._problems[key] = motion_problem(robot, self._scene, q)
        return self._problems[key]

    def pose(self, frame: str, q: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """Return `root_T_frame` of a link, scene frame or the planning frame, the robot at `q` (default: now)."""
        return frame_in_root(self.robot(None), self._scene, self.q if q is None else q, frame)

    def joint_names(self) -> list[str]:
        """Return the robot's movable joints, in URDF order."""
        model = self.robot(None).model
        return [j.name for j in self.config.urdf_joints.values() if j.type != "fixed" and model.existJointName(j.name)]

    def joint_value(self, joint: str, q: NDArray[np.float64] | None = None) -> float:
        """Return one joint's position in [rad] or [m] in `q` (default: now)."""
        q = self.q if q is None else q
        model = self.robot(None).model
        jid = model.getJointId(joint)
        index = model.idx_qs[jid]
        if model.nqs[jid] == 2:  # a continuous joint, stored as (cos, sin)
            return float(np.arctan2(q[index + 1], q[index]))
        return float(q[index])

    def with_joints(self, values: Mapping[str, float], q: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """Return `q` (default: now) with the joints of `values` set."""
        robot = self.robot(None)
        result = (self.q if q is None else q).copy()
        for joint, value in values.items():
            result = robot.set_joint(result, joint, float(value))
        return result

    def set_joints(self, state: Any, where: str) -> None:
        """Move the robot to a JointState's positions at once (MoveIt 1's fake controllers); return None.

        Raises:
            UsageError: Names and positions of different lengths, or a position that is no finite number.
            UnknownName: A joint the robot cannot move.
        """
        names, positions = list(state.name), list(state.position)
        if len(names) != len(positions):
            raise UsageError(f"{where}: {len(names)} names and {len(positions)} positions")
        movable = self.joint_names()
        values: dict[str, float] = {}
        for name, value in zip(names, positions, strict=True):
            if name not in movable:
                raise UnknownName("joint", str(name), f"{where} (the robot's movable joints)", movable)
            values[str(name)] = finite_number(value, f"{where}: {name}")
        self.q = self.with_joints(values)
        self.start_q = self.q.copy() if not self.executed else self.start_q

    def record(self, group: str, step: StepResult, summary: ExecutionSummary) -> None:
        """Add an executed motion, its step named uniquely, for save()."""
        names = {e.step.name for e in self.executed}
        name, k = step.name, 1
        while name in names:
            k += 1
            name = f"{step.name}_{k}"
        plant = self.execution.plant or (self.config.plant.model if self.config.plant else "mirror")
        self.executed.append(Executed(group, replace(step, name=name), summary, plant))

    def save(self, path: Path, distro: str) -> None:
        """Write every executed motion, in order, as one plan file at `path`.

        Raises:
            UsageError: Nothing was executed, motions of several groups were, or `path` is an input.
        """
        if not self.executed:
            raise UsageError(f"save('{path}'): no motion has been executed yet; a plan file holds at least one")
        groups = sorted({e.group for e in self.executed})
        if len(groups) > 1:
            raise UsageError(f"save('{path}'): motions of groups {', '.join(groups)} were executed; a plan file "
                             "holds the motions of one group")
        inputs = [self.scene_file, *self.config.sources.values()]
        if path.exists() and any(p is not None and p.exists() and os.path.samefile(path, p) for p in inputs):
            raise UsageError(f"save('{path}'): is an input of this session (the scene or a robot config file); "
                             "an output must not replace an input")
        executions = [{"step": e.step.name, "ok": e.summary.ok, "plant": e.plant,
                       "result": {"code": e.summary.result.code, "name": e.summary.result.name,
                                  "message": e.summary.result.message}} for e in self.executed]
        plan = session_plan(self.robot(groups[0]), self._scene, self.start_q, [e.step for e in self.executed],
                            self.seed, executions)
        write_session(path, plan, distro)
        logger.info("wrote %d motions to %s", len(self.executed), path)


_latest: World | None = None


def make_current(world: World) -> None:
    """Make `world` the one MoveGroupCommander, PlanningSceneInterface and tf use when given no robot."""
    global _latest
    _latest = world


def latest_world() -> World | None:
    """Return the World of the RobotCommander created last, None before the first."""
    return _latest


def current_world(robot: object, caller: str) -> World:
    """Return the World of `robot` if it is a RobotCommander, else the one created last (the ROS graph's move_group).

    Anything else in `robot`'s place (MoveIt's robot_description or ns string, tf2's cache_time)
    means the one created last, as it would name the one move_group of a ROS graph. Before any,
    one is created from `$MOVEPLAN_ROBOT`, as a script relies on a move_group launched before it.

    Raises:
        UsageError: No RobotCommander was created yet and MOVEPLAN_ROBOT is not set.
    """
    world = getattr(robot, "world", None)
    if isinstance(world, World):
        return world
    if _latest is None:
        name = os.environ.get(ROBOT_VARIABLE)
        if not name:
            raise UsageError(f"{caller}: no robot: create a RobotCommander first (RobotCommander('ur10e') stands in "
                             f"for launching move_group) or set {ROBOT_VARIABLE}")
        execution = ExecutionSettings("mirror", {}, None, 0)
        launched = World(RobotSource(name), None, execution, 0)  # as RobotCommander() would load it
        check_execution(launched.config, launched.robot(None).joint_names, execution)
        make_current(launched)
    assert _latest is not None
    return _latest
