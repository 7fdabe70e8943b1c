"""Execution pipeline: a plan file -> its embedded config -> simulated controller per step -> report.

Composes recording (reading plans), config, plants and the controller simulation,
as the plan pipeline composes planning and timing. Each step of a plan is one
FollowJointTrajectory goal, sent when the previous one has succeeded, from
wherever the simulated robot then is.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import AbstractContextManager, ExitStack
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from .. import bag as recording
from .._median import median
from ..bag import open_joint_states
from ..config import ControllerConfig, JointGoal, RobotConfig, check_joint_units
from ..control import (
    DEFAULT_RELEASE,
    CheckReport,
    ExecutionResult,
    ExecutionSummary,
    JointTracking,
    RecordingStart,
    SampleSource,
    Violation,
    check_goal_joints,
    check_recording,
    fills_point_before,
    merged_margins,
    merged_tracking,
    recorded_tracking,
    simulated_tracking,
    unchecked_joints,
    uses_velocities,
)
from ..errors import InputError, UnknownName
from ..types import TfSamples, TimeSource
from ._plan_files import configured_plant, plan_config, plan_controller, read_valid_plan

if TYPE_CHECKING:
    from ..control import Disturbance, ExecutionReport, Plant
    from ..model import Robot

_TF_RATE_HZ = 30.0

__all__ = [
    "CheckRequest", "CheckedRecording", "ExecuteRequest", "OpenRecorder", "PlanExecution", "StepExecution",
    "StepRecorder", "check", "execute",
]



@dataclass(frozen=True)
class ExecuteRequest:
    """What `moveplan execute --fake` was asked to do."""

    plan: Path
    plant: str | None = None
    """--plant; None: the robot config's plant (moveplan.yaml `plant`), else mirror."""
    plant_params: Mapping[str, float] | None = None
    disturbances: Sequence[Disturbance] = ()
    start_joints: JointGoal | None = None
    controllers: Path | None = None
    seed: int = 0
    strict: bool = False
    """--strict: a parameter the `controllers` file's controller does not declare is an error."""
    ros2_controllers: str = DEFAULT_RELEASE
    """--ros2-controllers: the release whose JointTrajectoryController is simulated (control/releases.py)."""
    controllers_as_data: bool = False
    """The `controllers` file is a plan's own (tune-pid's gains written into it): read without launch substitutions."""


@dataclass(frozen=True)
class CheckRequest:
    """What `moveplan check-tolerances` was asked to check; `skip_damaged` reads past a recording's damaged chunks."""

    plan: Path
    recording: Path
    topic: str = "/joint_states"
    controllers: Path | None = None
    start: RecordingStart = "auto"
    time_source: TimeSource = "header"
    skip_damaged: bool = False
    strict: bool = False


@dataclass(frozen=True)
class StepExecution:
    """One step's simulated execution; its times are from the step's start.

    `report` is the step's summary when it comes from `execute` (its samples went to the
    executed file, or nowhere), or a whole report when built by hand.
    """

    name: str
    report: ExecutionReport | ExecutionSummary


@dataclass(frozen=True)
class PlanExecution:
    """A whole plan's execution: the first failing step ends it.

    `tf` holds link poses along it, if whoever built it computed them; `request` is what
    `execute` was asked (report.write_execution replays it to write a file).
    """

    ok: bool
    result: ExecutionResult
    steps: tuple[StepExecution, ...]
    controller: ControllerConfig
    plan: recording.PlanFile
    tf: TfSamples | None = None
    request: ExecuteRequest | None = None
    prismatic: frozenset[str] = frozenset()
    """The robot's prismatic joints: their positions are in [m]."""

    @property
    def violations(self) -> tuple[tuple[str, Violation], ...]:
        """Return every violation with the name of its step."""
        return tuple((s.name, v) for s in self.steps for v in s.report.violations)

    @property
    def margins(self) -> dict[str, float]:
        """Return per joint the smallest margin to its tolerance over all steps."""
        return merged_margins(step.report.margins for step in self.steps)

    @property
    def tracking(self) -> dict[str, JointTracking]:
        """Return per joint the worst tracking figures over all steps."""
        # A step built by hand around a whole ExecutionReport carries no tracking figures.
        return merged_tracking([getattr(step.report, "tracking", {}) for step in self.steps])

    @property
    def duration_s(self) -> float:
        """Return the simulated time of all executed steps in [s]."""
        return sum(s.report.duration_s for s in self.steps)


@dataclass(frozen=True)
class CheckedRecording:
    """A check's verdict with what it was made from: the plan, controller and recorded samples (still open).

    `continuous` names the URDF continuous joints; `samples` are read by row ranges.
    """

    report: CheckReport
    plan: recording.PlanFile
    controller: ControllerConfig
    continuous: tuple[str, ...]
    samples: SampleSource


class StepRecorder(Protocol):
    """Where `execute` hands each step as it is simulated (report.ExecutionRecorder writes an executed file)."""

    def add_tf(self, tf: TfSamples) -> None:
        """Take link poses along a step (times on the execution's timeline), before the step's report."""

    def add_step(self, report: ExecutionReport) -> None:
        """Take a step's report, samples and all; it is dropped afterwards."""

    def finish(self, execution: PlanExecution) -> None:
        """Take the whole execution, after its last step."""


OpenRecorder = Callable[[ControllerConfig, recording.PlanFile, bool], AbstractContextManager[StepRecorder]]
"""Opens a StepRecorder for the controller and plan; the flag says whether link poses will come."""


def execute(
    request: ExecuteRequest, record: OpenRecorder | None = None, *, link_poses: bool = True
) -> PlanExecution:
    """Return what executing the plan through the simulated controller did; `record` gets each step as it runs.

    Each step is simulated, handed to the recorder `record` opens (its link poses, then
    its report) and dropped: the execution keeps per step only its summary, so memory does
    not grow with the number of steps or the update rate (one step's samples are the most
    it holds). report.execute_to_file records into an executed file. With `link_poses`
    False the recorder gets no link poses (a plot needs none; no kinematics are loaded).

    Raises:
        InputError: The plan is unreadable or invalid; and whatever the recorder raises.

    """
    # Imported here: check-tolerances shares this module and simulates nothing.

    plan = read_valid_plan(request.plan)
    config = plan_config(plan, request.plan)
    if request.start_joints is not None:
        check_joint_units(request.start_joints, config, ())
    controller = plan_controller(config, plan, request.plan, request.controllers, not request.controllers_as_data,
                                 request.strict)
    continuous = [j for j, lim in config.limits.items() if lim.continuous]
    plant = configured_plant(config, request.plant, request.plant_params, controller, continuous)
    reports = _simulated_steps(request, plan, controller, config, plant, continuous)
    robot = None
    if record is not None and link_poses:
        # pinocchio is imported here, not at the top: check-tolerances shares this module and needs no kinematics.
        from ..model import Robot

        robot = Robot(config, plan.group)
    steps: list[StepExecution] = []
    with ExitStack() as stack:
        recorder: StepRecorder | None = None
        offset_s = 0.0
        for name, report, figures in reports:
            if record is not None:
                if recorder is None:
                    # Link poses come when the first step ran at all: a refused step is the last one.
                    poses = robot is not None and len(report.times_s) > 0
                    recorder = stack.enter_context(record(controller, plan, poses))
                tf = _step_tf(robot, report, offset_s) if robot is not None else None
                if tf is not None:
                    recorder.add_tf(tf)
                recorder.add_step(report)
            offset_s += report.duration_s
            steps.append(StepExecution(name, replace(report.summary(), tracking=figures)))
            del report  # before the next step is simulated
        last = steps[-1].report
        execution = PlanExecution(last.ok, last.result, tuple(steps), controller, plan, request=request,
                                  prismatic=prismatic_joints(config))
        if recorder is not None:
            recorder.finish(execution)
    return execution


def _simulated_steps(
    request: ExecuteRequest,
    plan: recording.PlanFile,
    controller: ControllerConfig,
    config: RobotConfig,
    plant: Plant,
    continuous: list[str],
) -> Iterator[tuple[str, ExecutionReport, dict[str, JointTracking]]]:
    """Yield each step's name, report and tracking figures as it is simulated; a failing step is the last.

    Each step is one goal, sent from where the simulated robot ended the one before.
    """
    from ..control import Disturbance, simulate

    start = _start_positions(request, plan, controller, config.initial_positions)
    goal = np.array([controller.goal_tolerance[j] for j in controller.joints])
    wraps = np.array([j in continuous for j in controller.joints])
    for step in plan.steps:
        end = step.start_s + step.trajectory.duration_s
        last = step is plan.steps[-1]
        bumps = [Disturbance(d.time_s - step.start_s, d.joint, d.delta)
                 for d in request.disturbances if step.start_s <= d.time_s < end or (d.time_s >= end and last)]
        try:
            report = simulate(step.trajectory, controller, config.execution, plant, continuous_joints=continuous,
                              start_positions=start, disturbances=bumps, seed=request.seed,
                              fill_point_before=fills_point_before(request.ros2_controllers),
                              goal_tolerances=step.tolerances)
        except InputError as exc:
            raise InputError(f"{request.plan}: step '{step.name}': {exc}") from None
        ok = report.ok
        # A copy, not a view: a view would keep the step's samples alive through the next step.
        start = report.actual_positions[-1].copy() if len(report.times_s) else start
        # Bumps past the verdict land in the hold, where the last step is observed on.
        held = [(b.time_s, controller.joints.index(b.joint), b.delta) for b in bumps
                if last and b.time_s > report.duration_s]
        figures = simulated_tracking(report, plant, step.trajectory.duration_s, goal, wraps, held)
        yield step.name, report, figures
        del report
        if not ok:
            return


def _step_tf(robot: Robot, report: ExecutionReport, offset_s: float) -> TfSamples | None:
    """Return link poses along what the simulated robot did in one step, at a playback rate, from `offset_s` [s]."""
    times = report.times_s
    if not len(times):
        return None
    period = float(median(np.diff(times))) if len(times) > 1 else 1.0
    every = max(1, int(round(1.0 / (_TF_RATE_HZ * period))))
    rows = np.arange(0, len(times), every)
    if rows[-1] != len(times) - 1:  # the last sample too (np.unique's first call would import numpy.ma: 11 ms)
        rows = np.append(rows, len(times) - 1)
    columns = [report.joint_names.index(j) for j in robot.joint_names]
    return robot.tf_samples(offset_s + times[rows], report.actual_positions[rows][:, columns], robot.neutral())


def _start_positions(
    request: ExecuteRequest, plan: recording.PlanFile, controller: ControllerConfig, initial: Mapping[str, float]
) -> NDArray[np.float64] | None:
    """Return where the simulated robot starts, in the controller's joint order (None = plan start).

    Joints of the controller the plan leaves out start where the fake hardware starts them
    (`initial`): a controller allowing partial goals holds them there.
    """
    first = plan.steps[0].trajectory
    start = dict(zip(first.joint_names, first.positions[0], strict=True))
    others = {j: initial[j] for j in controller.joints if j not in start and j in initial}
    if request.start_joints is None and not others:
        return None
    start.update(others)
    named = request.start_joints.named_values if request.start_joints is not None else None
    for joint, value in (named or {}).items():
        if joint not in start:
            raise UnknownName("joint", joint, "--start-joints", start)
        start[joint] = value
    return np.array([start[j] for j in controller.joints if j in start])


def prismatic_joints(config: RobotConfig) -> frozenset[str]:
    """Return the names of the robot's prismatic joints (positions in [m])."""
    return frozenset(name for name, joint in config.urdf_joints.items() if joint.type == "prismatic")


def check(
    request: CheckRequest, then: Callable[[CheckedRecording], None] | None = None,
    read_plan: Callable[[Path], recording.PlanFile] = read_valid_plan,
) -> CheckReport:
    """Return the verdict of the controller's and MoveIt's rules on a recorded execution of a plan.

    `then`, if given, gets the verdict with what it was made from while the recording is
    still open (plots.check_plotted draws from it). `read_plan` reads and validates the plan
    file (a batch check keeps the plans it read).
    """
    plan = read_plan(request.plan)
    config = plan_config(plan, request.plan)
    controller = plan_controller(config, plan, request.plan, request.controllers, strict=request.strict)
    for step in plan.steps:  # a goal JTC refuses is said before the recording is read
        try:
            check_goal_joints(step.trajectory.joint_names, controller)
        except InputError as exc:
            raise InputError(f"{request.plan}: step '{step.name}': {exc}") from None
    continuous = [j for j, lim in config.limits.items() if lim.continuous]
    # The samples wait on disk and are read back a window at a time: memory does not grow with the recording.
    with open_joint_states(request.recording, request.topic, joints=controller.joints,
                           time_source=request.time_source, velocities=uses_velocities(plan, controller),
                           skip_damaged=request.skip_damaged) as recorded:
        report = check_recording(plan, recorded, controller, config.execution, continuous, request.start)
        report = replace(report, skipped=recorded.skipped, unchecked=unchecked_joints(controller),
                         prismatic=prismatic_joints(config))
        report = recorded_tracking(report, [s.trajectory for s in plan.steps], recorded, controller,
                                   np.array([j in continuous for j in controller.joints]))
        if then is not None:
            then(CheckedRecording(report, plan, controller, tuple(continuous), recorded))
        return report
