"""Verdicts of the JointTrajectoryController's per-cycle checks on time series.

The rules follow ros2_controllers' Jazzy-era joint_trajectory_controller (update())
and MoveIt's duration monitor. They work on time series, so the same code judges a
simulated execution and a recorded one: give it the reference the controller sampled,
the measured state and, per cycle, whether the controller was still before the
trajectory's last point.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ._moveit_checks import Timeout
from .margins import span_margins
from .results import (
    GOAL_TOLERANCE_VIOLATED,
    PATH_TOLERANCE_VIOLATED,
    SUCCESSFUL,
    TIMED_OUT,
    ToleranceReport,
    Violation,
    result_of,
)
from .tolerances import SegmentTolerances, StateTolerance, position_error, tolerance_limits

__all__ = ["judge", "judge_spans"]


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
    starts, stops = _span_bounds(span_starts, len(timeouts), len(series.times_s))
    outcomes = _outcomes(series, tolerances, before_last_point, starts, last_point_s)
    ends, decided = _deciding_cycles(outcomes, series.times_s, starts, stops, timeouts)
    # A span that runs out of cycles undecided says nothing of its goal: the robot may
    # still be on its way in.
    goal_checked = ~outcomes.before[ends] & decided[ends]
    margins = span_margins(series.joints, outcomes.magnitude, tolerances, outcomes.path_checked,
                           starts, ends, goal_checked)
    return [
        _report(series, tolerances, outcomes, int(end), int(end) - int(start), last_point_s,
                timeout, margin)
        for start, end, timeout, margin in zip(starts, ends, timeouts, margins, strict=True)
    ]


# --- the series and its spans ---------------------------------------------------------------


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


def _span_bounds(
    span_starts: npt.ArrayLike, span_count: int, cycle_count: int
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Return each span's first cycle and the cycle after its last, checked."""
    starts = np.asarray(span_starts, dtype=np.intp)
    stops = np.append(starts[1:], cycle_count)
    if len(starts) == 0 or len(starts) != span_count or starts[0] != 0 or np.any(stops <= starts):
        raise ValueError("span_starts: expected increasing indices from 0, one per timeout")
    return starts, stops


# --- what each cycle decides ----------------------------------------------------------------


@dataclass(frozen=True)
class _Outcomes:
    """What the checks find on each cycle of the stacked series: (K,), or (K, n) per joint.

    Attributes:
        before: The controller is before the trajectory's last point.
        path_checked: The path tolerances are checked: before the last point, or a span's first cycle.
        magnitude: |position error| per joint, (K, n).
        path_failed: Per joint, outside its path tolerance, (K, n).
        goal_failed: Per joint, outside its goal tolerance, (K, n).
        aborts_path: A path violation aborts the execution.
        succeeds: Past the last point and inside every goal tolerance.
        aborts_goal: Past the last point, outside a goal tolerance, later than a nonzero goal_time.
    """

    before: NDArray[np.bool_]
    path_checked: NDArray[np.bool_]
    magnitude: NDArray[np.float64]
    path_failed: NDArray[np.bool_]
    goal_failed: NDArray[np.bool_]
    aborts_path: NDArray[np.bool_]
    succeeds: NDArray[np.bool_]
    aborts_goal: NDArray[np.bool_]


def _outcomes(
    series: _Series, tolerances: SegmentTolerances, before_last_point: npt.ArrayLike,
    starts: NDArray[np.intp], last_point_s: float,
) -> _Outcomes:
    """Return what the path and goal checks find on every cycle."""
    before = np.asarray(before_last_point, dtype=bool)
    path_checked = before.copy()
    path_checked[starts] = True
    # A NaN error (a NaN sample) counts as an infinite one: outside every checked tolerance,
    # no margin, as JTC's `>` would not see it.
    magnitude = np.abs(series.error)
    np.fmin(magnitude, np.inf, out=magnitude)
    path_failed = _outside(magnitude, series.velocity_error, tolerances.state)
    goal_failed = _outside(magnitude, series.velocity_error, tolerances.goal)
    aborts_path = _any_per_row(path_failed) & path_checked
    succeeds = ~before & ~_any_per_row(goal_failed)
    late = series.times_s - last_point_s > tolerances.goal_time_s
    aborts_goal = ~before & ~succeeds & late & (tolerances.goal_time_s > 0.0)
    return _Outcomes(before, path_checked, magnitude, path_failed, goal_failed, aborts_path,
                     succeeds, aborts_goal)


def _deciding_cycles(
    outcomes: _Outcomes, times_s: NDArray[np.float64], starts: NDArray[np.intp],
    stops: NDArray[np.intp], timeouts: Sequence[Timeout],
) -> tuple[NDArray[np.intp], NDArray[np.bool_]]:
    """Return per span the cycle that ends it, and per cycle whether a check or timeout decides there."""
    lengths = stops - starts
    limit = np.repeat(np.array([t.time_s for t in timeouts], dtype=np.float64), lengths)
    decided = outcomes.aborts_path | outcomes.succeeds | outcomes.aborts_goal | (times_s > limit)
    times_out = decided.copy()
    times_out[stops - 1] = True
    decisive = np.flatnonzero(times_out)
    # Every span's last cycle decides, so each span's first decisive cycle lies inside it.
    return decisive[np.searchsorted(decisive, starts)], decided


def _outside_parts(
    error: NDArray[np.float64], velocity_error: NDArray[np.float64] | None,
    tolerances: Sequence[StateTolerance],
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Return per joint (of one cycle) whether position, resp. velocity, is outside its tolerance."""
    position, velocity = tolerance_limits(tolerances)
    # No acceleration errors are computed (no acceleration state), so they never fail.
    position_out = (position > 0.0) & ~(np.abs(error) <= position)  # NaN is outside
    if velocity_error is None:
        return position_out, np.zeros_like(position_out)
    return position_out, (velocity > 0.0) & ~(np.abs(velocity_error) <= velocity)


def _outside(
    magnitude: NDArray[np.float64], velocity_error: NDArray[np.float64] | None,
    tolerances: Sequence[StateTolerance],
) -> NDArray[np.bool_]:
    """Return per cycle and joint whether |error| `magnitude` or the velocity is outside."""
    position, velocity = tolerance_limits(tolerances)
    # A tolerance of 0 is not checked: nothing is above an infinite one.
    outside: NDArray[np.bool_] = magnitude > np.where(position > 0.0, position, np.inf)
    if velocity_error is not None and np.any(velocity > 0.0):
        outside |= (velocity > 0.0) & ~(np.abs(velocity_error) <= velocity)  # NaN is outside
    return outside


def _any_per_row(outside: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Return per cycle whether any joint is outside."""
    # Cheaper than any(axis=1) over few joints, as long as few cycles are outside.
    found = np.zeros(len(outside), dtype=bool)
    found[np.flatnonzero(outside) // max(outside.shape[1], 1)] = True
    return found


# --- reports --------------------------------------------------------------------------------


def _report(
    series: _Series, tolerances: SegmentTolerances, outcomes: _Outcomes, k: int, end_index: int,
    last_point_s: float, timeout: Timeout, margins: dict[str, float],
) -> ToleranceReport:
    """Return the report of a span decided at row `k` of `series`, its `end_index` in the span."""
    if outcomes.aborts_path[k]:
        violations = _state_violations(series, tolerances.state, outcomes.path_failed[k], k, "path")
        return ToleranceReport(result_of(PATH_TOLERANCE_VIOLATED, _path_message(violations)),
                               violations, margins, end_index)
    if outcomes.succeeds[k]:
        return ToleranceReport(result_of(SUCCESSFUL, "Goal successfully reached!"), (), margins,
                               end_index)
    outside = outcomes.goal_failed[k] & (not bool(outcomes.before[k]))
    state = _state_violations(series, tolerances.goal, outside, k, "goal", "stopped_velocity")
    t_end = float(series.times_s[k])
    if outcomes.aborts_goal[k]:
        # JTC's own message: it reports the time past the last point, not past goal_time.
        exceeded = t_end - last_point_s
        message = f"Aborted due to goal_time_tolerance exceeding by {exceeded:.6f} seconds"
        late_by = Violation("goal_time", "", t_end, last_point_s, t_end, last_point_s - t_end,
                            tolerances.goal_time_s)
        return ToleranceReport(result_of(GOAL_TOLERANCE_VIOLATED, message + _goal_details(state)),
                               (late_by, *state), margins, end_index)
    late_by = Violation("timeout", "", t_end, last_point_s, t_end, last_point_s - t_end,
                        timeout.time_s - last_point_s)
    return ToleranceReport(result_of(TIMED_OUT, timeout.message + _goal_details(state)),
                           (late_by, *state), margins, end_index)


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
    position, velocity = tolerance_limits(tolerances)
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


def _goal_details(violations: Sequence[Violation]) -> str:
    if not violations:
        return ""
    return "; outside goal tolerance: " + ", ".join(
        f"{v.joint} {v.check} {_error(v)}" for v in violations
    )


def _error(violation: Violation) -> str:
    """Return "error 0.21 > 0.2", or what is not finite: "actual nan (not a number)"."""
    if math.isfinite(violation.error):
        return f"error {violation.error:.6g} > {violation.tolerance:g}"
    which, value = "actual", violation.actual
    if math.isfinite(value):
        which, value = "reference", violation.reference
    if math.isfinite(value):
        return f"error {violation.error} > {violation.tolerance:g}"
    return f"{which} {value} ({'not a number' if math.isnan(value) else 'infinite'})"


def _path_message(violations: Sequence[Violation]) -> str:
    details = ", ".join(f"{v.joint} {_error(v)}" for v in violations)
    return f"Aborted due to path tolerance violation at {violations[0].time_s:.4f} s: {details}"
