"""One step of a plan judged over windows of a recording: the samples from its start, batched.

A window is a step's goal as sent at a start found in the recording: MoveIt's start
check at the send, then the controller's checks over the samples from there on, stacked
with the other windows of the same step so that one pass judges thousands of executions.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ...trajectory import PointBefore, sample
from .._judging import judge_spans
from .._moveit_checks import Timeout, check_start_state, expected_duration_s
from ..controller import WAIT_LIMIT_S
from ..results import INCOMPLETE, TIMED_OUT, ExecutionResult, ToleranceReport
from ..tolerances import SegmentTolerances
from ._alignment import StepProfile
from ._context import CheckContext

__all__ = ["judge_steps"]

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


def judge_steps(
    context: CheckContext, profile: StepProfile, starts: Sequence[float], ends: Sequence[int],
    end_reasons: Sequence[str],
) -> list[tuple[ToleranceReport, float]]:
    """Return per execution the step's verdict and the time [s] from its start to the deciding sample.

    Execution i's goal is sent at `starts[i]` [s]; its samples end before index `ends[i]`,
    and `end_reasons[i]` says what ends them: "recording" or "next cycle". Judged first over
    the samples up to a little past the step's end, then, for the few still undecided there,
    over growing spans: a step decided early does not sample the plan over the rest of an
    hour-long recording.
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
    context: CheckContext, profile: StepProfile, start: float, end: int, end_reason: str
) -> _Window | tuple[ToleranceReport, float]:
    """Return the step's goal as sent at `start`, or its verdict if it is decided at once."""
    samples = context.samples
    trajectory = profile.trajectory
    first = samples.search(start, side="left")
    at_send = max(first - 1, 0) if first >= samples.count or samples.time(first) > start else first
    current = samples.rows(at_send, at_send + 1)[0]
    if not context.before_recording(start):  # else the state at the send was not recorded
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
    last_s = samples.time(end - 1) - start
    timeout = _timeout(context, trajectory.duration_s, last_s, end_reason, context.tolerances_of(profile.name))
    # The recording ends before MoveIt would give up: its end cannot be a real timeout.
    runs_out = cut and last_s <= timeout.time_s
    return _Window(start, first, end, at_send, current, timeout, runs_out)


def _judge_windows(
    context: CheckContext, profile: StepProfile, windows: Sequence[_Window], extra: float
) -> list[tuple[ToleranceReport, float, bool]]:
    """Return per window the verdict over its samples up to `extra` [s] past the step's end.

    With the time [s] from the start to the deciding sample, and whether the verdict is
    only that the samples ran out before the step was decided (a longer span may decide it).
    """
    if not windows:
        return []
    duration = profile.trajectory.duration_s
    firsts = np.array([w.first for w in windows], dtype=np.intp)
    ends = np.array([w.end for w in windows], dtype=np.intp)
    stops = context.samples.search_many([w.start + duration + extra for w in windows], side="right")
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
    context: CheckContext, profile: StepProfile, windows: Sequence[_Window],
    firsts: NDArray[np.intp], stops: NDArray[np.intp],
) -> list[tuple[ToleranceReport, float, bool]]:
    """Return `_judge_windows`' verdicts, the windows judged over samples [firsts, stops) at once."""
    samples = context.samples
    trajectory = profile.trajectory
    duration = trajectory.duration_s
    lengths = stops - firsts
    span_starts = np.concatenate(([0], np.cumsum(lengths)[:-1]))
    begins, ends = firsts.tolist(), stops.tolist()
    since = np.concatenate([samples.times(b, e) - w.start
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
        context.tolerances_of(profile.name), since, reference, samples.spans(begins, ends),
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
    context: CheckContext, begins: Sequence[int], ends: Sequence[int]
) -> NDArray[np.float64] | None:
    """Return recorded velocities of samples [begins[i], ends[i]) when JTC computes velocity errors."""
    if not context.check_velocities:
        return None
    return context.samples.velocity_spans(begins, ends)


def _timeout(context: CheckContext, duration: float, last_s: float, end_reason: str,
             tolerances: SegmentTolerances) -> Timeout:
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
    goal_time = tolerances.goal_time_s
    waits = "forever" if goal_time == 0.0 else f"{goal_time:g} s after the last point"
    return Timeout(limit, (
        f"the {end_reason} ends {last_s:.3f} s after the step's start, before the controller "
        f"decided (it waits for the goal tolerance {waits})"))


def _point_before(context: CheckContext, window: _Window) -> PointBefore:
    """Return the state JTC blends from, with the fields its state interfaces provide."""
    states = context.controller.state_interfaces
    velocities = None
    if "velocity" in states and context.samples.has_velocities:
        velocities = context.samples.velocity_spans([window.at_send], [window.at_send + 1])[0]
    accelerations = None
    if velocities is not None and "acceleration" in states:
        accelerations = np.zeros_like(window.current)  # no acceleration is recorded: read as 0
    return PointBefore(window.current, velocities, accelerations)
