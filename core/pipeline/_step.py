"""One plan step, in named stages: settings, target, search, certified timed path, residual.

The target is joint values (a joints or named goal, or the IK solution of a pose or shift
goal) or, for a linear step, the pose of a link; the search is OMPL's or a straight line of
the tip; what is written is certified as the controller interpolates it.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial

import numpy as np
from numpy.typing import NDArray

from ..collision import MotionChecker
from ..config import JointGoal, NamedGoal, StepSpec, resolved
from ..errors import (
    GoalInCollision,
    GoalViolatesConstraints,
    PlanningFailed,
    PlanningTimeExceeded,
    StartViolatesConstraints,
    UsageError,
)
from ..model import Robot, Scene, solve_ik
from ..planning import (
    PathCheck,
    PathResult,
    Validity,
    check_limits,
    joint_target,
    orientation_tolerance,
    plan_path,
    pose_error,
    repair_path,
    straight_line,
    tip_target,
)
from ..timing import rest_to_rest, time_parameterize
from ..types import JointTrajectory, StepResult
from ._checks import Problem
from .request import PlanRequest

__all__ = ["plan_step"]

logger = logging.getLogger(__name__)

# The search checks edges every 0.05 rad; what is written is certified as the controller
# interpolates it, with no robot point moving more than 5 mm between checked states. A
# trajectory that fails certification has usually crossed a thin obstacle between two checked
# states: the path's segments are checked again every 0.005 rad, those that fail are planned
# again at that resolution, and the result is timed closer to the path.
_COARSE_RAD, _FINE_RAD = 0.05, 0.005  # edge check resolutions
_COARSE_STEP_RAD, _FINE_STEP_RAD = 0.05, 0.01  # timing resample steps

_Search = Callable[[Validity], PathResult]


@dataclass(frozen=True)
class _Settings:
    """A step's planner settings after precedence: step > request > robot config.

    Attributes:
        planner: OMPL planner name.
        planning_time: Seconds the planner may search: a budget of work.
        timeout: Wall-clock safety limit of each search in [s]; None: the default for the budget.
        max_velocity: Scaled velocity limits per group joint in [rad]/[s] or [m]/[s].
        max_acceleration: Scaled acceleration limits per group joint in [rad]/[s]^2 or [m]/[s]^2.
        scaling: The velocity and acceleration scaling factors those limits come from.
        min_fraction: Smallest fraction of a straight line that is a success.
    """

    planner: str
    planning_time: float
    timeout: float | None
    max_velocity: NDArray[np.float64]
    max_acceleration: NDArray[np.float64]
    min_fraction: float
    scaling: tuple[float, float]


@dataclass(frozen=True)
class _Target:
    """Where a step goes: group values (None for a linear step), and the link and pose a tip goal asks for."""

    values: NDArray[np.float64] | None
    link: str
    pose: NDArray[np.float64] | None = None
    also: tuple[tuple[str, NDArray[np.float64]], ...] = ()  # more links and their poses, reached with `link`


def plan_step(
    spec: StepSpec,
    request: PlanRequest,
    problem: Problem,
    start: NDArray[np.float64],
) -> StepResult:
    """Return one step planned from `start`: target, search, certified timing, residual."""
    began = time.perf_counter()
    robot, checks = problem.robot, problem.checks
    settings = _settings(spec, request, robot)
    if settings.planner in ("LIN", "CIRC"):  # Pilz's: the tool's straight line, or its arc
        spec = replace(spec, linear=True)
    if settings.planner == "CIRC" and spec.arc is None:
        raise UsageError("CIRC needs the point its arc passes through or turns about: a task step's "
                         "`arc: {center | interim: [x, y, z]}`, or path constraints named 'interim' or 'center' "
                         "with one position constraint, as Pilz takes them")
    constraints = _path_check(spec, robot, problem.scene, checks, start)
    target = _target(spec, request, robot, problem.scene, checks, start, constraints)
    search, fraction = _search(spec, settings, robot, problem.scene, checks, start, target, constraints)
    path, trajectory, stats = _certified(spec, settings, robot, checks, start, target, search, constraints)
    stats["path_length"] = float(np.sum(np.linalg.norm(np.diff(path.waypoints, axis=0), axis=1)))
    check_limits(robot, trajectory.positions.max(axis=0))
    check_limits(robot, trajectory.positions.min(axis=0))
    residual = _residual(robot, checks.base, target, trajectory.positions[-1], path.waypoints[-1])
    return StepResult(
        name=spec.name,
        goal=spec.goal.describe(),
        planner=path.planner,
        planning_time_s=time.perf_counter() - began,
        trajectory=trajectory,
        fraction=fraction,
        residual=residual,
        stats=stats,
        tolerances=spec.tolerances,
        scaling=settings.scaling,
    )


def _settings(spec: StepSpec, request: PlanRequest, robot: Robot) -> _Settings:
    """Return a step's planner, planning time, scaled limits and minimum fraction."""
    motion = resolved(spec.motion, request.motion, defaults=robot.config.motion)
    return _Settings(
        planner=motion.planner,
        planning_time=motion.planning_time,
        timeout=request.timeout,
        max_velocity=robot.max_velocity * motion.velocity_scaling,
        max_acceleration=robot.max_acceleration * motion.acceleration_scaling,
        scaling=(motion.velocity_scaling, motion.acceleration_scaling),
        min_fraction=spec.min_fraction if spec.min_fraction is not None else request.min_fraction,
    )


def _path_check(
    spec: StepSpec, robot: Robot, scene: Scene, checks: MotionChecker, start: NDArray[np.float64]
) -> PathCheck | None:
    """Return the step's path constraints, checked to hold at the start; None for a step without any."""
    if spec.constraints is None:
        return None
    constraints = PathCheck(robot, scene, spec.constraints, robot.configuration(start, checks.base))
    why = constraints.violation(start)
    if why is not None:
        raise StartViolatesConstraints(f"start state violates the path constraints of {spec.constraints.source}: "
                                       f"{why}")
    return constraints


def _target(
    spec: StepSpec, request: PlanRequest, robot: Robot, scene: Scene, checks: MotionChecker, start: NDArray[np.float64],
    constraints: PathCheck | None,
) -> _Target:
    """Return the group values a step goes to (checked free), or the pose of a link it moves to."""
    source = str(request.task.source) if request.task else "flags"
    goal = spec.goal
    if isinstance(goal, JointGoal | NamedGoal):
        values = joint_target(robot, goal, start, "--joints" if request.task is None else source)
        pair = checks.colliding_pair(values)
        if pair:
            raise GoalInCollision(pair)
        why = constraints.violation(values) if constraints is not None else None
        if why is not None:
            raise GoalViolatesConstraints(f"goal state violates the path constraints: {why}")
        if spec.linear:  # Pilz's LIN to a joint goal: the tool's straight line to where the goal puts it
            return _Target(None, robot.group.tip, robot.frame_pose(robot.configuration(values, checks.base),
                                                                    robot.group.tip))
        return _Target(values, robot.group.tip)
    base = checks.base
    q = robot.configuration(start, base)
    link, pose = tip_target(robot, scene, goal, q, source)
    also = tuple(tip_target(robot, scene, other, q, source) for other in getattr(goal, "also", ()))
    if spec.linear:
        if also:
            raise UsageError(f"{source}: a straight line moves one link; this goal places {len(also) + 1}")
        return _Target(None, link, pose)
    # Exhaustive: the first valid solution from a far start is not always the nearest one.
    is_free = checks.state_free if constraints is None else (
        lambda values: checks.state_free(values) and constraints.satisfied(values))
    solution = solve_ik(robot, pose, link, start, base=base, seed=request.seed, exhaustive=True,
                        orientation_tolerance=orientation_tolerance(goal), is_free=is_free,
                        colliding_pair=checks.checker.colliding_pair, also=also)
    return _Target(solution.values, link, pose, also)


def _search(
    spec: StepSpec, settings: _Settings, robot: Robot, scene: Scene, checks: MotionChecker,
    start: NDArray[np.float64], target: _Target, constraints: PathCheck | None,
) -> tuple[_Search, float]:
    """Return the step's search under given collision checks, and the fraction of the way it covers.

    A linear step's line is planned (and checked) here, once; the search then returns it. Joint
    constraints narrow the bounds the search samples within.
    """
    lower, upper = (robot.lower, robot.upper) if constraints is None else (constraints.lower, constraints.upper)
    if not spec.linear:
        goal = target.values
        assert goal is not None, "a step that is not linear has target values"
        if settings.planner == "PTP":
            return (lambda validity: _point_to_point(start, goal, validity)), 1.0
        return (lambda validity: plan_path(start, goal, lower, upper, validity, settings.planner,
                                           settings.planning_time, settings.timeout)), 1.0
    assert target.pose is not None, "a linear step has a target pose"
    free = checks.free if constraints is None else (
        lambda states: checks.free(states) & np.array([constraints.satisfied(v) for v in states], dtype=bool))
    arc = None
    if settings.planner == "CIRC" and spec.arc is not None:
        anchor, anchor_T_frame = scene.anchor(spec.arc.frame or robot.root_link, robot)
        root_T_frame = robot.frame_pose(robot.configuration(start, checks.base), anchor) @ anchor_T_frame
        arc = (spec.arc.kind, root_T_frame[:3, :3] @ np.array(spec.arc.xyz) + root_T_frame[:3, 3])
    line = straight_line(robot, target.link, start, target.pose, checks.base, free,
                         checks.checker.colliding_pair, arc)
    if line.fraction < settings.min_fraction:
        x, y, z = line.stopped_at
        raise PlanningFailed(f"straight line achieved {line.fraction:.1%} of the way (minimum "
                             f"{settings.min_fraction:.0%}): {line.reason}; stopped at [{x:.4f}, {y:.4f}, {z:.4f}] "
                             f"in {robot.root_link}")
    if line.fraction < 1.0:
        x, y, z = line.stopped_at
        logger.info("straight line stops at %.1f%% of the way: %s; at [%.4f, %.4f, %.4f] in %s", 100 * line.fraction,
                    line.reason, x, y, z, robot.root_link)
    line_path = PathResult(np.asarray(line.waypoints), settings.planner if settings.planner in ("LIN", "CIRC")
                           else "linear", 0.0, 0.0)
    return (lambda validity: line_path), line.fraction  # the line is already checked


def _point_to_point(start: NDArray[np.float64], goal: NDArray[np.float64], validity: Validity) -> PathResult:
    """Return Pilz's PTP path, the straight line in joint space, if it is free; else raise PlanningFailed."""
    began = time.perf_counter()
    if not validity.edge_free(start, goal):
        raise PlanningFailed("PTP: the straight joint-space motion from start to goal collides; PTP does not plan "
                             "around obstacles (plan with an OMPL planner, such as RRTConnect)")
    return PathResult(np.array([start, goal]), "PTP", time.perf_counter() - began, 0.0)


def _certified(
    spec: StepSpec, settings: _Settings, robot: Robot, checks: MotionChecker, start: NDArray[np.float64],
    target: _Target, search: _Search, constraints: PathCheck | None,
) -> tuple[PathResult, JointTrajectory, dict[str, float]]:
    """Return a path, its timed trajectory certified collision-free, and the step's statistics.

    Coarse search and timing first; a trajectory that collides when certified has its colliding
    segments planned again finer, then the whole search again finer, then (last resort) a search
    with edges checked at the certification states, timed to stop at every waypoint.
    """
    # The search checks the hulls, not the meshes, unless the start or goal is free only under the meshes.
    ends = start[None, :] if target.values is None else np.array([start, target.values])
    conservative = checks.conservative_available and bool(checks.free(ends, conservative=True).all())
    certifier = _Certifier(robot, checks, settings)

    def checked(resolution: float) -> Validity:
        return _within(Validity(partial(checks.state_free, conservative=conservative),
                                partial(checks.edge_free, resolution=resolution, conservative=conservative)),
                       constraints, resolution)

    path = search(checked(_COARSE_RAD))
    trajectory, hit = certifier.certified(path, _COARSE_STEP_RAD)
    if hit is not None and not spec.linear and settings.planner != "PTP":
        logger.debug("trajectory collides when certified; planning its colliding segments again, finer")
        try:
            lower, upper = (robot.lower, robot.upper) if constraints is None else (constraints.lower,
                                                                                   constraints.upper)
            path = repair_path(path.waypoints, lower, upper, checked(_FINE_RAD), settings.planner,
                               settings.planning_time, settings.timeout)
            trajectory, hit = certifier.certified(path, _FINE_STEP_RAD)
        except PlanningTimeExceeded:
            raise  # the clock never decides what a plan does next
        except PlanningFailed:
            pass  # a whole new search below
    if hit is not None:
        logger.debug("trajectory collides when certified; planning it all again, finer")
        path = search(checked(_FINE_RAD))
        trajectory, hit = certifier.certified(path, _FINE_STEP_RAD)
    if hit is not None:
        path = search(_within(Validity(checks.state_free, checks.edge_free_certified), constraints, _FINE_RAD))
        trajectory = certifier.rest_to_rest(path)
    if constraints is not None and not all(constraints.satisfied(p) for p in trajectory.positions):
        # Timing rounds the path's corners; stopping at each waypoint keeps to the checked edges.
        trajectory = certifier.rest_to_rest(path)
        why = next((w for p in trajectory.positions if (w := constraints.violation(p)) is not None), None)
        if why is not None:
            raise PlanningFailed(f"the path's states satisfy the path constraints, but a state between them does "
                                 f"not: {why}")
    return path, trajectory, certifier.stats


def _within(validity: Validity, constraints: PathCheck | None, resolution: float) -> Validity:
    """Return `validity` that also requires every state (on an edge: every `resolution`) to satisfy `constraints`."""
    if constraints is None:
        return validity
    return Validity(lambda values: validity.state_free(values) and constraints.satisfied(values),
                    lambda a, b: validity.edge_free(a, b) and constraints.edge(a, b, resolution))


@dataclass
class _Certifier:
    """Times paths within a step's limits, certifies the result, and adds up the step's statistics."""

    robot: Robot
    checks: MotionChecker
    settings: _Settings
    stats: dict[str, float] = field(
        default_factory=lambda: {"plan_s": 0.0, "simplify_s": 0.0, "timing_s": 0.0, "certify_s": 0.0, "checks": 0.0})

    def certified(self, path: PathResult, max_step: float) -> tuple[JointTrajectory, NDArray[np.float64] | None]:
        """Return the path timed (resampled every `max_step` [rad]) and its first colliding state, if any."""
        mark = time.perf_counter()
        trajectory = time_parameterize(self.robot.joint_names, path.waypoints, self.settings.max_velocity,
                                       self.settings.max_acceleration, max_step=max_step,
                                       compiled=self.checks.compiled)
        timed = time.perf_counter()
        hit = self.checks.first_collision_on_trajectory(trajectory)
        self._add(path, timed - mark, time.perf_counter() - timed)
        return trajectory, hit

    def rest_to_rest(self, path: PathResult) -> JointTrajectory:
        """Return the path timed to stop at every waypoint, its straight segments certified.

        A path hugging an obstacle defeats smoothing, and one through a thin obstacle can pass
        coarse edge checks. Stopping at each waypoint keeps every joint, the controller's
        quintics included, on the straight segments exactly.
        """
        mark = time.perf_counter()
        trajectory = rest_to_rest(self.robot.joint_names, path.waypoints, self.settings.max_velocity,
                                  self.settings.max_acceleration)
        timed = time.perf_counter()
        hit = self.checks.first_collision_on_path(path.waypoints)
        self._add(path, timed - mark, time.perf_counter() - timed)
        if hit is not None:
            pair = self.checks.colliding_pair(hit) or ("?", "?")
            raise PlanningFailed(f"the timed trajectory collides ({pair[0]} touches {pair[1]}) where the path did not")
        return trajectory

    def _add(self, path: PathResult, timing_s: float, certify_s: float) -> None:
        """Add one attempt's times to the step's statistics."""
        self.stats["plan_s"] += path.planning_s
        self.stats["simplify_s"] += path.simplify_s
        self.stats["timing_s"] += timing_s
        self.stats["certify_s"] += certify_s
        self.stats["checks"] += path.checks


def _residual(
    robot: Robot, base: NDArray[np.float64], target: _Target, end: NDArray[np.float64], path_end: NDArray[np.float64]
) -> dict[str, float]:
    """Return how far the trajectory's end is from the goal: in joint space, or as a tip pose error."""
    if target.pose is None:
        return {"joints_rad": float(np.max(np.abs(end - path_end)))}
    q = robot.configuration(end, base)
    errors = [pose_error(robot.frame_pose(q, link), pose) for link, pose in ((target.link, target.pose), *target.also)]
    return {"position_m": max(e[0] for e in errors), "orientation_rad": max(e[1] for e in errors)}
