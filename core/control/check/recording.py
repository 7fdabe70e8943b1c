"""Tolerance checks of recorded executions: a recording judged by the live controller's rules.

The rules are those of tolerances, judging and moveit_checks, as the simulated controller
applies them: the plan is sampled as JTC interpolates it (core.trajectory.sample) at the
recorded times, path tolerances hold before the last point, goal tolerances within
goal_time after it, the stopped-velocity tolerance only where JTC computes velocity
errors, and MoveIt checks the start state and the duration envelope. The recorded samples stand in for controller
cycles: a recording sparser than the controller's update rate can miss a short excursion.

Each step of a plan is one FollowJointTrajectory goal, as MoveIt executes a plan: judged
alone from its own start, and the first failing step ends the execution. (Not the
concatenation on the plan's timeline: a real robot pauses between goals for as long as
MoveIt takes to send the next one.) Where each goal started is alignment's to find;
a number for `start` puts the first step there instead, in seconds from the recording's
first sample.

An execution the recording cuts off is INCOMPLETE, not failed: one still undecided when
the recording ends, one whose goal was sent before the recording's first sample (its start
state is not recorded, so MoveIt's start check is skipped), and, with `start="all"`, one
already running when the recording began. A violation seen before the cut is still that
failure.

This module is the entry point; the parts are samples (the recording, read a block at a
time from memory or from a store on disk), context (what the checks share), windows (one
step judged over windows of samples), cycles (executions step by step, and every cycle),
verdicts (results and reports) and report (the values).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Literal

from ...config import ControllerConfig, ExecutionConfig
from ...errors import InputError, UsageError
from ...types import JointStateSeries
from ..tolerances import velocity_error_computable
from ._alignment import find_gaps, first_start
from ._context import CheckContext, CheckedPlan
from ._cycles import all_cycles, already_running, executions
from ._verdicts import cycles_report, execution_report
from .report import CheckReport, StepCheck
from .samples import SampleSource, source_of

__all__ = ["RecordingStart", "SampleSource", "check_recording", "uses_velocities"]

RecordingStart = float | Literal["auto", "all"]
"""Where the check starts: "auto", "all", or a time in [s] from the recording's first sample."""


def check_recording(
    plan: CheckedPlan,
    series: JointStateSeries | SampleSource,
    controller: ControllerConfig,
    execution: ExecutionConfig,
    continuous_joints: Iterable[str] = (),
    start: RecordingStart = "auto",
) -> CheckReport:
    """Return the verdict of the controller's and MoveIt's checks on a recorded execution.

    Args:
        plan: The plan: steps with name, start_s and trajectory (a PlanFile).
        series: The recorded joint states, in memory or read by row ranges (core.bag's
            JointStateStore: memory then does not grow with the recording); must hold
            every controller joint.
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
    recording = source_of(series)
    context = CheckContext.build(plan, recording, controller, execution, continuous_joints)
    warnings = list(context.warnings)
    gaps = find_gaps(context.samples, warnings)
    if start == "all":
        return cycles_report(all_cycles(context), gaps, warnings, recording.start_ns)
    first, aligned_by = _first_start(context, start, warnings)
    (steps,) = executions(context, [first], [aligned_by], [recording.count], ["recording"])
    warnings += _alignment_warnings(steps)
    return execution_report(context, first, steps, gaps, warnings, recording.start_ns)


def uses_velocities(plan: CheckedPlan, controller: ControllerConfig) -> bool:
    """Return True if `check_recording` reads the recorded velocities for this plan and controller.

    JTC computes velocity errors only with some interfaces, and blends from the velocity it
    read only into a first point after time 0.
    """
    blends = any(step.trajectory.times_s[0] > 0.0 for step in plan.steps)
    return velocity_error_computable(controller) or (
        blends and "velocity" in controller.state_interfaces)


def _first_start(context: CheckContext, start: RecordingStart, warnings: list[str]) -> tuple[float, str]:
    """Return where the one execution checked starts, in [s], and how that was found."""
    if isinstance(start, str):
        if start != "auto":
            raise UsageError(f"start must be 'auto', 'all' or a time in seconds, got '{start}'")
        first, aligned_by = first_start(context.samples, context.profiles[0])
        running = already_running(context) if aligned_by == "departure" else ""
        if running:
            warnings.append(f"{running}; the first execution found starts at {first:.3f} s")
        return first, aligned_by
    first = float(start)
    if not math.isfinite(first):
        raise UsageError(f"start must be a finite time in seconds, got {start}")
    return first, "given"


def _alignment_warnings(steps: Sequence[StepCheck]) -> list[str]:
    """Return a warning for each step whose start was not found by a departure from its first point."""
    return [
        f"step '{step.name}': start at {step.start_s:.3f} s found by "
        f"{step.aligned_by} (no departure from its first point was seen)"
        for step in steps
        if step.aligned_by in ("first departure", "first sample", "previous step")
    ]
