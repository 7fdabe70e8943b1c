"""Plots of a plan (`inspect --plot`) and of an execution or a checked recording (`execute`, `check-tolerances --plot`).

One PNG per command, one row of panels per joint, written atomically. The samples are
decimated to about POINTS_PER_SERIES per joint and series, each kept sample standing for
its bucket with the smallest and largest error in it, so memory stays bounded for long
recordings and no excursion between kept samples is hidden. plot_figures and tracking_figure
draw; they import matplotlib (Agg) only when drawing: a plain plan, execute or check never loads it.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import NDArray

from ...bag import PlanFile
from ...control import SCAN_ROWS, SampleSource, Violation, in_controller_order, position_error
from ...trajectory import PointBefore, sample
from .._plan_files import plan_config
from ..execution import (
    CheckedRecording,
    CheckRequest,
    ExecuteRequest,
    PlanExecution,
    StepRecorder,
    check,
    execute,
)
from ._figures import POINTS_PER_SERIES, position_units, step_budget, uncollected, write_png
from ._tracking import TrackedStep, Tracking, ViolationMark, tracking_figure

if TYPE_CHECKING:
    from ...config import ControllerConfig
    from ...control import CheckReport, ExecutionReport, StepCheck
    from ...types import JointTrajectory, TfSamples

__all__ = [
    "check_plotted", "checked_tracking", "execute_plotted", "thinned",
]

def execute_plotted(
    request: ExecuteRequest, plot: Path, output: Path | None = None, distro: str = "jazzy"
) -> PlanExecution:
    """Return what executing the plan did, drawn to the PNG `plot` (and written to `output` as it runs, if given).

    The PNG is written when the execution has its verdict, whatever it is, before the
    executed file is renamed into place; if anything fails, neither file is left.

    Raises:
        InputError: The plan is unreadable or invalid, or a file cannot be written.
        UsageError: `distro` has no shipped message definitions, or an output path is refused.

    """
    from ..report import execution_recorder

    @contextmanager
    def record(controller: ControllerConfig, plan: PlanFile, poses: bool) -> Iterator[StepRecorder]:
        drawn = _ExecutionPlot(request.plan, plan, plot)
        try:
            if output is None:
                yield drawn
            else:
                with execution_recorder(output, controller, plan, distro, poses) as written:
                    yield _Both(drawn, written)
        except BaseException:
            if drawn.written:
                plot.unlink(missing_ok=True)
            raise

    return execute(request, record, link_poses=output is not None)


def check_plotted(request: CheckRequest, plot: Path) -> CheckReport:
    """Return check-tolerances' verdict; one that is complete is also drawn to the PNG `plot`.

    With `start="all"`, the first failing cycle is drawn, else the first complete one.

    Raises:
        InputError: As `check`, or `plot` cannot be written.

    """

    @uncollected
    def draw(checked: CheckedRecording) -> None:
        if checked.report.complete:
            write_png(tracking_figure(checked_tracking(checked, request)), plot)

    return check(request, draw)


class _ExecutionPlot:
    """A StepRecorder keeping each step's samples, decimated, and drawing them when the execution ends."""

    def __init__(self, source: Path, plan: PlanFile, plot: Path) -> None:
        self._source = source
        self._plan = plan
        self._plot = plot
        self._total = sum(step.trajectory.duration_s for step in plan.steps)
        self._steps: list[TrackedStep] = []
        self._offset_s = 0.0
        self.written = False

    def add_tf(self, tf: TfSamples) -> None:
        """Ignore link poses: the plot draws joints; return None."""

    def add_step(self, report: ExecutionReport) -> None:
        """Keep the step's samples, decimated, on the execution's timeline; return None."""
        step = self._plan.steps[len(self._steps)]
        planned = step.trajectory.duration_s
        every = _every(len(report.times_s), step_budget(planned, self._total))
        series = thinned(report.times_s + self._offset_s, report.reference_positions, report.actual_positions,
                          report.error, every, last=True)
        self._steps.append(TrackedStep(step.name, self._offset_s, planned, self._offset_s + report.duration_s,
                                       *series, _marks(report.violations, self._offset_s)))
        self._offset_s += report.duration_s

    @uncollected
    def finish(self, execution: PlanExecution) -> None:
        """Draw the execution and write the PNG; return None."""
        controller = execution.controller
        last = execution.steps[-1]
        title = (f"moveplan execute {self._source.name}: {execution.result.name} - executed {len(execution.steps)} "
                 f"of {len(self._plan.steps)} steps in {execution.duration_s:.3f} s\n"
                 f"{_shortened(execution.result.message)}" + ("" if last.report.ok else f" (step '{last.name}')"))
        config = plan_config(self._plan, self._source)
        write_png(tracking_figure(_tracking(title, controller, position_units(config, controller.joints), self._steps)),
                  self._plot)
        self.written = True


class _Both:
    """Two StepRecorders fed together: the plot's first, so that its PNG is written before the file is renamed."""

    def __init__(self, first: StepRecorder, second: StepRecorder) -> None:
        self._recorders = (first, second)

    def add_tf(self, tf: TfSamples) -> None:
        """Hand link poses to both; return None."""
        for recorder in self._recorders:
            recorder.add_tf(tf)

    def add_step(self, report: ExecutionReport) -> None:
        """Hand a step's report to both; return None."""
        for recorder in self._recorders:
            recorder.add_step(report)

    def finish(self, execution: PlanExecution) -> None:
        """Hand the whole execution to both; return None."""
        for recorder in self._recorders:
            recorder.finish(execution)


def checked_tracking(checked: CheckedRecording, request: CheckRequest, points: int = POINTS_PER_SERIES) -> Tracking:
    """Return a checked execution's samples against the plan (about `points` per joint), and how to title it."""
    report, controller, plan = checked.report, checked.controller, checked.plan
    steps, which = _drawn_steps(report)
    samples = checked.samples
    columns = np.array([samples.names.index(j) for j in controller.joints], dtype=np.intp)
    continuous = np.array([j in checked.continuous for j in controller.joints])
    origin = steps[0].start_s if steps else 0.0
    total = sum(s.duration_s for s in steps) or 1.0
    tracked = []
    # The steps checked are the plan's, in order, from its first.
    hold = samples.read_positions(0, 1)[0, columns] if samples.count else None  # joints a partial goal leaves out
    for step, planned in zip(steps, plan.steps, strict=False):
        trajectory = in_controller_order(planned.trajectory, controller, hold)
        tracked.append(_recorded_step(samples, columns, continuous, step, trajectory, origin,
                                      step_budget(step.duration_s, total, points)))
    verdict = "within tolerances" if report.ok else report.result.name
    title = (f"moveplan check-tolerances {request.plan.name} {request.recording.name}: {verdict}{which}; "
             f"t = 0 is {round(origin, 3) + 0.0:.3f} s into the recording\n{_shortened(report.result.message)}")
    config = plan_config(plan, request.plan)
    return _tracking(title, controller, position_units(config, controller.joints), tracked)


def _drawn_steps(report: CheckReport) -> tuple[Sequence[StepCheck], str]:
    """Return the steps drawn and, for a recording of many cycles, which cycle they are (for the title)."""
    if not report.cycles:
        return report.steps, ""
    failing = [c for c in report.cycles if c.index in report.failing_cycles]
    if failing:
        cycle, why = failing[0], "the first that failed"
    else:
        cycle = next((c for c in report.cycles if c.steps and c.complete), report.cycles[0])
        why = "none failed: the first"
    return cycle.steps, f" - cycle {cycle.index} of {len(report.cycles)} drawn ({why})"


def _recorded_step(
    samples: SampleSource, columns: NDArray[np.intp], continuous: NDArray[np.bool_], step: StepCheck,
    trajectory: JointTrajectory, origin_s: float, budget: int,
) -> TrackedStep:
    """Return one checked step's recorded samples, decimated, against the plan sampled at their times."""
    begin = _search(samples, step.start_s, "left")
    end = max(_search(samples, step.start_s + step.duration_s, "right"), begin)
    every = _every(end - begin, budget)
    before = None
    if trajectory.times_s[0] > 0.0:  # JTC blends from the state it read when the goal came
        at_send = max(begin - 1, 0)
        before = PointBefore(samples.read_positions(at_send, at_send + 1)[0, columns])
    parts = []
    block = every * max(1, SCAN_ROWS // every)
    for at in range(begin, end, block):
        stop = min(at + block, end)
        since = samples.read_times(at, stop) - step.start_s
        actual = samples.read_positions(at, stop)[:, columns]
        reference = sample(trajectory, since, point_before=before, continuous=continuous, derivatives=0)[0]
        error = position_error(reference, actual, continuous)
        parts.append(thinned(since + step.start_s - origin_s, reference, actual, error, every, last=stop == end))
    n = len(columns)
    times_s, reference, actual, error, low, high = (
        np.concatenate([p[i] for p in parts]) if parts else np.zeros((0, n) if i else 0) for i in range(6))
    start = step.start_s - origin_s
    return TrackedStep(step.name, start, trajectory.duration_s, start + step.duration_s, times_s, reference, actual,
                       error, low, high, _marks(step.report.violations, start))


def _search(samples: SampleSource, time_s: float, side: Literal["left", "right"]) -> int:
    """Return where `time_s` [s] would go among the sample times (np.searchsorted), reading a few of them."""
    low, high = 0, samples.count
    while low < high:
        middle = (low + high) // 2
        value = float(samples.read_times(middle, middle + 1)[0])
        if value < time_s or (side == "right" and value == time_s):
            low = middle + 1
        else:
            high = middle
    return low


def _every(count: int, budget: int) -> int:
    """Return k: keeping every k-th of `count` samples keeps at most `budget`."""
    return max(1, math.ceil(count / max(budget, 1)))


_Series = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                NDArray[np.float64], NDArray[np.float64]]
"""Times, reference, actual, error, error min and error max of kept samples."""


def thinned(
    times: NDArray[np.float64], reference: NDArray[np.float64], actual: NDArray[np.float64],
    error: NDArray[np.float64], every: int, last: bool,
) -> _Series:
    """Return every `every`-th row (and the final one if `last`): times, reference, actual, error, error min, max.

    The min and max are over the rows each kept row stands for, so a peak between kept rows still shows.
    """
    count = len(times)
    if not count:
        n = reference.shape[1]
        return np.zeros(0), np.zeros((0, n)), np.zeros((0, n)), np.zeros((0, n)), np.zeros((0, n)), np.zeros((0, n))
    rows = np.arange(0, count, every)
    low, high = np.fmin.reduceat(error, rows, axis=0), np.fmax.reduceat(error, rows, axis=0)
    if last and rows[-1] != count - 1:
        rows = np.append(rows, count - 1)
        low, high = np.vstack((low, error[-1:])), np.vstack((high, error[-1:]))
    return times[rows], reference[rows], actual[rows], error[rows], low, high


def _marks(violations: Sequence[Violation], start_s: float) -> tuple[ViolationMark, ...]:
    """Return a step's violations on the plot's timeline (the step starts at `start_s` [s])."""
    return tuple(ViolationMark(start_s + v.time_s, v.joint, v.check, v.actual, v.error) for v in violations)


def _tracking(title: str, controller: ControllerConfig, units: Sequence[str], steps: Sequence[TrackedStep]) -> Tracking:
    """Return what tracking_figure draws: the steps, with the controller's tolerances per joint."""
    joints = controller.joints
    return Tracking(
        title=title, joints=joints, units=tuple(units), steps=tuple(steps),
        path_tolerance=np.array([controller.trajectory_tolerance.get(j, 0.0) for j in joints]),
        goal_tolerance=np.array([controller.goal_tolerance.get(j, 0.0) for j in joints]),
        goal_time_s=controller.goal_time_s,
        period_s=1.0 / controller.update_rate_hz,
    )


def _shortened(message: str, length: int = 150) -> str:
    """Return `message` cut to `length` characters: a title line, not a report."""
    return message if len(message) <= length else message[: length - 3] + "..."
