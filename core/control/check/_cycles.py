"""Executions of a plan in a recording: each judged step by step, and every cycle of a repeating robot."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...trajectory import sample
from ..results import INCOMPLETE, ExecutionResult
from ..tolerances import position_error
from ._alignment import ZONE_RAD, cycle_starts, next_start
from ._context import CheckContext
from ._verdicts import execution_verdict
from ._windows import judge_steps
from .report import CycleCheck, StepCheck

__all__ = ["all_cycles", "already_running", "executions"]


def executions(
    context: CheckContext, starts: Sequence[float], aligned_by: Sequence[str], ends: Sequence[int],
    end_reasons: Sequence[str],
) -> list[tuple[StepCheck, ...]]:
    """Return the steps of each execution judged in turn, each up to its first that fails.

    Step by step, every execution still going is judged in one pass. Samples of execution
    i at indices >= `ends[i]` belong to something else (the next cycle, or none exist).
    """
    samples = context.samples
    steps: list[list[StepCheck]] = [[] for _ in starts]
    begins, hows = list(starts), list(aligned_by)
    going = list(range(len(starts)))
    for number, profile in enumerate(context.profiles):
        if number > 0:
            going = [i for i in going if steps[i][-1].ok]
            for i in going:
                previous = steps[i][-1]
                decided = samples.search(previous.start_s + previous.duration_s, side="left")
                begins[i], hows[i] = next_start(context.samples, profile,
                                                min(decided, ends[i] - 1), ends[i])
        verdicts = judge_steps(context, profile, [begins[i] for i in going],
                               [ends[i] for i in going], [end_reasons[i] for i in going])
        for i, (report, decided_s) in zip(going, verdicts, strict=True):
            steps[i].append(StepCheck(profile.name, begins[i], decided_s, report, hows[i]))
    return [tuple(s) for s in steps]


def all_cycles(context: CheckContext) -> tuple[CycleCheck, ...]:
    """Return every execution of the plan found in the recording, judged."""
    samples = context.samples
    starts = cycle_starts(samples, context.profiles)
    # Each execution ends where the next one starts.
    ends = samples.search_many(starts[1:], side="left").tolist()
    ends.append(samples.count)
    reasons = ["next cycle"] * (len(starts) - 1) + ["recording"]
    judged = executions(context, starts, ["departure"] * len(starts), ends, reasons)
    cycles = [(start, steps, execution_verdict(context, start, steps))
              for start, steps in zip(starts, judged, strict=True)]
    running = already_running(context)
    if running:
        cycles.insert(0, (samples.first_time, (), ExecutionResult(INCOMPLETE, "INCOMPLETE", running)))
    return tuple(CycleCheck(index, start, steps, result)
                 for index, (start, steps, result) in enumerate(cycles))


def already_running(context: CheckContext) -> str:
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
