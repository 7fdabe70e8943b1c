"""The plan pipeline: request -> robot, scene, start -> per step goal, path, timing -> Plan.

Data flows one way; this module is the only one that composes planning,
timing and recording. Precedence of settings lives in `resolve_request`:
flag > MoveIt request > task file > robot config > built-in default.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from importlib.metadata import version
from pathlib import Path
from typing import Any

import coal
import numpy as np
from numpy.typing import NDArray

from moveplan.core import recording
from moveplan.core.cartesian import straight_line
from moveplan.core.collision import CollisionChecker
from moveplan.core.config import RobotConfig, load_robot_config
from moveplan.core.errors import (
    ConfigError,
    GoalInCollision,
    GoalUnreachable,
    PlanningFailed,
    PlanningTimeExceeded,
    StartInCollision,
    UnknownName,
    UsageError,
)
from moveplan.core.goals import check_limits, joint_target, pose_error, tip_target
from moveplan.core.kinematics import solve_ik
from moveplan.core.moveit_messages import known_joints
from moveplan.core.moveit_request import MotionPlanRequest, load_motion_plan_request
from moveplan.core.planning import PathResult, Validity, plan_path, repair_path, seed_planner
from moveplan.core.robot import Robot
from moveplan.core.scene import Scene, empty_scene, load_scene
from moveplan.core.sphere_check import SphereFilter, UnsupportedJoint
from moveplan.core.tasks import StepSpec, TaskFile
from moveplan.core.timing import time_parameterize
from moveplan.core.trajectory import sample
from moveplan.core.types import JointTrajectory, Plan, StepResult, TfSamples
from moveplan.core.validity import MotionChecker

__all__ = ["PlanRequest", "plan", "resolve_request"]

logger = logging.getLogger(__name__)

# The search checks edges every 0.05 rad; what is written is certified as the controller
# interpolates it, with no robot point moving more than 5 mm between checked states. A
# trajectory that fails certification has usually crossed a thin obstacle between two checked
# states: the path's segments are checked again every 0.005 rad, those that fail are planned
# again at that resolution, and the result is timed closer to the path.
_COARSE_RAD, _FINE_RAD = 0.05, 0.005  # edge check resolutions
_COARSE_STEP_RAD, _FINE_STEP_RAD = 0.05, 0.01  # timing resample steps
_TF_RATE_HZ = 30.0


@dataclass(frozen=True)
class PlanRequest:
    """Everything one `moveplan plan` run needs, after precedence has been applied."""

    robot: Path
    steps: tuple[StepSpec, ...]
    scene: Path | None = None
    group: str | None = None
    start: dict[str, Any] = field(default_factory=dict)
    planner: str | None = None
    planning_time: float | None = None
    velocity_scaling: float | None = None
    acceleration_scaling: float | None = None
    seed: int = 0
    min_fraction: float = 1.0
    package_paths: tuple[Path, ...] = ()
    xacro_args: dict[str, str] = field(default_factory=dict)
    task: TaskFile | None = None
    motion_request: MotionPlanRequest | None = None


def resolve_request(task: TaskFile | None, flags: dict[str, Any]) -> PlanRequest:
    """Return the request that flags, a MoveIt request (flags["request"]) and task give together.

    A flag wins over the MoveIt request, which wins over the task. A goal by flag replaces the
    request's goal; a request's goal and a task's steps conflict, as a flag goal and task steps do.
    The request's start state, when it has one, replaces the task's start.
    """
    motion = load_motion_plan_request(Path(flags["request"])) if flags.get("request") else None
    task_values: dict[str, Any] = {}
    if task is not None:
        task_values = {"robot": task.robot, "scene": task.scene, "group": task.group, "seed": task.seed,
                       **task.defaults}
    request_values: dict[str, Any] = {}
    if motion is not None:
        request_values = {"group": motion.group_name, "planner": motion.planner,
                          "planning_time": motion.planning_time, "velocity_scaling": motion.velocity_scaling,
                          "acceleration_scaling": motion.acceleration_scaling}
    merged = {k: v for k, v in task_values.items() if v is not None}
    merged.update({k: v for k, v in request_values.items() if v is not None})
    merged.update({k: v for k, v in flags.items() if v is not None and k not in ("steps", "start", "request")})
    steps = tuple(flags.get("steps") or ())
    if steps and task is not None and task.steps:
        raise UsageError(f"{task.source} has steps; give a goal by flag or by task, not both")
    if not steps and motion is not None and motion.goal is not None:
        if task is not None and task.steps:
            raise UsageError(f"{task.source} has steps and {motion.source} has goal_constraints; give one of them")
        steps = (motion.goal,)
    if task is not None and not steps:
        steps = task.steps
    if not steps:
        raise UsageError("no goal: give --joints, --named, --pose, --shift, a --request with goal_constraints, "
                         "or a task file with steps")
    if "robot" not in merged:
        raise UsageError("no robot: give --robot or a task file naming one")
    start = flags.get("start") or {}
    if not start and task is not None and not (motion is not None and motion.start):
        start = task.start
    return PlanRequest(
        robot=Path(merged["robot"]), steps=steps, scene=merged.get("scene"), group=merged.get("group"),
        start=start, planner=merged.get("planner"), planning_time=merged.get("planning_time"),
        velocity_scaling=merged.get("velocity_scaling"), acceleration_scaling=merged.get("acceleration_scaling"),
        seed=int(merged.get("seed") or 0), min_fraction=float(merged.get("min_fraction", 1.0)),
        package_paths=tuple(flags.get("package_paths") or ()),
        xacro_args=dict(flags.get("xacro_args") or {}), task=task, motion_request=motion,
    )


def plan(request: PlanRequest, config: RobotConfig | None = None, exact_check: bool = False) -> Plan:
    """Return the timed, collision-free plan for every step of `request`, in order.

    `config` is the loaded `request.robot` when the caller has it (a benchmark plans many
    problems with one robot). With `exact_check`, each step's `stats["exact_valid"]` says
    whether its trajectory is free under the URDF's exact meshes, checked independently of
    the planner's geometry (1.0 or 0.0).
    """
    seed_planner(request.seed)
    if config is None:
        config = load_robot_config(request.robot, request.package_paths, request.xacro_args)
    motion = request.motion_request
    if motion is not None and motion.group_name and request.group == motion.group_name:
        if motion.group_name not in config.srdf.groups:
            raise UnknownName("group", motion.group_name, f"{motion.source}: group_name", config.srdf.groups)
    robot = Robot(config, request.group)
    if motion is not None and motion.goal is not None and any(s is motion.goal for s in request.steps):
        for joint in motion.goal.goal.get("joints", {}):
            if joint not in robot.joint_names:
                raise UnknownName("joint", joint, f"{motion.source}: goal_constraints[0].joint_constraints "
                                  f"(group '{robot.group.name}')", robot.joint_names)
    missing = config.missing_acceleration_limits(robot.group.name)
    if missing:
        raise ConfigError(f"{config.root}: no acceleration limit for joints {', '.join(missing)} "
                          "(joint_limits.yaml: has_acceleration_limits, max_acceleration)")
    scene = load_scene(request.scene, robot) if request.scene else empty_scene()
    checker = CollisionChecker(robot, scene.objects, scene.source, geometry=config.planning["collision"],
                               allowed=scene.allowed)
    base, current = _start_values(request, robot, scene)
    hulls = _hull_checker(robot, checker, scene)
    checks = MotionChecker(robot, checker, base, _sphere_filter(robot, checker, hulls, scene, base), hulls)
    pair = checks.colliding_pair(current)
    if pair:
        raise StartInCollision(pair)

    steps: list[StepResult] = []
    for spec in request.steps:
        try:
            step = _plan_step(spec, request, robot, scene, checks, current)
        except (PlanningFailed, GoalUnreachable, StartInCollision, ConfigError) as exc:
            raise _in_step(exc, spec.name) from None
        steps.append(step)
        current = step.trajectory.positions[-1].copy()
    if exact_check:
        exact = checker if checker.mode == "exact" else CollisionChecker(
            robot, scene.objects, scene.source, geometry="exact", allowed=scene.allowed)
        referee = MotionChecker(robot, exact, base)
        for step in steps:
            step.stats["exact_valid"] = float(referee.first_collision_on_trajectory(step.trajectory) is None)
    return Plan(
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
        metadata={"seed": str(request.seed), "moveplan_version": version("moveplan"),
                  "planners": ",".join(s.planner for s in steps)},
    )


def _sphere_filter(
    robot: Robot, checker: CollisionChecker, hulls: CollisionChecker | None, scene: Scene, base: NDArray[np.float64]
) -> SphereFilter | None:
    """Return the fast conservative pre-check for `robot` (other joints at `base`) in `scene`, or None."""
    try:
        return SphereFilter(robot, checker.robot_geometry, scene.objects, scene.allowed, base,
                            (hulls or checker).robot_geometry)
    except UnsupportedJoint as exc:
        logger.info("no sphere filter (%s): every state is checked by coal", exc)
        return None


def _hull_checker(robot: Robot, checker: CollisionChecker, scene: Scene) -> CollisionChecker | None:
    """Return a checker of the robot's meshes as convex hulls in `scene` when `checker` has meshes, else None."""
    meshes = any(isinstance(obj.geometry, coal.BVHModelBase) for obj in checker.robot_geometry.geometryObjects)
    if checker.mode != "exact" or not meshes:
        return None  # the hulls would be the checker's own shapes, checked twice
    try:
        return CollisionChecker(robot, scene.objects, scene.source, geometry="convex", allowed=scene.allowed)
    except ConfigError as exc:
        logger.info("no hull stage (%s): states the spheres cannot clear go to the meshes", exc)
        return None


def _in_step(exc: Exception, step: str) -> Exception:
    """Return `exc` with the failing step's name in front of its message."""
    exc.args = (f"step '{step}': {exc.args[0] if exc.args else exc}",)
    return exc


def _start_values(
    request: PlanRequest, robot: Robot, scene: Scene
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the start configuration (all joints) and the group's start values.

    Every joint starts at the initial positions, overridden by the scene's robot state, then
    by the MoveIt request's start state (MoveIt applies a request's start state on top of the
    scene's). The group's joints then take a start flag or the task's start, if given.
    """
    base = robot.neutral()
    states = [scene.robot_state]
    if request.motion_request is not None:
        motion = request.motion_request
        states.append(known_joints(motion.start, robot, f"{motion.source}: start_state.joint_state.name"))
    for state in states:
        for joint, value in state.items():
            base = robot.set_joint(base, joint, value)
    start = request.start
    neutral = robot.values(base)
    if not start:
        return base, neutral
    if "from" in start:
        last = recording.read_plan(Path(start["from"])).steps[-1].trajectory
        values = dict(zip(last.joint_names, last.positions[-1], strict=True))
        start = {"joints": {j: float(v) for j, v in values.items() if j in robot.joint_names}}
    source = str(request.task.source) if request.task else "--start-joints"
    return base, joint_target(robot, start, neutral, source)


def _scaling(robot: Robot, request: PlanRequest, spec: StepSpec) -> tuple[float, float]:
    config = robot.config
    velocity = spec.velocity_scaling or request.velocity_scaling or config.default_velocity_scaling
    acceleration = spec.acceleration_scaling or request.acceleration_scaling or config.default_acceleration_scaling
    return velocity, acceleration


def _plan_step(
    spec: StepSpec,
    request: PlanRequest,
    robot: Robot,
    scene: Scene,
    checks: MotionChecker,
    start: NDArray[np.float64],
) -> StepResult:
    began = time.perf_counter()
    source = str(request.task.source) if request.task else "flags"
    base = checks.base
    planner = spec.planner or request.planner or robot.config.planning["planner"]
    planning_time = spec.planning_time or request.planning_time or robot.config.planning["planning_time"]
    fraction, target_pose, link = 1.0, None, robot.group.tip
    search: Callable[[Validity], PathResult]
    if "joints" in spec.goal or "named" in spec.goal:
        goal = joint_target(robot, spec.goal, start, "--joints" if request.task is None else source)
        pair = checks.colliding_pair(goal)
        if pair:
            raise GoalInCollision(pair)
    else:
        link, target_pose = tip_target(robot, scene, spec.goal, robot.configuration(start, base), source)
        if not spec.linear:
            # Exhaustive: the first valid solution from a far start is not always the nearest one.
            goal = solve_ik(robot, target_pose, link, start, base=base, seed=request.seed, exhaustive=True,
                            is_free=checks.state_free, colliding_pair=checks.checker.colliding_pair).values
    if spec.linear:
        planner = "linear"
        line = straight_line(robot, link, start, target_pose, base, checks.free, checks.checker.colliding_pair)
        fraction = line.fraction
        minimum = spec.min_fraction if spec.min_fraction is not None else request.min_fraction
        if fraction < minimum:
            x, y, z = line.stopped_at
            raise PlanningFailed(f"straight line achieved {fraction:.1%} of the way (minimum {minimum:.0%}): "
                                 f"{line.reason}; stopped at [{x:.4f}, {y:.4f}, {z:.4f}] in {robot.root_link}")
        line_path = PathResult(np.asarray(line.waypoints), planner, 0.0, 0.0)
        search = lambda validity: line_path  # noqa: E731 - the line is already checked
    else:
        search = lambda validity: plan_path(  # noqa: E731
            start, goal, robot.lower, robot.upper, validity, planner, planning_time)
    v_scale, a_scale = _scaling(robot, request, spec)
    max_velocity, max_acceleration = robot.max_velocity * v_scale, robot.max_acceleration * a_scale
    stats = {"plan_s": 0.0, "simplify_s": 0.0, "timing_s": 0.0, "certify_s": 0.0, "checks": 0.0}
    # The search checks the hulls, not the meshes, unless the start or goal is free only under the meshes.
    ends = start[None, :] if spec.linear else np.array([start, goal])
    conservative = checks.conservative_available and bool(checks.free(ends, conservative=True).all())

    def checked(resolution: float) -> Validity:
        return Validity(partial(checks.state_free, conservative=conservative),
                        partial(checks.edge_free, resolution=resolution, conservative=conservative))

    def certified(path: PathResult, max_step: float) -> tuple[JointTrajectory, NDArray[np.float64] | None]:
        mark = time.perf_counter()
        trajectory = time_parameterize(robot.joint_names, path.waypoints, max_velocity, max_acceleration,
                                       max_step=max_step)
        timed = time.perf_counter()
        hit = checks.first_collision_on_trajectory(trajectory)
        _add(stats, path, timed - mark, time.perf_counter() - timed)
        return trajectory, hit

    path = search(checked(_COARSE_RAD))
    trajectory, hit = certified(path, _COARSE_STEP_RAD)
    if hit is not None and not spec.linear:
        logger.debug("trajectory collides when certified; planning its colliding segments again, finer")
        try:
            path = repair_path(path.waypoints, robot.lower, robot.upper, checked(_FINE_RAD), planner, planning_time)
            trajectory, hit = certified(path, _FINE_STEP_RAD)
        except PlanningTimeExceeded:
            raise
        except PlanningFailed:
            pass  # a whole new search below
    if hit is not None:
        logger.debug("trajectory collides when certified; planning it all again, finer")
        path = search(checked(_FINE_RAD))
        trajectory, hit = certified(path, _FINE_STEP_RAD)
    if hit is not None:
        # A path hugging an obstacle defeats smoothing, and one through a thin obstacle can pass
        # coarse edge checks. Last resort: plan with edges checked at the certification states
        # and stop at each waypoint, so every joint, the controller's quintics included, stays on
        # the straight segments exactly; certify those segments.
        path = search(Validity(checks.state_free, checks.edge_free_certified))
        mark = time.perf_counter()
        trajectory = _rest_to_rest(robot.joint_names, path.waypoints, max_velocity, max_acceleration)
        timed = time.perf_counter()
        hit = checks.first_collision_on_path(path.waypoints)
        _add(stats, path, timed - mark, time.perf_counter() - timed)
        if hit is not None:
            pair = checks.colliding_pair(hit) or ("?", "?")
            raise PlanningFailed(f"the timed trajectory collides ({pair[0]} touches {pair[1]}) where the path did not")
    waypoints = path.waypoints
    stats["path_length"] = float(np.sum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1)))
    check_limits(robot, trajectory.positions.max(axis=0))
    check_limits(robot, trajectory.positions.min(axis=0))
    end = trajectory.positions[-1]
    if target_pose is None:
        residual = {"joints_rad": float(np.max(np.abs(end - waypoints[-1])))}
    else:
        reached = robot.frame_pose(robot.configuration(end, base), link)
        position, angle = pose_error(reached, target_pose)
        residual = {"position_m": position, "orientation_rad": angle}
    return StepResult(
        name=spec.name,
        goal=_describe(spec.goal),
        planner=path.planner,
        planning_time_s=time.perf_counter() - began,
        trajectory=trajectory,
        fraction=fraction,
        residual=residual,
        stats=stats,
    )


def _add(stats: dict[str, float], path: PathResult, timing_s: float, certify_s: float) -> None:
    """Add one attempt's times to a step's statistics."""
    stats["plan_s"] += path.planning_s
    stats["simplify_s"] += path.simplify_s
    stats["timing_s"] += timing_s
    stats["certify_s"] += certify_s
    stats["checks"] += path.checks


def _rest_to_rest(
    joint_names: tuple[str, ...],
    waypoints: NDArray[np.float64],
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
) -> JointTrajectory:
    """Return a trajectory that stops at every waypoint, each segment timed on its own straight line."""
    segments = [time_parameterize(joint_names, waypoints[k : k + 2], max_velocity, max_acceleration)
                for k in range(len(waypoints) - 1)]
    segments = [s for s in segments if len(s.times_s) > 1] or segments[:1]
    times, rows = [segments[0].times_s], [segments[0]]
    for segment in segments[1:]:
        # Consecutive segments share their joining point; keep it once, at the end of the first.
        times.append(times[-1][-1] + segment.times_s[1:])
        rows.append(segment)
    first = [rows[0].positions, rows[0].velocities, rows[0].accelerations]
    rest = [[r.positions[1:], r.velocities[1:], r.accelerations[1:]] for r in rows[1:]]
    columns = [np.concatenate([first[i], *(r[i] for r in rest)]) for i in range(3)]
    return JointTrajectory(joint_names, np.round(np.concatenate(times) * 1e9) / 1e9, *columns)


def _describe(goal: dict[str, Any]) -> dict[str, Any]:
    return {k: (dict(v) if isinstance(v, dict) else list(v) if isinstance(v, list | tuple) else v)
            for k, v in goal.items()}


def _tf_samples(robot: Robot, base: NDArray[np.float64], steps: list[StepResult]) -> TfSamples:
    """Return the moving joints' transforms along the whole plan, at a playback rate."""
    times, values = [], []
    offset = 0.0
    for step in steps:
        trajectory = step.trajectory
        count = max(2, int(np.ceil(trajectory.duration_s * _TF_RATE_HZ)) + 1)
        local = np.linspace(0.0, trajectory.duration_s, count)
        values.append(sample(trajectory, local)[0])
        times.append(offset + local)
        offset += trajectory.duration_s
    return robot.tf_samples(np.concatenate(times), np.concatenate(values), base)


def _attachments(config: RobotConfig, request: PlanRequest) -> dict[str, bytes]:
    files = dict(config.files)
    if request.scene is not None:
        files[f"scene{Path(request.scene).suffix}"] = Path(request.scene).read_bytes()
    if request.task is not None:
        files["task.yaml"] = request.task.raw
    if request.motion_request is not None:
        files["request.yaml"] = request.motion_request.raw
    return files
