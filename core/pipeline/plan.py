"""The plan pipeline: request -> robot, scene, start -> per step goal, path, timing -> Plan.

Data flows one way; this module and step.py are the only ones that compose planning,
timing and recording. Precedence of settings lives in `resolve_request` (request.py):
flag > MoveIt request > task file > robot config > built-in default. Each step is
planned in named stages (step.py).
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..bag import END_STATES_KEY, write_plan
from ..collision import exact_checks
from ..config import (
    DEFAULT_ACCELERATION,
    JointGoal,
    NamedGoal,
    RobotConfig,
    StartFrom,
    check_joint_units,
    load_robot_config,
    load_task,
    read_input,
)
from ..errors import InputError, MoveplanError, StartInCollision, StartOutsideLimits, UnknownName, UsageError
from ..model import Robot, Scene, attach_request_objects, empty_scene, known_joints, load_scene
from ..planning import check_limits, joint_target, seed_planner
from ..trajectory import sample
from ..types import Plan, StepResult, TfSamples
from ..version import moveplan_version
from ._checks import Problem, build_problem, filter_threshold
from ._step import plan_step
from .request import PlanFlags, PlanRequest, resolve_request
from .robot_state import RobotState, robot_state

__all__ = ["PlanFlags", "PlanRequest", "PlanResult", "assemble", "exact_valid", "plan", "plan_to_file", "planned",
           "resolve_request"]

logger = logging.getLogger(__name__)

_TF_RATE_HZ = 30.0


@dataclass(frozen=True)
class PlanResult(Plan):
    """A plan, with where each step ends: its group joint values and the tip's pose in the planning frame.

    Attributes:
        end_states: One per step, in order (joints outside the group as the plan starts).
    """

    end_states: tuple[RobotState, ...] = ()


def plan_to_file(task: Path | None, flags: PlanFlags, output: Path, ros_distro: str = "jazzy") -> PlanResult:
    """Plan what a task file (if any) and the flags ask for, write it to `output` for `ros_distro`, return it."""
    request = resolve_request(load_task(task) if task is not None else None, flags)
    config = load_robot_config(request.robot, request.package_paths, request.xacro_args, urdf=request.urdf,
                               srdf=request.srdf, strict_limits=request.strict_limits,
                               joint_limits=request.joint_limits, launch=request.launch,
                               launch_args=request.launch_args, strict=request.strict)
    _refuse_replacing_inputs(output, request, config)
    if (request.group or config.planning["group"]) in config.srdf.groups:
        _warn_default_accelerations(config, request.group or config.planning["group"])
    result = plan(request, config, filter_after=filter_threshold())
    write_plan(output, result, ros_distro)
    return result


def _refuse_replacing_inputs(output: Path, request: PlanRequest, config: RobotConfig) -> None:
    """Raise UsageError if `output` is a file the plan is made from: writing it would replace that file."""
    named = [
        ("the task file", request.task.source if request.task else None),
        ("the scene", request.scene),
        ("the MotionPlanRequest", request.motion_request.source if request.motion_request else None),
        ("the --start-from plan", request.start.plan if isinstance(request.start, StartFrom) else None),
        *((f"the robot config's {key}", path) for key, path in config.sources.items()),
        *(("a file of the robot's URDF", path) for path in config.urdf_includes),
    ]
    if not output.exists():
        return
    for what, path in named:
        if path is not None and Path(path).exists() and os.path.samefile(output, path):
            raise UsageError(f"-o '{output}': is also {what} ({path}); an output must not replace an input")


def plan(request: PlanRequest, config: RobotConfig | None = None, filter_after: int = 0) -> PlanResult:
    """Return the timed, collision-free plan for every step of `request`, in order.

    `config` is the loaded `request.robot` when the caller has it (a benchmark plans many
    problems with one robot); a config loaded here also warns about the group's joints that
    plan with the default acceleration limit (limits.DEFAULT_ACCELERATION). The sphere filter
    is built after `filter_after` states checked without it in this process (core/pipeline/_checks.py): 0, now.

    Raises:
        MoveplanError: Any error while planning a step carries the step's name (`step`), and
            the plan of the steps before it (`partial`, None if it is the first).
    """
    return planned(request, config, filter_after)[0]


def planned(
    request: PlanRequest, config: RobotConfig | None = None, filter_after: int = 0
) -> tuple[PlanResult, Problem]:
    """Return `plan`'s plan and the problem it was planned in: the robot, the scene and their collision checks."""
    seed_planner(request.seed)
    loaded_here = config is None
    if config is None:
        config = load_robot_config(request.robot, request.package_paths, request.xacro_args, urdf=request.urdf,
                                   srdf=request.srdf, strict_limits=request.strict_limits,
                                   joint_limits=request.joint_limits, launch=request.launch,
                                   launch_args=request.launch_args, strict=request.strict)
    robot = _robot(request, config)
    if loaded_here:
        _warn_default_accelerations(config, robot.group.name)
    for goal in (request.start, *(spec.goal for spec in request.steps)):
        if isinstance(goal, JointGoal):  # degrees without their unit, before any planning
            check_joint_units(goal, config, robot.joint_names)
    scene = load_scene(request.scene, robot) if request.scene else empty_scene()
    base, current = _start_values(request, robot, scene)
    if request.motion_request is not None:  # objects the request's start state carries
        scene = attach_request_objects(scene, request.motion_request, robot, robot.configuration(current, base))
    problem = build_problem(robot, scene, config.planning["collision"], base, filter_after)
    pair = problem.checks.colliding_pair(current)
    if pair:
        raise StartInCollision(pair)
    steps: list[StepResult] = []
    try:
        for step in _planned_steps(request, problem, current):
            steps.append(step)
    except MoveplanError as exc:
        if steps:
            exc.partial = assemble(request, config, robot, scene, base, steps)
        raise
    return assemble(request, config, robot, scene, base, steps), problem


def exact_valid(plan: PlanResult, problem: Problem) -> bool:
    """Return True if every step's certified states are free under the URDF's exact meshes, checked anew (a referee)."""
    referee = exact_checks(problem.checks, problem.scene)
    return all(referee.first_collision_on_trajectory(step.trajectory, between=False) is None for step in plan.steps)


def _robot(request: PlanRequest, config: RobotConfig) -> Robot:
    """Return the robot's planning group, with the request's group and joint names checked against it."""
    motion = request.motion_request
    if motion is not None and motion.group_name and request.group == motion.group_name:
        if motion.group_name not in config.srdf.groups:
            raise UnknownName("group", motion.group_name, f"{motion.source}: group_name", config.srdf.groups)
    robot = Robot(config, request.group)
    if motion is not None and motion.goal is not None and any(s is motion.goal for s in request.steps):
        named = motion.goal.goal.named_values if isinstance(motion.goal.goal, JointGoal) else None
        for joint in named or {}:
            if joint not in robot.joint_names:
                raise UnknownName("joint", joint, f"{motion.source}: goal_constraints[0].joint_constraints "
                                  f"(group '{robot.group.name}')", robot.joint_names)
    return robot


def _warn_default_accelerations(config: RobotConfig, group: str) -> None:
    """Log a warning naming the group's joints the config gives no acceleration limit, and the file."""
    defaulted = config.missing_acceleration_limits(group)
    if defaulted:
        where = config.sources.get("joint_limits", config.urdf_path)
        logger.warning("%s: no acceleration limit for joints %s; planning with the default %g rad/s^2 (m/s^2 for "
                       "a prismatic joint), as MoveIt 1 did (--strict-limits makes this an error)",
                       where, ", ".join(defaulted), DEFAULT_ACCELERATION)


def _start_values(
    request: PlanRequest, robot: Robot, scene: Scene
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the start configuration (all joints) and the group's start values.

    Every joint starts at the initial positions (RobotConfig.initial_positions), overridden by
    the scene's robot state, then by the MoveIt request's start state (MoveIt applies a request's
    start state on top of the scene's). The group's joints then take a start flag or the task's
    start, if given. The group's start is checked against the limits before anything else.

    Raises:
        StartOutsideLimits: A group joint starts outside its limits; names the joint and where
            its value came from.
    """
    base = robot.neutral()
    origins = dict(robot.config.initial_sources)
    layers = [(scene.robot_state, f"{scene.source}: robot_state")]
    if request.motion_request is not None:
        motion = request.motion_request
        state = known_joints(motion.start, robot, f"{motion.source}: start_state.joint_state.name")
        layers.append((state, f"{motion.source}: start_state"))
    for state, origin in layers:
        for joint, value in state.items():
            base = robot.set_joint(base, joint, value)
            origins[joint] = origin
    values = robot.values(base)
    start, origin = request.start, _start_origin(request)
    if isinstance(start, StartFrom):
        start = _start_from(Path(start.plan), robot)
    try:
        if start is None:
            check_limits(robot, values, StartOutsideLimits)
            return base, values
        return base, joint_target(robot, start, values, origin, StartOutsideLimits)
    except StartOutsideLimits as exc:
        # A joint the start leaves out keeps its value from the initial positions, scene or request.
        given = _joints_set_by(robot, start) if start is not None else set()
        where = origin if exc.joint in given else origins.get(exc.joint, "the initial positions")
        raise StartOutsideLimits(exc.joint, exc.value, exc.lower, exc.upper, where) from None


def _start_origin(request: PlanRequest) -> str:
    """Return where the request's start comes from, as messages name it: the task file, or a start flag."""
    start = request.start
    if request.task is not None and start is request.task.start:
        return f"{request.task.source}: start"
    if isinstance(start, StartFrom):
        return f"--start-from {start.plan}"
    return f"--start-named {start.name}" if isinstance(start, NamedGoal) else "--start-joints"


def _joints_set_by(robot: Robot, start: JointGoal | NamedGoal) -> set[str]:
    """Return the group joints a start gives a value (the others keep theirs)."""
    if isinstance(start, NamedGoal):
        return set(robot.config.srdf.group_states.get(robot.group.name, {}).get(start.name, {}))
    return set(robot.joint_names if start.named_values is None else start.named_values)



def _start_from(path: Path, robot: Robot) -> JointGoal:
    """Return where the plan file at `path` ends, as a start for `robot`'s group.

    Raises:
        InputError: The file is no readable plan, ends on a non-finite value, is a plan of
            another robot, or moves none of the group's joints.

    """
    # Imported here: execution's district (the controller simulation) is no part of planning.
    from ._plan_files import read_valid_plan

    plan = read_valid_plan(path)
    name = robot.config.name
    last = plan.steps[-1].trajectory
    shared = [j for j in last.joint_names if j in robot.joint_names]
    if plan.robot_name != name or not shared:
        raise InputError(
            f"--start-from {path}: a plan of robot '{plan.robot_name}' (joints "
            f"{', '.join(last.joint_names)}), not of robot '{name}' (group '{robot.group.name}': "
            f"{', '.join(robot.joint_names)})")
    values = dict(zip(last.joint_names, last.positions[-1].tolist(), strict=True))
    return JointGoal.by_name({j: values[j] for j in shared})


def _planned_steps(request: PlanRequest, problem: Problem, start: NDArray[np.float64]) -> Iterator[StepResult]:
    """Yield every step planned in order, each from where the previous one ended."""
    current = start
    for spec in request.steps:
        try:
            step = plan_step(spec, request, problem, current)
        except MoveplanError as exc:
            raise exc.in_step(spec.name) from None
        yield step
        current = step.trajectory.positions[-1].copy()


def assemble(
    request: PlanRequest, config: RobotConfig, robot: Robot, scene: Scene, base: NDArray[np.float64],
    steps: list[StepResult],
) -> PlanResult:
    """Return the plan of the planned steps, with what replaying and checking it needs, and where each step ends.

    It takes the robot, scene and base, not a Problem: a commander session assembles its executed
    motions without building collision checks.
    """
    # Each step's end: the pose of the link its goal moved (a pose goal's link), else the tip's.
    ends = tuple(robot_state(robot, scene, robot.configuration(step.trajectory.positions[-1], base), _goal_link(step))
                 for step in steps)
    return PlanResult(
        robot_name=config.name,
        group=robot.group.name,
        planning_frame=robot.root_link,
        steps=tuple(steps),
        urdf=config.urdf,
        static_frames=(*robot.fixed_frames(), *scene.frames),
        objects=scene.objects,
        tf=_tf_samples(robot, base, steps),
        limits={j: {"lower": float(robot.lower[i]), "upper": float(robot.upper[i]),
                    "max_velocity": float(robot.max_velocity[i]),
                    "max_acceleration": float(robot.max_acceleration[i])}
                for i, j in enumerate(robot.joint_names)},
        attachments=_attachments(config, request),
        metadata={"seed": str(request.seed), "moveplan_version": moveplan_version(),
                  "planners": ",".join(s.planner for s in steps),
                  "limit_sources": json.dumps({j: config.limits[j].source for j in robot.joint_names}, sort_keys=True),
                  # `inspect` reads where each step ends from here, without loading the robot.
                  END_STATES_KEY: json.dumps([end.as_dict() for end in ends])},
        end_states=ends,
    )


def _tf_samples(robot: Robot, base: NDArray[np.float64], steps: list[StepResult]) -> TfSamples:
    """Return the moving joints' transforms along the whole plan, at a playback rate."""
    times, values = [], []
    offset = 0.0
    for step in steps:
        trajectory = step.trajectory
        count = max(2, int(np.ceil(trajectory.duration_s * _TF_RATE_HZ)) + 1)
        local = np.linspace(0.0, trajectory.duration_s, count)
        values.append(sample(trajectory, local, derivatives=0)[0])  # /tf carries positions alone
        times.append(offset + local)
        offset += trajectory.duration_s
    return robot.tf_samples(np.concatenate(times), np.concatenate(values), base)


def _attachments(config: RobotConfig, request: PlanRequest) -> dict[str, bytes]:
    """Return the files a plan embeds: the robot config's, and the scene, task and request given."""
    files = dict(config.files)
    if request.scene is not None:
        files[f"scene{Path(request.scene).suffix}"] = read_input(Path(request.scene))
    if request.task is not None:
        files["task.yaml"] = request.task.raw
    if request.motion_request is not None:
        files["request.yaml"] = request.motion_request.raw
    return files


def _goal_link(step: StepResult) -> str | None:
    """Return the link a step's pose goal moved (`--link`, a task's `link`), None for the tip."""
    pose = step.goal.get("pose")
    link = pose.get("link") if isinstance(pose, dict) else None
    return link if isinstance(link, str) and link else None
