"""Robot states as `moveplan state` reports them: the group's joint values and a link's pose in a frame.

What MoveIt's `get_current_joint_values()` and tf2's `lookup_transform(frame, link)` answer,
for a state given by joint values, a named state, the config's start, or a time of a plan file.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..config import PLANNING_SCENE_KEYS, JointGoal, NamedGoal, RobotConfig, check_joint_units, mapping, parse_yaml
from ..errors import FrameNotFound, InputError, OutsideLimits, UnknownName, UsageError
from ..model import Robot, Scene, empty_scene, load_scene, moveplan_scene, read_planning_scene
from ..planning import joint_target
from ..trajectory import sample
from ..types import LinkPose, RobotState
from .request import RobotSource

__all__ = [
    "EMBEDDED_SCENES", "LinkPose", "RobotState", "StateRequest", "StateResult", "robot_state",
    "state",
]

EMBEDDED_SCENES = ("scene.yaml", "scene.yml")
"""Attachment names under which `moveplan plan` embeds the scene it was given."""


@dataclass(frozen=True)
class StateRequest:
    """What `moveplan state` was asked; the rules between its flags hold (UsageError otherwise).

    Attributes:
        robot: The robot config; None only with `plan`, whose embedded config is used.
        group: Planning group (default: the config's, or with `plan` the plan's).
        joints, named: The state: group joint values, or an SRDF group_state, on top of the
            config's start state. At most one of `joints`, `named` and `plan`.
        plan: A plan file; the state is where it ends, or at `at_s`.
        step: With `plan`: a step's name; its end, or `at_s` from its start.
        at_s: With `plan`: a time in [s] from the plan's start (from the step's start with `step`).
        link: The link (or scene frame) whose pose is reported; default the group's tip.
        frame: The frame the pose is given in; default the planning frame.
        scene: A scene file, for its frames (with `plan`, instead of the one the plan embeds).
    """

    robot: RobotSource | None = None
    group: str | None = None
    joints: JointGoal | None = None
    named: str | None = None
    plan: Path | None = None
    step: str | None = None
    at_s: float | None = None
    link: str | None = None
    frame: str | None = None
    scene: Path | None = None

    def __post_init__(self) -> None:
        given = [flag for flag, value in (("--joints", self.joints), ("--named", self.named), ("--from", self.plan))
                 if value is not None]
        if len(given) > 1:
            raise UsageError(f"give one of --joints, --named and --from, got {', '.join(given)}")
        for flag, value in (("--step", self.step), ("--at", self.at_s)):
            if value is not None and self.plan is None:
                raise UsageError(f"{flag} goes with --from PLAN.mcap")
        if self.robot is None and self.plan is None:
            raise UsageError("no robot: give --robot, or --from a plan file (it carries its robot config)")


@dataclass(frozen=True)
class StateResult:
    """A state `moveplan state` reports: the robot and group, where the state comes from, and the state."""

    robot: str
    group: str
    source: str
    state: RobotState


def robot_state(
    robot: Robot, scene: Scene, q: NDArray[np.float64], link: str | None = None, frame: str | None = None
) -> RobotState:
    """Return the group's values in configuration `q` and `link`'s pose in `frame` (tip; planning frame)."""
    link = link or robot.group.tip
    frame = frame or robot.root_link
    root_T_link = _frame_pose(robot, scene, q, link, "--link")
    root_T_frame = _frame_pose(robot, scene, q, frame, "--frame")
    joints = dict(zip(robot.joint_names, (float(v) for v in robot.values(q)), strict=True))
    prismatic = tuple(j for j in robot.joint_names if robot.config.urdf_joints[j].type == "prismatic")
    return RobotState(joints, LinkPose.of(link, frame, np.linalg.inv(root_T_frame) @ root_T_link), prismatic)


def _frame_pose(robot: Robot, scene: Scene, q: NDArray[np.float64], name: str, flag: str) -> NDArray[np.float64]:
    """Return `root_T_name` of a robot link, a scene frame or a name of the planning frame, in configuration `q`."""
    try:
        anchor, anchor_T_frame = scene.anchor(name, robot)
    except FrameNotFound as exc:
        where = f"robot '{robot.config.name}'" + ("" if not scene.frames else f" or {scene.source}")
        raise FrameNotFound(name, f"{where} ({flag})", exc.valid) from None
    return robot.frame_pose(q, anchor) @ anchor_T_frame


def state(request: StateRequest) -> StateResult:
    """Return the state `request` asks for: its joint values and the link's pose in the frame."""
    if request.plan is not None:
        return _plan_state(request, request.plan)
    assert request.robot is not None, "StateRequest checks it"
    config = request.robot.load()
    robot = Robot(config, request.group)
    scene = load_scene(request.scene, robot) if request.scene is not None else empty_scene()
    base = robot.neutral()
    for joint, value in scene.robot_state.items():  # where a PlanningScene puts the robot, as plan starts
        base = robot.set_joint(base, joint, value)
    source = f"{scene.source}: robot_state" if scene.robot_state else "the config's start state"
    goal: JointGoal | NamedGoal | None = request.joints
    if request.named is not None:
        goal = NamedGoal(request.named)
    if goal is not None:
        flag = "--joints" if isinstance(goal, JointGoal) else f"--named {goal.name}"
        base = robot.configuration(_values(robot, config, goal, robot.values(base), flag), base)
        source = flag
    return StateResult(config.name, robot.group.name, source,
                       robot_state(robot, scene, base, request.link, request.frame))


def _values(
    robot: Robot, config: RobotConfig, goal: JointGoal | NamedGoal, start: NDArray[np.float64], flag: str
) -> NDArray[np.float64]:
    """Return the group values `goal` sets on top of `start`, checked for units and against the limits."""
    if isinstance(goal, JointGoal):
        check_joint_units(goal, config, robot.joint_names)
    try:
        return joint_target(robot, goal, start, flag)
    except OutsideLimits as exc:
        raise UsageError(f"{flag}: joint '{exc.joint}' at {exc.value:.6g} is outside its limits "
                         f"[{exc.lower:.6g}, {exc.upper:.6g}]") from None


def _plan_state(request: StateRequest, path: Path) -> StateResult:
    """Return the state of a plan file at the end, a step's end, or a time (`request.step`, `request.at_s`)."""
    # Imported here: reading plan files is execution's business, and `state` without --from needs none of it.
    from ._plan_files import plan_config, read_valid_plan

    plan = read_valid_plan(path)
    config = request.robot.load() if request.robot is not None else plan_config(plan, path)
    if config.name != plan.robot_name:
        raise InputError(f"--from {path}: a plan of robot '{plan.robot_name}', not of robot '{config.name}' (--robot)")
    robot = Robot(config, request.group or plan.group)
    scene = _plan_scene(request.scene, plan.attachments, path, robot)
    names = [step.name for step in plan.steps]
    if request.step is not None and request.step not in names:
        raise UnknownName("step", request.step, str(path), names)
    steps = [s for s in plan.steps if request.step is None or s.name == request.step]
    origin = steps[0].start_s
    end_s = steps[-1].start_s + steps[-1].trajectory.duration_s - origin
    at_s = end_s if request.at_s is None else request.at_s
    if at_s > end_s + 1e-9:
        span = f"step '{request.step}'" if request.step is not None else "the plan"
        raise UsageError(f"--at: {at_s:g} s is after the end of {span} ({end_s:.6g} s)")
    # At a boundary between two steps, the later one: it starts where the earlier one ends.
    step = next((s for s in reversed(steps) if s.start_s - origin <= at_s), steps[0])
    trajectory = step.trajectory
    positions = sample(trajectory, [min(at_s - (step.start_s - origin), trajectory.duration_s)])[0][0]
    q = robot.neutral()
    for joint, value in zip(trajectory.joint_names, positions, strict=True):
        if not robot.model.existJointName(joint):
            raise InputError(f"--from {path}: joint '{joint}' of the plan is not a joint of robot '{config.name}'")
        q = robot.set_joint(q, joint, float(value))
    if request.at_s is None:
        source = f"{path}: end of step '{step.name}'" if request.step is not None else f"{path}: end of the plan"
    elif request.step is not None:
        source = f"{path}: {at_s:g} s into step '{step.name}'"
    else:
        source = f"{path}: {at_s:g} s from the plan's start (step '{step.name}')"
    return StateResult(config.name, robot.group.name, source,
                       robot_state(robot, scene, q, request.link, request.frame))


def _plan_scene(scene: Path | None, attachments: dict[str, bytes], path: Path, robot: Robot) -> Scene:
    """Return the frames of `scene` if given, else of the scene the plan embeds, else an empty scene.

    Of an embedded moveplan scene only the frames are read: its objects' mesh files stayed
    beside the original scene file.
    """
    if scene is not None:
        return load_scene(scene, robot)
    name = next((n for n in EMBEDDED_SCENES if n in attachments), None)
    if name is None:
        return empty_scene()
    shown = Path(f"{path}: embedded {name}")
    try:
        top = mapping(parse_yaml(attachments[name].decode("utf-8"), shown), str(shown))
    except UnicodeDecodeError:
        raise InputError(f"{shown}: not UTF-8 text") from None
    if PLANNING_SCENE_KEYS & set(top):
        return read_planning_scene(_without_mesh_files(top), shown, robot)
    return moveplan_scene({"frames": top.get("frames")}, shown, robot)


# A triangle standing in for a mesh file: an object's frames do not depend on its shapes.
_STAND_IN = {"vertices": [[0.0, 0.0, 0.0], [1e-3, 0.0, 0.0], [0.0, 1e-3, 0.0]], "triangles": [[0, 1, 2]]}


def _without_mesh_files(top: dict[str, Any]) -> dict[str, Any]:
    """Return an embedded PlanningScene with each mesh file (`resource`) replaced by a stand-in triangle.

    A plan carries no mesh file: a `resource` names a path or package of the machine that
    planned, and opening a plan file must read nothing of this machine's.
    """
    def objects(section: Any, key: str) -> list[Any]:
        found = section.get(key) if isinstance(section, dict) else None
        return found if isinstance(found, list) else []

    copied = copy.deepcopy(top)
    attached = [a.get("object") for a in objects(copied.get("robot_state"), "attached_collision_objects")
                if isinstance(a, dict)]
    for obj in [*objects(copied.get("world"), "collision_objects"), *attached]:
        for k, mesh in enumerate(objects(obj, "meshes")):
            if isinstance(mesh, dict) and ("resource" in mesh or "dimensions" in mesh):
                obj["meshes"][k] = copy.deepcopy(_STAND_IN)
    return copied
