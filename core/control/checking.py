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

An execution the recording cuts off is INCOMPLETE, not failed: one still undecided when
the recording ends, one whose goal was sent before the recording's first sample (its start
state is not recorded, so MoveIt's start check is skipped), and, with `start="all"`, one
already running when the recording began. A violation seen before the cut is still that
failure.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from ..config.robot_config import ControllerConfig, ExecutionConfig
from ..errors import InputError, UsageError
from ..trajectory import PointBefore, sample
from ..types import JointStateSeries, JointTrajectory
from .alignment import (
    ZONE_RAD,
    Samples,
    StepProfile,
    cycle_starts,
    find_gaps,
    first_start,
    next_start,
)
from .controller import WAIT_LIMIT_S
from .tolerances import (
    INCOMPLETE,
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
    judge_spans,
    position_error,
    segment_tolerances,
    velocity_error_computable,
)

__all__ = ["CheckReport", "CycleCheck", "StepCheck", "check_recording", "uses_velocities"]

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

    @property
    def complete(self) -> bool:
        """Return False if the recording cuts the step off before a verdict (INCOMPLETE)."""
        return self.report.result.code != INCOMPLETE


@dataclass(frozen=True)
class CycleCheck:
    """One execution of the plan found in the recording (`start="all"`).

    Attributes:
        index: Its place in the recording, in time order from 0.
        start_s: Where its first goal started, in [s] from the recording's first sample; for
            one already running when the recording began, the first sample's time.
        steps: Its steps judged, up to the first that did not succeed (none for one already
            running when the recording began).
        result: Its verdict: the failing step's result, else INCOMPLETE if the recording cuts
            it off, else SUCCESSFUL.

    """

    index: int
    start_s: float
    steps: tuple[StepCheck, ...]
    result: ExecutionResult

    @property
    def ok(self) -> bool:
        """Return True if the execution succeeded."""
        return self.result.code == SUCCESSFUL

    @property
    def complete(self) -> bool:
        """Return False if the recording cuts the execution off before a verdict (INCOMPLETE)."""
        return self.result.code != INCOMPLETE

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
        if not self.steps:
            return 0.0
        last = self.steps[-1]
        return last.start_s + last.duration_s - self.start_s


@dataclass(frozen=True)
class CheckReport:
    """The verdict on a recording.

    Attributes:
        ok: True if the execution succeeded; with `start="all"`, if no cycle failed and at
            least one is complete (INCOMPLETE cycles count neither way).
        result: How the execution ended, INCOMPLETE if the recording cuts it off before a
            verdict; with `start="all"`, the first failing cycle's code with a message naming
            it, else SUCCESSFUL, or INCOMPLETE if no cycle is complete.
        violations: (step name, violation) of the execution reported (the first failing
            cycle's, with `start="all"`); violation times are from that step's start.
        margins: Per joint the smallest tolerance - |error| over all checks, in [rad].
        duration_s: From the first checked start to the last decision in [s].
        start_s: The first execution's start in [s] from the recording's first sample.
        steps: The steps of the single execution (empty with `start="all"`).
        cycles: Every execution found (`start="all"` only), in time order.
        failing_cycles: Indices of the cycles that failed.
        incomplete_cycles: Indices of the cycles the recording cuts off (INCOMPLETE).
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
    incomplete_cycles: tuple[int, ...]
    gaps: tuple[tuple[float, float], ...]
    warnings: tuple[str, ...]
    recording_start_ns: int

    @property
    def complete(self) -> bool:
        """Return False if the recording cuts the execution (every execution) off before a verdict."""
        return self.result.code != INCOMPLETE


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
        running = _already_running(context) if aligned_by == "departure" else ""
        if running:
            warnings.append(f"{running}; the first execution found starts at {first:.3f} s")
    else:
        first, aligned_by = float(start), "given"
        if not math.isfinite(first):
            raise UsageError(f"start must be a finite time in seconds, got {start}")
    (steps,) = _executions(context, [first], [aligned_by], [len(series.times_s)], ["recording"])
    for step in steps:
        if step.aligned_by in ("first departure", "first sample", "previous step"):
            warnings.append(f"step '{step.name}': start at {step.start_s:.3f} s found by "
                            f"{step.aligned_by} (no departure from its first point was seen)")
    last = steps[-1]
    result = _verdict(context, first, steps)
    return CheckReport(
        ok=result.code == SUCCESSFUL,
        result=result,
        violations=tuple((s.name, v) for s in steps for v in s.report.violations),
        margins=_merged_margins(steps),
        duration_s=last.start_s + last.duration_s - first,
        start_s=first,
        steps=steps,
        cycles=(),
        failing_cycles=(),
        incomplete_cycles=(),
        gaps=gaps,
        warnings=tuple(warnings),
        recording_start_ns=series.start_ns,
    )


def uses_velocities(plan: _Plan, controller: ControllerConfig) -> bool:
    """Return True if `check_recording` reads the recorded velocities for this plan and controller.

    JTC computes velocity errors only with some interfaces, and blends from the velocity it
    read only into a first point after time 0.
    """
    blends = any(step.trajectory.times_s[0] > 0.0 for step in plan.steps)
    return velocity_error_computable(controller) or (
        blends and "velocity" in controller.state_interfaces)


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

# Samples judged in one stacked pass: enough to spread numpy's per-call cost over a few
# executions, few enough to keep each array of a pass at a megabyte or two.
_BATCH_ROWS = 1 << 15


@dataclass(frozen=True)
class _Window:
    """A step's goal sent at `start` [s]: judged from sample `first` on, never at or past `end`.

    `runs_out`: the recording ends at `end` before MoveIt would give up, so a verdict of
    TIMED_OUT there only means the recording cut the step off.
    """

    start: float
    first: int
    end: int
    at_send: int
    current: NDArray[np.float64]
    timeout: Timeout
    runs_out: bool


def _all_cycles(context: _Context) -> tuple[CycleCheck, ...]:
    """Return every execution of the plan found in the recording, judged."""
    times = context.samples.times
    starts = cycle_starts(context.samples, context.profiles)
    # Each execution ends where the next one starts.
    ends = np.searchsorted(times, starts[1:], side="left").tolist()
    ends.append(len(times))
    reasons = ["next cycle"] * (len(starts) - 1) + ["recording"]
    executions = _executions(context, starts, ["departure"] * len(starts), ends, reasons)
    cycles = [(start, steps, _verdict(context, start, steps))
              for start, steps in zip(starts, executions, strict=True)]
    running = _already_running(context)
    if running:
        cycles.insert(0, (float(times[0]), (), ExecutionResult(INCOMPLETE, "INCOMPLETE", running)))
    return tuple(CycleCheck(index, start, steps, result)
                 for index, (start, steps, result) in enumerate(cycles))


def _verdict(context: _Context, start: float, steps: Sequence[StepCheck]) -> ExecutionResult:
    """Return an execution's result: its failure, else INCOMPLETE if the recording cuts it off."""
    last = steps[-1]
    result = last.report.result
    times = context.samples.times
    if result.code == INCOMPLETE:
        number = len(steps) - 1
        remaining = (last.start_s + context.profiles[number].trajectory.duration_s - times[-1]
                     + sum(p.trajectory.duration_s for p in context.profiles[number + 1 :]))
        if remaining > 0.0:
            return replace(result, message=(
                f"the recording ends {remaining:.3f} s before the plan's execution could finish "
                f"(step '{last.name}': {result.message})"))
        return replace(result, message=f"the recording ends before the controller decided step "
                                       f"'{last.name}' ({result.message})")
    if result.code == SUCCESSFUL and _before_recording(context, start):
        return ExecutionResult(INCOMPLETE, "INCOMPLETE", (
            f"the recording begins about {times[0] - start:.3f} s after the execution started: "
            "its start state and first motion are not recorded"))
    return result


def _before_recording(context: _Context, start: float) -> bool:
    """Return True if a goal started at `start` [s] was sent before the recording's first sample.

    A sample period of slack: an execution recorded from its send time (an executed file)
    is aligned to within a period of its first sample, on either side.
    """
    return start < float(context.samples.times[0]) - context.samples.period_s


def _already_running(context: _Context) -> str:
    """Return why the recording begins inside an execution already running, "" if it does not.

    It does if, at its first sample, the robot is away from the plan's first point but on
    the plan's path: within the largest path tolerance (at least ZONE_RAD) of a planned
    position. Such an execution has no departure to align it by; it is not judged.
    """
    samples, home = context.samples, context.profiles[0]
    robot = samples.rows(0, 1)[0]
    away = np.abs(position_error(home.trajectory.positions[0], robot, samples.continuous))
    if away.max() <= home.zone_in:  # at rest at the first point, or departing from it
        return ""
    radius = max(ZONE_RAD, *context.controller.trajectory_tolerance.values())
    for profile in context.profiles:
        planned, _, _ = sample(profile.trajectory, profile.times, derivatives=0)
        off = np.abs(position_error(planned, robot, samples.continuous)).max(axis=1)
        closest = int(np.argmin(off))
        if off[closest] <= radius:
            return (f"the recording begins during an execution already running (the robot is "
                    f"on the plan's path, nearest step '{profile.name}' at "
                    f"{profile.times[closest]:.3f} s): it is not checked")
    return ""


def _executions(
    context: _Context, starts: Sequence[float], aligned_by: Sequence[str], ends: Sequence[int],
    end_reasons: Sequence[str],
) -> list[tuple[StepCheck, ...]]:
    """Return the steps of each execution judged in turn, each up to its first that fails.

    Step by step, every execution still going is judged in one pass. Samples of execution
    i at indices >= `ends[i]` belong to something else (the next cycle, or none exist).
    """
    times = context.samples.times
    steps: list[list[StepCheck]] = [[] for _ in starts]
    begins, hows = list(starts), list(aligned_by)
    going = list(range(len(starts)))
    for number, profile in enumerate(context.profiles):
        if number > 0:
            going = [i for i in going if steps[i][-1].ok]
            for i in going:
                previous = steps[i][-1]
                decided = int(np.searchsorted(times, previous.start_s + previous.duration_s,
                                              side="left"))
                begins[i], hows[i] = next_start(context.samples, profile,
                                                min(decided, ends[i] - 1), ends[i])
        verdicts = _judge_steps(context, profile, [begins[i] for i in going],
                                [ends[i] for i in going], [end_reasons[i] for i in going])
        for i, (report, decided_s) in zip(going, verdicts, strict=True):
            steps[i].append(StepCheck(profile.name, begins[i], decided_s, report, hows[i]))
    return [tuple(s) for s in steps]


def _judge_steps(
    context: _Context, profile: StepProfile, starts: Sequence[float], ends: Sequence[int],
    end_reasons: Sequence[str],
) -> list[tuple[ToleranceReport, float]]:
    """Return per execution the step's verdict and the time [s] from its start to the deciding sample.

    Judged first over the samples up to a little past the step's end, then, for the few
    still undecided there, over growing spans: a step decided early does not sample the
    plan over the rest of an hour-long recording.
    """
    verdicts: dict[int, tuple[ToleranceReport, float]] = {}
    windows: list[tuple[int, _Window]] = []
    for slot, (start, end, end_reason) in enumerate(zip(starts, ends, end_reasons, strict=True)):
        opened = _open(context, profile, start, end, end_reason)
        if isinstance(opened, _Window):
            windows.append((slot, opened))
        else:
            verdicts[slot] = opened
    # A step that succeeds is decided a cycle or two past its last point.
    extra = 4.0 / context.controller.update_rate_hz + 4.0 * context.samples.period_s + 0.02
    judged = _judge_windows(context, profile, [window for _, window in windows], extra)
    for (slot, window), (report, decided_s, undecided) in zip(windows, judged, strict=True):
        grown = extra
        while undecided:
            grown *= 4.0
            ((report, decided_s, undecided),) = _judge_windows(context, profile, [window], grown)
        if window.runs_out and report.result.code == TIMED_OUT:
            # Not a failed check: the goal-tolerance state at the cut is no violation yet.
            result = replace(report.result, code=INCOMPLETE, name="INCOMPLETE")
            report = replace(report, result=result, violations=())
        verdicts[slot] = (report, decided_s)
    return [verdicts[slot] for slot in range(len(starts))]


def _open(
    context: _Context, profile: StepProfile, start: float, end: int, end_reason: str
) -> _Window | tuple[ToleranceReport, float]:
    """Return the step's goal as sent at `start`, or its verdict if it is decided at once."""
    samples = context.samples
    times = samples.times
    trajectory = profile.trajectory
    first = int(np.searchsorted(times, start, side="left"))
    at_send = max(first - 1, 0) if first >= len(times) or times[first] > start else first
    current = samples.rows(at_send, at_send + 1)[0]
    if not _before_recording(context, start):  # else the state at the send was not recorded
        refused = check_start_state(trajectory.joint_names, current, trajectory.positions[0],
                                    context.execution.allowed_start_tolerance, samples.continuous)
        if refused is not None:
            return refused, 0.0
    cut = end_reason == "recording"
    if first >= end:
        message = f"the {end_reason} ends before the step's start at {start:.3f} s"
        result = ExecutionResult(INCOMPLETE, "INCOMPLETE", message) if cut else \
            ExecutionResult(TIMED_OUT, "TIMED_OUT", message)
        return ToleranceReport(result, (), {}, 0), 0.0
    last_s = float(times[end - 1]) - start
    timeout = _timeout(context, trajectory.duration_s, last_s, end_reason)
    # The recording ends before MoveIt would give up: its end cannot be a real timeout.
    runs_out = cut and last_s <= timeout.time_s
    return _Window(start, first, end, at_send, current, timeout, runs_out)


def _judge_windows(
    context: _Context, profile: StepProfile, windows: Sequence[_Window], extra: float
) -> list[tuple[ToleranceReport, float, bool]]:
    """Return per window the verdict over its samples up to `extra` [s] past the step's end.

    With the time [s] from the start to the deciding sample, and whether the verdict is
    only that the samples ran out before the step was decided (a longer span may decide it).
    """
    if not windows:
        return []
    times = context.samples.times
    duration = profile.trajectory.duration_s
    firsts = np.array([w.first for w in windows], dtype=np.intp)
    ends = np.array([w.end for w in windows], dtype=np.intp)
    stops = np.searchsorted(times, [w.start + duration + extra for w in windows], side="right")
    stops = np.minimum(np.maximum(stops, firsts + 1), ends)
    judged: list[tuple[ToleranceReport, float, bool]] = []
    begin = 0
    while begin < len(windows):
        # As many windows as fit in a batch; one longer than a batch gets a pass of its own.
        total = np.cumsum(stops[begin:] - firsts[begin:])
        count = max(1, int(np.searchsorted(total, _BATCH_ROWS, side="right")))
        batch = slice(begin, begin + count)
        judged += _judge_stacked(context, profile, windows[batch], firsts[batch], stops[batch])
        begin += count
    return judged


def _judge_stacked(
    context: _Context, profile: StepProfile, windows: Sequence[_Window],
    firsts: NDArray[np.intp], stops: NDArray[np.intp],
) -> list[tuple[ToleranceReport, float, bool]]:
    """Return `_judge_windows`' verdicts, the windows judged over samples [firsts, stops) at once."""
    samples = context.samples
    trajectory = profile.trajectory
    duration = trajectory.duration_s
    lengths = stops - firsts
    span_starts = np.concatenate(([0], np.cumsum(lengths)[:-1]))
    begins, ends = firsts.tolist(), stops.tolist()
    since = np.concatenate([samples.times[b:e] - w.start
                            for w, b, e in zip(windows, begins, ends, strict=True)])
    derivatives = 1 if context.check_velocities else 0
    if trajectory.times_s[0] > 0.0:
        # JTC blends from the state it read at the send time: each window its own.
        parts = [
            sample(trajectory, since[a : a + n], point_before=_point_before(context, w),
                   continuous=samples.continuous, derivatives=derivatives)
            for w, a, n in zip(windows, span_starts.tolist(), lengths.tolist(), strict=True)
        ]
        reference = np.concatenate([p[0] for p in parts])
        reference_v = np.concatenate([p[1] for p in parts])
    else:
        reference, reference_v, _ = sample(trajectory, since, derivatives=derivatives)
    reports = judge_spans(
        context.tolerances, since, reference, samples.spans(begins, ends),
        # As the simulation: JTC takes the segment from the command's time, one period on.
        before_last_point=since + 1.0 / context.controller.update_rate_hz < duration,
        last_point_s=duration,
        span_starts=span_starts,
        timeouts=[w.timeout for w in windows],
        reference_velocities=reference_v if context.check_velocities else None,
        actual_velocities=_velocities(context, begins, ends),
        continuous=samples.continuous,
    )
    judged = []
    for window, report, at, length, stop in zip(windows, reports, span_starts.tolist(),
                                                lengths.tolist(), stops.tolist(), strict=True):
        last = at + length - 1
        undecided = (report.result.code == TIMED_OUT and report.end_index == length - 1
                     and since[last] <= window.timeout.time_s)
        judged.append((report, float(since[at + report.end_index]),
                       undecided and stop != window.end))
    return judged


def _velocities(
    context: _Context, begins: Sequence[int], ends: Sequence[int]
) -> NDArray[np.float64] | None:
    """Return recorded velocities of samples [begins[i], ends[i]) when JTC computes velocity errors."""
    if not context.check_velocities or context.velocities is None:
        return None
    velocities = context.velocities
    block = np.concatenate([velocities[b:e] for b, e in zip(begins, ends, strict=True)])
    return block[:, context.samples.columns]


def _timeout(context: _Context, duration: float, last_s: float, end_reason: str) -> Timeout:
    """Return when MoveIt gives up, with the message for a recording that ends undecided.

    Without MoveIt's duration monitor, a controller with goal_time 0 never gives up: the
    check then stops where the simulation does, WAIT_LIMIT_S after the last point.
    """
    expected = expected_duration_s(duration, context.execution)
    if context.execution.execution_duration_monitoring:
        limit = expected
        stops = (f"Controller is taking too long to execute trajectory (the expected upper bound "
                 f"for the trajectory execution was {expected:.6f} seconds). Stopping trajectory.")
    else:
        limit = max(expected, duration + WAIT_LIMIT_S)
        stops = (f"no result {limit:.6f} s after the step's start: the controller was still "
                 f"waiting for the goal tolerance and MoveIt's execution_duration_monitoring "
                 f"is off (checked up to {WAIT_LIMIT_S:g} s after the last point, as execute does)")
    if last_s > limit:
        return Timeout(limit, stops)
    goal_time = context.controller.goal_time_s
    waits = "forever" if goal_time == 0.0 else f"{goal_time:g} s after the last point"
    return Timeout(limit, (
        f"the {end_reason} ends {last_s:.3f} s after the step's start, before the controller "
        f"decided (it waits for the goal tolerance {waits})"))


def _point_before(context: _Context, window: _Window) -> PointBefore:
    """Return the state JTC blends from, with the fields its state interfaces provide."""
    states = context.controller.state_interfaces
    velocities = None
    if "velocity" in states and context.velocities is not None:
        velocities = context.velocities[window.at_send, context.samples.columns]
    accelerations = None
    if velocities is not None and "acceleration" in states:
        accelerations = np.zeros_like(window.current)  # no acceleration is recorded: read as 0
    return PointBefore(window.current, velocities, accelerations)


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
    failing = tuple(c.index for c in cycles if not c.ok and c.complete)
    incomplete = tuple(c.index for c in cycles if not c.complete)
    complete = len(cycles) - len(incomplete)
    margins = _merged_margins(step for cycle in cycles for step in cycle.steps)
    first, last = cycles[0], cycles[-1]
    cut = (f"; {len(incomplete)} incomplete (cut off by the recording): cycle "
           f"{', '.join(map(str, incomplete))}") if incomplete else ""
    kind = "complete execution" if incomplete else "execution"
    violations: tuple[tuple[str, Violation], ...] = ()
    if failing:
        bad = cycles[failing[0]]
        step = bad.steps[-1]
        message = (f"{len(failing)} of {complete} {kind}s failed; the first: cycle "
                   f"{bad.index} at {bad.start_s:.3f} s, step '{step.name}': {bad.result.message}")
        result = replace(bad.result, message=message)
        violations = tuple((s.name, v) for s in bad.steps for v in s.report.violations)
    elif complete == 0:
        message = (f"no complete execution in the recording{cut}; cycle {first.index}: "
                   f"{first.result.message}")
        result = ExecutionResult(INCOMPLETE, "INCOMPLETE", message)
    else:
        counted = f"all {complete} {kind}s" if complete > 1 else f"the one {kind}"
        result = ExecutionResult(SUCCESSFUL, "SUCCESSFUL", f"{counted} within tolerances{cut}")
    return CheckReport(
        ok=not failing and complete > 0,
        result=result,
        violations=violations,
        margins=margins,
        duration_s=last.start_s + last.duration_s - first.start_s,
        start_s=first.start_s,
        steps=(),
        cycles=cycles,
        failing_cycles=failing,
        incomplete_cycles=incomplete,
        gaps=gaps,
        warnings=tuple(warnings),
        recording_start_ns=start_ns,
    )
