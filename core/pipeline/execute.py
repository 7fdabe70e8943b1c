"""Execution pipeline: a plan file -> its embedded config -> simulated controller per step -> report.

Composes recording (reading plans), config, plants and the controller simulation,
as the plan pipeline composes planning and timing. Each step of a plan is one
FollowJointTrajectory goal, sent when the previous one has succeeded, from
wherever the simulated robot then is.
"""

from __future__ import annotations

import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .. import bag as recording
from ..bag.jointstates import read_joint_states
from ..config.controllers import ControllerConfig, parse_controllers
from ..config.robot_config import RobotConfig, load_robot_config
from ..config.sources import CONFIG_FILE
from ..control.check_report import CheckReport
from ..control.checking import check_recording, uses_velocities
from ..control.goal_validation import validate_goal
from ..control.margins import merged_margins
from ..control.results import ExecutionResult, Violation
from ..errors import ConfigError, InputError, UnknownName
from ..types import TfSamples

if TYPE_CHECKING:
    from ..control.controller import Disturbance, ExecutionReport
    from ..model.robot import Robot

_TF_RATE_HZ = 30.0

__all__ = [
    "CheckRequest", "ExecuteRequest", "PlanExecution", "StepExecution", "check", "execute", "pick_controller",
    "plan_config", "read_valid_plan",
]


@dataclass(frozen=True)
class ExecuteRequest:
    """What `moveplan execute --fake` was asked to do."""

    plan: Path
    plant: str = "mirror"
    plant_params: Mapping[str, float] | None = None
    disturbances: Sequence[Disturbance] = ()
    start_joints: Mapping[str, float] | None = None
    controllers: Path | None = None
    seed: int = 0


@dataclass(frozen=True)
class CheckRequest:
    """What `moveplan check-tolerances` was asked to check."""

    plan: Path
    recording: Path
    topic: str = "/joint_states"
    controllers: Path | None = None
    start: str | float = "auto"
    time_source: str = "header"


@dataclass(frozen=True)
class StepExecution:
    """One step's simulated execution; its times are from the step's start."""

    name: str
    report: ExecutionReport


@dataclass(frozen=True)
class PlanExecution:
    """A whole plan's execution: the first failing step ends it."""

    ok: bool
    result: ExecutionResult
    steps: tuple[StepExecution, ...]
    controller: ControllerConfig
    plan: recording.PlanFile
    tf: TfSamples | None = None

    @property
    def violations(self) -> tuple[tuple[str, Violation], ...]:
        """Return every violation with the name of its step."""
        return tuple((s.name, v) for s in self.steps for v in s.report.violations)

    @property
    def margins(self) -> dict[str, float]:
        """Return per joint the smallest margin to its tolerance over all steps."""
        return merged_margins(step.report.margins for step in self.steps)

    @property
    def duration_s(self) -> float:
        """Return the simulated time of all executed steps in [s]."""
        return sum(s.report.duration_s for s in self.steps)


def plan_config(plan: recording.PlanFile, source: Path) -> RobotConfig:
    """Return the robot config embedded in a plan file."""
    if CONFIG_FILE not in plan.attachments:
        raise InputError(f"{source}: the plan carries no robot config ({CONFIG_FILE} attachment missing)")
    with tempfile.TemporaryDirectory(prefix="moveplan-") as folder:
        for name, data in plan.attachments.items():
            path = Path(folder) / name
            if not path.resolve().is_relative_to(Path(folder).resolve()):
                raise InputError(f"{source}: attachment name '{name}' points outside the config")
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        try:
            return load_robot_config(folder)
        except ConfigError as exc:
            raise InputError(f"{source}: embedded config: {exc}") from None


def read_valid_plan(path: Path) -> recording.PlanFile:
    """Return the plan file at `path`, each step checked as JTC validates a goal.

    Raises:
        InputError: The file is unreadable, or a step holds a NaN or infinite value or
            times that are not strictly increasing (the message names step, point and joint).

    """
    plan = recording.read_plan(path)
    for step in plan.steps:
        validate_goal(step.trajectory, f"{path}: step '{step.name}' on /planned_trajectory")
    return plan


def pick_controller(
    controllers: Mapping[str, ControllerConfig], joints: Sequence[str], source: str
) -> ControllerConfig:
    """Return the JointTrajectoryController that drives all of `joints`."""
    fitting = [c for c in controllers.values() if set(joints) <= set(c.joints)]
    if not fitting:
        raise ConfigError(f"{source}: no JointTrajectoryController drives all of {', '.join(joints)}; "
                          f"controllers: {', '.join(controllers) or '(none)'}")
    return min(fitting, key=lambda c: len(c.joints))


def execute(request: ExecuteRequest) -> PlanExecution:
    """Return what executing the plan through the simulated controller did."""
    # Imported here: check-tolerances shares this module and simulates nothing.
    from ..control.controller import Disturbance, simulate
    from ..control.plants import make_plant

    plan = read_valid_plan(request.plan)
    config = plan_config(plan, request.plan)
    controller = _controller(config, plan, request.controllers)
    continuous = [j for j, lim in config.limits.items() if lim.continuous]
    plant = make_plant(request.plant, dict(request.plant_params or {}), controller, continuous)
    start = _start_positions(request, plan, controller)
    steps = []
    for step in plan.steps:
        end = step.start_s + step.trajectory.duration_s
        last = step is plan.steps[-1]
        bumps = [Disturbance(d.time_s - step.start_s, d.joint, d.delta)
                 for d in request.disturbances if step.start_s <= d.time_s < end or (d.time_s >= end and last)]
        report = simulate(step.trajectory, controller, config.execution, plant, continuous_joints=continuous,
                          start_positions=start, disturbances=bumps, seed=request.seed)
        steps.append(StepExecution(step.name, report))
        if not report.ok:
            break
        start = report.actual_positions[-1] if len(report.times_s) else start
    last = steps[-1].report
    # pinocchio is imported here, not at the top: check-tolerances shares this module and needs no kinematics.
    from ..model.robot import Robot

    tf = _executed_tf(Robot(config, plan.group), steps)
    return PlanExecution(last.ok, last.result, tuple(steps), controller, plan, tf)


def _executed_tf(robot: Robot, steps: list[StepExecution]) -> TfSamples | None:
    """Return link poses along what the simulated robot did, at a playback rate, steps end to end."""
    times, values = [], []
    offset = 0.0
    for step in steps:
        report = step.report
        if len(report.times_s):
            period = float(np.median(np.diff(report.times_s))) if len(report.times_s) > 1 else 1.0
            every = max(1, int(round(1.0 / (_TF_RATE_HZ * period))))
            rows = np.unique(np.append(np.arange(0, len(report.times_s), every), len(report.times_s) - 1))
            columns = [report.joint_names.index(j) for j in robot.joint_names]
            times.append(offset + report.times_s[rows])
            values.append(report.actual_positions[rows][:, columns])
        offset += report.duration_s
    if not times:
        return None
    return robot.tf_samples(np.concatenate(times), np.concatenate(values), robot.neutral())


def _start_positions(
    request: ExecuteRequest, plan: recording.PlanFile, controller: ControllerConfig
) -> NDArray[np.float64] | None:
    """Return where the simulated robot starts, in the controller's joint order (None = plan start)."""
    if not request.start_joints:
        return None
    first = plan.steps[0].trajectory
    start = dict(zip(first.joint_names, first.positions[0], strict=True))
    for joint, value in request.start_joints.items():
        if joint not in start:
            raise UnknownName("joint", joint, "--start-joints", start)
        start[joint] = value
    return np.array([start[j] for j in controller.joints if j in start])


def check(request: CheckRequest) -> CheckReport:
    """Return the verdict of the controller's and MoveIt's rules on a recorded execution of a plan."""
    plan = read_valid_plan(request.plan)
    config = plan_config(plan, request.plan)
    controller = _controller(config, plan, request.controllers)
    series = read_joint_states(request.recording, request.topic, joints=controller.joints,
                               time_source=request.time_source,
                               velocities=uses_velocities(plan, controller))
    continuous = [j for j, lim in config.limits.items() if lim.continuous]
    return check_recording(plan, series, controller, config.execution, continuous, request.start)


def _controller(config: RobotConfig, plan: recording.PlanFile, override: Path | None) -> ControllerConfig:
    """Return the controller driving the plan's joints, from `override` or the plan's own config."""
    controllers = config.controllers
    source = str(config.sources.get("controllers", config.root / "ros2_controllers.yaml"))
    if override is not None:
        controllers, source = parse_controllers(override), str(override)
    return pick_controller(controllers, plan.steps[0].trajectory.joint_names, source)
