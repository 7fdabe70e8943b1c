"""A planning session in memory: motions planned one at a time from any state, in a scene that changes, executed.

What moveplan.commander (the MoveIt-style Python API) calls, as the CLI calls plan.py and
execute.py: each motion is one step planned by `step.plan_step`, executed through the same
simulated JointTrajectoryController `moveplan execute --fake` runs, and the executed motions
are assembled and written as one plan file by the plan pipeline's own assembly and writer.
Nothing here keeps state: the caller holds the robot's configuration and the scene.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..bag import write_plan
from ..config import (
    ControllerConfig,
    MotionSettings,
    PoseGoal,
    RobotConfig,
    StepSpec,
    check_shape_count,
    default_controller,
    first_repeated,
    parse_controllers,
)
from ..control import ExecutionReport, simulate, validate_goal, validate_goal_end
from ..errors import ConfigError, NoPlan, StartInCollision, StartOutsideLimits
from ..model import Robot, Scene, resolve_frames
from ..planning import check_limits, seed_planner
from ..types import CollisionObject, Frame, GoalTolerances, JointTrajectory, Plan, StepResult
from ._checks import Problem, build_problem, filter_threshold
from ._plan_files import configured_plant, pick_controller
from ._step import plan_step
from .plan import assemble
from .request import PlanRequest

__all__ = [
    "ExecutionSettings", "cartesian_motion", "check_execution", "compose_scene", "execute_motion",
    "frame_in_root", "motion_problem", "plan_motion", "session_plan", "start_configuration", "write_session",
]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class ExecutionSettings:
    """The simulated hardware and controller a motion is executed on: `execute --fake`'s options.

    Attributes:
        plant: mirror, lag or pid; None: the robot config's plant, else mirror.
        plant_params: Its parameters (`--plant-param k=v`), over the config's.
        controllers: A ros2_controllers.yaml replacing the robot config's (`--controllers`).
        seed: Seeds the plant's measurement noise.
    """

    plant: str | None = None
    plant_params: Mapping[str, float] = field(default_factory=dict)
    controllers: Path | None = None
    seed: int = 0


def start_configuration(robot: Robot, scene: Scene) -> NDArray[np.float64]:
    """Return where the robot starts, all joints: the initial positions, then the scene's robot state, checked.

    Raises:
        StartOutsideLimits: A group joint starts outside its limits; names where its value came from.
    """
    q = robot.neutral()
    for joint, value in scene.robot_state.items():
        q = robot.set_joint(q, joint, value)
    try:
        check_limits(robot, robot.values(q), StartOutsideLimits)
    except StartOutsideLimits as exc:
        origin = f"{scene.source}: robot_state" if exc.joint in scene.robot_state else "the initial positions"
        raise StartOutsideLimits(exc.joint, exc.value, exc.lower, exc.upper, origin) from None
    return q


def compose_scene(
    source: str, frames: Sequence[Frame], objects: Sequence[CollisionObject], robot: Robot,
    allowed: frozenset[frozenset[str]] = frozenset(), robot_state: Mapping[str, float] | None = None,
) -> Scene:
    """Return the scene of `frames` (`parent_T_frame`) and `objects` (world ones in the planning frame, attached ones).

    Raises:
        ConfigError: Two objects share a name, a frame has a robot link's name, frames form a loop,
            or there are more shapes than a scene may hold; `source` names the scene.
        FrameNotFound: A frame's parent is neither a frame nor a robot link.
    """
    anchors = resolve_frames(list(frames), robot, source)
    check_shape_count(len(objects), source)
    if (twice := first_repeated(o.name for o in objects)) is not None:
        raise ConfigError(f"{source}: object name '{twice}' is used twice")
    return Scene(source, tuple(frames), tuple(objects), anchors, allowed, dict(robot_state or {}))


def frame_in_root(robot: Robot, scene: Scene, q: NDArray[np.float64], frame: str) -> NDArray[np.float64]:
    """Return `root_T_frame` of a robot link, scene frame or planning-frame name with the robot at `q`."""
    link, link_T_frame = scene.anchor(frame, robot)
    return robot.frame_pose(q, link) @ link_T_frame


def motion_problem(robot: Robot, scene: Scene, q: NDArray[np.float64]) -> Problem:
    """Return the problem of `robot`'s group in `scene`, the other joints as in `q`.

    The sphere filter is built when `moveplan plan` would build it (_checks.filter_threshold).
    """
    return build_problem(robot, scene, robot.config.planning["collision"], q, filter_threshold())


def plan_motion(
    problem: Problem, spec: StepSpec, q: NDArray[np.float64], settings: MotionSettings, seed: int = 0,
) -> StepResult:
    """Return one motion planned from the configuration `q` (`problem` built for it): a step of `moveplan plan`.

    `settings` leave what they do not set to the robot config, as the CLI does; `seed` seeds OMPL
    and the IK restarts, each motion anew, as one `moveplan plan` is.

    Raises:
        StartOutsideLimits, StartInCollision: The start is unusable.
        NoPlan: Any other reason the step has no plan (IK, search, a linear path cut short).
    """
    robot = problem.robot
    start = robot.values(q)
    check_limits(robot, start, StartOutsideLimits)
    pair = problem.checks.colliding_pair(start)
    if pair:
        raise StartInCollision(pair)
    seed_planner(seed)
    request = PlanRequest(robot=Path(robot.config.name), steps=(spec,), motion=settings, seed=seed)
    return plan_step(spec, request, problem, start)


def cartesian_motion(
    problem: Problem, waypoints: Sequence[PoseGoal], q: NDArray[np.float64], settings: MotionSettings, seed: int = 0,
    name: str = "cartesian",
) -> tuple[StepResult | None, float]:
    """Return the straight-line motion through `waypoints` in turn, and the fraction of the way it covers.

    Each leg is a linear step of its own (it comes to rest at every waypoint); a leg cut short,
    or one with no plan at all (a start in collision), ends the motion there, as MoveIt's path
    ends. The fraction is MoveIt's: (legs done + fraction of the leg cut short) / legs. The
    motion is None when nothing moves.
    """
    legs: list[StepResult] = []
    fraction = 0.0
    for k, goal in enumerate(waypoints):
        start = q if not legs else problem.robot.configuration(legs[-1].trajectory.positions[-1], q)
        spec = StepSpec(f"{name}[{k}]", goal, linear=True, min_fraction=0.0)
        try:
            leg = plan_motion(problem, spec, start, settings, seed)
        except NoPlan as exc:
            # MoveIt too returns the path up to where it could not go on.
            logger.info("%s: the path stops before waypoint %d: %s", name, k, exc)
            break
        if len(leg.trajectory.times_s) > 1:
            legs.append(leg)
        fraction = (k + leg.fraction) / len(waypoints)
        if leg.fraction < 1.0:
            logger.info("%s: waypoint %d: %.1f%% of its line", name, k, 100.0 * leg.fraction)
            break
    if not legs:
        return None, fraction
    return _joined(legs, name, fraction), fraction


def _joined(legs: Sequence[StepResult], name: str, fraction: float) -> StepResult:
    """Return one step whose trajectory runs the legs' trajectories one after the other."""
    times, rows = [legs[0].trajectory.times_s], [legs[0].trajectory]
    offset = legs[0].trajectory.duration_s
    for leg in legs[1:]:
        # Each leg starts at rest where the previous one stopped: its first point is that stop.
        times.append(offset + leg.trajectory.times_s[1:])
        rows.append(leg.trajectory)
        offset += leg.trajectory.duration_s
    first = rows[0]
    trajectory = JointTrajectory(
        first.joint_names, np.concatenate(times),
        *(np.concatenate([getattr(first, key)] + [getattr(r, key)[1:] for r in rows[1:]])
          for key in ("positions", "velocities", "accelerations")),
    )
    return StepResult(
        name=name, goal={"cartesian": [leg.goal["pose"] for leg in legs]}, planner="linear",
        planning_time_s=sum(leg.planning_time_s for leg in legs), trajectory=trajectory, fraction=fraction,
        residual=legs[-1].residual, stats={key: sum(leg.stats.get(key, 0.0) for leg in legs) for key in legs[0].stats},
        scaling=legs[0].scaling,
    )


def execute_motion(
    config: RobotConfig, trajectory: JointTrajectory, start: Mapping[str, float], settings: ExecutionSettings,
    where: str = "execute", tolerances: GoalTolerances | None = None,
) -> ExecutionReport:
    """Return what the simulated controller did with `trajectory`, sent with the robot at `start` (joint -> value).

    The controller is the robot config's JointTrajectoryController driving the trajectory's
    joints (or the one in `settings.controllers`), on the plant `settings` names: what
    `moveplan execute --fake` runs for one step. `tolerances` are those the goal carries.

    Raises:
        InputError: The trajectory holds a non-finite value or times JTC refuses; the message
            begins with `where`.
        ConfigError: No controller drives the trajectory's joints.
        UsageError: An unknown plant or plant parameter.
    """
    validate_goal(trajectory, where)
    controller = _controller(config, trajectory.joint_names, settings.controllers)
    validate_goal_end(trajectory, controller.allow_nonzero_velocity_at_trajectory_end, where)
    continuous = [j for j, lim in config.limits.items() if lim.continuous]
    plant = configured_plant(config, settings.plant, settings.plant_params, controller, continuous)
    positions = np.array([start[j] for j in controller.joints if j in start])
    return simulate(trajectory, controller, config.execution, plant, continuous_joints=continuous,
                    start_positions=positions, seed=settings.seed, goal_tolerances=tolerances)


def check_execution(config: RobotConfig, joints: Sequence[str], settings: ExecutionSettings) -> None:
    """Raise if `settings` cannot execute motions of `joints`: no controller drives them, or the plant is unknown.

    Raises:
        ConfigError: No controller drives the joints, or `settings.controllers` is invalid.
        UsageError: An unknown plant or plant parameter.
    """
    controller = _controller(config, joints, settings.controllers)
    configured_plant(config, settings.plant, settings.plant_params, controller,
               [j for j, lim in config.limits.items() if lim.continuous])


def _controller(config: RobotConfig, joints: Sequence[str], override: Path | None) -> ControllerConfig:
    """Return the controller driving `joints`: `override`'s, the config's ros2_controllers.yaml's, or JTC's defaults."""
    if override is not None:
        return pick_controller(parse_controllers(override), joints, str(override))
    if "controllers" not in config.sources:
        logger.info("%s: no ros2_controllers.yaml; executing with a JointTrajectoryController at ros2_controllers' "
                    "defaults", config.name)
        return default_controller(joints)
    return pick_controller(config.controllers, joints, str(config.sources["controllers"]),
                           config.execution.default_controllers)


def session_plan(
    robot: Robot, scene: Scene, q: NDArray[np.float64], steps: Sequence[StepResult], seed: int,
    executions: Sequence[Mapping[str, object]] = (),
) -> Plan:
    """Return the plan file's content for motions executed in turn, assembled as `moveplan plan` assembles one.

    `q` holds the joints outside the group; `executions` (one document per step: its result)
    goes into the metadata as "executions".
    """
    request = PlanRequest(robot=Path(robot.config.name), steps=(), seed=seed)
    plan = assemble(request, robot.config, robot, scene, q, list(steps))
    metadata = {**plan.metadata, "made_by": "moveplan.commander", "executions": json.dumps(list(executions))}
    return replace(plan, metadata=metadata)


def write_session(path: Path, plan: Plan, distro: str = "jazzy") -> None:
    """Write a session's plan to `path` for `distro`, atomically, with the CLI's plan writer; return None."""
    write_plan(path, plan, distro)
