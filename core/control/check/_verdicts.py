"""Verdicts of a recording check: an execution's result, and the report on one or every execution."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from ..margins import merged_margins
from ..results import INCOMPLETE, SUCCESSFUL, ExecutionResult, Violation
from ._context import CheckContext
from .report import CheckReport, CycleCheck, StepCheck

__all__ = ["cycles_report", "execution_report", "execution_verdict"]


def execution_verdict(context: CheckContext, start: float, steps: Sequence[StepCheck]) -> ExecutionResult:
    """Return an execution's result: its failure, else INCOMPLETE if the recording cuts it off."""
    last = steps[-1]
    result = last.report.result
    samples = context.samples
    if result.code == INCOMPLETE:
        number = len(steps) - 1
        remaining = (last.start_s + context.profiles[number].trajectory.duration_s - samples.last_time
                     + sum(p.trajectory.duration_s for p in context.profiles[number + 1 :]))
        if remaining > 0.0:
            return replace(result, message=(
                f"the recording ends {remaining:.3f} s before the plan's execution could finish "
                f"(step '{last.name}': {result.message})"))
        return replace(result, message=f"the recording ends before the controller decided step "
                                       f"'{last.name}' ({result.message})")
    if result.code == SUCCESSFUL and context.before_recording(start):
        return ExecutionResult(INCOMPLETE, "INCOMPLETE", (
            f"the recording begins about {samples.first_time - start:.3f} s after the execution started: "
            "its start state and first motion are not recorded"))
    return result


def execution_report(
    context: CheckContext, start: float, steps: tuple[StepCheck, ...],
    gaps: tuple[tuple[float, float], ...], warnings: Sequence[str], start_ns: int,
) -> CheckReport:
    """Return the report on the one execution that started at `start` [s], judged as `steps`."""
    last = steps[-1]
    result = execution_verdict(context, start, steps)
    return CheckReport(
        ok=result.code == SUCCESSFUL,
        result=result,
        violations=tuple((s.name, v) for s in steps for v in s.report.violations),
        margins=merged_margins(s.report.margins for s in steps),
        duration_s=last.start_s + last.duration_s - start,
        start_s=start,
        steps=steps,
        cycles=(),
        failing_cycles=(),
        incomplete_cycles=(),
        gaps=gaps,
        warnings=tuple(warnings),
        recording_start_ns=start_ns,
    )


def cycles_report(
    cycles: tuple[CycleCheck, ...], gaps: tuple[tuple[float, float], ...], warnings: Sequence[str],
    start_ns: int,
) -> CheckReport:
    """Return the report on every execution found (`start="all"`), naming the first that failed."""
    failing = tuple(c.index for c in cycles if not c.ok and c.complete)
    incomplete = tuple(c.index for c in cycles if not c.complete)
    complete = len(cycles) - len(incomplete)
    margins = merged_margins(step.report.margins for cycle in cycles for step in cycle.steps)
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
