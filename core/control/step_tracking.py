"""Tracking figures of executed steps: a simulated step held past its verdict, a recorded step from its samples.

A step's verdict comes a cycle or two after its last point when the joints are within their
goal tolerances, too soon to see a joint ring. After success JTC holds the last point, and
the robot keeps moving as its gains make it: a simulated step is therefore observed
HOLD_S longer, on a copy of the plant (the next step still starts from where the verdict
left it), and a recorded step up to the next step's start or, for the last one, HOLD_S
past its verdict, as far as the recording goes.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..config import ControllerConfig
from ..trajectory import PointBefore, sample
from ..types import JointTrajectory
from .check import CheckReport, CycleCheck, SampleSource, StepCheck
from .quality import JointTracking, tracking
from .results import SUCCESSFUL
from .tolerances import in_controller_order, position_error

if TYPE_CHECKING:
    from .controller import ExecutionReport
    from .plants import Plant

__all__ = ["HOLD_S", "recorded_tracking", "sample_index", "simulated_tracking"]

HOLD_S = 2.0
"""How long [s] a step is observed past its verdict, holding its last point."""


def simulated_tracking(
    report: ExecutionReport,
    plant: Plant,
    last_point_s: float,
    goal_tolerances: NDArray[np.float64],
    continuous: NDArray[np.bool_],
    bumps: Sequence[tuple[float, int, float]] = (),
) -> dict[str, JointTracking]:
    """Return per joint how a simulated step tracked, held HOLD_S past a successful verdict.

    `plant` is the plant as the step left it (copied, not changed); `bumps` are (time [s]
    from the step's start, joint column, displacement) applied during the hold.
    """
    times, reference, error = report.times_s, report.reference_positions, report.error
    if report.result.code == SUCCESSFUL and len(times) > 1:
        dt = float(times[1] - times[0])
        count = max(1, round(HOLD_S / dt))
        held = np.repeat(reference[-1:], count, axis=0)
        moves = np.zeros_like(held)
        hold_times = times[-1] + dt * np.arange(1, count + 1)
        for time_s, column, delta in bumps:
            row = int(np.searchsorted(hold_times, time_s - 1e-9))
            if row < count:
                moves[row, column] += delta
        still = np.zeros_like(held)
        with np.errstate(over="ignore", invalid="ignore"):
            actual, _, _ = copy.deepcopy(plant).run(held, still, still, dt, moves)
        times = np.concatenate((times, hold_times))
        reference = np.vstack((reference, held))
        error = np.vstack((error, position_error(held, actual, continuous)))
    return tracking(report.joint_names, times, reference, error, last_point_s, goal_tolerances)


def recorded_tracking(
    report: CheckReport,
    trajectories: Sequence[JointTrajectory],
    samples: SampleSource,
    controller: ControllerConfig,
    continuous: NDArray[np.bool_],
) -> CheckReport:
    """Return the check's report with each judged step's tracking filled in, from the recorded samples.

    The steps are those of the single execution, or with `start="all"` of the cycle the
    result names (the first failing one, else the first complete one). `trajectories` are
    the plan's steps in order; the samples' columns are the controller's joints.
    """
    cycle = _reported_cycle(report)
    steps = report.steps if cycle is None else cycle.steps
    if not steps:
        return report
    later = [c.start_s for c in report.cycles if cycle is not None and c.start_s > cycle.start_s]
    goal = np.array([controller.goal_tolerance[j] for j in controller.joints])
    hold = samples.read_positions(0, 1)[0] if samples.count else None  # where joints a partial goal leaves out stay
    tracked = []
    for number, step in enumerate(steps):
        last = number + 1 == len(steps)
        end_s = step.start_s + step.duration_s + HOLD_S if last else steps[number + 1].start_s
        trajectory = in_controller_order(trajectories[number], controller, hold)
        figures = _recorded_step(step, trajectory, samples, min([end_s, *later]), goal, continuous)
        tracked.append(replace(step, report=replace(step.report, tracking=figures)))
    if cycle is None:
        return replace(report, steps=tuple(tracked))
    cycles = tuple(replace(c, steps=tuple(tracked)) if c is cycle else c for c in report.cycles)
    return replace(report, cycles=cycles)


def _reported_cycle(report: CheckReport) -> CycleCheck | None:
    """Return the cycle a `start="all"` report describes: its first failing, else its first complete one."""
    if not report.cycles:
        return None
    failing = set(report.failing_cycles)
    chosen = [c for c in report.cycles if c.index in failing] or [c for c in report.cycles if c.complete]
    return (chosen or list(report.cycles))[0]


def _recorded_step(
    step: StepCheck, trajectory: JointTrajectory, samples: SampleSource, end_s: float,
    goal_tolerances: NDArray[np.float64], continuous: NDArray[np.bool_],
) -> dict[str, JointTracking]:
    """Return one recorded step's figures over its samples from its start to `end_s` [s]."""
    first, stop = sample_index(samples, step.start_s), sample_index(samples, end_s)
    if stop <= first:
        return {}
    since = samples.read_times(first, stop) - step.start_s
    columns = [samples.names.index(j) for j in trajectory.joint_names]
    actual = samples.read_positions(first, stop)[:, columns]
    # As JTC blends from the state it read when the goal came: the first sample of the step.
    before = PointBefore(actual[0], None, None)
    reference, _, _ = sample(trajectory, since, point_before=before, continuous=continuous, derivatives=0)
    error = position_error(reference, actual, continuous)
    return tracking(trajectory.joint_names, since, reference, error, trajectory.duration_s, goal_tolerances)


def sample_index(samples: SampleSource, time_s: float) -> int:
    """Return the index of the first sample at or after `time_s` [s] (bisection: the store is on disk)."""
    low, high = 0, samples.count
    while low < high:
        middle = (low + high) // 2
        if float(samples.read_times(middle, middle + 1)[0]) < time_s - 1e-9:
            low = middle + 1
        else:
            high = middle
    return low
