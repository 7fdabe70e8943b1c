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
MoveIt takes to send the next one.)

Where a goal started is not recorded, so it is found from the motion. Distances are the
largest joint distance, shortest angle for continuous joints, in [rad]:

* Departure: the robot, having been within a zone of the step's first point (ZONE_RAD,
  or twice MoveIt's allowed_start_tolerance if larger), moves beyond twice that radius.
  "auto" takes the first departure; "all" takes every departure at least 0.9 plan
  durations after the previous one, each an execution of the plan.
* Alignment: the robot's departure is where it first moves DEPARTURE_THRESHOLD_RAD from
  where it rested before (interpolated between samples); the goal started as long before
  that as the plan takes to move as far from its first point. A constant lag of the robot
  behind its command is therefore not counted as error, just as the send time of a live
  goal is unknown.
* Later steps are searched from the sample where the previous step was decided; a step
  whose departure is not seen starts at that sample.
* Fallbacks: a recording that never rests near the first point is aligned by its first
  departure from its first sample (MoveIt's start check then fails); one that never
  moves starts at its first sample. A number for `start` puts the first step there, in
  seconds from the recording's first sample.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from moveplan.core.config import ControllerConfig, ExecutionConfig
from moveplan.core.errors import InputError, UnknownName, UsageError, known
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
    judge,
    position_error,
    segment_tolerances,
    velocity_error_computable,
)
from moveplan.core.trajectory import PointBefore, sample, shortest_angular_distance
from moveplan.core.types import JointTrajectory

if TYPE_CHECKING:
    from moveplan.core.jointstates import JointStateSeries

__all__ = [
    "DEPARTURE_THRESHOLD_RAD",
    "GAP_FACTOR",
    "ZONE_RAD",
    "CheckReport",
    "CycleCheck",
    "StepCheck",
    "check_recording",
]

DEPARTURE_THRESHOLD_RAD = 1e-3
"""How far [rad] the robot moves from where it rested before it counts as departed."""

ZONE_RAD = 0.02
"""Radius [rad] around a step's first point the robot must rest in before the step counts
as begun (at least twice MoveIt's allowed_start_tolerance, so that a start too far off is
still found, and reported); the robot must then move beyond twice this radius."""

GAP_FACTOR = 5.0
"""A pause between samples longer than this many median sample periods is reported."""

_MAX_GAPS = 1000
# Several cycles of the same plan cannot overlap: the controller follows the plan's timing.
_MIN_CYCLE_FRACTION = 0.9
_LOOKBACK_PAD_S = 0.05

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
    gaps = _gaps(series.times_s, context.period_s, warnings)
    if start == "all":
        cycles = _all_cycles(context)
        return _cycles_report(cycles, gaps, warnings, series.start_ns)
    if isinstance(start, str):
        if start != "auto":
            raise UsageError(f"start must be 'auto', 'all' or a time in seconds, got '{start}'")
        first_start, aligned_by = _auto_start(context)
    else:
        first_start, aligned_by = float(start), "given"
        if not math.isfinite(first_start):
            raise UsageError(f"start must be a finite time in seconds, got {start}")
    steps = _execution(context, first_start, aligned_by, len(series.times_s), "recording")
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
        duration_s=last.start_s + last.duration_s - first_start,
        start_s=first_start,
        steps=steps,
        cycles=(),
        failing_cycles=(),
        gaps=gaps,
        warnings=tuple(warnings),
        recording_start_ns=series.start_ns,
    )


# --- preparation ----------------------------------------------------------------------------


@dataclass(frozen=True)
class _Profile:
    """A step's trajectory in controller order and how fast it leaves its first point.

    `distance` is max over joints of |p(t) - p(0)| on the grid `times` [s]; the radii of
    the home zone and the departure threshold are scaled down for steps that barely move.
    """

    name: str
    trajectory: JointTrajectory
    times: NDArray[np.float64]
    distance: NDArray[np.float64]
    threshold: float
    zone_in: float
    zone_out: float
    _times_to: dict[float, float] = field(default_factory=dict, compare=False, repr=False)

    @property
    def moves(self) -> bool:
        """Return True if the step moves far enough for its departure to be seen."""
        return self.zone_out > 0.0

    def time_to(self, distance: float) -> float:
        """Return when the plan is first more than `distance` from its first point, in [s]."""
        if distance not in self._times_to:
            crossing = _crossing(self.times, self.distance, distance, 0)
            self._times_to[distance] = self.trajectory.duration_s if crossing is None else crossing
        return self._times_to[distance]


@dataclass(frozen=True)
class _Context:
    """Everything the checks share, computed once."""

    times: NDArray[np.float64]
    positions: NDArray[np.float64]
    columns: NDArray[np.intp]
    velocities: NDArray[np.float64] | None
    check_velocities: bool
    continuous: NDArray[np.bool_]
    controller: ControllerConfig
    execution: ExecutionConfig
    tolerances: SegmentTolerances
    profiles: tuple[_Profile, ...]
    period_s: float
    warnings: tuple[str, ...]

    @staticmethod
    def build(
        plan: _Plan, series: JointStateSeries, controller: ControllerConfig,
        execution: ExecutionConfig, continuous_joints: Iterable[str],
    ) -> _Context:
        joints = controller.joints
        missing = [j for j in joints if j not in series.names]
        if missing:
            raise InputError(
                f"{series.source or 'the recording'}: no joint {', '.join(missing)} in the "
                f"recording; joints present: {known(series.names)}")
        columns = np.array([series.names.index(j) for j in joints], dtype=np.intp)
        names = set(continuous_joints)
        continuous = np.array([j in names for j in joints])
        zone = max(ZONE_RAD, 2.0 * execution.allowed_start_tolerance)
        profiles = tuple(
            _profile(step.name, _in_controller_order(step.trajectory, controller), continuous, zone)
            for step in plan.steps
        )
        computable = velocity_error_computable(controller)
        warnings = []
        period = _median_period(series.times_s)
        if period > 1.5 / controller.update_rate_hz:
            warnings.append(
                f"the recording has a sample every {period * 1e3:.3g} ms, the controller checks "
                f"every {1e3 / controller.update_rate_hz:.3g} ms: short excursions between "
                "samples are not seen")
        if series.velocities is None and computable:
            warnings.append("the recording carries no velocities: the stopped velocity "
                            "tolerance is not checked")
        return _Context(series.times_s, series.positions, columns, series.velocities,
                        computable and series.velocities is not None, continuous, controller,
                        execution, segment_tolerances(controller), profiles, period,
                        tuple(warnings))

    def rows(self, begin: int, end: int) -> NDArray[np.float64]:
        """Return the positions of samples [begin, end) in controller order."""
        return self.positions[begin:end][:, self.columns]

    def distance(self, begin: int, end: int, point: NDArray[np.float64]) -> NDArray[np.float64]:
        """Return per sample in [begin, end) the largest joint distance to `point` in [rad]."""
        result = np.zeros(end - begin)
        for j, column in enumerate(self.columns):
            values = self.positions[begin:end, column]
            if self.continuous[j]:
                gap = np.abs(shortest_angular_distance(point[j], values))
            else:
                gap = np.abs(values - point[j])
            np.maximum(result, gap, out=result)
        return result


def _profile(
    name: str, trajectory: JointTrajectory, continuous: NDArray[np.bool_], zone: float
) -> _Profile:
    duration = trajectory.duration_s
    count = int(min(200_000, max(2, math.ceil(duration / 1e-3) + 1)))
    times = np.linspace(0.0, duration, count)
    positions, _, _ = sample(trajectory, times)
    error = position_error(positions, trajectory.positions[0], continuous)
    distance = np.abs(error).max(axis=1)
    extent = float(distance.max(initial=0.0))
    if extent < 4.0 * DEPARTURE_THRESHOLD_RAD:  # too little motion to be told from noise
        return _Profile(name, trajectory, times, distance, 0.0, 0.0, 0.0)
    zone_in = min(zone, extent / 4.0)
    zone_out = min(2.0 * zone_in, extent / 2.0)
    threshold = min(DEPARTURE_THRESHOLD_RAD, zone_in / 2.0)
    return _Profile(name, trajectory, times, distance, threshold, zone_in, zone_out)


def _in_controller_order(
    trajectory: JointTrajectory, controller: ControllerConfig
) -> JointTrajectory:
    """Return the trajectory's columns in the controller's joint order, as JTC sorts goals."""
    for joint in trajectory.joint_names:
        if joint not in controller.joints:
            raise UnknownName("joint", joint, f"controller '{controller.name}'", controller.joints)
    missing = [j for j in controller.joints if j not in trajectory.joint_names]
    if missing:
        raise InputError(
            f"Joints on incoming trajectory don't match the controller joints: controller "
            f"'{controller.name}' also has {', '.join(missing)} (partial goals are not allowed)")
    order = [trajectory.joint_names.index(j) for j in controller.joints]
    return JointTrajectory(controller.joints, trajectory.times_s, trajectory.positions[:, order],
                           trajectory.velocities[:, order], trajectory.accelerations[:, order])


def _median_period(times: NDArray[np.float64]) -> float:
    """Return the median time between samples in [s], over up to 100 000 spread intervals."""
    every = max(1, len(times) // 100_000)
    steps = times[every::every] - times[every - 1 : -1 : every]
    steps = steps[steps > 0.0]
    return float(np.median(steps)) if len(steps) else 0.0


def _gaps(
    times: NDArray[np.float64], period: float, warnings: list[str]
) -> tuple[tuple[float, float], ...]:
    """Return (start_s, length_s) of pauses longer than GAP_FACTOR median periods `period`."""
    if period <= 0.0:
        return ()
    steps = np.diff(times)
    found = np.flatnonzero(steps > GAP_FACTOR * period)
    if len(found):
        longest = int(found[np.argmax(steps[found])])
        warnings.append(
            f"{len(found)} gap(s) in the recording longer than {GAP_FACTOR:g} median sample "
            f"periods ({period * 1e3:.3g} ms), the longest {steps[longest]:.3f} s at "
            f"{times[longest]:.3f} s: the tolerances are not checked inside them")
    return tuple((float(times[i]), float(steps[i])) for i in found[:_MAX_GAPS])


# --- alignment ------------------------------------------------------------------------------


def _crossing(
    times: NDArray[np.float64], values: NDArray[np.float64], level: float, begin: int
) -> float | None:
    """Return when `values` first rises above `level` at or after index `begin`, interpolated."""
    above = np.flatnonzero(values[begin:] > level)
    if len(above) == 0:
        return None
    k = begin + int(above[0])
    if k == 0:
        return float(times[0])
    v0, v1 = float(values[k - 1]), float(values[k])
    fraction = (level - v0) / (v1 - v0) if v1 > v0 else 1.0
    return float(times[k - 1] + min(max(fraction, 0.0), 1.0) * (times[k] - times[k - 1]))


def _exits(
    distance: NDArray[np.float64], zone_in: float, zone_out: float, inside_at_first: bool
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Return sample indices where the robot leaves the zone, and where it last entered it.

    Hysteresis: inside is within `zone_in`, outside beyond `zone_out`; in between the
    previous state holds, so noise at the boundary does not count as many departures.
    """
    count = len(distance)
    event = np.zeros(count, dtype=np.int8)
    event[distance <= zone_in] = 1
    event[distance > zone_out] = -1
    last = np.where(event != 0, np.arange(count), -1)
    np.maximum.accumulate(last, out=last)
    state = np.where(last >= 0, event[np.maximum(last, 0)], 1 if inside_at_first else 0)
    before = np.concatenate(([1 if inside_at_first else 0], state[:-1]))
    exits = np.flatnonzero((state == -1) & (before == 1))
    entries = np.flatnonzero((state == 1) & (before != 1))
    dwell = np.zeros(len(exits), dtype=np.intp)
    if len(entries):
        found = np.searchsorted(entries, exits, side="right") - 1
        dwell = np.where(found >= 0, entries[np.maximum(found, 0)], 0)
    return exits, dwell


def _departure_start(
    context: _Context, profile: _Profile, exit_index: int, lower: int
) -> float:
    """Return the goal's start [s] for a departure that leaves the zone at `exit_index`.

    The robot rested before it: the sample taken as rest is far enough before the exit
    for the plan to have been still, and not before `lower`.
    """
    times = context.times
    lookback = profile.time_to(profile.zone_out + profile.zone_in) + _LOOKBACK_PAD_S
    lookback += 3.0 * context.period_s
    rest = int(np.searchsorted(times, times[exit_index] - lookback, side="left"))
    rest = min(max(rest, lower), exit_index)
    moved = context.distance(rest, exit_index + 1, context.rows(rest, rest + 1)[0])
    departure = _crossing(times[rest : exit_index + 1], moved, profile.threshold, 0)
    if departure is None:
        departure = float(times[exit_index])
    return departure - profile.time_to(profile.threshold)


def _auto_start(context: _Context) -> tuple[float, str]:
    """Return the first execution's start [s] and how it was found."""
    profile = context.profiles[0]
    count = len(context.times)
    if not profile.moves:
        return float(context.times[0]), "first sample"
    home = profile.trajectory.positions[0]
    distance = context.distance(0, count, home)
    exits, dwell = _exits(distance, profile.zone_in, profile.zone_out, inside_at_first=False)
    if len(exits):
        return _departure_start(context, profile, int(exits[0]), int(dwell[0])), "departure"
    # Never rested near the first point (the start check will say so), or never left it.
    rest = context.rows(0, 1)[0]
    moved = context.distance(0, count, rest)
    departure = _crossing(context.times, moved, profile.threshold, 0)
    if departure is None:
        return float(context.times[0]), "first sample"
    return departure - profile.time_to(profile.threshold), "first departure"


def _all_cycles(context: _Context) -> tuple[CycleCheck, ...]:
    """Return every execution of the plan: each departure from its first point, judged."""
    profile = context.profiles[0]
    times, count = context.times, len(context.times)
    if not profile.moves:
        raise InputError("the plan's first step does not move: executions cannot be told apart")
    home = profile.trajectory.positions[0]
    distance = context.distance(0, count, home)
    exits, dwell = _exits(distance, profile.zone_in, profile.zone_out, inside_at_first=False)
    if len(exits) == 0:
        closest = int(np.argmin(distance))
        raise InputError(
            f"no execution of the plan found: the robot never rests within {profile.zone_in:g} "
            f"rad of the plan's first point and then leaves it (closest approach "
            f"{distance[closest]:.4g} rad at {times[closest]:.3f} s)")
    cycle_s = sum(p.trajectory.duration_s for p in context.profiles)
    starts: list[float] = []
    accepted_exit = -math.inf
    for exit_index, lower in zip(exits.tolist(), dwell.tolist(), strict=True):
        if times[exit_index] - accepted_exit < _MIN_CYCLE_FRACTION * cycle_s:
            continue
        accepted_exit = float(times[exit_index])
        starts.append(_departure_start(context, profile, exit_index, lower))
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


# --- judging ------------------------------------------------------------------------------


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
            decided = int(np.searchsorted(context.times, previous.start_s + previous.duration_s,
                                          side="left"))
            start, aligned_by = _next_start(context, profile, min(decided, end - 1), end)
        report, decided_s = _judge_step(context, profile, start, end, end_reason)
        steps.append(StepCheck(profile.name, start, decided_s, report, aligned_by))
        if not report.ok:
            break
    return tuple(steps)


def _next_start(context: _Context, profile: _Profile, after: int, end: int) -> tuple[float, str]:
    """Return a later step's start: its departure after sample `after`, else that sample's time."""
    after = max(after, 0)
    fallback = float(context.times[min(after, len(context.times) - 1)])
    if not profile.moves or after >= end - 1:
        return fallback, "previous step"
    # Searched in growing windows: the robot usually departs soon. Without an exit in a
    # window the robot is still inside at its end, so the next window starts inside.
    times, begin = context.times, after
    window = profile.time_to(profile.zone_out + profile.zone_in) + 1.0
    while begin < end:
        stop = min(end, int(np.searchsorted(times, times[begin] + window, side="right")) + 1)
        distance = context.distance(begin, stop, profile.trajectory.positions[0])
        exits, _ = _exits(distance, profile.zone_in, profile.zone_out, inside_at_first=True)
        if len(exits):
            return _departure_start(context, profile, begin + int(exits[0]), after), "departure"
        begin, window = stop, 4.0 * window
    return fallback, "previous step"


def _judge_step(
    context: _Context, profile: _Profile, start: float, end: int, end_reason: str
) -> tuple[ToleranceReport, float]:
    """Return the step's verdict and the time [s] from its start to the deciding sample.

    Judged over growing spans of samples, so a step decided early does not sample the
    plan over the rest of an hour-long recording.
    """
    times = context.times
    trajectory = profile.trajectory
    first = int(np.searchsorted(times, start, side="left"))
    at_send = max(first - 1, 0) if first >= len(times) or times[first] > start else first
    current = context.rows(at_send, at_send + 1)[0]
    refused = check_start_state(trajectory.joint_names, current, trajectory.positions[0],
                                context.execution.allowed_start_tolerance, context.continuous)
    if refused is not None:
        return refused, 0.0
    if first >= end:
        message = f"the {end_reason} ends before the step's start at {start:.3f} s"
        return ToleranceReport(ExecutionResult(TIMED_OUT, "TIMED_OUT", message), (), {}, 0), 0.0
    duration = trajectory.duration_s
    timeout = _timeout(context, duration, float(times[end - 1]) - start, end_reason)
    point_before = _point_before(context, at_send, current)
    # A step that succeeds is decided a cycle or two past its last point.
    extra = 4.0 / context.controller.update_rate_hz + 4.0 * context.period_s + 0.02
    while True:
        stop = int(np.searchsorted(times, start + duration + extra, side="right"))
        stop = min(max(stop, first + 1), end)
        since = times[first:stop] - start
        reference, reference_v, _ = sample(trajectory, since, point_before=point_before,
                                           continuous=context.continuous)
        report = judge(
            context.tolerances, since, reference, context.rows(first, stop),
            # As the simulation: JTC takes the segment from the command's time, one period on.
            before_last_point=since + 1.0 / context.controller.update_rate_hz < duration,
            last_point_s=duration,
            timeout=timeout,
            reference_velocities=reference_v if context.check_velocities else None,
            actual_velocities=_velocities(context, first, stop),
            continuous=context.continuous,
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
    return context.velocities[begin:end][:, context.columns]


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
        velocities = context.velocities[index, context.columns]
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
