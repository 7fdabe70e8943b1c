"""Tolerance rules of the JointTrajectoryController and of MoveIt's execution manager, and verdicts.

The rules follow ros2_controllers' Jazzy-era joint_trajectory_controller
(tolerances.hpp, update()) and MoveIt's TrajectoryExecutionManager. They work
on time series, so the same code judges a simulated execution and a recorded
one: give it the reference the controller sampled, the measured state and, per
cycle, whether the controller was still before the trajectory's last point.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ..config.robot_config import ControllerConfig, ExecutionConfig
from ..errors import InputError, UnknownName
from ..trajectory import shortest_angular_distance
from ..types import JointTrajectory

__all__ = [
    "in_controller_order",
    "GOAL_TOLERANCE_VIOLATED",
    "INCOMPLETE",
    "PATH_TOLERANCE_VIOLATED",
    "START_STATE_INVALID",
    "SUCCESSFUL",
    "TIMED_OUT",
    "ExecutionResult",
    "SegmentTolerances",
    "StateTolerance",
    "Timeout",
    "ToleranceReport",
    "Violation",
    "check_start_state",
    "check_state_tolerance_per_joint",
    "expected_duration_s",
    "judge",
    "judge_spans",
    "position_error",
    "segment_tolerances",
    "velocity_error_computable",
]

SUCCESSFUL = 0
PATH_TOLERANCE_VIOLATED = -4
GOAL_TOLERANCE_VIOLATED = -5
TIMED_OUT = -6
START_STATE_INVALID = -26
INCOMPLETE = -100
_NAMES = {
    SUCCESSFUL: "SUCCESSFUL",
    PATH_TOLERANCE_VIOLATED: "PATH_TOLERANCE_VIOLATED",
    GOAL_TOLERANCE_VIOLATED: "GOAL_TOLERANCE_VIOLATED",
    TIMED_OUT: "TIMED_OUT",
    START_STATE_INVALID: "START_STATE_INVALID",
    INCOMPLETE: "INCOMPLETE",
}


@dataclass(frozen=True)
class ExecutionResult:
    """How an execution ended: a numeric code, its name, and a message.

    Codes 0, -4 and -5 are control_msgs/FollowJointTrajectory result codes, as the
    JointTrajectoryController returns them. The two outcomes MoveIt decides use
    moveit_msgs/MoveItErrorCodes, whose values do not collide with those: TIMED_OUT (-6)
    is what MoveIt reports when its duration monitor stops an execution. MoveIt reports a
    start state too far from the plan's first point as ABORTED / CONTROL_FAILED (-4),
    which would read as a path violation here, so it is START_STATE_INVALID (-26), the
    MoveIt code for an unusable start state, with MoveIt's "start point deviates" message.
    INCOMPLETE (-100) is moveplan's own, outside both ranges (control_msgs uses 0 to -5,
    MoveItErrorCodes 1, 99999 and -1 to -31): a recording that cuts an execution off
    before the controller or MoveIt decided it, so there is no verdict to report.
    """

    code: int
    name: str
    message: str


def _result(code: int, message: str) -> ExecutionResult:
    return ExecutionResult(code, _NAMES[code], message)


@dataclass(frozen=True)
class Violation:
    """One failed check: which, where and when, with the numbers compared.

    `check` is one of path, goal, goal_time, stopped_velocity, start_tolerance, timeout.
    For state checks, values are positions in [rad] or [m] (velocities for
    stopped_velocity) and `error` is reference - actual. For the time checks
    (goal_time, timeout) `joint` is "", `reference` is the planned end time, `actual`
    the time the execution was stopped, `error` their difference and `tolerance` the
    lateness allowed, all in [s]. Times are from the trajectory's start.
    """

    check: str
    joint: str
    time_s: float
    reference: float
    actual: float
    error: float
    tolerance: float


@dataclass(frozen=True)
class StateTolerance:
    """Tolerances on position [rad], velocity [rad]/[s], acceleration [rad]/[s]^2; 0 = unchecked."""

    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass(frozen=True)
class SegmentTolerances:
    """The tolerances of one execution, per joint (JTC's SegmentTolerances).

    Attributes:
        joint_names: Joint order of `state` and `goal`.
        state: Path tolerances, checked while the trajectory runs.
        goal: Goal tolerances, checked at and after the last point.
        goal_time_s: Time after the last point to reach the goal in [s]; 0 = no limit.
    """

    joint_names: tuple[str, ...]
    state: tuple[StateTolerance, ...]
    goal: tuple[StateTolerance, ...]
    goal_time_s: float


def segment_tolerances(controller: ControllerConfig) -> SegmentTolerances:
    """Return the controller's default tolerances, built as JTC's get_segment_tolerances does."""
    joints = controller.joints
    path = controller.trajectory_tolerance
    goal = controller.goal_tolerance
    stopped = controller.stopped_velocity_tolerance
    return SegmentTolerances(
        joint_names=joints,
        state=tuple(StateTolerance(position=path.get(j, 0.0)) for j in joints),
        goal=tuple(StateTolerance(position=goal.get(j, 0.0), velocity=stopped) for j in joints),
        goal_time_s=controller.goal_time_s,
    )


def check_state_tolerance_per_joint(
    position_error: float,
    velocity_error: float,
    acceleration_error: float,
    tolerance: StateTolerance,
) -> bool:
    """Return True if the errors are within `tolerance`; only strictly above a nonzero one fails."""
    return not (
        (tolerance.position > 0.0 and abs(position_error) > tolerance.position)
        or (tolerance.velocity > 0.0 and abs(velocity_error) > tolerance.velocity)
        or (tolerance.acceleration > 0.0 and abs(acceleration_error) > tolerance.acceleration)
    )


def position_error(
    reference: npt.ArrayLike, actual: npt.ArrayLike, continuous: npt.ArrayLike | None = None
) -> NDArray[np.float64]:
    """Return reference - actual in [rad] or [m], as the shortest angle for continuous joints.

    Jazzy wraps only joints that are continuous in the URDF; Humble-era JTC wrapped all.
    """
    difference = np.asarray(reference, dtype=np.float64) - np.asarray(actual, dtype=np.float64)
    if continuous is None or not np.any(continuous):
        return difference
    wrapped = shortest_angular_distance(actual, reference)
    return np.where(np.asarray(continuous, dtype=bool), wrapped, difference)


def velocity_error_computable(controller: ControllerConfig) -> bool:
    """Return True if JTC computes velocity errors: velocity state, velocity or effort command.

    Otherwise the error stays 0, so velocity tolerances (stopped_velocity_tolerance too)
    never fail: a quirk of Jazzy-era compute_error_for_joint, kept on purpose.
    """
    commands = controller.command_interfaces
    velocity_state = "velocity" in controller.state_interfaces
    return velocity_state and ("velocity" in commands or "effort" in commands)


def expected_duration_s(duration_s: float, execution: ExecutionConfig) -> float:
    """Return MoveIt's upper bound on the execution time in [s]: duration x scaling + margin."""
    scaling = execution.allowed_execution_duration_scaling
    return float(duration_s * scaling + execution.allowed_goal_duration_margin)


@dataclass(frozen=True)
class Timeout:
    """When an unfinished execution is given up: after `time_s` [s], saying `message`."""

    time_s: float
    message: str


@dataclass(frozen=True)
class ToleranceReport:
    """The verdict on one execution.

    Attributes:
        result: How it ended.
        violations: The failed checks on the cycle it ended (empty on success).
        margins: Per joint with a nonzero position tolerance, the smallest tolerance - |error|
            in [rad]: over all path-checked cycles, and of the goal check on the final cycle.
        end_index: Index of the cycle on which it ended.
    """

    result: ExecutionResult
    violations: tuple[Violation, ...]
    margins: dict[str, float]
    end_index: int

    @property
    def ok(self) -> bool:
        """Return True if the execution succeeded."""
        return self.result.code == SUCCESSFUL


def check_start_state(
    joint_names: Sequence[str],
    start: npt.ArrayLike,
    first_point: npt.ArrayLike,
    allowed_start_tolerance: float,
    continuous: npt.ArrayLike | None = None,
) -> ToleranceReport | None:
    """Return a failed report if the start is too far from the first point, else None.

    MoveIt's TrajectoryExecutionManager check before it sends a trajectory: per joint
    distance (shortest angle for continuous joints) strictly above
    `allowed_start_tolerance` fails; a tolerance of 0 skips the check.
    """
    if allowed_start_tolerance <= 0.0:
        return None
    reference = np.asarray(first_point, dtype=np.float64)
    actual = np.asarray(start, dtype=np.float64)
    error = position_error(reference, actual, continuous)
    violations = tuple(
        Violation("start_tolerance", joint, 0.0, float(reference[j]), float(actual[j]),
                  float(error[j]), allowed_start_tolerance)
        for j, joint in enumerate(joint_names)
        if abs(error[j]) > allowed_start_tolerance
    )
    if not violations:
        return None
    first = violations[0]
    message = (
        f"Invalid Trajectory: start point deviates from current robot state more than "
        f"{allowed_start_tolerance:g} at joint '{first.joint}' (expected {first.reference:.6g}, "
        f"current {first.actual:.6g})"
    )
    return ToleranceReport(_result(START_STATE_INVALID, message), violations, {}, 0)


@dataclass(frozen=True)
class _Series:
    """Per-cycle values, each (K, n), with the joint names and cycle times (K,).

    The velocity arrays are None when no velocity errors are computed (they would be 0).
    """

    joints: tuple[str, ...]
    times_s: NDArray[np.float64]
    reference: NDArray[np.float64]
    actual: NDArray[np.float64]
    error: NDArray[np.float64]
    velocity_reference: NDArray[np.float64] | None
    velocity_actual: NDArray[np.float64] | None
    velocity_error: NDArray[np.float64] | None


def judge(
    tolerances: SegmentTolerances,
    times_s: npt.ArrayLike,
    reference_positions: npt.ArrayLike,
    actual_positions: npt.ArrayLike,
    before_last_point: npt.ArrayLike,
    last_point_s: float,
    timeout: Timeout,
    *,
    reference_velocities: npt.ArrayLike | None = None,
    actual_velocities: npt.ArrayLike | None = None,
    continuous: npt.ArrayLike | None = None,
) -> ToleranceReport:
    """Return the verdict of JTC's per-cycle checks on a time series, from the cycle that decides.

    Cycle k is path-checked if `before_last_point[k]` or k == 0 (the first sample is always
    checked); a path violation aborts. From the first cycle not before the last point the
    goal is checked: inside every goal tolerance succeeds; outside one, more than goal_time
    (if > 0) after `last_point_s` aborts. Undecided, the first cycle after `timeout.time_s`,
    or else the last cycle, ends it as TIMED_OUT.

    Args:
        tolerances: Tolerances in the column order of the arrays.
        times_s: Cycle times from the trajectory's start in [s], shape (K,).
        reference_positions: What the controller sampled at each cycle, (K, n).
        actual_positions: The measured positions, (K, n).
        before_last_point: Per cycle, True while the controller is before the last point.
        last_point_s: Time of the trajectory's last point in [s].
        timeout: When MoveIt (or the simulation) gives up.
        reference_velocities: (K, n), given with `actual_velocities` only when the controller
            computes velocity errors (`velocity_error_computable`); else velocity errors are 0.
        actual_velocities: (K, n) measured velocities.
        continuous: Per joint, True for continuous joints.
    """
    (report,) = judge_spans(
        tolerances, times_s, reference_positions, actual_positions, before_last_point,
        last_point_s, [0], [timeout], reference_velocities=reference_velocities,
        actual_velocities=actual_velocities, continuous=continuous,
    )
    return report


def judge_spans(
    tolerances: SegmentTolerances,
    times_s: npt.ArrayLike,
    reference_positions: npt.ArrayLike,
    actual_positions: npt.ArrayLike,
    before_last_point: npt.ArrayLike,
    last_point_s: float,
    span_starts: npt.ArrayLike,
    timeouts: Sequence[Timeout],
    *,
    reference_velocities: npt.ArrayLike | None = None,
    actual_velocities: npt.ArrayLike | None = None,
    continuous: npt.ArrayLike | None = None,
) -> list[ToleranceReport]:
    """Return `judge`'s verdict on each of several executions of one trajectory, stacked.

    Span s holds the cycles from `span_starts[s]` up to the next span's start (the last
    up to the end); its times are from its own trajectory start and its report's
    end_index counts from its first cycle. One pass over the stacked arrays judges them
    all: a long recording holds thousands of executions.

    Args:
        tolerances: As for `judge`.
        times_s: Cycle times of every span, each from its trajectory's start in [s], (K,).
        reference_positions: (K, n), as for `judge`; so are the other arrays.
        actual_positions: (K, n).
        before_last_point: (K,).
        last_point_s: Time of the trajectory's last point in [s], the same for every span.
        span_starts: Index of each span's first cycle, increasing from 0; no span is empty.
        timeouts: When MoveIt gives up on each span.
        reference_velocities: (K, n) or None, as for `judge`.
        actual_velocities: (K, n) or None.
        continuous: Per joint, True for continuous joints.
    """
    series = _series(tolerances.joint_names, times_s, reference_positions, actual_positions,
                     reference_velocities, actual_velocities, continuous)
    count = len(series.times_s)
    starts = np.asarray(span_starts, dtype=np.intp)
    stops = np.append(starts[1:], count)
    if len(starts) == 0 or len(starts) != len(timeouts) or starts[0] != 0 or np.any(stops <= starts):
        raise ValueError("span_starts: expected increasing indices from 0, one per timeout")
    before = np.asarray(before_last_point, dtype=bool)
    path_checked = before.copy()
    path_checked[starts] = True
    magnitude = np.abs(series.error)
    path_failed = _outside(magnitude, series.velocity_error, tolerances.state)
    goal_failed = _outside(magnitude, series.velocity_error, tolerances.goal)
    aborts_path = _any_per_row(path_failed) & path_checked
    succeeds = ~before & ~_any_per_row(goal_failed)
    late = series.times_s - last_point_s > tolerances.goal_time_s
    aborts_goal = ~before & ~succeeds & late & (tolerances.goal_time_s > 0.0)
    lengths = stops - starts
    limit = np.repeat(np.array([t.time_s for t in timeouts], dtype=np.float64), lengths)
    decided = aborts_path | succeeds | aborts_goal | (series.times_s > limit)
    times_out = decided.copy()
    times_out[stops - 1] = True
    decisive = np.flatnonzero(times_out)
    # Every span's last cycle decides, so each span's first decisive cycle lies inside it.
    ends = decisive[np.searchsorted(decisive, starts)]
    # A span that runs out of cycles undecided says nothing of its goal: the robot may
    # still be on its way in.
    goal_checked = ~before[ends] & decided[ends]
    margins = _margins(series, magnitude, tolerances, path_checked, starts, ends, goal_checked)
    return [
        _report(series, tolerances, int(end) - int(start), int(end), last_point_s, timeout,
                bool(aborts_path[end]), bool(succeeds[end]), bool(aborts_goal[end]),
                bool(before[end]), margin, path_failed[end], goal_failed[end])
        for start, end, timeout, margin in zip(starts, ends, timeouts, margins, strict=True)
    ]


def _report(
    series: _Series, tolerances: SegmentTolerances, end_index: int, k: int, last_point_s: float,
    timeout: Timeout, aborts_path: bool, succeeds: bool, aborts_goal: bool, before: bool,
    margins: dict[str, float], path_failed: NDArray[np.bool_], goal_failed: NDArray[np.bool_],
) -> ToleranceReport:
    """Return the report of a span decided at row `k` of `series`, its `end_index` in the span."""
    if aborts_path:
        violations = _state_violations(series, tolerances.state, path_failed, k, "path")
        return ToleranceReport(_result(PATH_TOLERANCE_VIOLATED, _path_message(violations)),
                               violations, margins, end_index)
    if succeeds:
        return ToleranceReport(_result(SUCCESSFUL, "Goal successfully reached!"), (), margins,
                               end_index)
    outside = goal_failed & (not before)
    state = _state_violations(series, tolerances.goal, outside, k, "goal", "stopped_velocity")
    t_end = float(series.times_s[k])
    if aborts_goal:
        # JTC's own message: it reports the time past the last point, not past goal_time.
        exceeded = t_end - last_point_s
        message = f"Aborted due to goal_time_tolerance exceeding by {exceeded:.6f} seconds"
        late_by = Violation("goal_time", "", t_end, last_point_s, t_end, last_point_s - t_end,
                            tolerances.goal_time_s)
        return ToleranceReport(_result(GOAL_TOLERANCE_VIOLATED, message + _goal_details(state)),
                               (late_by, *state), margins, end_index)
    late_by = Violation("timeout", "", t_end, last_point_s, t_end, last_point_s - t_end,
                        timeout.time_s - last_point_s)
    return ToleranceReport(_result(TIMED_OUT, timeout.message + _goal_details(state)),
                           (late_by, *state), margins, end_index)


def _series(
    joints: tuple[str, ...],
    times_s: npt.ArrayLike,
    reference: npt.ArrayLike,
    actual: npt.ArrayLike,
    velocity_reference: npt.ArrayLike | None,
    velocity_actual: npt.ArrayLike | None,
    continuous: npt.ArrayLike | None,
) -> _Series:
    # Read, not copied: the series lives only for one verdict, and copies of stacked
    # executions would cost as much as the checks.
    times = _checked(times_s, (None,), "times_s")
    if len(times) == 0:
        raise ValueError("a time series needs at least one cycle")
    shape = (len(times), len(joints))
    ref = _checked(reference, shape, "reference_positions")
    act = _checked(actual, shape, "actual_positions")
    error = position_error(ref, act, continuous)
    if velocity_reference is None or velocity_actual is None:
        return _Series(joints, times, ref, act, error, None, None, None)
    v_ref = _checked(velocity_reference, shape, "reference_velocities")
    v_act = _checked(velocity_actual, shape, "actual_velocities")
    return _Series(joints, times, ref, act, error, v_ref, v_act, v_ref - v_act)


def _checked(value: npt.ArrayLike, shape: tuple[int | None, ...], name: str) -> NDArray[np.float64]:
    """Return `value` as a float64 array, checked against `shape` (None = any size)."""
    array = np.asarray(value, dtype=np.float64)
    if array.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(array.shape, shape, strict=True)
    ):
        raise ValueError(f"{name}: expected shape {shape}, got {array.shape}")
    return array


def _limits(
    tolerances: Sequence[StateTolerance],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the position and velocity tolerances per joint."""
    position = np.array([t.position for t in tolerances], dtype=np.float64)
    velocity = np.array([t.velocity for t in tolerances], dtype=np.float64)
    return position, velocity


def _outside_parts(
    error: NDArray[np.float64], velocity_error: NDArray[np.float64] | None,
    tolerances: Sequence[StateTolerance],
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Return per joint (of one cycle) whether position, resp. velocity, is outside its tolerance."""
    position, velocity = _limits(tolerances)
    # No acceleration errors are computed (no acceleration state), so they never fail.
    position_out = (position > 0.0) & (np.abs(error) > position)
    if velocity_error is None:
        return position_out, np.zeros_like(position_out)
    return position_out, (velocity > 0.0) & (np.abs(velocity_error) > velocity)


def _outside(
    magnitude: NDArray[np.float64], velocity_error: NDArray[np.float64] | None,
    tolerances: Sequence[StateTolerance],
) -> NDArray[np.bool_]:
    """Return per cycle and joint whether |error| `magnitude` or the velocity is outside."""
    position, velocity = _limits(tolerances)
    # A tolerance of 0 is not checked: nothing is above an infinite one.
    outside: NDArray[np.bool_] = magnitude > np.where(position > 0.0, position, np.inf)
    if velocity_error is not None and np.any(velocity > 0.0):
        outside |= (velocity > 0.0) & (np.abs(velocity_error) > velocity)
    return outside


def _any_per_row(outside: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Return per cycle whether any joint is outside."""
    # Cheaper than any(axis=1) over few joints, as long as few cycles are outside.
    found = np.zeros(len(outside), dtype=bool)
    found[np.flatnonzero(outside) // max(outside.shape[1], 1)] = True
    return found


def _state_violations(
    series: _Series,
    tolerances: Sequence[StateTolerance],
    joints_outside: NDArray[np.bool_],
    k: int,
    position_check: str,
    velocity_check: str = "path",
) -> tuple[Violation, ...]:
    """Return cycle `k`'s violations of joints in `joints_outside`: positions, then velocities."""
    velocity_error = None if series.velocity_error is None else series.velocity_error[k]
    position_out, velocity_out = _outside_parts(series.error[k], velocity_error, tolerances)
    position, velocity = _limits(tolerances)
    t = float(series.times_s[k])
    found = [
        Violation(position_check, series.joints[j], t, float(series.reference[k, j]),
                  float(series.actual[k, j]), float(series.error[k, j]), float(position[j]))
        for j in map(int, np.flatnonzero(joints_outside & position_out))
    ]
    if series.velocity_reference is not None and series.velocity_actual is not None:
        assert series.velocity_error is not None
        found += [
            Violation(velocity_check, series.joints[j], t, float(series.velocity_reference[k, j]),
                      float(series.velocity_actual[k, j]), float(series.velocity_error[k, j]),
                      float(velocity[j]))
            for j in map(int, np.flatnonzero(joints_outside & velocity_out))
        ]
    return tuple(found)


def _margins(
    series: _Series, magnitude: NDArray[np.float64], tolerances: SegmentTolerances,
    path_checked: NDArray[np.bool_], starts: NDArray[np.intp], ends: NDArray[np.intp],
    goal: NDArray[np.bool_],
) -> list[dict[str, float]]:
    """Return per span the smallest position tolerance - |error| over the checks that ran.

    Span s counts its path-checked cycles up to `ends[s]`, and the goal check of cycle
    `ends[s]` if `goal[s]`. A goal margin before the last cycle says nothing: the robot
    may still be on its way in.
    """
    path, _ = _limits(tolerances.state)
    goal_tolerance, _ = _limits(tolerances.goal)
    values = path - magnitude
    values[~path_checked] = np.inf
    for end, stop in zip(ends.tolist(), [*starts[1:].tolist(), len(values)], strict=True):
        values[end + 1 : stop] = np.inf
    margin = np.where(path > 0.0, np.minimum.reduceat(values, starts, axis=0), np.inf)
    goal_margin = goal_tolerance - magnitude[ends]
    margin = np.where((goal_tolerance > 0.0) & goal[:, None], np.minimum(margin, goal_margin),
                      margin)
    return [
        {j: float(m) for j, m in zip(series.joints, row.tolist(), strict=True) if math.isfinite(m)}
        for row in margin
    ]


def _goal_details(violations: Sequence[Violation]) -> str:
    if not violations:
        return ""
    return "; outside goal tolerance: " + ", ".join(
        f"{v.joint} {v.check} error {v.error:.6g} > {v.tolerance:g}" for v in violations
    )


def _path_message(violations: Sequence[Violation]) -> str:
    details = ", ".join(f"{v.joint} error {v.error:.6g} > {v.tolerance:g}" for v in violations)
    return f"Aborted due to path tolerance violation at {violations[0].time_s:.4f} s: {details}"


def in_controller_order(
    trajectory: JointTrajectory, controller: ControllerConfig
) -> JointTrajectory:
    """Return the trajectory with columns in the controller's joint order, as JTC sorts goals."""
    for joint in trajectory.joint_names:
        if joint not in controller.joints:
            raise UnknownName("joint", joint, f"controller '{controller.name}'", controller.joints)
    missing = [j for j in controller.joints if j not in trajectory.joint_names]
    if missing:
        raise InputError(
            f"Joints on incoming trajectory don't match the controller joints: controller "
            f"'{controller.name}' also has {', '.join(missing)} (partial goals are not allowed)"
        )
    if trajectory.joint_names == controller.joints:
        return trajectory
    order = [trajectory.joint_names.index(j) for j in controller.joints]
    return JointTrajectory(
        controller.joints, trajectory.times_s, trajectory.positions[:, order],
        trajectory.velocities[:, order], trajectory.accelerations[:, order],
    )
