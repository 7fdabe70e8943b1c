"""Results of execute and check-tolerances: their documents (in the executed file and `--json`), and the executed file.

One document per command, built here and nowhere else, so that the executed file and
`--json` say the same; numbers that are not finite (a diverged plant) are null, so every
document is strict JSON.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import asdict
from typing import TYPE_CHECKING, Any, cast

from .. import bag as recording
from ..bag import ExecutedStep, ExecutionWriter, execution_writer, seconds_to_ns, stamps_ns
from ..config import ControllerConfig
from ..control import (
    ExecutionReport,
    ExecutionSummary,
    JointTracking,
    controller_states,
    merged_tracking,
    unchecked_joints,
)
from ..errors import InputError
from ..types import TfSamples

if TYPE_CHECKING:
    from pathlib import Path

    from ..control import CheckReport, ExecutionResult, Violation
    from .execution import ExecuteRequest, PlanExecution

__all__ = [
    "ExecutionRecorder", "check_document", "execute_to_file", "execution_document", "execution_recorder", "finite",
    "finite_numbers", "tracking_document", "write_execution",
]


_BLOCK_CYCLES = 4096
"""Control cycles encoded and written at a time: the encoded messages of a long step stay a few MB."""


class ExecutionRecorder:
    """An executed file written while the execution runs (`execution_recorder`), one step at a time.

    Log times run from 0, the execution's start; each step starts where the one before it
    ended (its start plus its duration_s, in whole nanoseconds: no drift over many steps).
    """

    def __init__(self, writer: ExecutionWriter, controller: ControllerConfig) -> None:
        self._writer = writer
        self._controller = controller
        self._start_ns = 0

    def add_tf(self, tf: TfSamples) -> None:
        """Write link poses (times on the execution's timeline); add a step's before its cycles; return None."""
        self._writer.add_tf(tf)

    def add_step(self, report: ExecutionReport) -> None:
        """Write a step's cycles, in blocks, starting where the previous step ended; return None.

        Raises:
            ValueError: The report's output interface is not a JTC command interface.

        """
        times_ns = stamps_ns(report.times_s)
        for first in range(0, len(times_ns), _BLOCK_CYCLES):
            stop = first + _BLOCK_CYCLES
            block, block_ns = report.cycles(first, stop), times_ns[first:stop]
            states = controller_states(block, self._controller, self._start_ns + block_ns, block_ns)
            self._writer.add_cycles(ExecutedStep(block.joint_names, block.actual_positions, block.actual_velocities,
                                                 states))
        self._start_ns += seconds_to_ns(report.duration_s)

    def finish(self, execution: PlanExecution) -> None:
        """Write the result document when the last step ended: that is when it was known; return None."""
        self._writer.finish(execution_document(execution), self._start_ns)


@contextmanager
def execution_recorder(
    path: Path, controller: ControllerConfig, plan: recording.PlanFile, distro: str = "jazzy", tf: bool = False
) -> Iterator[ExecutionRecorder]:
    """Yield a recorder writing an executed file for `distro` to `path`, renamed into place when the block ends.

    The file has /robot_description (the plan's URDF), /tf if `tf`, and the block must end
    with `ExecutionRecorder.finish`; on any error no file is written.

    Raises:
        UsageError: `distro` has no shipped message definitions, or `path` cannot be an output file.
        InputError: `path` cannot be written.

    """
    urdf = recording.plan_urdf(plan)
    with execution_writer(path, controller=controller.name, urdf=urdf, distro=distro, tf=tf) as writer:
        yield ExecutionRecorder(writer, controller)


def execute_to_file(request: ExecuteRequest, path: Path, distro: str = "jazzy") -> PlanExecution:
    """Return what executing the plan did, written to `path` for `distro` as it runs (`execute -o`).

    Memory does not grow with the number of steps or the update rate: each step's samples
    go to the file as soon as the step is simulated. On any error no file is written.

    Raises:
        UsageError: `distro` has no shipped message definitions, or `path` cannot be an output file.
        InputError: The plan is unreadable or invalid, or `path` cannot be written.

    """
    from .execution import execute

    return execute(request, lambda controller, plan, tf: execution_recorder(path, controller, plan, distro, tf))


def write_execution(path: Path, execution: PlanExecution, distro: str = "jazzy", tf: TfSamples | None = None) -> None:
    """Write what `execution` did to `path` as a ROS 2 bag for `distro`, atomically; return None.

    Steps that carry their samples (reports built by hand) are written with `tf`, if given.
    An execution from `pipeline.execution.execute` keeps only per-step summaries: it is run
    again from its request straight into the file (the simulation is deterministic, so the
    file holds what it did); `execute_to_file` writes it in the one run.

    Raises:
        UsageError: `distro` has no shipped message definitions.
        InputError: `path` cannot be written.
        ValueError: A step's output interface is not a JTC command interface, or the steps
            are summaries and the execution has no request to run again.

    """
    if any(isinstance(step.report, ExecutionSummary) for step in execution.steps):
        if execution.request is None:
            raise ValueError("the execution kept only per-step summaries and has no request to run again")
        execute_to_file(execution.request, path, distro)
        return
    with execution_recorder(path, execution.controller, execution.plan, distro, tf is not None) as recorder:
        if tf is not None:
            recorder.add_tf(tf)
        for step in execution.steps:
            assert isinstance(step.report, ExecutionReport)
            recorder.add_step(step.report)
        recorder.finish(execution)


def execution_document(execution: PlanExecution, output: Path | None = None) -> dict[str, Any]:
    """Return the result document of an execution: the executed file's, and `execute --json`'s.

    Keys: ok, result {code, name, message}, violations (each with its step: step, check,
    joint, time_s, reference, actual, error, tolerance, unit of those four; times from the
    step's start), margins {joint: margin}, unchecked {path: [joints], goal: [joints]} (a
    tolerance of 0, which JTC does not check), then controller, duration_s and steps (name, ok, result,
    start_s and duration_s on the execution's timeline, tracking) and tracking (per joint, the
    worst over the steps: core.control.quality); last output, the executed file written, if
    `output` is given (the file's own document has none). Non-finite numbers are null.
    """
    steps, start_ns = [], 0
    for step in execution.steps:
        report = step.report
        steps.append(
            {
                "name": step.name,
                "ok": report.ok,
                "result": report.result.name,
                "start_s": start_ns / 1e9,
                "duration_s": report.duration_s,
                "tracking": tracking_document(getattr(report, "tracking", {})),
            }
        )
        start_ns += seconds_to_ns(report.duration_s)
    document: dict[str, Any] = {
        **_verdict(execution.ok, execution.result, execution.violations, execution.margins,
                   execution.prismatic),
        "unchecked": {check: list(joints) for check, joints in unchecked_joints(execution.controller).items()},
        "controller": execution.controller.name,
        "duration_s": start_ns / 1e9,
        "steps": steps,
        "tracking": tracking_document(execution.tracking),
    }
    if output is not None:
        document["output"] = str(output)
    return cast(dict[str, Any], _finite_numbers(document))


def check_document(report: CheckReport, recording: Path) -> dict[str, Any]:
    """Return the result document of a check of `recording`: `check-tolerances --json`'s.

    Keys: ok, result, violations, margins and unchecked as in `execution_document`; duration_s and
    start_s (the first execution's start, from the recording's first sample); steps (name,
    ok, result, start_s, duration_s, aligned_by); gaps [{start_s, length_s}]; warnings;
    skipped [{file, offset, part, reason}], the damaged parts of the recording left out (--skip-damaged);
    error, null unless no execution is complete: then {exit_code, kind, message}, the check
    could not be done on this recording (bad input). With `start="all"` also cycles
    [{index, start_s, ok, result, worst_margin}], failing_cycles and incomplete_cycles.
    "ok" of a step or cycle is null when the recording cuts it off before a verdict
    (INCOMPLETE). tracking, per joint, over the steps (each step's under steps); with
    `start="all"` over the steps of the cycle tracking_cycle names. Non-finite numbers are null.
    """
    error = None
    if not report.complete:
        cut = InputError(f"{recording}: {report.result.message}")
        error = {"exit_code": cut.exit_code, "kind": cut.kind, "message": str(cut)}
    document: dict[str, Any] = {
        **_verdict(report.ok, report.result, report.violations, report.margins, report.prismatic),
        "unchecked": {check: list(joints) for check, joints in report.unchecked.items()},
        "duration_s": report.duration_s,
        "start_s": report.start_s,
        "steps": [{"name": s.name, "ok": s.ok if s.complete else None, "result": s.report.result.name,
                   "start_s": s.start_s, "duration_s": s.duration_s, "aligned_by": s.aligned_by,
                   "tracking": tracking_document(s.report.tracking)}
                  for s in report.steps],
        "gaps": [{"start_s": start, "length_s": length} for start, length in report.gaps],
        "warnings": list(report.warnings),
        "skipped": [part.as_dict() for part in report.skipped],
        "error": error,
    }
    tracked = [c for c in report.cycles if any(step.report.tracking for step in c.steps)]
    steps = tracked[0].steps if tracked else report.steps
    document["tracking"] = tracking_document(merged_tracking([step.report.tracking for step in steps]))
    if report.cycles:
        document["tracking_cycle"] = tracked[0].index if tracked else None
        document["cycles"] = [{"index": c.index, "start_s": c.start_s, "ok": c.ok if c.complete else None,
                               "result": _result(c.result), "worst_margin": c.worst_margin}
                              for c in report.cycles]
        document["failing_cycles"] = list(report.failing_cycles)
        document["incomplete_cycles"] = list(report.incomplete_cycles)
    return cast(dict[str, Any], _finite_numbers(document))


def tracking_document(figures: Mapping[str, JointTracking]) -> dict[str, dict[str, Any]]:
    """Return tracking figures by joint as JSON: peak_error, overshoot, settling_time_s, oscillations, ..."""
    return {joint: asdict(each) for joint, each in figures.items()}


def finite(value: float) -> float | None:
    """Return `value` as a float, or None (JSON null) if NaN or infinite (a diverged plant)."""
    number = float(value)
    return number if math.isfinite(number) else None


def _verdict(
    ok: bool, result: ExecutionResult, violations: Iterable[tuple[str, Violation]], margins: Mapping[str, float],
    prismatic: Iterable[str] = (),
) -> dict[str, Any]:
    """Return the head both documents share: ok, result, violations (with their step and unit), margins."""
    linear = frozenset(prismatic)
    return {
        "ok": ok,
        "result": _result(result),
        "violations": [
            {
                "step": step,
                "check": v.check,
                "joint": v.joint,
                "time_s": v.time_s,
                "reference": v.reference,
                "actual": v.actual,
                "error": v.error,
                "tolerance": v.tolerance,
                "unit": _unit(v, linear),
            }
            for step, v in violations
        ],
        "margins": dict(margins),
    }


def _unit(violation: Violation, prismatic: frozenset[str]) -> str:
    """Return the unit of a violation's numbers: s for the time checks, else the joint's position or velocity unit."""
    if violation.check in ("goal_time", "timeout"):
        return "s"
    length = "m" if violation.joint in prismatic else "rad"
    return f"{length}/s" if violation.check == "stopped_velocity" else length


def _result(result: ExecutionResult) -> dict[str, Any]:
    return {"code": result.code, "name": result.name, "message": result.message}


def finite_numbers(value: Any) -> Any:
    """Return `value` with every float in it, at any depth, made `finite` (JSON null if not): strict JSON."""
    return _finite_numbers(value)


def _finite_numbers(value: Any) -> Any:
    """Return `value` with every float in it, at any depth, made `finite`: strict JSON."""
    if isinstance(value, float):
        return finite(value)
    if isinstance(value, dict):
        return {key: _finite_numbers(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_finite_numbers(item) for item in value]
    return value
