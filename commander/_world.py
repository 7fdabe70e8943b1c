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

import numpy as np
from numpy.typing import NDArray

from ..core.control import ExecutionSummary
from ..core.errors import UsageError
from ..core.model import Robot, Scene, empty_scene, load_scene
from ..core.pipeline import (
    ExecutionSettings,
    Problem,
    RobotSource,
    compose_scene,
    frame_in_root,
    motion_problem,
    session_plan,
    start_configuration,
    write_session,
)
from ..core.types import CollisionObject, Frame, StepResult

__all__ = ["Executed", "World", "current_world", "make_current"]

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
        self._robot_state = dict(base.robot_state)
        self._scene: Scene = compose_scene(self.source, base.frames, base.objects, robot, self._allowed,
                                           self._robot_state)
        self.q = start_configuration(robot, self._scene)
        self.start_q = self.q.copy()
        self._problems: dict[tuple[str, bytes], Problem] = {}
        self.executed: list[Executed] = []

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

    def change(self, frames: Mapping[str, Frame] | None = None,
               objects: Mapping[str, CollisionObject] | None = None) -> None:
        """Replace the scene's frames and/or objects, checked as a scene file's are; on error nothing changes."""
        new_frames = dict(self._frames if frames is None else frames)
        new_objects = dict(self._objects if objects is None else objects)
        self._scene = compose_scene(self.source, list(new_frames.values()), list(new_objects.values()),
                                    self.robot(None), self._allowed, self._robot_state)
        self._frames, self._objects = new_frames, new_objects
        if objects is not None:
            self._problems.clear()

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

    def record(self, group: str, step: StepResult, summary: ExecutionSummary) -> None:
        """Add an executed motion, its step named uniquely, for save()."""
        names = {e.step.name for e in self.executed}
        name, k = step.name, 1
        while name in names:
            k += 1
            name = f"{step.name}_{k}"
        self.executed.append(Executed(group, replace(step, name=name), summary, self.execution.plant))

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


def current_world(robot: object, caller: str) -> World:
    """Return the World of `robot` if it is a RobotCommander, else the one created last (the ROS graph's move_group).

    Anything else in `robot`'s place (MoveIt's robot_description or ns string, tf2's cache_time)
    means the one created last, as it would name the one move_group of a ROS graph.

    Raises:
        UsageError: No RobotCommander was created yet.
    """
    world = getattr(robot, "world", None)
    if isinstance(world, World):
        return world
    if _latest is None:
        raise UsageError(f"{caller}: no robot: create a RobotCommander first (RobotCommander('ur10e') stands in "
                         "for launching move_group)")
    return _latest
