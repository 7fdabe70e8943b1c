"""Tolerance checks of recorded executions: a recording judged by the live controller's rules.

The rules are core.tolerances', as the simulated controller applies them: the plan is
sampled as JTC interpolates it (core.trajectory.sample) at the recorded times, path
tolerances hold before the last point, goal tolerances within goal_time after it, the
stopped-velocity tolerance only where JTC computes velocity errors, and MoveIt checks the
start state and the duration envelope. The recorded samples stand in for controller
cycles: a recording sparser than the controller's update rate can miss a short excursion.

Each step of a plan is one FollowJointTrajectory goal, as MoveIt executes a plan: judged
alone from its own start, and the first failing step ends the execution. (Not the
concatenation on the plan's timeline: a real robot pauses between goals for as long as
MoveIt takes to send the next one.) Where each goal started is core.alignment's to find;
a number for `start` puts the first step there instead, in seconds from the recording's
first sample.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from moveplan.core.alignment import (
    ZONE_RAD,
    Samples,
    StepProfile,
    cycle_starts,
    find_gaps,
    first_start,
    next_start,
)
from moveplan.core.config import ControllerConfig, ExecutionConfig
from moveplan.core.errors import InputError, UsageError
from moveplan.core.tolerances import (
    SUCCESSFUL,
    TIMED_OUT,
    ExecutionResult,
    SegmentTolerances,
    Timeout,
    ToleranceReport,
    Violation,
    check_start_state,
    expected_duration_s,
    in_controller_order,
    judge,
    segment_tolerances,
    velocity_error_computable,
)
from moveplan.core.trajectory import PointBefore, sample
from moveplan.core.types import JointStateSeries, JointTrajectory

__all__ = ["CheckReport", "CycleCheck", "StepCheck", "check_recording"]

Start = float | Literal["auto", "all"]


class _Step(Protocol):
    @property
    def name(self) -> str: ...
    @property
    def start_s(self) -> float: ...
    @property
    def trajectory(self) -> JointTrajectory: ...


class _Plan(Protocol):
    @property
    def steps(self) -> Sequence[_Step]: ...


@dataclass(frozen=True)
class StepCheck:
    """One step judged as a goal of its own.

    Attributes:
        name: The step's name.
        start_s: Where its goal starts, in [s] from the recording's first sample.
        duration_s: From its start to the sample that decided, in [s].
        report: The verdict; its times are from the step's start.
        aligned_by: How the start was found: "departure", "given", "previous step",
            "first departure" (never rested near the first point) or "first sample".

    """

    name: str
    start_s: float
    duration_s: float
    report: ToleranceReport
    aligned_by: str

    @property
    def ok(self) -> bool:
        """Return True if the step succeeded."""
        return self.report.ok


@dataclass(frozen=True)
class CycleCheck:
    """One execution of the plan found in the recording (`start="all"`)."""

    index: int
    start_s: float
    steps: tuple[StepCheck, ...]

    @property
    def ok(self) -> bool:
        """Return True if every step of this execution succeeded."""
        return all(step.ok for step in self.steps)

    @property
    def result(self) -> ExecutionResult:
        """Return the result of the step that ended the execution."""
        return self.steps[-1].report.result

    @property
    def margins(self) -> dict[str, float]:
        """Return per joint the smallest margin to its tolerance over the steps, in [rad]."""
        return _merged_margins(self.steps)

    @property
    def worst_margin(self) -> float | None:
        """Return the smallest margin of any joint in [rad], None if nothing was checked."""
        return min(self.margins.values(), default=None)

    @property
    def duration_s(self) -> float:
        """Return the time from the execution's start to its last decision in [s]."""
        last = self.steps[-1]
        return last.start_s + last.duration_s - self.start_s


@dataclass(frozen=True)
class CheckReport:
    """The verdict on a recording.

    Attributes:
        ok: True if every checked execution succeeded.
        result: How the execution ended; with `start="all"`, the first failing cycle's code
            with a message naming it, else SUCCESSFUL.
        violations: (step name, violation) of the execution reported (the first failing
            cycle's, with `start="all"`); violation times are from that step's start.
        margins: Per joint the smallest tolerance - |error| over all checks, in [rad].
        duration_s: From the first checked start to the last decision in [s].
        start_s: The first execution's start in [s] from the recording's first sample.
        steps: The steps of the single execution (empty with `start="all"`).
        cycles: Every execution found (`start="all"` only), in time order.
        failing_cycles: Indices of the cycles that failed.
        gaps: (start_s, length_s) of pauses between samples longer than GAP_FACTOR median
            periods, start in [s] from the recording's first sample.
        warnings: Things the user should know: gaps, sparse samples, alignment fallbacks.
        recording_start_ns: Time of the recording's first sample in [ns].

    """

    ok: bool
    result: ExecutionResult
    violations: tuple[tuple[str, Violation], ...]
    margins: dict[str, float]
    duration_s: float
    start_s: float
    steps: tuple[StepCheck, ...]
    cycles: tuple[CycleCheck, ...]
    failing_cycles: tuple[int, ...]
    gaps: tuple[tuple[float, float], ...]
    warnings: tuple[str, ...]
    recording_start_ns: int


def check_recording(
    plan: _Plan,
    series: JointStateSeries,
    controller: ControllerConfig,
    execution: ExecutionConfig,
    continuous_joints: Iterable[str] = (),
    start: Start = "auto",
) -> CheckReport:
    """Return the verdict of the controller's and MoveIt's checks on a recorded execution.

    Args:
        plan: The plan: steps with name, start_s and trajectory (a PlanFile).
        series: The recorded joint states; must hold every controller joint.
        controller: The JointTrajectoryController whose tolerances apply.
        execution: MoveIt's trajectory_execution settings (start tolerance, duration envelope).
        continuous_joints: URDF continuous joints: their errors wrap around.
        start: "auto" (the first execution found), a time in [s] from the recording's first
            sample, or "all" (every execution of a robot repeating the plan).

    Raises:
        InputError: A controller joint is missing from the recording or the plan, or with
            "all", no execution of the plan is found.
        UsageError: `start` is none of the above.

    """
    if not plan.steps:
        raise InputError("the plan has no steps")
    context = _Context.build(plan, series, controller, execution, continuous_joints)
    warnings = list(context.warnings)
    gaps = find_gaps(context.samples, warnings)
    if start == "all":
        cycles = _all_cycles(context)
        return _cycles_report(cycles, gaps, warnings, series.start_ns)
    if isinstance(start, str):
        if start != "auto":
            raise UsageError(f"start must be 'auto', 'all' or a time in seconds, got '{start}'")
        first, aligned_by = first_start(context.samples, context.profiles[0])
    else:
        first, aligned_by = float(start), "given"
        if not math.isfinite(first):
            raise UsageError(f"start must be a finite time in seconds, got {start}")
    steps = _execution(context, first, aligned_by, len(series.times_s), "recording")
    for step in steps:
        if step.aligned_by in ("first departure", "first sample", "previous step"):
            warnings.append(f"step '{step.name}': start at {step.start_s:.3f} s found by "
                            f"{step.aligned_by} (no departure from its first point was seen)")
    last = steps[-1]
    return CheckReport(
        ok=last.ok,
        result=last.report.result,
        violations=tuple((s.name, v) for s in steps for v in s.report.violations),
        margins=_merged_margins(steps),
        duration_s=last.start_s + last.duration_s - first,
        start_s=first,
        steps=steps,
        cycles=(),
        failing_cycles=(),
        gaps=gaps,
        warnings=tuple(warnings),
        recording_start_ns=series.start_ns,
    )


# --- preparation ----------------------------------------------------------------------------


@dataclass(frozen=True)
class _Context:
    """Everything the checks share, computed once."""

    samples: Samples
    profiles: tuple[StepProfile, ...]
    velocities: NDArray[np.float64] | None
    check_velocities: bool
    controller: ControllerConfig
    execution: ExecutionConfig
    tolerances: SegmentTolerances
    warnings: tuple[str, ...]

    @staticmethod
    def build(
        plan: _Plan, series: JointStateSeries, controller: ControllerConfig,
        execution: ExecutionConfig, continuous_joints: Iterable[str],
    ) -> _Context:
        samples = Samples.build(series, controller.joints, continuous_joints)
        zone = max(ZONE_RAD, 2.0 * execution.allowed_start_tolerance)
        profiles = tuple(
            StepProfile.build(step.name, in_controller_order(step.trajectory, controller),
                              samples.continuous, zone)
            for step in plan.steps
        )
        computable = velocity_error_computable(controller)
        warnings = []
        period = samples.period_s
        if period > 1.5 / controller.update_rate_hz:
            warnings.append(
                f"the recording has a sample every {period * 1e3:.3g} ms, the controller checks "
                f"every {1e3 / controller.update_rate_hz:.3g} ms: short excursions between "
                "samples are not seen")
        if series.velocities is None and computable:
            warnings.append("the recording carries no velocities: the stopped velocity "
                            "tolerance is not checked")
        return _Context(samples, profiles, series.velocities,
                        computable and series.velocities is not None, controller, execution,
                        segment_tolerances(controller), tuple(warnings))


# --- judging ------------------------------------------------------------------------------


def _all_cycles(context: _Context) -> tuple[CycleCheck, ...]:
    """Return every execution of the plan found in the recording, judged."""
    starts = cycle_starts(context.samples, context.profiles)
    times = context.samples.times
    cycles = []
    for index, start in enumerate(starts):
        end = len(times)
        reason = "recording"
        if index + 1 < len(starts):
            end = int(np.searchsorted(times, starts[index + 1], side="left"))
            reason = "next cycle"
        steps = _execution(context, start, "departure", end, reason)
        cycles.append(CycleCheck(index, start, steps))
    return tuple(cycles)


def _execution(
    context: _Context, start: float, aligned_by: str, end: int, end_reason: str
) -> tuple[StepCheck, ...]:
    """Return the steps of one execution judged in turn, up to the first that fails.

    Samples at indices >= `end` belong to something else (the next cycle, or none exist).
    """
    steps: list[StepCheck] = []
    for number, profile in enumerate(context.profiles):
        if number > 0:
            previous = steps[-1]
            decided = int(np.searchsorted(context.samples.times,
                                          previous.start_s + previous.duration_s, side="left"))
            start, aligned_by = next_start(context.samples, profile, min(decided, end - 1), end)
        report, decided_s = _judge_step(context, profile, start, end, end_reason)
        steps.append(StepCheck(profile.name, start, decided_s, report, aligned_by))
        if not report.ok:
            break
    return tuple(steps)


def _judge_step(
    context: _Context, profile: StepProfile, start: float, end: int, end_reason: str
) -> tuple[ToleranceReport, float]:
    """Return the step's verdict and the time [s] from its start to the deciding sample.

    Judged over growing spans of samples, so a step decided early does not sample the
    plan over the rest of an hour-long recording.
    """
    samples = context.samples
    times = samples.times
    trajectory = profile.trajectory
    first = int(np.searchsorted(times, start, side="left"))
    at_send = max(first - 1, 0) if first >= len(times) or times[first] > start else first
    current = samples.rows(at_send, at_send + 1)[0]
    refused = check_start_state(trajectory.joint_names, current, trajectory.positions[0],
                                context.execution.allowed_start_tolerance, samples.continuous)
    if refused is not None:
        return refused, 0.0
    if first >= end:
        message = f"the {end_reason} ends before the step's start at {start:.3f} s"
        return ToleranceReport(ExecutionResult(TIMED_OUT, "TIMED_OUT", message), (), {}, 0), 0.0
    duration = trajectory.duration_s
    timeout = _timeout(context, duration, float(times[end - 1]) - start, end_reason)
    point_before = _point_before(context, at_send, current)
    # A step that succeeds is decided a cycle or two past its last point.
    extra = 4.0 / context.controller.update_rate_hz + 4.0 * samples.period_s + 0.02
    while True:
        stop = int(np.searchsorted(times, start + duration + extra, side="right"))
        stop = min(max(stop, first + 1), end)
        since = times[first:stop] - start
        reference, reference_v, _ = sample(trajectory, since, point_before=point_before,
                                           continuous=samples.continuous,
                                           derivatives=1 if context.check_velocities else 0)
        report = judge(
            context.tolerances, since, reference, samples.rows(first, stop),
            # As the simulation: JTC takes the segment from the command's time, one period on.
            before_last_point=since + 1.0 / context.controller.update_rate_hz < duration,
            last_point_s=duration,
            timeout=timeout,
            reference_velocities=reference_v if context.check_velocities else None,
            actual_velocities=_velocities(context, first, stop),
            continuous=samples.continuous,
        )
        undecided = (report.result.code == TIMED_OUT and report.end_index == stop - first - 1
                     and since[-1] <= timeout.time_s)
        if stop == end or not undecided:
            return report, float(since[report.end_index])
        extra *= 4.0


def _velocities(context: _Context, begin: int, end: int) -> NDArray[np.float64] | None:
    """Return recorded velocities of samples [begin, end) when JTC would compute velocity errors."""
    if not context.check_velocities or context.velocities is None:
        return None
    return context.velocities[begin:end][:, context.samples.columns]


def _timeout(context: _Context, duration: float, last_s: float, end_reason: str) -> Timeout:
    """Return when MoveIt gives up, with the message for a recording that ends undecided."""
    expected = expected_duration_s(duration, context.execution)
    limit = expected if context.execution.execution_duration_monitoring else math.inf
    if last_s > limit:
        return Timeout(expected, (
            f"Controller is taking too long to execute trajectory (the expected upper bound for "
            f"the trajectory execution was {expected:.6f} seconds). Stopping trajectory."))
    goal_time = context.controller.goal_time_s
    waits = "forever" if goal_time == 0.0 else f"{goal_time:g} s after the last point"
    return Timeout(limit, (
        f"the {end_reason} ends {last_s:.3f} s after the step's start, before the controller "
        f"decided (it waits for the goal tolerance {waits})"))


def _point_before(context: _Context, index: int, positions: NDArray[np.float64]) -> PointBefore:
    """Return the state JTC blends from, with the fields its state interfaces provide."""
    states = context.controller.state_interfaces
    velocities = None
    if "velocity" in states and context.velocities is not None:
        velocities = context.velocities[index, context.samples.columns]
    accelerations = None
    if velocities is not None and "acceleration" in states:
        accelerations = np.zeros_like(positions)  # no acceleration is recorded: read as 0
    return PointBefore(positions, velocities, accelerations)


# --- reports --------------------------------------------------------------------------------


def _merged_margins(steps: Iterable[StepCheck]) -> dict[str, float]:
    margins: dict[str, float] = {}
    for step in steps:
        for joint, margin in step.report.margins.items():
            margins[joint] = min(margin, margins.get(joint, margin))
    return margins


def _cycles_report(
    cycles: tuple[CycleCheck, ...], gaps: tuple[tuple[float, float], ...], warnings: list[str],
    start_ns: int,
) -> CheckReport:
    failing = tuple(c.index for c in cycles if not c.ok)
    margins = _merged_margins(step for cycle in cycles for step in cycle.steps)
    first, last = cycles[0], cycles[-1]
    if failing:
        bad = cycles[failing[0]]
        step = bad.steps[-1]
        message = (f"{len(failing)} of {len(cycles)} executions failed; the first: cycle "
                   f"{bad.index} at {bad.start_s:.3f} s, step '{step.name}': {bad.result.message}")
        result = replace(bad.result, message=message)
        violations = tuple((s.name, v) for s in bad.steps for v in s.report.violations)
    else:
        counted = f"all {len(cycles)} executions" if len(cycles) > 1 else "the one execution"
        result = ExecutionResult(SUCCESSFUL, "SUCCESSFUL", f"{counted} within tolerances")
        violations = ()
    return CheckReport(
        ok=not failing,
        result=result,
        violations=violations,
        margins=margins,
        duration_s=last.start_s + last.duration_s - first.start_s,
        start_s=first.start_s,
        steps=(),
        cycles=cycles,
        failing_cycles=failing,
        gaps=gaps,
        warnings=tuple(warnings),
        recording_start_ns=start_ns,
    )
